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
//! commands and names the missing shard indices. The manifest also records the shard's
//! output as written (`output`: size and FNV-1a hash of the bytes on standard output), so
//! `rmtx --verify` and the merge ([`Manifest::check_output`]) tell a complete shard from a
//! missing, truncated, altered or stale one and name it: what a resume of a failed job
//! array needs to rerun only those (`examples/slurm/resume.sh`).

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

/// The header lines that identify a run whose pieces are being merged: all but the lines
/// a piece changes (`piece`: `SHARD=` and `NROWS=` for row shards, `HOURS=` and `NCOLS=`
/// for hour chunks) and the dates.
pub(crate) fn identity<'a>(header: &'a Header, piece: [&str; 2]) -> Vec<&'a str> {
    header
        .lines
        .iter()
        .filter(|l| {
            !piece
                .iter()
                .chain(&["CAPDATE=", "GMT="])
                .any(|s| l.starts_with(s))
        })
        .map(|l| l.trim_end())
        .collect()
}

/// Check that `shards` (name, header, NROWS) are all N shards of one run, in order, and
/// return the unsharded header (shard 0's, `SHARD=` removed, `NROWS=` the total).
pub fn merged_header(shards: &[(String, Header, usize)]) -> Result<Header> {
    let Some((name0, h0, _)) = shards.first() else {
        return Err(Error::Usage("no shards to merge".into()));
    };
    let mut infos = Vec::with_capacity(shards.len());
    for (name, h, _) in shards {
        match ShardInfo::of(h, name)? {
            Some(i) => infos.push(i),
            None => {
                return Err(Error::Mismatch(format!(
                    "{name} has no {SHARD_VAR}= line but {name0} has: merge rdc shards only \
                     with each other"
                )));
            }
        }
    }
    let pieces: Vec<(&str, ShardInfo, usize)> = shards
        .iter()
        .zip(&infos)
        .map(|((name, _, nrows), i)| (name.as_str(), *i, *nrows))
        .collect();
    check_pieces(&pieces, "rows")?;
    let id0 = identity(h0, ["SHARD=", "NROWS="]);
    for (name, h, _) in shards {
        if identity(h, ["SHARD=", "NROWS="]) != id0 {
            return Err(Error::Mismatch(format!(
                "{name} and {name0} come from different runs (their headers differ beyond \
                 SHARD=, NROWS= and the dates)"
            )));
        }
    }
    let first = infos[0];
    let mut h = h0.clone();
    h.lines.retain(|l| !l.starts_with("SHARD="));
    if let Some(i) = nrows_line(&h) {
        h.lines[i] = format!("NROWS={}", first.total);
    }
    Ok(h)
}

/// Check that `pieces` (name, its `SHARD=` line, the items it holds) are all N shards of
/// one run of TOTAL items (`unit`: rows, views), in order, each holding exactly its block.
pub fn check_pieces(pieces: &[(&str, ShardInfo, usize)], unit: &str) -> Result<()> {
    let Some(&(name0, first, _)) = pieces.first() else {
        return Ok(());
    };
    for &(name, info, _) in pieces {
        if info.shard.count != first.shard.count || info.total != first.total {
            return Err(Error::Mismatch(format!(
                "{name} is shard {} of {} {unit} but {name0} is shard {} of {} {unit}: not one \
                 run",
                info.shard, info.total, first.shard, first.total
            )));
        }
    }
    check_indices(pieces.iter().map(|&(name, i, _)| (name, i.shard)))?;
    let mut next = 0;
    for &(name, info, n) in pieces {
        let want = info.shard.rows(info.total);
        if info.first != next || want != (info.first..info.first + n) {
            return Err(Error::Mismatch(format!(
                "{name}: shard {} holds {unit} {}..{} but should hold {}..{} of {}",
                info.shard,
                info.first,
                info.first + n,
                want.start,
                want.end,
                info.total
            )));
        }
        next += n;
    }
    Ok(())
}

/// Check that manifests `ms` (path, manifest) describe `pieces` (name, `SHARD=` line,
/// items), one per piece in the same order, all of one run.
pub fn check_manifests_for(
    ms: &[(String, Manifest)],
    pieces: &[(&str, ShardInfo, usize)],
) -> Result<()> {
    check_manifests(ms)?;
    if ms.len() != pieces.len() {
        return Err(Error::Mismatch(format!(
            "{} manifests for {} shards: give one manifest per shard, in the same order",
            ms.len(),
            pieces.len()
        )));
    }
    for ((mp, m), (p, i, n)) in ms.iter().zip(pieces) {
        m.check_piece(mp, p, i, *n)?;
    }
    Ok(())
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
    /// The shard's output as written (size and FNV-1a hash), so that a merge or a resume
    /// can tell a complete shard from a truncated, altered or stale one. Absent in
    /// manifests of older versions and of text shards (which carry their own `# END=`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<InputSum>,
}

