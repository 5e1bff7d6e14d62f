//! # Hour chunks: one annual matrix product cut along time, merged back byte for byte
//!
//! `rmtx --hours A:B dc.mtx sky.smx` computes columns `A..B` of the product: the columns
//! (time steps) of the right-most matrix, the sky, are restricted to `A..B` before anything
//! is multiplied. Hours are **0-based column indices, half-open**: `A` is included, `B` is
//! not, so `0:730` and `730:1460` follow each other without a gap or an overlap and a chunk
//! holds `B - A` columns; `0 <= A < B <= NCOLS`. `--hours K/N` names the K-th (0-based) of N
//! blocks, split as `rdc --shard` splits rows ([`crate::shard::Shard::rows`]: `NCOLS / N`
//! columns each, the first `NCOLS % N` one more), which is what a Slurm array task knows.
//!
//! Why the chunks are exact: column `j` of `C = A · S` is `Σ_h A[i][h] S[h][j]`, summed in the
//! same order whatever other columns are computed, and the channel transform (`-c`) and the
//! scale (`-s`) work element by element; so a chunk's numbers are the whole product's
//! columns `A..B` bit for bit, and so are their float or ascii encodings.
//!
//! ## The chunk header
//!
//! A chunk writes the header the whole product would have (same command line: `--hours`
//! and `--manifest` are left out of it, since they only say which piece this is), with
//! `NCOLS=` the chunk's own column count and, after the command line, one more line
//!
//! ```text
//! HOURS= A:B TOTAL
//! ```
//!
//! (TOTAL: the whole product's NCOLS). `rmtx --cat-columns` of chunks
//! ([`crate::matrix::Pipeline`]) checks that they belong together (same header apart from
//! `HOURS=`, `NCOLS=` and the dates, so the same NROWS, NCOMP, format and command) and that
//! their hours tile `0..TOTAL` in the order given, writes chunk 0's header without `HOURS=`
//! and with `NCOLS=TOTAL`, and joins each row from the chunks' row pieces verbatim: the
//! whole product's bytes.
//!
//! ## Manifests
//!
//! `rmtx --hours A:B --manifest FILE` writes a JSON [`ChunkManifest`] (the scheme of
//! [`crate::shard::Manifest`]: tool, version, command without `--hours`/`--manifest`, every
//! input file with its size and FNV-1a 64 hash, and the chunk's hours); the merge's
//! `--manifests` refuses chunks of different inputs, versions or commands.

use crate::error::{Error, Result};
use crate::header::Header;
use crate::shard::identity;
use crate::shard::{InputSum, RunId, Shard, read_json, same_run, write_json};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// The header variable that marks an hour chunk.
pub const HOURS_VAR: &str = "HOURS";

/// What `--hours` takes: explicit hours, or the K-th of N blocks of the columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HourSpan {
    /// `A:B`: columns `A..B` (0-based, `B` excluded).
    Range { first: usize, end: usize },
    /// `K/N`: the K-th of N blocks ([`Shard::rows`] over the columns).
    Block(Shard),
}

impl HourSpan {
    /// Parse `A:B` or `K/N`; `opt` names the option in errors.
    pub fn parse(s: &str, opt: &str) -> Result<HourSpan> {
        if s.contains('/') {
            return Shard::parse(s, opt).map(HourSpan::Block);
        }
        let bad = || {
            Error::Usage(format!(
                "{opt} {s}: expected A:B (0-based columns, A included, B not: 0:730 is the \
                 first 730 hours) or K/N (the K-th of N blocks, 0-based)"
            ))
        };
        let (a, b) = s.split_once(':').ok_or_else(bad)?;
        let first: usize = a.trim().parse().map_err(|_| bad())?;
        let end: usize = b.trim().parse().map_err(|_| bad())?;
        if first >= end {
            return Err(bad());
        }
        Ok(HourSpan::Range { first, end })
    }

