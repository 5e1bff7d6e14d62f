//! Compiled scene files (`rdc --compile scene.rdb room.rad ...`): the container, the record
//! of the files a scene was made from, and the binary encoding of a [`Scene`].
//!
//! The layout is `docs/scene-binary-formats.md`'s ("Compiled scenes"): a Radiance-style
//! text header (`#?RADIANCE`, the command, `FORMAT=rdaylight_compiled_scene`, an empty
//! line), then [`MAGIC`], the format [`VERSION`], the whole file's length and a checksum
//! ([`rdaylight_base::hash::wide64`]) of everything after it, then the body. The body
//! starts with the tool and geometry revisions and the [`SourceRecord`]s; the tracer writes
//! the rest (the scene's modifiers, material slots, surfaces and BVH).
//!
//! Reading never trusts a count or an index: every count is checked against the bytes
//! left before anything is allocated, every reference against what it refers to, and a
//! damaged, truncated or foreign file is one error line naming the file and what to do.
//! The [`Decoder`] reads with `nom`'s number parsers.

use std::path::{Path, PathBuf};

use nom::Parser;
use nom::number::complete::{le_f32, le_f64, le_u8, le_u32, le_u64};

use super::otype::OType;
use super::specdata::SpecData;
use super::{Alias, Object, Primitive, Scene};
use crate::error::{Error, Location, Result};
use rdaylight_base::hash::wide64;

/// The `FORMAT=` of a compiled scene's header.
pub const FORMAT: &str = "rdaylight_compiled_scene";
/// The bytes that open the binary part.
pub const MAGIC: &[u8; 8] = b"RDSCENE\0";
/// The format this code writes and reads; any other is refused (recompile).
pub const VERSION: u32 = 1;
/// The longest text header read before giving up (a foreign file is not read whole).
const MAX_HEADER: usize = 64 << 10;

/// What to tell the user for any damage.
const RECOMPILE: &str = "recompile it with rdc --compile";

/// Little-endian writer of a compiled scene's body.
#[derive(Debug, Default)]
pub struct Encoder {
    pub buf: Vec<u8>,
}

impl Encoder {
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn u32(&mut self, v: u32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f32(&mut self, v: f32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64s(&mut self, v: &[f64]) {
        self.buf.reserve(8 * v.len());
        for &x in v {
            self.f64(x);
        }
    }
    pub fn bytes(&mut self, v: &[u8]) {
        self.buf.extend_from_slice(v);
    }
    /// A length or count (8 bytes).
    pub fn len(&mut self, n: usize) {
        self.u64(n as u64);
    }
    /// A string: its length, then its UTF-8 bytes.
    /// A `file:line:column` location: the file name, then line and column (0: none).
    pub fn location(&mut self, loc: &Location) {
        self.str(&loc.file);
        self.u32(loc.line.map_or(0, |l| l as u32));
        self.u32(loc.col.map_or(0, |c| c as u32));
    }
    pub fn str(&mut self, s: &str) {
        self.len(s.len());
        self.bytes(s.as_bytes());
    }
    /// An optional index (`u32::MAX` for none).
    pub fn index(&mut self, i: Option<usize>) {
        self.u32(i.map_or(u32::MAX, |i| i as u32));
    }
}

/// Bounds-checked little-endian reader of a compiled scene's body (`nom` number parsers);
/// errors name the file, the byte offset and what was being read.
pub struct Decoder<'a> {
    rest: &'a [u8],
    /// Offset of `rest` in the file.
    offset: usize,
    name: &'a str,
}

type NomResult<'a, T> = nom::IResult<&'a [u8], T, ()>;

impl<'a> Decoder<'a> {
    /// A decoder over `bytes`, which start at byte `offset` of the file `name`.
    pub fn new(bytes: &'a [u8], offset: usize, name: &'a str) -> Self {
        Decoder {
            rest: bytes,
            offset,
            name,
        }
    }

    /// The error for damage found here: `what` was expected.
    pub fn corrupted(&self, what: impl std::fmt::Display) -> Error {
        Error::parse(
            Location::file(self.name),
            format!(
                "damaged compiled scene: {what} (byte {}); {RECOMPILE}",
                self.offset
            ),
        )
    }

