//! Any text fed to the `.rad` parser gives Ok or Err, never a panic. Inline commands are
//! refused (a fuzzer must never run shell commands).
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::scene::{LoadOptions, parse_str};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let opts = LoadOptions {
        allow_exec: false,
        ..LoadOptions::default()
    };
    if let Ok(scene) = parse_str(text, "fuzz.rad", std::path::Path::new(""), &opts) {
        let _ = scene.bounding_box();
        let _ = scene.to_string();
    }
});
