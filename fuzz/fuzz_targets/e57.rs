//! Any bytes fed to the ASTM E57 reader (binary header, CRC pages, XML, compressed vector
//! sections) give a cloud or Err, never a panic or an unbounded allocation. Read from
//! memory: nothing is written to disk.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "cloud_common.rs"]
mod cloud_common;

fuzz_target!(|data: &[u8]| {
    if let Ok(c) = rdaylight::recon::e57::read_from(std::io::Cursor::new(data), "fuzz.e57") {
        cloud_common::check(&c);
    }
});