    fn take<T>(
        &mut self,
        mut p: impl FnMut(&'a [u8]) -> NomResult<'a, T>,
        what: &str,
    ) -> Result<T> {
        match p(self.rest) {
            Ok((rest, v)) => {
                self.offset += self.rest.len() - rest.len();
                self.rest = rest;
                Ok(v)
            }
            Err(_) => Err(self.corrupted(format!("truncated while reading {what}"))),
        }
    }

    pub fn u8(&mut self, what: &str) -> Result<u8> {
        self.take(|i| le_u8.parse(i), what)
    }
    pub fn u32(&mut self, what: &str) -> Result<u32> {
        self.take(|i| le_u32.parse(i), what)
    }
    pub fn u64(&mut self, what: &str) -> Result<u64> {
        self.take(|i| le_u64.parse(i), what)
    }
    pub fn f32(&mut self, what: &str) -> Result<f32> {
        self.take(|i| le_f32.parse(i), what)
    }
    pub fn f64(&mut self, what: &str) -> Result<f64> {
        self.take(|i| le_f64.parse(i), what)
    }
    /// Six `f32`s (a box: minimum, maximum).
    pub fn f32s6(&mut self, what: &str) -> Result<[f32; 6]> {
        let mut out = [0.0; 6];
        for v in &mut out {
            *v = self.f32(what)?;
        }
        Ok(out)
    }
    pub fn bool(&mut self, what: &str) -> Result<bool> {
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(self.corrupted(format!("{what} is {v}, expected 0 or 1"))),
        }
    }
    pub fn bytes(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        self.take(|i| nom::bytes::complete::take(n).parse(i), what)
    }
    /// `n` reals.
    pub fn f64s(&mut self, n: usize, what: &str) -> Result<Vec<f64>> {
        let b = self.bytes(n.saturating_mul(8), what)?;
        Ok(b.chunks_exact(8)
            .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect())
    }
    /// A count of items of at least `item_bytes` bytes each: refused when the bytes left
    /// cannot hold them (so a damaged count never makes a huge allocation).
    pub fn count(&mut self, item_bytes: usize, what: &str) -> Result<usize> {
        let n = self.u64(what)?;
        let fits = usize::try_from(n)
            .ok()
            .filter(|&n| n.saturating_mul(item_bytes.max(1)) <= self.rest.len());
        fits.ok_or_else(|| {
            self.corrupted(format!(
                "{what} {n} cannot fit in the {} bytes left",
                self.rest.len()
            ))
        })
    }
    /// A location as [`Encoder::location`] wrote it (`what` names it in errors).
    pub fn location(&mut self, what: &str) -> Result<Location> {
        let file = self.str(&format!("{what} file"))?;
        let (line, col) = (
            self.u32(&format!("{what} line"))?,
            self.u32(&format!("{what} column"))?,
        );
        Ok(Location {
            file,
            line: (line > 0).then_some(line as usize),
            col: (col > 0).then_some(col as usize),
        })
    }
    pub fn str(&mut self, what: &str) -> Result<String> {
        let n = self.count(1, what)?;
        let b = self.bytes(n, what)?;
        String::from_utf8(b.to_vec()).map_err(|_| self.corrupted(format!("{what} is not UTF-8")))
    }
    /// An index below `bound`, or `None` for `u32::MAX`.
    pub fn index(&mut self, bound: usize, what: &str) -> Result<Option<usize>> {
        match self.u32(what)? {
            u32::MAX => Ok(None),
            i if (i as usize) < bound => Ok(Some(i as usize)),
            i => Err(self.corrupted(format!("{what} {i} out of range (below {bound})"))),
        }
    }
    /// An index below `bound` that must be there.
    pub fn required_index(&mut self, bound: usize, what: &str) -> Result<usize> {
        self.index(bound, what)?
            .ok_or_else(|| self.corrupted(format!("{what} missing")))
    }
    /// The bytes not read yet (to decode a run of fixed records in place; then
    /// [`Decoder::bytes`] the length used).
    pub fn peek(&self) -> &'a [u8] {
        self.rest
    }
    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.rest.len()
    }
    /// The error when bytes are left over after the last section.
    pub fn finish(&self) -> Result<()> {
        if self.rest.is_empty() {
            Ok(())
        } else {
            Err(self.corrupted(format!("{} bytes after the end", self.rest.len())))
        }
    }
}