    /// The columns out of `total` (the right-most matrix's NCOLS, in `name`).
    pub fn resolve(&self, total: usize, name: &str) -> Result<Range<usize>> {
        match *self {
            HourSpan::Block(s) => Ok(s.rows(total)),
            HourSpan::Range { first, end } if end <= total => Ok(first..end),
            HourSpan::Range { first, end } => Err(Error::Mismatch(format!(
                "--hours {first}:{end}: {name} has {total} columns (hours 0:{total})"
            ))),
        }
    }
}

/// What a chunk's `HOURS=` line says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HoursInfo {
    pub first: usize,
    pub end: usize,
    /// Columns of the whole product.
    pub total: usize,
}

impl HoursInfo {
    /// The header line.
    pub fn line(&self) -> String {
        format!("{HOURS_VAR}= {}:{} {}", self.first, self.end, self.total)
    }

    /// Read the `HOURS=` line of `header` (`None` when there is none); `name` for errors.
    pub fn of(header: &Header, name: &str) -> Result<Option<HoursInfo>> {
        let Some(v) = header.get(HOURS_VAR) else {
            return Ok(None);
        };
        let bad = || {
            Error::Mismatch(format!(
                "{name}: bad {HOURS_VAR}= line '{}': expected A:B TOTAL",
                v.trim()
            ))
        };
        let w: Vec<&str> = v.split_whitespace().collect();
        let [span, total] = w[..] else {
            return Err(bad());
        };
        let (a, b) = span.split_once(':').ok_or_else(bad)?;
        let info = HoursInfo {
            first: a.parse().map_err(|_| bad())?,
            end: b.parse().map_err(|_| bad())?,
            total: total.parse().map_err(|_| bad())?,
        };
        if info.first >= info.end || info.end > info.total {
            return Err(bad());
        }
        Ok(Some(info))
    }

    fn span(&self) -> String {
        format!("{}:{}", self.first, self.end)
    }
}

/// Check that `chunks` (name, header) are hour chunks of one product whose hours tile
/// `0..TOTAL` in the order given, each with `NCOLS=` its hours; return the whole product's
/// header (chunk 0's, `HOURS=` removed, `NCOLS=TOTAL` in place) and each chunk's hours.
pub fn merged_header(chunks: &[(String, Header)]) -> Result<(Header, Vec<HoursInfo>)> {
    let Some((name0, h0)) = chunks.first() else {
        return Err(Error::Usage("no hour chunks to merge".into()));
    };
    let mut infos = Vec::with_capacity(chunks.len());
    for (name, h) in chunks {
        let info = HoursInfo::of(h, name)?.ok_or_else(|| {
            Error::Mismatch(format!(
                "{name} has no {HOURS_VAR}= line but {name0} has: merge rmtx --hours chunks \
                 only with each other"
            ))
        })?;
        let ncols = h.get_usize("NCOLS", name)?;
        if ncols != Some(info.end - info.first) {
            return Err(Error::Mismatch(format!(
                "{name}: {HOURS_VAR}= {} but NCOLS={}: a damaged chunk?",
                info.span(),
                ncols.map_or("(none)".into(), |n| n.to_string())
            )));
        }
        infos.push(info);
    }
    let id0 = identity(h0, ["HOURS=", "NCOLS="]);
    let total = infos[0].total;
    for ((name, h), info) in chunks.iter().zip(&infos) {
        if info.total != total {
            return Err(Error::Mismatch(format!(
                "{name} is a chunk of {} hours but {name0} of {total}: not one product",
                info.total
            )));
        }
        if identity(h, ["HOURS=", "NCOLS="]) != id0 {
            return Err(Error::Mismatch(format!(
                "{name} and {name0} come from different products (their headers differ \
                 beyond {HOURS_VAR}=, NCOLS= and the dates: command, NROWS, NCOMP or format)"
            )));
        }
    }
    check_tiling(
        chunks.iter().map(|(n, _)| n.as_str()).zip(infos.iter()),
        total,
    )?;
    let mut h = h0.clone();
    h.lines.retain(|l| !l.starts_with("HOURS="));
    if let Some(i) = h.lines.iter().position(|l| l.starts_with("NCOLS=")) {
        h.lines[i] = format!("NCOLS={total}");
    }
    Ok((h, infos))
}

