//! Any bytes fed to the streaming matrix reader (header, ascii tokens, binary rows,
//! picture-coded rows) give rows or Err, never a panic or an unbounded allocation.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::formats::matrix::{MatrixReader, ReadOptions};

fuzz_target!(|data: &[u8]| {
    let Ok(mut r) = MatrixReader::new(
        std::io::Cursor::new(data),
        "fuzz.mtx",
        &ReadOptions::default(),
    ) else {
        return;
    };
    let mut row = vec![0.0; r.row_len()];
    // Bounded: a fuzzer input is small, but a header may claim many empty rows.
    for _ in 0..10_000 {
        match r.read_row(&mut row) {
            Ok(true) => {}
            _ => break,
        }
    }
});
