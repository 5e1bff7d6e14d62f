//! # Shards: one heavy job cut into N row blocks, merged back byte for byte
//!
//! `rdc --shard K/N` computes the K-th of N contiguous blocks of output rows (sensor rows,
//! or the pixel rows of whole scanlines in picture mode). K is **0-based** (`0 <= K < N`,
//! `N <= 100000`), so a Slurm array `--array=0-(N-1)` passes `$SLURM_ARRAY_TASK_ID`
//! unchanged. Row split ([`Shard::rows`]): with `R` rows, every shard gets `R / N` rows and
//! the first `R % N` shards one more; shards may be empty when `N > R`.
//!
//! ## The shard header
//!
//! A shard writes the header the unsharded run would write (same command line: `--shard`
//! and `--manifest` are left out of it, since they only say where this piece goes), with
//! `NROWS=` the shard's own row count and, just before it, one more line
//!
//! ```text
//! SHARD= K/N FIRST TOTAL
//! ```
//!
//! (FIRST: the global index of the shard's first row; TOTAL: the unsharded run's NROWS).
//! `rmtx --cat` of shards ([`crate::matrix::Pipeline`]) checks the shards belong together
//! (same header apart from `SHARD=`, `NROWS=`, `CAPDATE=`, `GMT=`; indices 0..N-1 in
//! order; rows adding up), writes shard 0's header without `SHARD=` and with `NROWS=TOTAL`,
//! and copies the data verbatim: the result is the unsharded run's bytes. The dates come
//! from shard 0; with `SOURCE_DATE_EPOCH` set (the reproducible-builds convention, honoured
//! by [`crate::header::Header::push_dates`]) they match a single run's too.
//!
//! ## Manifests
//!
//! `rdc --shard K/N --manifest FILE` writes a JSON [`Manifest`]: tool and version, the
//! command (without `--shard`/`--manifest`), N, K, the seed, the shard's rows, and every
//! input with its size and 64-bit FNV-1a hash ([`Fnv64`]; scene files by content, a
//! `!command` by its text, the sensors as read from standard input). Only the files named
//! on the command line are hashed, not files they reference (`.cal`, `specfile`, `!xform`
//! targets). [`check_manifests`] refuses shards of different inputs, versions, seeds or
//! commands and names the missing shard indices.

use crate::error::{Error, Result};
use crate::header::Header;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Largest N accepted by `--shard K/N` (a Slurm array is far smaller; this bounds typos).
pub const MAX_SHARDS: usize = 100_000;

/// The header variable that marks a shard.
pub const SHARD_VAR: &str = "SHARD";