impl Manifest {
    /// Check that piece `p` (its `SHARD=` line `info`, `rows` rows) is the shard this
    /// manifest (file `mp`) describes.
    pub fn check_piece(&self, mp: &str, p: &str, info: &ShardInfo, rows: usize) -> Result<()> {
        if (info.shard, info.first, info.total) != (self.shard, self.first_row, self.total_rows)
            || rows != self.rows
        {
            return Err(Error::Mismatch(format!(
                "{mp} describes shard {} (rows {}..{} of {}) but {p} is not that shard",
                self.shard,
                self.first_row,
                self.first_row + self.rows,
                self.total_rows
            )));
        }
        Ok(())
    }

    /// Check that file `path` holds the output this manifest recorded (nothing to check
    /// when it recorded none).
    pub fn check_output(&self, path: &str) -> Result<()> {
        let Some(want) = &self.output else {
            return Ok(());
        };
        let got = InputSum::of_file(path)?;
        if (got.bytes, &got.fnv1a64) != (want.bytes, &want.fnv1a64) {
            return Err(Error::Mismatch(format!(
                "{path}: {} bytes, fnv1a64 {}, but its manifest recorded {} bytes, fnv1a64 \
                 {}: a corrupt or stale shard; run shard {} again",
                got.bytes, got.fnv1a64, want.bytes, want.fnv1a64, self.shard
            )));
        }
        Ok(())
    }

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

/// First line of a text shard: `# SHARD= K/N FIRST TOTAL`.
const TEXT_SHARD: &str = "# SHARD=";
/// Second line: `# COMMAND= ...`, the unsharded run's command line.
const TEXT_COMMAND: &str = "# COMMAND=";
/// Last line: `# END= BYTES FNV1A64` of the body.
const TEXT_END: &str = "# END=";

/// The two lines that open a text shard (module docs of the tool that writes one, e.g.
/// `rglare annual --shard`): where the piece goes and which run it belongs to.
///
/// A text shard is a report that is not a matrix, framed so that its merge can check it:
///
/// ```text
/// # SHARD= K/N FIRST TOTAL     (FIRST: its first item, TOTAL: the whole run's items)
/// # COMMAND= <the unsharded command line>
/// <body: the whole run's output for items FIRST.., verbatim>
/// # END= BYTES FNV1A64         (the body's size and hash: a killed or damaged job shows)
/// ```
///
/// [`merge_text_shards`] writes the bodies one after the other: the unsharded output.
pub fn text_preamble(info: &ShardInfo, command: &[String]) -> String {
    format!(
        "{TEXT_SHARD} {} {} {}\n{TEXT_COMMAND} {}\n",
        info.shard,
        info.first,
        info.total,
        command.join(" ")
    )
}

/// Counts and hashes what passes through it (a text shard's body); [`trailer`] is the
/// closing `# END=` line.
///
/// [`trailer`]: HashingWriter::trailer
pub struct HashingWriter<W> {
    inner: W,
    hash: Fnv64,
    bytes: u64,
}

impl<W: std::io::Write> HashingWriter<W> {
    pub fn new(inner: W) -> Self {
        HashingWriter {
            inner,
            hash: Fnv64::default(),
            bytes: 0,
        }
    }

    /// The `# END=` line for what was written so far.
    pub fn trailer(&self) -> String {
        format!("{TEXT_END} {} {}\n", self.bytes, self.hash.hex())
    }

    pub fn into_inner(self) -> W {
        self.inner
    }

