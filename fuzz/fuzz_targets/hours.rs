//! Any bytes fed to the readers of split runs give Ok or Err, never a panic: `--hours` and
//! `--shard` values, and the `HOURS=` / `SHARD=` lines of matrix headers that `rmtx
//! --cat-columns` and the shard merge check. The input is a header (two chunks when
//! separated by `\n---\n`); its first line is also tried as an option value.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::formats::header::Header;
use rdaylight::formats::hours::{HourSpan, HoursInfo, merged_header};
use rdaylight::formats::shard::{self, Shard, ShardInfo};

fn header(bytes: &[u8], name: &str) -> Option<(String, Header)> {
    let h = Header::read(&mut std::io::Cursor::new(bytes), name).ok()?;
    Some((name.to_string(), h))
}

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let first = text.lines().next().unwrap_or("");
        if let Ok(span) = HourSpan::parse(first, "--hours") {
            for total in [0, 1, 7, 8760, usize::MAX] {
                let _ = span.resolve(total, "fuzz.mtx");
            }
        }
        if let Ok(s) = Shard::parse(first, "--shard") {
            for total in [0, 1, 7, usize::MAX] {
                let r = s.rows(total);
                assert!(r.start <= r.end && r.end <= total);
            }
        }
    }
    let sep = b"\n---\n";
    let cut = data.windows(sep.len()).position(|w| w == sep);
    let parts: Vec<&[u8]> = match cut {
        Some(i) => vec![&data[..i + 1], &data[i + sep.len()..]],
        None => vec![data],
    };
    let chunks: Vec<(String, Header)> = parts
        .iter()
        .enumerate()
        .filter_map(|(k, p)| header(p, &format!("fuzz{k}.mtx")))
        .collect();
    for (name, h) in &chunks {
        let _ = HoursInfo::of(h, name);
        let _ = ShardInfo::of(h, name);
    }
    let _ = merged_header(&chunks);
    let with_rows: Vec<(String, Header, usize)> = chunks
        .iter()
        .map(|(n, h)| (n.clone(), h.clone(), 3))
        .collect();
    let _ = shard::merged_header(&with_rows);
});
