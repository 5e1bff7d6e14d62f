//! Any bytes fed to the Radiance header reader give Ok or Err, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut r = std::io::Cursor::new(data);
    if let Ok(h) = rdaylight::formats::header::Header::read(&mut r, "fuzz") {
        let _ = h.format();
        let _ = h.exposure();
        let _ = h.colorcorr();
        let _ = h.pixaspect();
        let _ = h.big_endian("fuzz");
        let _ = h.get_usize("NROWS", "fuzz");
        let _ = h.wavelength_splits("fuzz");
        let _ = h.channels("fuzz");
    }
});
