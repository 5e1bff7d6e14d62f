//! Any text fed to `ruplift proxy`'s points reader (`x, y, rho` or `x, y, r, g, b`, CSV or
//! white space, an optional header line) gives points or Err, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(points) = rdaylight::uplift::proxy::parse_points(text, "fuzz-points.csv") {
        assert!(points.iter().all(|p| p.rho.len() == 1 || p.rho.len() == 3));
    }
});