/// What a compiled scene was made from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SourceKind {
    /// A file (scene input, `specfile` data, mesh, octree): checked on every use.
    File,
    /// A `!command` whose output went into the scene: its text is recorded (it is part of
    /// the scene file's bytes anyway) but it is not re-run.
    Command,
}

/// One file a compiled scene was made from, as it was then.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceRecord {
    pub kind: SourceKind,
    /// For a file: its path relative to the compiled scene's folder when it is inside
    /// (or below a common ancestor), else absolute. For a command: its text.
    pub path: String,
    pub size: u64,
    /// Modification time (seconds and nanoseconds since 1970; 0 when unknown).
    pub mtime: (i64, u32),
    /// [`wide64`] of its bytes.
    pub hash: u64,
}

/// The modification time of a file as stored in [`SourceRecord::mtime`].
fn mtime_of(meta: &std::fs::Metadata) -> (i64, u32) {
    match meta
        .modified()
        .map(|t| t.duration_since(std::time::UNIX_EPOCH))
    {
        Ok(Ok(d)) => (d.as_secs() as i64, d.subsec_nanos()),
        Ok(Err(e)) => (
            -(e.duration().as_secs() as i64),
            e.duration().subsec_nanos(),
        ),
        Err(_) => (0, 0),
    }
}

/// `path` relative to folder `base` (both made absolute), `..` where needed; `path` made
/// absolute when they share no ancestor.
fn relative_to(path: &Path, base: &Path) -> PathBuf {
    let (Ok(p), Ok(b)) = (std::path::absolute(path), std::path::absolute(base)) else {
        return path.to_path_buf();
    };
    let (pc, bc): (Vec<_>, Vec<_>) = (p.components().collect(), b.components().collect());
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    // Sharing only the root (or nothing): an absolute path survives moving the folder.
    if common <= 1 {
        return p;
    }
    let mut out = PathBuf::new();
    for _ in common..bc.len() {
        out.push("..");
    }
    for c in &pc[common..] {
        out.push(c);
    }
    out
}

/// The folder a compiled scene's relative paths start from.
fn folder_of(rdb: &Path) -> PathBuf {
    rdb.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

impl SourceRecord {
    /// Record file `path` (read now) for a compiled scene to be written at `rdb`.
    pub fn file(path: &Path, rdb: &Path) -> Result<SourceRecord> {
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, e))?;
        let meta = std::fs::metadata(path).map_err(|e| Error::io(&shown, e))?;
        Ok(SourceRecord {
            kind: SourceKind::File,
            path: relative_to(path, &folder_of(rdb)).display().to_string(),
            size: bytes.len() as u64,
            mtime: mtime_of(&meta),
            hash: wide64(&bytes),
        })
    }

    /// Record an inline command (its text; nothing is checked on use).
    pub fn command(text: &str) -> SourceRecord {
        SourceRecord {
            kind: SourceKind::Command,
            path: text.to_string(),
            size: 0,
            mtime: (0, 0),
            hash: 0,
        }
    }

    /// Where the file is for a compiled scene at `rdb`.
    pub fn resolve(&self, rdb: &Path) -> PathBuf {
        let p = Path::new(&self.path);
        let folder = folder_of(rdb);
        if p.is_absolute() || folder == Path::new(".") {
            p.to_path_buf()
        } else {
            folder.join(p)
        }
    }

    /// `None` when the file is as it was (same size and time, or same bytes), else what
    /// changed, in words. Commands are never checked.
    pub fn changed(&self, rdb: &Path) -> Option<String> {
        if self.kind == SourceKind::Command {
            return None;
        }
        let path = self.resolve(rdb);
        let shown = path.display();
        let meta = match std::fs::metadata(&path) {
            Ok(m) => m,
            Err(_) => return Some(format!("{shown} is gone")),
        };
        if meta.len() == self.size && mtime_of(&meta) == self.mtime {
            return None;
        }
        // Touched or copied: the bytes decide.
        match std::fs::read(&path) {
            Ok(b) if b.len() as u64 == self.size && wide64(&b) == self.hash => None,
            Ok(b) if b.len() as u64 != self.size => Some(format!(
                "{shown} changed ({} bytes, {} when compiled)",
                b.len(),
                self.size
            )),
            Ok(_) => Some(format!("{shown} changed (same size, other bytes)")),
            Err(e) => Some(format!("{shown} cannot be read ({e})")),
        }
    }

    fn encode(&self, e: &mut Encoder) {
        e.u8(match self.kind {
            SourceKind::File => 0,
            SourceKind::Command => 1,
        });
        e.str(&self.path);
        e.u64(self.size);
        e.u64(self.mtime.0 as u64);
        e.u32(self.mtime.1);
        e.u64(self.hash);
    }

    fn decode(d: &mut Decoder) -> Result<SourceRecord> {
        let kind = match d.u8("source kind")? {
            0 => SourceKind::File,
            1 => SourceKind::Command,
            k => return Err(d.corrupted(format!("source kind {k}"))),
        };
        Ok(SourceRecord {
            kind,
            path: d.str("source path")?,
            size: d.u64("source size")?,
            mtime: (d.u64("source time")? as i64, d.u32("source time")?),
            hash: d.u64("source hash")?,
        })
    }
}