/// Hours given in order must run from 0 to `total` without gaps or overlaps; the error
/// names the chunk given out of order, the missing hours or the overlapping chunks.
fn check_tiling<'a>(
    chunks: impl Iterator<Item = (&'a str, &'a HoursInfo)>,
    total: usize,
) -> Result<()> {
    let chunks: Vec<(&str, &HoursInfo)> = chunks.collect();
    let mut next = 0;
    let mut prev: Option<(&str, &HoursInfo)> = None;
    for (pos, &(name, info)) in chunks.iter().enumerate() {
        if info.first > next {
            if let Some((late, i)) = chunks[pos + 1..].iter().find(|(_, i)| i.first == next) {
                return Err(Error::Mismatch(format!(
                    "{late} (hours {}) comes after {name} ({}): give the chunks in order of \
                     hours",
                    i.span(),
                    info.span()
                )));
            }
            let after = prev.map_or(String::new(), |(p, i)| format!(" after {p} ({})", i.span()));
            return Err(Error::Mismatch(format!(
                "hours {next}:{} of {total} missing{after}, before {name} ({}): give every \
                 chunk, in order of hours",
                info.first,
                info.span()
            )));
        }
        if info.first < next {
            let (p, i) = prev.unwrap_or((name, info));
            return Err(Error::Mismatch(format!(
                "{name} (hours {}) overlaps {p} ({}): give each hour once, chunks in order \
                 of hours",
                info.span(),
                i.span()
            )));
        }
        next = info.end;
        prev = Some((name, info));
    }
    if next < total {
        return Err(Error::Mismatch(format!(
            "hours {next}:{total} of {total} missing after {}: give every chunk, in order of \
             hours",
            prev.map_or("the last chunk".into(), |(p, i)| format!(
                "{p} ({})",
                i.span()
            ))
        )));
    }
    Ok(())
}

/// What `rmtx --hours A:B --manifest FILE` writes for one chunk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChunkManifest {
    pub tool: String,
    pub version: String,
    /// The command line without `--hours` and `--manifest`.
    pub command: Vec<String>,
    /// The chunk's hours `first_hour..end_hour` out of `total_hours` columns.
    pub first_hour: usize,
    pub end_hour: usize,
    pub total_hours: usize,
    pub inputs: Vec<InputSum>,
}

impl ChunkManifest {
    pub fn read(path: &str) -> Result<ChunkManifest> {
        read_json(path, "an rmtx --hours chunk manifest")
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
            seed: None,
            inputs: &self.inputs,
        }
    }
}

