//! Any text fed to rcalib's spectral readings reader (channel columns named by wavelength)
//! or its response-curve reader gives Ok or Err, never a panic; what parses is mapped onto
//! the simulated bands, directly and through the curves. The input is the readings, then
//! optionally a line `---` and the response curves.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::calib::spectral::channels::{ChannelMap, Responses};
use rdaylight::calib::spectral::readings::SpectralReadings;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (readings, responses) = text.split_once("\n---\n").unwrap_or((text, ""));
    let ch = rdaylight::calib::spectral::seed_channels();
    let resp = Responses::parse(responses, "fuzz-responses.csv");
    let Ok(r) = SpectralReadings::parse(readings, "fuzz.csv") else {
        return;
    };
    if let Ok(m) = ChannelMap::bands(&r, &ch) {
        let _ = m.apply(&vec![1.0; ch.ncomp]);
        let _ = m.weights(true);
    }
    if let Ok(resp) = resp
        && let Ok(m) = ChannelMap::with_responses(&r, &resp, &ch)
    {
        let _ = m.apply(&vec![1.0; ch.ncomp]);
        let _ = m.weights(false);
    }
    let ids: Vec<String> = r
        .readings
        .iter()
        .take(4)
        .map(|x| x.sensor.clone())
        .collect();
    let steps: Vec<(u32, u32, f64)> = r
        .readings
        .iter()
        .take(4)
        .map(|x| (x.month, x.day, x.hour))
        .collect();
    let _ = r.bind(&ids, &steps, "fuzz.wea");
});
