//! Any bytes fed to the PLY (ascii, binary little and big endian; header, element counts, property lists) point-cloud reader give a cloud or Err, never a panic or an
//! unbounded allocation; a cloud that reads has one entry per point in each per-point array.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "cloud_common.rs"]
mod cloud_common;

fuzz_target!(|data: &[u8]| {
    if let Ok(c) = rdaylight::recon::ply::read(data, "fuzz.ply") {
        cloud_common::check(&c);
    }
});
