//! Radiance's portable binary encoding, shared by compiled meshes ([`super::mesh`]) and
//! octrees ([`super::octree`]).
//!
//! Sources (read to understand, not copied): `src/common/portio.c` (`getint`, `getflt`,
//! `getstr`), `src/common/sceneio.c` (`readscene`, `getobj`), `src/common/readoct.c` and
//! `src/common/readmesh.c` (`gettree`/`skiptree`), `src/common/octree.h`.
//!
//! - An integer of `n` bytes is big-endian, its first byte sign-extended (`-1` in any width
//!   is all ones: `OVOID`, the `void` modifier).
//! - A real is 5 bytes: a 4-byte mantissa `l` and a 1-byte exponent `e`; the value is
//!   `(l + 0.5 - [l < 0]) / 0x7fffffff * 2^e`, and `l = 0` is exactly zero (its exponent
//!   byte is read and ignored).
//! - A string is NUL-terminated.
//! - A binary scene is a list of type names closed by an empty string (the writer's
//!   `otypes.h` order, so readers map names, not numbers), then objects: type number (1 byte,
//!   `-1` ends the list), modifier (object index within the file, `-1` = `void`; `objsize`
//!   bytes), name, string arguments (2-byte count), real arguments (2-byte count).
//! - An octree is written in pre-order: 1 byte `0` empty, `1` full (a set: count then that
//!   many object numbers of `objsize` bytes), `2` a tree (eight children follow).
//!
//! Every read is a `nom` parser over the whole file in memory; failures name the byte offset
//! and what was expected.

use nom::bytes::complete::{take, take_until};
use nom::number::complete::be_u8;
use nom::{IResult, Parser};

use crate::error::{Error, Location, Result};
use crate::scene::{OType, Object, Primitive};

/// The most objects in one octree leaf set (`MAXSET` in `octree.h`).
const MAXSET: i64 = 511;
/// The most a `sizeof(OBJECT)` may be (`MAXOBJSIZ` in `octree.h`).
pub(crate) const MAXOBJSIZ: i64 = 8;

fn be_int(n: usize) -> impl Fn(&[u8]) -> IResult<&[u8], i64> {
    move |i: &[u8]| {
        let (rest, bytes) = take(n).parse(i)?;
        let mut r = bytes[0] as i8 as i64; // sign-extend the first byte
        for &b in &bytes[1..] {
            r = (r << 8) | b as i64;
        }
        Ok((rest, r))
    }
}

fn radiance_real(i: &[u8]) -> IResult<&[u8], f64> {
    let (i, l) = be_int(4)(i)?;
    let (i, e) = be_int(1)(i)?;
    if l == 0 {
        return Ok((i, 0.0));
    }
    let d = (l as f64 + 0.5 - if l < 0 { 1.0 } else { 0.0 }) * (1.0 / 0x7fff_ffff as f64);
    Ok((i, d * 2f64.powi(e as i32)))
}

fn c_string(i: &[u8]) -> IResult<&[u8], &[u8]> {
    let (i, s) = take_until(&b"\0"[..]).parse(i)?;
    let (i, _) = be_u8(i)?;
    Ok((i, s))
}

/// A cursor over a binary file: each read runs one `nom` parser and turns a failure into a
/// one-line error naming the file, the byte offset and what was expected.
pub(crate) struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    name: &'a str,
    /// What kind of file this is, for messages ("mesh file", "octree").
    kind: &'static str,
}

impl<'a> Reader<'a> {
    pub fn new(data: &'a [u8], pos: usize, name: &'a str, kind: &'static str) -> Self {
        Reader {
            data,
            pos,
            name,
            kind,
        }
    }

    pub fn pos(&self) -> usize {
        self.pos
    }

    /// An error at the current offset.
    pub fn error(&self, msg: impl std::fmt::Display) -> Error {
        self.error_at(self.pos, msg)
    }

    pub fn error_at(&self, pos: usize, msg: impl std::fmt::Display) -> Error {
        Error::parse(
            Location::file(self.name),
            format!("byte {pos} of the {}: {msg}", self.kind),
        )
    }