/// The K-th (0-based) of N shards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Parse `K/N` (what `--shard` takes); `opt` names the option in errors.
    pub fn parse(s: &str, opt: &str) -> Result<Shard> {
        let bad = || {
            Error::Usage(format!(
                "{opt} {s}: expected K/N with 0 <= K < N <= {MAX_SHARDS} (K is 0-based, as \
                 $SLURM_ARRAY_TASK_ID with --array=0-(N-1))"
            ))
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let shard = Shard {
            index: k.trim().parse().map_err(|_| bad())?,
            count: n.trim().parse().map_err(|_| bad())?,
        };
        shard.validate().map_err(|_| bad())?;
        Ok(shard)
    }

    pub fn validate(&self) -> Result<()> {
        if self.count == 0 || self.count > MAX_SHARDS || self.index >= self.count {
            return Err(Error::Usage(format!(
                "--shard {}/{}: expected K/N with 0 <= K < N <= {MAX_SHARDS} (K is 0-based)",
                self.index, self.count
            )));
        }
        Ok(())
    }

    /// The shard's rows out of `total`: `total / N` each, one more for the first
    /// `total % N` shards, in order, so the blocks tile `0..total`.
    pub fn rows(&self, total: usize) -> Range<usize> {
        let (base, extra) = (total / self.count, total % self.count);
        let k = self.index;
        let first = k * base + k.min(extra);
        first..first + base + usize::from(k < extra)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What a shard's `SHARD=` line says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShardInfo {
    pub shard: Shard,
    /// Global index of the shard's first row.
    pub first: usize,
    /// Rows of the unsharded run.
    pub total: usize,
}

impl ShardInfo {
    /// Mark `header` (already holding the unsharded run's `NROWS=`) as this shard's: the
    /// `SHARD=` line goes just before `NROWS=`, which becomes `nrows`, both in place so the
    /// merge can restore the unsharded header line for line.
    pub fn mark(&self, header: &mut Header, nrows: usize) {
        let line = format!("{SHARD_VAR}= {} {} {}", self.shard, self.first, self.total);
        match nrows_line(header) {
            Some(i) => {
                header.lines[i] = format!("NROWS={nrows}");
                header.lines.insert(i, line);
            }
            None => header.lines.push(line),
        }
    }

    /// Read the `SHARD=` line of `header` (`None` when there is none); `name` for errors.
    pub fn of(header: &Header, name: &str) -> Result<Option<ShardInfo>> {
        let Some(v) = header.get(SHARD_VAR) else {
            return Ok(None);
        };
        let bad = || {
            Error::Mismatch(format!(
                "{name}: bad {SHARD_VAR}= line '{}': expected K/N FIRST TOTAL",
                v.trim()
            ))
        };
        let w: Vec<&str> = v.split_whitespace().collect();
        let [kn, first, total] = w[..] else {
            return Err(bad());
        };
        let shard = Shard::parse(kn, "SHARD=").map_err(|_| bad())?;
        Ok(Some(ShardInfo {
            shard,
            first: first.parse().map_err(|_| bad())?,
            total: total.parse().map_err(|_| bad())?,
        }))
    }
}

fn nrows_line(header: &Header) -> Option<usize> {
    header.lines.iter().position(|l| l.starts_with("NROWS="))
}

/// The header lines that identify a run: all but `SHARD=`, `NROWS=` and the dates.
fn identity(header: &Header) -> Vec<&str> {
    const SKIP: [&str; 4] = ["SHARD=", "NROWS=", "CAPDATE=", "GMT="];
    header
        .lines
        .iter()
        .filter(|l| !SKIP.iter().any(|s| l.starts_with(s)))
        .map(|l| l.trim_end())
        .collect()
}

/// Check that `shards` (name, header, NROWS) are all N shards of one run, in order, and
/// return the unsharded header (shard 0's, `SHARD=` removed, `NROWS=` the total).
pub fn merged_header(shards: &[(String, Header, usize)]) -> Result<Header> {
    let mut infos = Vec::with_capacity(shards.len());
    for (name, h, _) in shards {
        match ShardInfo::of(h, name)? {
            Some(i) => infos.push(i),
            None => {
                return Err(Error::Mismatch(format!(
                    "{name} has no {SHARD_VAR}= line but {} has: merge rdc shards only with \
                     each other",
                    shards[0].0
                )));
            }
        }
    }
    let (name0, h0, _) = &shards[0];
    let first = infos[0];
    let n = first.shard.count;
    let id0 = identity(h0);
    for ((name, h, _), info) in shards.iter().zip(&infos) {
        if info.shard.count != n || info.total != first.total {
            return Err(Error::Mismatch(format!(
                "{name} is shard {} of {} rows but {name0} is shard {} of {} rows: not one run",
                info.shard, info.total, first.shard, first.total
            )));
        }
        if identity(h) != id0 {
            return Err(Error::Mismatch(format!(
                "{name} and {name0} come from different runs (their headers differ beyond \
                 SHARD=, NROWS= and the dates)"
            )));
        }
    }
    check_indices(
        shards
            .iter()
            .zip(&infos)
            .map(|((name, _, _), i)| (name.as_str(), i.shard)),
    )?;
    let mut next = 0;
    for ((name, _, nrows), info) in shards.iter().zip(&infos) {
        let want = info.shard.rows(info.total);
        if info.first != next || want != (info.first..info.first + nrows) {
            return Err(Error::Mismatch(format!(
                "{name}: shard {} holds rows {}..{} but should hold {}..{} of {}",
                info.shard,
                info.first,
                info.first + nrows,
                want.start,
                want.end,
                info.total
            )));
        }
        next += nrows;
    }
    let mut h = h0.clone();
    h.lines.retain(|l| !l.starts_with("SHARD="));
    if let Some(i) = nrows_line(&h) {
        h.lines[i] = format!("NROWS={}", first.total);
    }
    Ok(h)
}

/// Shards given in order: each of 0..N-1 exactly once, at its position; names the missing
/// and repeated indices otherwise.
fn check_indices<'a>(shards: impl Iterator<Item = (&'a str, Shard)> + Clone) -> Result<()> {
    let Some((_, s0)) = shards.clone().next() else {
        return Ok(());
    };
    let n = s0.count;
    let mut seen = vec![0usize; n];
    for (_, s) in shards.clone() {
        seen[s.index.min(n - 1)] += 1;
    }
    let missing: Vec<String> = (0..n)
        .filter(|&k| seen[k] == 0)
        .map(|k| k.to_string())
        .collect();
    let repeated: Vec<String> = (0..n)
        .filter(|&k| seen[k] > 1)
        .map(|k| k.to_string())
        .collect();
    if !missing.is_empty() || !repeated.is_empty() {
        let mut msg = format!("shards of {n}:");
        if !missing.is_empty() {
            msg += &format!(" missing {}", missing.join(", "));
        }
        if !repeated.is_empty() {
            msg += &format!(
                "{} given twice {}",
                if missing.is_empty() { "" } else { ";" },
                repeated.join(", ")
            );
        }
        return Err(Error::Mismatch(msg));
    }
    for (pos, (name, s)) in shards.enumerate() {
        if s.index != pos {
            return Err(Error::Mismatch(format!(
                "{name} is shard {s} but comes in position {pos}: give the shards in order 0..{}",
                n - 1
            )));
        }
    }
    Ok(())
}

