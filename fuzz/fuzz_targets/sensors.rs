//! Any bytes fed to the sensor-ray reader (ascii, float and double records) and to the CSV
//! sensor reader give rays or Err, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::formats::sensors::{RayFormat, RayReader, read_csv};

fuzz_target!(|data: &[u8]| {
    for f in [RayFormat::Ascii, RayFormat::Float, RayFormat::Double] {
        for ray in RayReader::new(std::io::Cursor::new(data), "fuzz.pts", f).take(10_000) {
            if ray.is_err() {
                break;
            }
        }
    }
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = read_csv(text, "fuzz.csv");
    }
});
