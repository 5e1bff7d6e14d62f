//! Any bytes fed to the PNG/JPEG readers (`ruplift photo`'s photo as linear RGB, and the
//! material mask of `ruplift photo` and `proxy`) give a picture or Err, never a panic or an
//! unbounded allocation: sizes are checked from the header before pixels are decoded.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::uplift::mask::LabelMap;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = rdaylight::formats::picture::preview::read_photo_bytes(data, "fuzz.png") {
        assert_eq!(p.data.len(), p.width * p.height * 3);
    }
    if let Ok(m) = LabelMap::from_bytes(data, None, "fuzz-mask.png") {
        assert_eq!(m.labels.len(), m.width * m.height);
        let _ = m.regions();
        let _ = m.erode(1);
    }
});
