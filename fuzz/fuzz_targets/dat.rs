//! Any text fed to the Radiance data-file readers (`specfile`'s one-dimensional spectra and
//! the N-dimensional arrays of `specdata`/`brightdata`) gives Ok or Err, never a panic or an
//! unbounded allocation; an array that parses interpolates anywhere, inside or outside its
//! axes, without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::scene::specdata::{DataArray, SpecData};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = SpecData::parse(&text, "fuzz.dat");
    let Ok(d) = DataArray::parse(&text, "fuzz.dat") else {
        return;
    };
    let n = d.dims();
    for v in [0.0, 0.5, -1e9, 1e9, f64::NAN, 550.0] {
        let pt = vec![v; n];
        let _ = d.value(&pt);
        if n >= 2 {
            let _ = d.vector(&pt[..n - 1]);
        }
    }
});