/// The head of a compiled scene's body: who wrote it and from what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Provenance {
    /// The writing tool and version (`rdaylight 0.1.0`).
    pub tool: String,
    /// The geometry revision of the writer (what triangulation and BVH it used).
    pub geometry: String,
    pub sources: Vec<SourceRecord>,
}

impl Provenance {
    pub fn encode(&self, e: &mut Encoder) {
        e.str(&self.tool);
        e.str(&self.geometry);
        e.len(self.sources.len());
        for s in &self.sources {
            s.encode(e);
        }
    }

    pub fn decode(d: &mut Decoder) -> Result<Provenance> {
        let tool = d.str("tool")?;
        let geometry = d.str("geometry revision")?;
        let n = d.count(33, "source count")?;
        let sources = (0..n)
            .map(|_| SourceRecord::decode(d))
            .collect::<Result<_>>()?;
        Ok(Provenance {
            tool,
            geometry,
            sources,
        })
    }

    /// The first source that changed since compiling, as one error for the compiled
    /// scene at `rdb`.
    pub fn check_fresh(&self, rdb: &Path) -> Result<()> {
        for s in &self.sources {
            if let Some(what) = s.changed(rdb) {
                return Err(Error::Usage(format!(
                    "{} is out of date: {what}; recompile it with rdc --compile",
                    rdb.display()
                )));
            }
        }
        Ok(())
    }
}

/// The checksum of a file whose checksum field starts at byte `at`: [`wide64`] of the
/// [`wide64`]s of what comes before the field and of what comes after it, so that every
/// byte but the field's own is covered (the text header too).
fn checksum(bytes: &[u8], at: usize) -> u64 {
    let (head, tail) = (&bytes[..at], &bytes[(at + 8).min(bytes.len())..]);
    let mut both = [0u8; 16];
    both[..8].copy_from_slice(&wide64(head).to_le_bytes());
    both[8..].copy_from_slice(&wide64(tail).to_le_bytes());
    wide64(&both)
}

/// Write a compiled scene to `path` atomically: the header (with `command`), then `body`.
pub fn write(path: &Path, command: &str, body: &[u8]) -> Result<()> {
    // The command is one header line: its own line breaks would end the header.
    let command = command.replace(['\n', '\r'], " ");
    let header = format!(
        "#?RADIANCE\n{command}\nSOFTWARE= rdaylight {}\nFORMAT={FORMAT}\n\n",
        env!("CARGO_PKG_VERSION")
    );
    let mut head = header.into_bytes();
    head.extend_from_slice(MAGIC);
    head.extend_from_slice(&VERSION.to_le_bytes());
    let len = head.len() + 8 + 8 + body.len();
    head.extend_from_slice(&(len as u64).to_le_bytes());
    let at = head.len();
    // The checksum of head + (field) + body, without copying the body.
    let mut both = [0u8; 16];
    both[..8].copy_from_slice(&wide64(&head).to_le_bytes());
    both[8..].copy_from_slice(&wide64(body).to_le_bytes());
    head.extend_from_slice(&wide64(&both).to_le_bytes());
    debug_assert_eq!(at + 8, head.len());
    let shown = path.display().to_string();
    crate::io::write_atomically(path, |w| {
        let io = |e| Error::io(&shown, e);
        w.write_all(&head).map_err(io)?;
        w.write_all(body).map_err(io)
    })
}

