//! Any text fed to the weather reader (.wea or EPW, detected by content) gives Ok or Err,
//! never a panic; what parses can be written back as .wea.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = rdaylight::formats::weather::decode_text(data);
    if let Ok(w) = rdaylight::formats::weather::Weather::parse(&text, "fuzz.epw") {
        let _ = w.to_wea(true);
    }
});