pub use rdaylight_base::hash::Fnv64;

/// The running hash and byte count of a [`HashingReader`], shared with its owner.
pub type SharedHash = std::sync::Arc<std::sync::Mutex<(Fnv64, u64)>>;

/// A `BufRead` that hashes and counts what is consumed through it (the sensors a shard
/// reads from standard input).
pub struct HashingReader<R> {
    inner: R,
    hash: SharedHash,
}

impl<R: std::io::BufRead> HashingReader<R> {
    pub fn new(inner: R, hash: SharedHash) -> Self {
        HashingReader { inner, hash }
    }

    fn consume_hashed(&mut self, amt: usize) {
        if let Ok(buf) = self.inner.fill_buf() {
            let mut g = self.hash.lock().unwrap_or_else(|e| e.into_inner());
            g.0.write(&buf[..amt.min(buf.len())]);
            g.1 += amt as u64;
        }
        self.inner.consume(amt);
    }
}

impl<R: std::io::BufRead> std::io::Read for HashingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let avail = self.inner.fill_buf()?;
            let n = avail.len().min(buf.len());
            buf[..n].copy_from_slice(&avail[..n]);
            n
        };
        self.consume_hashed(n);
        Ok(n)
    }
}

impl<R: std::io::BufRead> std::io::BufRead for HashingReader<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }
    fn consume(&mut self, amt: usize) {
        self.consume_hashed(amt);
    }
}

/// One input of a shard: its name as given, size in bytes and FNV-1a hash.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputSum {
    pub name: String,
    pub bytes: u64,
    pub fnv1a64: String,
}

impl InputSum {
    /// A file by its content; a `!command` by its text (its output is not run twice);
    /// `-` (a scene on standard input) cannot be read twice and gets an empty hash.
    pub fn of_scene_input(name: &str) -> Result<InputSum> {
        if name.starts_with('!') || name == "-" {
            let mut h = Fnv64::default();
            h.write(name.as_bytes());
            return Ok(InputSum {
                name: name.to_string(),
                bytes: 0,
                fnv1a64: h.hex(),
            });
        }
        InputSum::of_file(name)
    }

    /// A file by its content, read in blocks (coefficient matrices of a campus run are
    /// hundreds of MB: hashing must not load them whole).
    pub fn of_file(name: &str) -> Result<InputSum> {
        use std::io::Read;
        let mut f = std::fs::File::open(name).map_err(|e| Error::io(name, e))?;
        let (mut h, mut bytes) = (Fnv64::default(), 0u64);
        let mut buf = vec![0u8; 1 << 16];
        loop {
            let n = f.read(&mut buf).map_err(|e| Error::io(name, e))?;
            if n == 0 {
                break;
            }
            h.write(&buf[..n]);
            bytes += n as u64;
        }
        Ok(InputSum {
            name: name.to_string(),
            bytes,
            fnv1a64: h.hex(),
        })
    }
}

/// What `rdc --manifest FILE` writes for one shard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub tool: String,
    pub version: String,
    /// The command line without `--shard` and `--manifest`.
    pub command: Vec<String>,
    pub shard: Shard,
    pub seed: u64,
    /// Global index of the first row, the shard's rows, the unsharded run's rows.
    pub first_row: usize,
    pub rows: usize,
    pub total_rows: usize,
    pub inputs: Vec<InputSum>,
}

impl Manifest {
    pub fn read(path: &str) -> Result<Manifest> {
        read_json(path, "an rdc shard manifest")
    }

    /// Write atomically (a killed job leaves no half manifest behind).
    pub fn write(&self, path: &str) -> Result<()> {
        write_json(path, self)
    }

    fn run_id(&self) -> RunId<'_> {
        RunId {
            tool: &self.tool,
            version: &self.version,
            command: &self.command,
            seed: Some(self.seed),
            inputs: &self.inputs,
        }
    }
}

/// Read a manifest (`what` names the kind in errors).
pub(crate) fn read_json<T: serde::de::DeserializeOwned>(path: &str, what: &str) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| {
        Error::parse(
            crate::error::Location::line(path, e.line()),
            format!("not {what}: {e}"),
        )
    })
}

