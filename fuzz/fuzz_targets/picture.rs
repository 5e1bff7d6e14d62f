//! Any bytes fed to the picture reader (header, resolution string, flat/old/new RLE and
//! spectral scanlines) give Ok or Err, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = rdaylight::formats::picture::Picture::read(std::io::Cursor::new(data), "fuzz") {
        let _ = p.radiance_values();
        let _ = p.view_strings();
    }
});
