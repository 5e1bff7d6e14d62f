//! # Daylight-coefficient cache on disk
//!
//! Coefficient matrices are stored under a key that hashes everything they depend on (scene
//! text, sensors, sampling settings, kind of coefficients, sun positions), so re-running
//! `rcalib compare`/`explain` on the same inputs traces nothing. The key is 64-bit FNV-1a
//! (Fowler, Noll, Vo; IETF draft-eastlake-fnv) of those texts: stable across runs and Rust
//! versions, unlike `std`'s hasher. A file is `RCALIBDC1`, the value count (u64 LE) and the
//! values (f64 LE); anything else is treated as absent and recomputed. Records that check
//! their own format (re-weighting records) are stored as raw bytes ([`store_bytes`]).

use std::path::{Path, PathBuf};

const MAGIC: &[u8; 9] = b"RCALIBDC1";

/// FNV-1a over a sequence of byte strings (each followed by a separator byte), after the
/// crate version and the tracer's [`crate::trace::REVISION`]: a cache written by another
/// tracer is never read back.
pub fn key(parts: &[&[u8]]) -> u64 {
    let mut h = rdaylight_base::hash::Fnv64::new();
    let version: [&[u8]; 2] = [
        env!("CARGO_PKG_VERSION").as_bytes(),
        crate::trace::REVISION.as_bytes(),
    ];
    for p in version.iter().chain(parts) {
        h.write(p);
        h.write(&[0xff]);
    }
    h.finish()
}

fn path(dir: &Path, key: u64) -> PathBuf {
    dir.join(format!("dc-{key:016x}.bin"))
}

/// The cached values for `key`, if a complete file is there.
pub fn load(dir: &Path, key: u64) -> Option<Vec<f64>> {
    let p = path(dir, key);
    let bytes = std::fs::read(&p).ok()?;
    // A hit marks the entry as used now (its modification time), so the entries a run
    // needs can be told from stale ones (`make calib-cases-cache` keeps only those).
    if let Ok(f) = std::fs::File::options().append(true).open(&p) {
        let _ = f.set_modified(std::time::SystemTime::now());
    }
    let rest = bytes.strip_prefix(MAGIC.as_slice())?;
    let (n, data) = rest.split_at_checked(8)?;
    let n = u64::from_le_bytes(n.try_into().ok()?) as usize;
    if data.len() != n.checked_mul(8)? {
        return None;
    }
    Some(
        data.chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect(),
    )
}

/// Store `values` under `key` (best effort: a cache that cannot be written is skipped).
pub fn store(dir: &Path, key: u64, values: &[f64]) {
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let mut bytes = Vec::with_capacity(17 + values.len() * 8);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let p = path(dir, key);
    let tmp = p.with_extension(format!("part{}", std::process::id()));
    if std::fs::write(&tmp, &bytes).is_ok() {
        let _ = std::fs::rename(&tmp, &p);
    }
}

/// Raw bytes stored under `key` ([`store_bytes`]), if the file is there.
pub fn load_bytes(dir: &Path, key: u64) -> Option<Vec<u8>> {
    let p = dir.join(format!("raw-{key:016x}.bin"));
    let bytes = std::fs::read(&p).ok()?;
    if let Ok(f) = std::fs::File::options().append(true).open(&p) {
        let _ = f.set_modified(std::time::SystemTime::now());
    }
    Some(bytes)
}

/// Store raw bytes under `key` (a format that checks itself, such as re-weighting records;
/// best effort, as [`store`]).
pub fn store_bytes(dir: &Path, key: u64, bytes: &[u8]) {
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let p = dir.join(format!("raw-{key:016x}.bin"));
    let tmp = p.with_extension(format!("part{}", std::process::id()));
    if std::fs::write(&tmp, bytes).is_ok() {
        let _ = std::fs::rename(&tmp, &p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_corruption() {
        let d = tempfile::tempdir().unwrap();
        let k = key(&[b"a", b"b"]);
        assert_ne!(k, key(&[b"ab"]), "parts are separated");
        store(d.path(), k, &[1.0, -2.5]);
        assert_eq!(load(d.path(), k), Some(vec![1.0, -2.5]));
        let p = path(d.path(), k);
        let b = std::fs::read(&p).unwrap();
        for n in 0..b.len() {
            std::fs::write(&p, &b[..n]).unwrap();
            assert_eq!(load(d.path(), k), None);
        }
    }
}
