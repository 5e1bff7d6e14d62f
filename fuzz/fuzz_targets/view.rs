//! Any text fed to the view parser (a `VIEW=` value or a view file) gives Ok or Err, never a
//! panic; a view that parses either sets up or is rejected, and its rays never panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::formats::view::View;

fuzz_target!(|data: &[u8]| {
    let mut v = View::default();
    let mut r = std::io::Cursor::new(data);
    if v.apply_reader(&mut r, "fuzz.vf").is_err() {
        return;
    }
    if let Ok(cam) = v.setup() {
        for (x, y) in [(0.5, 0.5), (0.0, 0.0), (1.0, 1.0), (0.25, 0.9)] {
            let _ = cam.view_ray(x, y);
        }
        let _ = cam.pixel_solid_angle(0, 0, 8, 8);
    }
});
