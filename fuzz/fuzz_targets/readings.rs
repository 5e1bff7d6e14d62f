//! Any text fed to rcalib's photopic readings reader (long and wide layouts, units, time
//! stamps) gives readings or Err, never a panic. The first line, when it looks like a
//! `--columns` spec, is also parsed as one and used for the rest.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::calib::measurements::{Columns, Measurements};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let m = match text.split_once('\n') {
        Some((spec, rest)) if spec.contains('=') => match Columns::parse(spec) {
            Ok(cols) => Measurements::parse_with(rest, "fuzz.csv", &cols),
            Err(_) => return,
        },
        _ => Measurements::parse(text, "fuzz.csv"),
    };
    if let Ok(m) = m {
        let ids: Vec<String> = m
            .readings
            .iter()
            .take(4)
            .map(|r| r.sensor.clone())
            .collect();
        let steps: Vec<(u32, u32, f64)> = m
            .readings
            .iter()
            .take(4)
            .map(|r| (r.month, r.day, r.hour))
            .collect();
        let _ = m.bind(&ids, &steps, "fuzz.wea");
    }
});
