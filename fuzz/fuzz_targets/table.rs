//! Any text fed to rmetrics' table reader (the TSV `rmetrics` writes, read back by
//! `rmetrics compare`) gives a table or Err, never a panic; a table that reads compares
//! with itself and with a table of other columns without a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::metrics::compare::compare_tables;
use rdaylight::metrics::report::read_tsv;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (a, b) = text.split_once("\n---\n").unwrap_or((text, text));
    let Ok(bench) = read_tsv(a, "fuzz-a.tsv") else {
        return;
    };
    for s in &bench.sensors {
        assert_eq!(s.len(), bench.columns.len());
    }
    let _ = compare_tables(&bench, "fuzz-a.tsv", &[("self".into(), bench.clone())]);
    if let Ok(other) = read_tsv(b, "fuzz-b.tsv") {
        let _ = compare_tables(&bench, "fuzz-a.tsv", &[("b".into(), other)]);
    }
});