/// True when `head` (a file's first bytes) is a compiled scene's header.
pub fn is_compiled(head: &[u8]) -> bool {
    let Some(end) = head.windows(2).position(|w| w == b"\n\n") else {
        return false;
    };
    head.starts_with(b"#?")
        && String::from_utf8_lossy(&head[..end])
            .lines()
            .any(|l| l.trim_end() == format!("FORMAT={FORMAT}"))
}

/// Read a compiled scene's bytes, checking header, magic, version, length and checksum.
/// Returns the file's bytes and where the body starts.
pub fn read(path: &Path) -> Result<(Vec<u8>, usize)> {
    let shown = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, e))?;
    let body = check(&bytes, &shown)?;
    Ok((bytes, body))
}

/// [`read`] for bytes in memory (`name` for messages): where the body starts.
pub fn check(bytes: &[u8], name: &str) -> Result<usize> {
    let bad = |msg: String| Error::parse(Location::file(name), msg);
    let head = &bytes[..bytes.len().min(MAX_HEADER)];
    if !is_compiled(head) {
        return Err(bad(format!(
            "not a compiled scene (expected a header with FORMAT={FORMAT}); make one with rdc --compile"
        )));
    }
    let start = head
        .windows(2)
        .position(|w| w == b"\n\n")
        .map_or(bytes.len(), |p| p + 2);
    let mut d = Decoder::new(&bytes[start..], start, name);
    let magic = d.bytes(MAGIC.len(), "the magic number")?;
    if magic != MAGIC {
        return Err(d.corrupted("wrong magic number"));
    }
    let version = d.u32("the format version")?;
    if version != VERSION {
        return Err(bad(format!(
            "compiled scene format {version}; this rdc reads format {VERSION}: {RECOMPILE}"
        )));
    }
    let len = d.u64("the file length")?;
    if len != bytes.len() as u64 {
        return Err(bad(format!(
            "{} bytes, {len} when written: the file is {}; {RECOMPILE}",
            bytes.len(),
            if (bytes.len() as u64) < len {
                "truncated"
            } else {
                "damaged"
            }
        )));
    }
    let at = start + MAGIC.len() + 4 + 8;
    let sum = d.u64("the checksum")?;
    if checksum(bytes, at) != sum {
        return Err(bad(format!(
            "damaged compiled scene (checksum mismatch); {RECOMPILE}"
        )));
    }
    Ok(at + 8)
}

/// Write the objects of `scene` (not its directives) with `index[k]`, the position of
/// object `k` in the whole scene it came from.
pub fn encode_scene(scene: &Scene, index: &[u32], e: &mut Encoder) {
    e.len(scene.objects.len());
    for (k, o) in scene.objects.iter().enumerate() {
        e.u32(index.get(k).copied().unwrap_or(u32::MAX));
        e.str(o.kind.type_name());
        e.index(o.modifier);
        e.str(&o.modifier_name);
        e.str(&o.id);
        let (strings, reals) = o.kind.to_args();
        e.len(strings.len());
        for s in &strings {
            e.str(s);
        }
        e.len(reals.len());
        e.f64s(&reals);
        match &o.alias {
            None => e.u8(0),
            Some(a) => {
                e.u8(1);
                e.index(Some(a.target));
                e.str(&a.target_id);
            }
        }
        e.location(&o.loc);
        match &o.kind {
            Primitive::SpecFile { data: Some(d), .. } => {
                e.u8(1);
                e.len(d.wavelengths.len());
                e.f64s(&d.wavelengths);
                e.len(d.values.len());
                e.f64s(&d.values);
            }
            _ => e.u8(0),
        }
    }
}