    fn run<T>(&mut self, what: &str, p: impl Fn(&'a [u8]) -> IResult<&'a [u8], T>) -> Result<T> {
        match p(&self.data[self.pos..]) {
            Ok((rest, v)) => {
                self.pos = self.data.len() - rest.len();
                Ok(v)
            }
            Err(_) => Err(self.error(format!(
                "expected {what}, found the end of the file (truncated {}?)",
                self.kind
            ))),
        }
    }

    /// A `n`-byte signed integer (`getint`).
    pub fn int(&mut self, n: usize, what: &str) -> Result<i64> {
        self.run(what, be_int(n))
    }

    /// A 5-byte real (`getflt`).
    pub fn real(&mut self, what: &str) -> Result<f64> {
        self.run(what, radiance_real)
    }

    /// A NUL-terminated string (`getstr`), as UTF-8 (lossy: names are ASCII in practice).
    pub fn string(&mut self, what: &str) -> Result<String> {
        self.run(what, c_string)
            .map(|s| String::from_utf8_lossy(s).into_owned())
    }

    /// A string holding a number (the octree cube's origin and size are written as text).
    pub fn number_string(&mut self, what: &str) -> Result<f64> {
        let at = self.pos;
        let s = self.string(what)?;
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.error_at(at, format!("expected {what}, found '{s}'")))
    }