/// Write a manifest atomically (a killed job leaves no half manifest behind).
pub(crate) fn write_json<T: Serialize>(path: &str, value: &T) -> Result<()> {
    let text =
        serde_json::to_string_pretty(value).map_err(|e| Error::Usage(format!("{path}: {e}")))?;
    crate::io::write_atomically(std::path::Path::new(path), |w| {
        w.write_all(text.as_bytes())
            .and_then(|_| w.write_all(b"\n"))
            .map_err(|e| Error::io(path, e))
    })
}

/// What makes pieces parts of one run, whatever the piece (rows of `rdc --shard`, views of
/// `rglare annual --shard`, hours of `rmtx --hours`).
pub(crate) struct RunId<'a> {
    pub tool: &'a str,
    pub version: &'a str,
    pub command: &'a [String],
    pub seed: Option<u64>,
    pub inputs: &'a [InputSum],
}

/// The error naming what differs between the runs of manifests `p` and `p0`, if anything.
pub(crate) fn same_run(p: &str, a: RunId, p0: &str, b: RunId) -> Result<()> {
    let differ = |what: &str, x: &dyn std::fmt::Debug, y: &dyn std::fmt::Debug| {
        Err(Error::Mismatch(format!(
            "{p} and {p0} are pieces of different runs: {what} {x:?} vs {y:?}"
        )))
    };
    if (a.tool, a.version) != (b.tool, b.version) {
        return differ("tool version", &(a.tool, a.version), &(b.tool, b.version));
    }
    if a.seed != b.seed {
        return differ("seed", &a.seed, &b.seed);
    }
    if a.command != b.command {
        return differ("command", &a.command.join(" "), &b.command.join(" "));
    }
    for (x, y) in a.inputs.iter().zip(b.inputs) {
        if x != y {
            return Err(Error::Mismatch(format!(
                "{p} and {p0} are pieces of different inputs: {} (fnv1a64 {}, {} bytes) vs \
                 {} (fnv1a64 {}, {} bytes)",
                x.name, x.fnv1a64, x.bytes, y.name, y.fnv1a64, y.bytes
            )));
        }
    }
    if a.inputs.len() != b.inputs.len() {
        return differ("number of inputs", &a.inputs.len(), &b.inputs.len());
    }
    Ok(())
}

/// Check that `manifests` (path, manifest) describe all N shards of one run (same tool
/// version, command, seed, N, inputs), in order; the error names what differs or which
/// shard indices are missing.
pub fn check_manifests(manifests: &[(String, Manifest)]) -> Result<()> {
    let Some((p0, m0)) = manifests.first() else {
        return Ok(());
    };
    for (p, m) in &manifests[1..] {
        if m.shard.count != m0.shard.count {
            return Err(Error::Mismatch(format!(
                "{p} and {p0} are shards of different runs: shard count N {} vs {}",
                m.shard.count, m0.shard.count
            )));
        }
        if m.total_rows != m0.total_rows {
            return Err(Error::Mismatch(format!(
                "{p} and {p0} are shards of different runs: total rows {} vs {}",
                m.total_rows, m0.total_rows
            )));
        }
        same_run(p, m.run_id(), p0, m0.run_id())?;
    }
    check_indices(manifests.iter().map(|(p, m)| (p.as_str(), m.shard)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_tile_the_total_first_shards_longer() {
        for total in [0, 1, 7, 165] {
            for n in [1, 2, 3, 5, 200] {
                let mut next = 0;
                for k in 0..n {
                    let r = Shard { index: k, count: n }.rows(total);
                    assert_eq!(r.start, next);
                    assert_eq!(r.len(), total / n + usize::from(k < total % n));
                    next = r.end;
                }
                assert_eq!(next, total);
            }
        }
    }

    #[test]
    fn parse_checks_bounds() {
        assert_eq!(
            Shard::parse("2/3", "--shard").unwrap(),
            Shard { index: 2, count: 3 }
        );
        for bad in ["3/3", "0/0", "1", "a/2", "0/100001", "-1/2"] {
            assert!(Shard::parse(bad, "--shard").is_err(), "{bad}");
        }
    }

    #[test]
    fn missing_and_misordered_shards_are_named() {
        let s = |k| Shard { index: k, count: 4 };
        let e = check_indices([("a", s(0)), ("b", s(2))].into_iter()).unwrap_err();
        assert!(e.to_string().contains("missing 1, 3"), "{e}");
        let e = check_indices([("a", s(1)), ("b", s(0)), ("c", s(2)), ("d", s(3))].into_iter())
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("a is shard 1/4 but comes in position 0"),
            "{e}"
        );
    }
}