/// Read what [`encode_scene`] wrote: the scene and each object's position.
pub fn decode_scene(d: &mut Decoder) -> Result<(Scene, Vec<u32>)> {
    // The smallest object: position, 4 lengths of empty strings, modifier, 2 counts,
    // alias flag, file, line, column, data flag.
    let n = d.count(4 + 8 * 4 + 4 + 8 * 2 + 1 + 8 + 4 + 4 + 1, "object count")?;
    let mut objects: Vec<Object> = Vec::with_capacity(n);
    let mut index = Vec::with_capacity(n);
    for k in 0..n {
        index.push(d.u32("object position")?);
        let tname = d.str("object type")?;
        let otype = OType::from_name(&tname)
            .ok_or_else(|| d.corrupted(format!("unknown type '{tname}'")))?;
        let modifier = d.index(k, "modifier")?;
        let modifier_name = d.str("modifier name")?;
        let id = d.str("object name")?;
        let ns = d.count(8, "string count")?;
        let strings = (0..ns)
            .map(|_| d.str("string argument"))
            .collect::<Result<Vec<_>>>()?;
        let nr = d.count(8, "real count")?;
        let reals = d.f64s(nr, "real arguments")?;
        let alias = match d.u8("alias flag")? {
            0 => None,
            1 => Some(Alias {
                target: d.required_index(k, "alias target")?,
                target_id: d.str("alias target name")?,
            }),
            v => return Err(d.corrupted(format!("alias flag {v}"))),
        };
        let loc = d.location("object")?;
        let mut kind = Primitive::from_args(otype, strings, reals)
            .ok_or_else(|| d.corrupted(format!("{tname} '{id}' with bad arguments")))?;
        if d.bool("data flag")? {
            let nw = d.count(8, "wavelength count")?;
            let wavelengths = d.f64s(nw, "wavelengths")?;
            let nv = d.count(8, "value count")?;
            let values = d.f64s(nv, "values")?;
            match &mut kind {
                Primitive::SpecFile { data, .. } => {
                    *data = Some(SpecData {
                        wavelengths,
                        values,
                    })
                }
                _ => return Err(d.corrupted(format!("data for {tname} '{id}'"))),
            }
        }
        objects.push(Object {
            modifier,
            modifier_name,
            id,
            kind,
            alias,
            loc,
        });
    }
    Ok((
        Scene {
            objects,
            directives: Vec::new(),
        },
        index,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_round_trip_and_damage_is_an_error() {
        let text = "void plastic red 0 0 5 .5 .1 .1 0 0\nred alias red2 red\n\
                    void brightfunc f 2 skybr skybright.cal 0 3 1 2 3\n\
                    f glow sky 0 0 4 1 1 1 0\nsky source s 0 0 4 0 0 1 180\n";
        let scene =
            crate::scene::parse_str(text, "t.rad", Path::new(""), &Default::default()).unwrap();
        let mut e = Encoder::default();
        encode_scene(&scene, &[0, 1, 2, 3, 4], &mut e);
        let mut d = Decoder::new(&e.buf, 0, "t.rdb");
        let (back, index) = decode_scene(&mut d).unwrap();
        d.finish().unwrap();
        assert_eq!(index, [0, 1, 2, 3, 4]);
        assert_eq!(back.objects, scene.objects);
        // Every prefix is an error, never a panic; so is any byte changed (or it decodes).
        for n in 0..e.buf.len() {
            let mut d = Decoder::new(&e.buf[..n], 0, "t.rdb");
            assert!(
                decode_scene(&mut d).and_then(|_| d.finish()).is_err(),
                "{n}"
            );
        }
        for k in 0..e.buf.len() {
            let mut b = e.buf.clone();
            b[k] ^= 0xa5;
            let mut d = Decoder::new(&b, 0, "t.rdb");
            let _ = decode_scene(&mut d);
        }
    }

    #[test]
    fn relative_paths_climb_to_a_common_folder() {
        let r = relative_to(Path::new("/a/b/c.rad"), Path::new("/a/d"));
        assert_eq!(r, Path::new("../b/c.rad"));
        let r = relative_to(Path::new("/a/b/c.rad"), Path::new("/a/b"));
        assert_eq!(r, Path::new("c.rad"));
        let r = relative_to(Path::new("/usr/lib/x.cal"), Path::new("/a/b"));
        assert_eq!(r, Path::new("/usr/lib/x.cal"));
    }
}
