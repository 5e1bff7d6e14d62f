//! Any bytes fed to the re-weighting file reader (`rdc --reweight`: a JSON line, then
//! binary rows of terms) give records or Err, never a panic or an unbounded allocation;
//! records that read can be applied, differentiated and written back.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::trace::reweight::Reweighting;

fuzz_target!(|data: &[u8]| {
    let Ok(rw) = Reweighting::parse(data, "fuzz.rw") else {
        return;
    };
    let n = rw.materials.len();
    let _ = rw.apply(&vec![0.5; n]);
    let _ = rw.apply_channels(&vec![0.5; n * rw.ncomp]);
    let _ = rw.apply_entries(&vec![0.9; rw.entries.len()]);
    if n > 0 {
        let _ = rw.sensitivity(0);
    }
    let mut out = Vec::new();
    rw.write(&mut out, "fuzz").unwrap();
    let back = Reweighting::parse(&out, "fuzz-back.rw").unwrap();
    assert_eq!(back.size(), rw.size());
});
