//! Any text fed to `ruplift`'s mask legend reader (colour, name, known reflectance,
//! reference) gives a legend or Err, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::uplift::mask::{Legend, reflectance_values};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(l) = Legend::parse(text, "fuzz-legend.csv") {
        for e in &l.entries {
            assert!(l.find(&e.name).is_some());
        }
    }
    let _ = reflectance_values(text);
});
