//! Any bytes fed to the OpenEXR reader (what `ruplift proxy` and the picture tools read)
//! give a picture or Err, never a panic or an unbounded allocation: sizes are checked from
//! the headers before any pixel is decoded.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) =
        rdaylight::formats::picture::exr::read_exr_from(std::io::Cursor::new(data), "fuzz.exr")
    {
        assert_eq!(p.data.len(), p.width * p.height * p.channels.ncomp);
        let _ = p.radiance_values();
    }
});