    /// What was written, as a manifest records it (`name`: where it went).
    pub fn sum(&self, name: &str) -> InputSum {
        InputSum {
            name: name.to_string(),
            bytes: self.bytes,
            fnv1a64: self.hash.hex(),
        }
    }
}

impl<W: std::io::Write> std::io::Write for HashingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hash.write(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// A text shard's frame, read and checked against its `# END=` line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextShard {
    pub name: String,
    pub info: ShardInfo,
    /// The `# COMMAND=` value.
    pub command: String,
    /// Byte offset and length of the body.
    pub body: (u64, u64),
}

/// Read the frame of text shard `path` and check its body's size and hash; the error
/// names the file and says whether it is no shard, incomplete or corrupt.
pub fn read_text_shard(path: &str) -> Result<TextShard> {
    use std::io::{BufRead, Read, Seek, SeekFrom};
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let size = f.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut r = std::io::BufReader::new(f);
    let mut offset = 0u64;
    let mut line = |what: &str| -> Result<String> {
        let mut raw = Vec::new();
        let n = (&mut r)
            .take(1 << 16)
            .read_until(b'\n', &mut raw)
            .map_err(|e| Error::io(path, e))?;
        offset += n as u64;
        let text = String::from_utf8(raw).unwrap_or_default();
        match text.strip_prefix(what) {
            Some(v) if text.ends_with('\n') => Ok(v.trim().to_string()),
            _ => Err(Error::Mismatch(format!(
                "{path}: expected a '{what}' line (shard header); not a shard, or cut short"
            ))),
        }
    };
    let shard = line(TEXT_SHARD)?;
    let command = line(TEXT_COMMAND)?;
    let header = {
        let mut h = Header::new();
        h.push(format!("{SHARD_VAR}= {shard}"));
        h
    };
    let info = ShardInfo::of(&header, path)?
        .ok_or_else(|| Error::Mismatch(format!("{path}: no {SHARD_VAR}= line")))?;
    // The trailer is the last line, under 64 bytes: read the file's tail.
    let tail_start = size.saturating_sub(128).max(offset);
    let mut tail = Vec::new();
    let mut f = r.into_inner();
    f.seek(SeekFrom::Start(tail_start))
        .and_then(|_| f.read_to_end(&mut tail))
        .map_err(|e| Error::io(path, e))?;
    let incomplete = || {
        Error::Mismatch(format!(
            "{path}: no '{TEXT_END}' line at the end: an incomplete shard (killed job?); run \
             it again"
        ))
    };
    if tail.last() != Some(&b'\n') {
        return Err(incomplete());
    }
    let start = tail[..tail.len() - 1]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let last = std::str::from_utf8(&tail[start..]).unwrap_or("");
    let Some(end) = last.strip_prefix(TEXT_END) else {
        return Err(incomplete());
    };
    // No newline before the last line within the tail: it is longer than any END= line.
    if start == 0 && tail_start > offset {
        return Err(incomplete());
    }
    let body_len = tail_start + start as u64 - offset;
    let mut h = Fnv64::default();
    let mut f = std::io::BufReader::new(f);
    f.seek(SeekFrom::Start(offset))
        .map_err(|e| Error::io(path, e))?;
    let mut left = body_len;
    while left > 0 {
        let buf = f.fill_buf().map_err(|e| Error::io(path, e))?;
        if buf.is_empty() {
            break;
        }
        let n = buf.len().min(left as usize);
        h.write(&buf[..n]);
        f.consume(n);
        left -= n as u64;
    }
    let want = end.trim();
    let got = format!("{body_len} {}", h.hex());
    if want != got {
        return Err(Error::Mismatch(format!(
            "{path}: the body ({got}) does not match its END= line ({want}): a corrupt \
             shard; run it again"
        )));
    }
    Ok(TextShard {
        name: path.to_string(),
        info,
        command,
        body: (offset, body_len),
    })
}

/// Merge text shards (all N of one run, in order; with `manifests`, one per shard, checked
/// as [`check_manifests_for`]) into `out`: their bodies one after the other. `unit` names
/// the items in errors (views). Everything is checked before the first byte is written.
pub fn merge_text_shards(
    paths: &[String],
    manifests: &[String],
    unit: &str,
    out: &mut dyn std::io::Write,
) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    if paths.is_empty() {
        return Err(Error::Usage("no shards to merge".into()));
    }
    let shards = paths
        .iter()
        .map(|p| read_text_shard(p))
        .collect::<Result<Vec<_>>>()?;
    let s0 = &shards[0];
    let pieces: Vec<(&str, ShardInfo, usize)> = shards
        .iter()
        .map(|s| {
            (
                s.name.as_str(),
                s.info,
                s.info.shard.rows(s.info.total).len(),
            )
        })
        .collect();
    check_pieces(&pieces, unit)?;
    for s in &shards[1..] {
        if s.command != s0.command {
            return Err(Error::Mismatch(format!(
                "{} and {} come from different runs: COMMAND= {} vs {}",
                s.name, s0.name, s.command, s0.command
            )));
        }
    }
    if !manifests.is_empty() {
        let ms = manifests
            .iter()
            .map(|p| Manifest::read(p).map(|m| (p.clone(), m)))
            .collect::<Result<Vec<_>>>()?;
        check_manifests_for(&ms, &pieces)?;
    }
    for s in &shards {
        let mut f = std::fs::File::open(&s.name).map_err(|e| Error::io(&s.name, e))?;
        f.seek(SeekFrom::Start(s.body.0))
            .map_err(|e| Error::io(&s.name, e))?;
        std::io::copy(&mut f.take(s.body.1), out).map_err(|e| Error::io(&s.name, e))?;
    }
    out.flush().map_err(|e| Error::io("<output>", e))
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

    /// Fuzzing (fuzz/README.md, `hours` target): merging no shards indexed the first one
    /// and panicked; it is an error, as for hour chunks.
    #[test]
    fn merging_no_shards_is_an_error() {
        let e = merged_header(&[]).unwrap_err().to_string();
        assert_eq!(e, "no shards to merge");
        let e = crate::hours::merged_header(&[]).unwrap_err().to_string();
        assert_eq!(e, "no hour chunks to merge");
    }
}