    /// Skip a pre-ordered octree (`skiptree`), iteratively so that a damaged file cannot
    /// exhaust the stack.
    pub fn skip_tree(&mut self, objsize: usize) -> Result<()> {
        let mut pending: u64 = 1;
        while pending > 0 {
            pending -= 1;
            let at = self.pos;
            match self.int(1, "an octree node (0 empty, 1 full, 2 tree)")? {
                0 => {}
                1 => {
                    let n = self.int(objsize, "the size of an octree leaf set")?;
                    if !(0..=MAXSET).contains(&n) {
                        return Err(self.error_at(
                            at,
                            format!("octree leaf set of {n} objects; expected 0 to {MAXSET}"),
                        ));
                    }
                    let skip = n as usize * objsize;
                    if self.data.len() - self.pos < skip {
                        return Err(self.error(format!(
                            "expected a leaf set of {n} objects, found the end of the file (truncated {}?)",
                            self.kind
                        )));
                    }
                    self.pos += skip;
                }
                2 => pending += 8,
                b => {
                    return Err(self.error_at(
                        at,
                        format!(
                            "octree node {b}; expected 0, 1 or 2 (damaged {}?)",
                            self.kind
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A binary scene (`readscene`): the objects, with modifier links resolved within the
    /// file. Objects are located at `loc` (the file) for later messages.
    pub fn scene(&mut self, objsize: usize) -> Result<Vec<Object>> {
        let mut types: Vec<Option<OType>> = Vec::new();
        let mut names: Vec<String> = Vec::new();
        loop {
            let s = self.string("an object type name")?;
            if s.is_empty() {
                break;
            }
            if types.len() >= 256 {
                return Err(self.error("more than 256 object type names (damaged file?)"));
            }
            types.push(OType::from_name(&s));
            names.push(s);
        }
        let mut objects: Vec<Object> = Vec::new();
        loop {
            let at = self.pos;
            let t = self.int(1, "an object type number (or -1 to end the objects)")?;
            if t == -1 {
                break;
            }
            let Some(Some(otype)) = usize::try_from(t).ok().and_then(|t| types.get(t).copied())
            else {
                let name = usize::try_from(t)
                    .ok()
                    .and_then(|t| names.get(t))
                    .map_or("(none)", |s| s.as_str());
                return Err(self.error_at(
                    at,
                    format!("object of type number {t} ('{name}'), which rdaylight does not know"),
                ));
            };
            let m = self.int(objsize, "the object's modifier number")?;
            let modifier = match m {
                -1 => None,
                m if m >= 0 && (m as usize) < objects.len() => Some(m as usize),
                m => {
                    return Err(self.error_at(
                        at,
                        format!(
                            "object {} has modifier number {m}; expected -1 (void) or an earlier object (0..{})",
                            objects.len(),
                            objects.len()
                        ),
                    ));
                }
            };
            let id = self.string("the object's name")?;
            let ns = self.int(2, "the number of string arguments")?.max(0) as usize;
            let mut strings = Vec::with_capacity(ns.min(1024));
            for _ in 0..ns {
                strings.push(self.string("a string argument")?);
            }
            let nf = self.int(2, "the number of real arguments")?.max(0) as usize;
            let mut reals = Vec::with_capacity(nf.min(1024));
            for _ in 0..nf {
                reals.push(self.real("a real argument")?);
            }
            let kind = Primitive::from_args(otype, strings, reals).ok_or_else(|| {
                self.error_at(
                    at,
                    format!("{otype} '{id}' has {ns} string and {nf} real arguments, which do not fit its type"),
                )
            })?;
            let modifier_name = modifier.map_or("void".to_string(), |m| objects[m].id.clone());
            objects.push(Object {
                modifier,
                modifier_name,
                id,
                kind,
                alias: None,
                loc: Location::file(self.name),
            });
        }
        Ok(objects)
    }
}

/// The header of a binary Radiance file and the offset just after it: checks
/// `FORMAT=<format>`.
pub(crate) fn header(data: &[u8], name: &str, format: &str, kind: &str) -> Result<usize> {
    let mut cur = std::io::Cursor::new(data);
    let h = crate::header::Header::read(&mut cur, name)?;
    if h.magic.is_none() {
        return Err(Error::parse(
            Location::file(name),
            format!("not a Radiance {kind}: expected a '#?RADIANCE' header with FORMAT={format}"),
        ));
    }
    match h.format() {
        Some(f) if f == format => Ok(cur.position() as usize),
        other => Err(Error::parse(
            Location::file(name),
            format!(
                "not a Radiance {kind}: header says FORMAT={}, expected FORMAT={format}",
                other.unwrap_or("(none)")
            ),
        )),
    }
}

/// The object size from a format number (`magic + sizeof(OBJECT)`).
pub(crate) fn objsize(r: &mut Reader, magic: i64) -> Result<usize> {
    let at = r.pos();
    let n = r.int(2, "the format number")? - magic;
    if !(1..=MAXOBJSIZ).contains(&n) {
        return Err(r.error_at(
            at,
            format!(
                "format number {} is not one Radiance writes (object size {n}; expected 1 to 8)",
                n + magic
            ),
        ));
    }
    Ok(n as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_sign_extend_and_reals_decode() {
        assert_eq!(be_int(2)(&[0xff, 0xff]).unwrap().1, -1);
        assert_eq!(be_int(4)(&[0, 0, 1, 2]).unwrap().1, 258);
        // 0.75 = 0x60000000/0x7fffffff * 2^0 (to the encoding's 1 part in 2^31).
        let (_, v) = radiance_real(&[0x60, 0, 0, 0, 0]).unwrap();
        assert!((v - 0.75).abs() < 1e-9, "{v}");
        let (_, v) = radiance_real(&[0xa0, 0, 0, 0, 2]).unwrap();
        assert!((v + 3.0).abs() < 1e-8, "{v}");
        assert_eq!(radiance_real(&[0, 0, 0, 0, 7]).unwrap().1, 0.0);
        assert!(radiance_real(&[1, 2]).is_err());
    }

    #[test]
    fn truncated_reads_name_the_offset() {
        let mut r = Reader::new(b"ab\0c", 0, "x.rtm", "mesh file");
        assert_eq!(r.string("a name").unwrap(), "ab");
        let e = r.string("a name").unwrap_err().to_string();
        assert_eq!(
            e,
            "x.rtm: byte 3 of the mesh file: expected a name, found the end of the file (truncated mesh file?)"
        );
    }

    #[test]
    fn deep_trees_are_skipped_without_recursion() {
        // 100,000 nested tree nodes, each with seven empty siblings: no stack overflow, and
        // the missing eighth child is a clean error.
        let data = vec![2u8; 100_000];
        let mut r = Reader::new(&data, 0, "x.oct", "octree");
        assert!(r.skip_tree(4).is_err());
    }
}