/// Check that `manifests` (path, manifest) describe `chunks` (name, hours), one per chunk
/// in the same order, all of one product (tool version, command, inputs).
pub fn check_manifests(
    manifests: &[(String, ChunkManifest)],
    chunks: &[(String, HoursInfo)],
) -> Result<()> {
    if manifests.len() != chunks.len() {
        return Err(Error::Mismatch(format!(
            "{} manifests for {} chunks: give one manifest per chunk, in the same order",
            manifests.len(),
            chunks.len()
        )));
    }
    if let Some((p0, m0)) = manifests.first() {
        for (p, m) in &manifests[1..] {
            same_run(p, m.run_id(), p0, m0.run_id())?;
        }
    }
    for ((mp, m), (p, h)) in manifests.iter().zip(chunks) {
        if (m.first_hour, m.end_hour, m.total_hours) != (h.first, h.end, h.total) {
            return Err(Error::Mismatch(format!(
                "{mp} describes hours {}:{} of {} but {p} holds {}: not that chunk",
                m.first_hour,
                m.end_hour,
                m.total_hours,
                h.span()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(first: usize, end: usize, total: usize) -> (String, Header) {
        let mut h = Header::new();
        h.push("rmtx -ff dc.mtx sky.smx");
        h.push(HoursInfo { first, end, total }.line());
        h.set("NROWS", 5);
        h.set("NCOLS", end - first);
        h.set("NCOMP", 3);
        h.set("FORMAT", "float");
        (format!("c{first}.mtx"), h)
    }

    #[test]
    fn spans_parse_and_resolve() {
        let r = |s: &str, total| HourSpan::parse(s, "--hours")?.resolve(total, "sky.smx");
        assert_eq!(r("0:730", 8760).unwrap(), 0..730);
        assert_eq!(r("8000:8760", 8760).unwrap(), 8000..8760);
        // K/N splits as rdc --shard: 10 columns in 3 blocks of 4, 3, 3.
        assert_eq!(r("0/3", 10).unwrap(), 0..4);
        assert_eq!(r("2/3", 10).unwrap(), 7..10);
        let e = r("8000:8761", 8760).unwrap_err().to_string();
        assert_eq!(
            e,
            "--hours 8000:8761: sky.smx has 8760 columns (hours 0:8760)"
        );
        for bad in ["5:5", "6:5", "a:3", "3", "-1:4", "3/3"] {
            assert!(HourSpan::parse(bad, "--hours").is_err(), "{bad}");
        }
    }

    #[test]
    fn bad_hours_lines_are_errors_not_panics() {
        for bad in [
            "5:3 10", "x", "1:2", "1:20 10", "1:2:3 9", ":4 9", "0:0 9", "",
        ] {
            let mut h = Header::new();
            h.push(format!("{HOURS_VAR}= {bad}"));
            let e = HoursInfo::of(&h, "c.mtx").unwrap_err().to_string();
            assert!(e.starts_with("c.mtx: bad HOURS= line"), "{bad}: {e}");
        }
        let mut h = Header::new();
        h.push(format!("{HOURS_VAR}= 0:9 9"));
        let info = HoursInfo::of(&h, "c.mtx").unwrap().unwrap();
        assert_eq!(info.line(), "HOURS= 0:9 9");
    }

    #[test]
    fn merged_header_restores_the_whole_product() {
        let chunks = [chunk(0, 4, 10), chunk(4, 7, 10), chunk(7, 10, 10)];
        let (h, infos) = merged_header(&chunks).unwrap();
        assert_eq!(infos.len(), 3);
        let mut want = Header::new();
        want.push("rmtx -ff dc.mtx sky.smx");
        want.set("NROWS", 5);
        want.set("NCOLS", 10);
        want.set("NCOMP", 3);
        want.set("FORMAT", "float");
        assert_eq!(h.lines, want.lines);
    }

    #[test]
    fn gaps_overlaps_and_strangers_are_named() {
        let e = |c: &[(String, Header)]| merged_header(c).unwrap_err().to_string();
        let gap = e(&[chunk(0, 4, 10), chunk(7, 10, 10)]);
        assert!(
            gap.starts_with("hours 4:7 of 10 missing after c0.mtx (0:4), before c7.mtx"),
            "{gap}"
        );
        let first = e(&[chunk(4, 10, 10)]);
        assert!(
            first.starts_with("hours 0:4 of 10 missing, before c4.mtx"),
            "{first}"
        );
        let end = e(&[chunk(0, 4, 10), chunk(4, 7, 10)]);
        assert!(
            end.starts_with("hours 7:10 of 10 missing after c4.mtx (4:7)"),
            "{end}"
        );
        let order = e(&[chunk(0, 4, 10), chunk(7, 10, 10), chunk(4, 7, 10)]);
        assert!(
            order.starts_with("c4.mtx (hours 4:7) comes after c7.mtx (7:10)"),
            "{order}"
        );
        let over = e(&[chunk(0, 4, 10), chunk(3, 10, 10)]);
        assert!(
            over.starts_with("c3.mtx (hours 3:10) overlaps c0.mtx (0:4)"),
            "{over}"
        );
        let mut other = chunk(4, 10, 10);
        other.1.lines[0] = "rmtx -fa dc.mtx sky.smx".into();
        let cmd = e(&[chunk(0, 4, 10), other]);
        assert!(cmd.contains("come from different products"), "{cmd}");
        let mut plain = chunk(4, 10, 10);
        plain.1.remove(HOURS_VAR);
        assert!(e(&[chunk(0, 4, 10), plain]).contains("has no HOURS= line"));
    }
}
