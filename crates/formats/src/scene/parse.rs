//! Reading scene text: words, comments, `!` lines, objects, aliases and modifier links.
//!
//! Grammar (radiance-notes.md 4.1; `src/common/readobj.c`, `readfargs.c`, `fgetword.c`,
//! `fgetline.c`, `words.c`):
//!
//! ```text
//! # comment to end of line               only where a statement starts
//! !command ...                            '\' + newline continues the line
//! modifier type identifier
//! N s1 ... sN                             words; '...' and "..." quote (also mid-word)
//! 0                                       integer arguments: the count must be 0
//! M r1 ... rM                             reals in C float syntax (isflt)
//! modifier alias new_id old_id            modifier 'inherit' keeps old_id's modifier
//! ```
//!
//! A modifier name refers to the most recently defined *modifier* (non-surface) with that id;
//! an unknown name is an error, as in Radiance. Words are separated by C `isspace` characters.
//! Differences from Radiance, all towards reporting instead of guessing: an unterminated quote
//! is an error (Radiance reads to end of file), words are not cut at 511 characters, reals
//! that overflow to infinity are rejected.

use std::borrow::Cow;
use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::{tag, take_till, take_while1},
    character::complete::{char, digit1, one_of},
    combinator::{all_consuming, opt, recognize},
    multi::{fold_many1, many0},
    sequence::delimited,
};

use super::otype::OType;
use super::primitive::Primitive;
use super::specdata::SpecData;
use super::table::{SurfaceTable, VOID, is_plain_surface};
use super::{Alias, LoadOptions, Object, Scene, exec};
use crate::error::{Error, Location, Result};

/// Nesting limit for `!` commands whose output holds more `!` commands (a runaway generator
/// would otherwise recurse forever).
const MAX_COMMAND_DEPTH: usize = 16;

/// Most inline commands one load runs, nested or not. Each is a process start (a few ms),
/// and a scene whose commands include the scene again multiplies them: ten `!cat self.rad`
/// lines ran 11,110 commands for 32 s before the depth limit stopped them (issue #19).
/// Real scenes run tens to a few hundred (`!xform` instances of furniture, `!genbox`).
pub(crate) const MAX_COMMANDS: usize = 4096;

/// C `isspace` in the "C" locale (note: includes vertical tab, unlike `is_ascii_whitespace`).
fn is_space(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\n' | '\x0B' | '\x0C' | '\r')
}

fn is_quote(c: char) -> bool {
    c == '\'' || c == '"'
}

/// What each byte is for the word scanners: white space (C `isspace`), a quote, or part
/// of a word. White space and quotes are ASCII, and no byte of a multi-byte UTF-8
/// character is either, so scanning bytes finds the same words as scanning characters.
const BYTE_CLASS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut k = 0;
    let space = [b' ', b'\t', b'\n', 0x0B, 0x0C, b'\r'];
    while k < space.len() {
        t[space[k] as usize] = SPACE;
        k += 1;
    }
    t[b'\'' as usize] = QUOTE;
    t[b'"' as usize] = QUOTE;
    t
};
const SPACE: u8 = 1;
const QUOTE: u8 = 2;

/// C `isspace` for one byte of UTF-8 text.
#[inline(always)]
fn is_space_byte(b: u8) -> bool {
    BYTE_CLASS[b as usize] == SPACE
}

/// A byte of an unquoted word.
#[inline(always)]
fn is_plain_byte(b: u8) -> bool {
    BYTE_CLASS[b as usize] == 0
}

/// nom's `take_while` over bytes, with the predicate inlined: nom calls it through a
/// reference for every byte, and for the ~100 MB of a 1M-polygon scene those calls were a
/// third of the reading time (issue 18). Never fails (an empty match is allowed).
#[inline(always)]
fn bytes_while(input: &[u8], f: impl Fn(u8) -> bool) -> IResult<&[u8], &[u8], ()> {
    let n = input.iter().position(|&b| !f(b)).unwrap_or(input.len());
    Ok((&input[n..], &input[..n]))
}

/// [`bytes_while`] that needs at least one byte (nom's `take_while1`).
#[inline(always)]
fn bytes_while1(input: &[u8], f: impl Fn(u8) -> bool) -> IResult<&[u8], &[u8], ()> {
    match bytes_while(input, f)? {
        (_, []) => Err(nom::Err::Error(())),
        ok => Ok(ok),
    }
}

/// One word as `fgetword` reads it: runs of unquoted non-space characters and quoted
/// segments (quotes removed), up to the first unquoted white space. A word without quotes
/// (nearly all of them) is found byte by byte and borrowed from the input, not copied.
fn word(input: &str) -> IResult<&str, Cow<'_, str>> {
    if let Ok((rest, w)) = bytes_while1(input.as_bytes(), is_plain_byte) {
        if !matches!(rest.first(), Some(b'\'' | b'"')) {
            // The word ends before an ASCII byte (or the end): a character boundary.
            let (w, rest) = input.split_at(w.len());
            return Ok((rest, Cow::Borrowed(w)));
        }
    }
    fold_many1(
        alt((
            delimited(char('\''), take_till(|c| c == '\''), char('\'')),
            delimited(char('"'), take_till(|c| c == '"'), char('"')),
            take_while1(|c: char| !is_space(c) && !is_quote(c)),
        )),
        String::new,
        |mut acc, s: &str| {
            acc.push_str(s);
            acc
        },
    )
    .map(Cow::Owned)
    .parse(input)
}

/// The text of a `!` line after the `!`, joined across backslash-newlines (kept verbatim, the
/// shell removes them), without the final newline.
fn command_line(input: &str) -> IResult<&str, &str> {
    let (rest, _) = char('!').parse(input)?;
    recognize(many0(alt((
        take_while1(|c| c != '\\' && c != '\n'),
        tag("\\\r\n"),
        tag("\\\n"),
        tag("\\"),
    ))))
    .parse(rest)
}

/// A `#` comment up to (not including) the end of the line.
fn comment(input: &str) -> IResult<&str, &str> {
    recognize((char('#'), take_till(|c| c == '\n'))).parse(input)
}

/// `isint` from `src/common/words.c`: optional sign, digits.
fn parse_count(w: &str) -> Option<i64> {
    // One digit (nearly every count: `0`, `0`, `9`) without the general grammar.
    if let [d @ b'0'..=b'9'] = w.as_bytes() {
        return Some(i64::from(d - b'0'));
    }
    all_consuming(recognize((opt(one_of("+-")), digit1::<&str, ()>)))
        .parse(w)
        .ok()
        .and_then(|_| w.parse::<i64>().ok())
}

/// A real argument: `isflt` syntax from `src/common/words.c` (optional sign, digits with an
/// optional fraction or a fraction alone, optional exponent), converted like `atof`. Returns
/// `None` for anything else, including values that overflow to infinity.
///
/// The check is on the characters only (digits, signs, `.`, `e`, `E`): over them Rust's own
/// float grammar (`f64::from_str`: sign, digits with an optional fraction or a fraction
/// alone, optional exponent, `e` in either case) is exactly `isflt`'s, so the conversion
/// rejects the rest (`1.2.3`, `1e`, `--1`); the words `inf` and `nan` it would take are not
/// made of those characters.
pub(crate) fn parse_real(w: &str) -> Option<f64> {
    // Plain decimals (nearly every coordinate) are recognised and converted in one pass.
    if let Some(v) = plain_decimal(w.as_bytes()) {
        return Some(v);
    }
    let (rest, _) = bytes_while1(w.as_bytes(), |b: u8| {
        b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E')
    })
    .ok()?;
    if !rest.is_empty() {
        return None;
    }
    w.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Powers of ten exact in `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The value of `[+-]digits[.digits]` without an exponent, when its digits make an integer
/// `m < 2^53` and it has at most 22 decimals: then `m` and `10^k` are exact doubles and
/// one division rounds correctly (Clinger 1990, "How to read floating point numbers
/// accurately"), so the result is the very double `f64::from_str` gives, found without its
/// general machinery (issue 18: converting 9M coordinates was a fifth of loading a
/// 1M-polygon scene). `None` for anything else (the caller converts it the general way).
fn plain_decimal(b: &[u8]) -> Option<f64> {
    match decimal_prefix(b) {
        Some((v, len)) if len == b.len() => Some(v),
        _ => None,
    }
}

/// The plain decimal ([`plain_decimal`]) that `b` starts with and its length in bytes.
#[inline(always)]
fn decimal_prefix(b: &[u8]) -> Option<(f64, usize)> {
    let (neg, mut i) = match b.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    // Wrapping arithmetic: more than 15 digits are refused below, before `m` is used.
    let mut m: u64 = 0;
    let mut digits = |i: &mut usize| {
        let start = *i;
        while let Some(&c) = b.get(*i) {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            m = m.wrapping_mul(10).wrapping_add(u64::from(d));
            *i += 1;
        }
        *i - start
    };
    let mut n = digits(&mut i);
    let mut k = 0;
    if b.get(i) == Some(&b'.') {
        i += 1;
        k = digits(&mut i);
        n += k;
    }
    // Up to 15 digits: `m` < 10^15 < 2^53, and `k` <= 15 < 23.
    if n == 0 || n > 15 {
        return None;
    }
    let v = m as f64 / POW10[k];
    Some((if neg { -v } else { v }, i))
}

/// One piece of scene text being read.
struct Source<'t> {
    /// File name as shown in locations (`room.rad`, `<stdin>`, `room.rad:12: !genbox ...`).
    name: Rc<str>,
    text: &'t str,
    /// Folder for `!` commands and data files.
    base_dir: PathBuf,
    pos: usize,
    /// Lines counted so far: up to byte `.0`, which is on line `.1`, whose first byte is
    /// `.2`. White space is counted as it is skipped, words without quotes have no line
    /// breaks, and anything else is counted when a location is asked for: no second pass
    /// over the text, and no table of line starts (8 bytes per line).
    cursor: Cell<(usize, usize, usize)>,
    /// The file's number in a [`SurfaceTable`], once it has one.
    file_number: Cell<Option<u32>>,
}

impl<'t> Source<'t> {
    fn new(name: String, text: &'t str, base_dir: PathBuf) -> Self {
        Source {
            name: name.into(),
            text,
            base_dir,
            pos: 0,
            cursor: Cell::new((0, 1, 0)),
            file_number: Cell::new(None),
        }
    }

    /// The file's number in `table`, asked of the table once per file.
    fn file_number_in(&self, table: &mut SurfaceTable) -> Result<u32> {
        if let Some(k) = self.file_number.get() {
            return Ok(k);
        }
        let k = table.file_number(&self.name)?;
        self.file_number.set(Some(k));
        Ok(k)
    }

    fn rest(&self) -> &'t str {
        self.text.get(self.pos..).unwrap_or("")
    }

    fn advance(&mut self, rest: &str) {
        self.pos = self.text.len() - rest.len();
    }

    /// 1-based line and column (in characters) of byte `offset`.
    fn line_col(&self, offset: usize) -> (usize, usize) {
        let bytes = self.text.as_bytes();
        let offset = offset.min(bytes.len());
        // Lines from `from` (on line `line`, starting at `start`) up to `offset`.
        let count = |from: usize, mut line: usize, mut start: usize| {
            for (i, &b) in bytes[from..offset].iter().enumerate() {
                if b == b'\n' {
                    line += 1;
                    start = from + i + 1;
                }
            }
            (line, start)
        };
        let (from, line, start) = self.cursor.get();
        let (line, start) = if offset >= from {
            let (l, s) = count(from, line, start);
            self.cursor.set((offset, l, s));
            (l, s)
        } else if offset >= start {
            // On the counted line (an object's first word, just read).
            (line, start)
        } else {
            // An earlier line (errors only): counted from the beginning.
            count(0, 1, 0)
        };
        let col = self
            .text
            .get(start..offset)
            .map_or(1, |s| s.chars().count() + 1);
        (line, col)
    }

    fn skip_space(&mut self) {
        let bytes = self.rest().as_bytes();
        let (_, skipped) = bytes_while(bytes, is_space_byte).unwrap_or((bytes, &[]));
        let n = skipped.len();
        let (from, mut line, mut start) = self.cursor.get();
        if from == self.pos {
            for (i, &b) in skipped.iter().enumerate() {
                if b == b'\n' {
                    line += 1;
                    start = from + i + 1;
                }
            }
            self.cursor.set((from + n, line, start));
        }
        // White space is ASCII, so what follows starts a character.
        self.pos += n;
    }

    /// The next word when it has no quotes (nearly every word) and where it starts, found
    /// in one pass over the bytes with the line count; `None`, with nothing consumed, for
    /// anything else (quotes, the end of the text), which [`Source::word`] then reads.
    #[inline(always)]
    fn plain_word(&mut self) -> Option<(&'t str, usize)> {
        let text: &'t str = self.text;
        let bytes = text.as_bytes();
        let i = self.pos;
        let (rest, space) = bytes_while(bytes.get(i..)?, is_space_byte).ok()?;
        let (after, w) = bytes_while1(rest, is_plain_byte).ok()?;
        if after.first().is_some_and(|&b| !is_space_byte(b)) {
            return None; // a quote continues the word
        }
        let w0 = i + space.len();
        let end = w0 + w.len();
        // Both ends are next to ASCII bytes (or the text's ends): character boundaries.
        let word = text.get(w0..end)?;
        let (from, mut line, mut start) = self.cursor.get();
        if from == i {
            for (k, &b) in space.iter().enumerate() {
                if b == b'\n' {
                    line += 1;
                    start = i + k + 1;
                }
            }
            self.cursor.set((end, line, start));
        }
        self.pos = end;
        Some((word, w0))
    }

    /// The next `n` words as plain decimals ([`plain_decimal`]) into `out`, in one pass
    /// over the bytes: the coordinates of a million polygons. `false`, with nothing
    /// consumed and `out` as it was, at the first word that needs [`Source::word`] and
    /// [`parse_real`] (quotes, an exponent, no more text, not a number), which then also
    /// give the error, so messages and locations are those of the general reader.
    fn plain_reals(&mut self, n: usize, out: &mut Vec<f64>) -> bool {
        let bytes = self.text.as_bytes();
        let (from, mut line, mut start) = self.cursor.get();
        let tracked = from == self.pos;
        let kept = out.len();
        let mut i = self.pos;
        for _ in 0..n {
            let (rest, space) =
                bytes_while(&bytes[i..], is_space_byte).unwrap_or((&bytes[i..], &[]));
            if tracked {
                for (k, &b) in space.iter().enumerate() {
                    if b == b'\n' {
                        line += 1;
                        start = i + k + 1;
                    }
                }
            }
            i += space.len();
            // A decimal that is the whole word: white space or the end right after it.
            let value = decimal_prefix(rest)
                .filter(|&(_, len)| rest.get(len).is_none_or(|&b| is_space_byte(b)));
            let Some((v, len)) = value else {
                out.truncate(kept);
                return false;
            };
            out.push(v);
            i += len;
        }
        self.pos = i;
        if tracked {
            self.cursor.set((i, line, start));
        }
        true
    }

    /// The location of byte `offset`, computed only when it is needed (an error, or once
    /// per object): a 1M-polygon scene has ~15M words.
    fn at(&self, offset: usize) -> Location {
        let (l, c) = self.line_col(offset);
        Location::at(self.name.to_string(), l, c)
    }

    /// The next word and the byte offset where it starts, or an error naming `context` and
    /// what was expected when the text ends first (both built only on error).
    fn word(
        &mut self,
        context: &dyn Fn() -> String,
        what: &dyn Fn() -> String,
    ) -> Result<(Cow<'t, str>, usize)> {
        if let Some((w, start)) = self.plain_word() {
            return Ok((Cow::Borrowed(w), start));
        }
        self.skip_space();
        let start = self.pos;
        if self.rest().is_empty() {
            return Err(Error::parse(
                self.at(start),
                format!("unexpected end of file {}; expected {}", context(), what()),
            ));
        }
        match word(self.rest()) {
            Ok((rest, w)) if !rest.starts_with(is_quote) => {
                self.advance(rest);
                // A word without quotes holds no line break: counted up to its end.
                let (from, line, line_start) = self.cursor.get();
                if from == start && matches!(w, Cow::Borrowed(_)) {
                    self.cursor.set((self.pos, line, line_start));
                }
                Ok((w, start))
            }
            _ => Err(Error::parse(
                self.at(start),
                format!("unterminated quote {}; expected {}", context(), what()),
            )),
        }
    }
}

/// Texts shorter than this are read on one thread: a thread's start and the merge would
/// cost more than they save.
const MIN_PIECE: usize = 1 << 20;

/// Where to cut `text` for reading ahead ([`Loader::parse`]): at most `pieces - 1` byte
/// offsets, each just after a line break, increasing, each piece at least `min_piece`
/// bytes. None for a text of `u32::MAX` bytes or more (the pieces' columns count in `u32`).
fn cuts(text: &str, pieces: usize, min_piece: usize) -> Vec<usize> {
    let bytes = text.as_bytes();
    let n = bytes.len();
    if u32::try_from(n).is_err() {
        return Vec::new();
    }
    let pieces = pieces.min(n / min_piece.max(1)).max(1);
    let mut cuts: Vec<usize> = Vec::new();
    for j in 1..pieces {
        let at = (j * (n / pieces)).max(cuts.last().map_or(0, |&c| c + 1));
        let Some(k) = bytes
            .get(at..)
            .and_then(|b| b.iter().position(|&b| b == b'\n'))
        else {
            break;
        };
        if at + k + 1 < n {
            cuts.push(at + k + 1);
        }
    }
    cuts
}

/// Plain surfaces read ahead from a cut of the text ([`speculate`]).
struct Ahead<'t> {
    /// Where the first statement after the cut starts (the first byte that is not white
    /// space).
    start: usize,
    /// Its line, counted from 1 at the cut.
    start_line: usize,
    /// Where reading stopped: the start of the first statement at or after the piece's
    /// end, or of one it does not read, or the end of the text.
    end: usize,
    /// Its line, counted from 1 at the cut, and that line's first byte.
    end_line: usize,
    end_line_start: usize,
    /// The surfaces read; their modifier is an index into `names` ([`VOID`] for `void`),
    /// their position counts from 0, their lines from 1 at the cut, their file is 0.
    table: SurfaceTable,
    names: Vec<&'t str>,
}

/// Read plain surfaces (and plain comments) from byte `cut` of `text` (a line start), as
/// [`Loader::object`] reads them, until a statement starts at or after `limit`. Stops
/// before anything else: `!` commands, `#@rfluxmtx` lines, modifiers, aliases, `inherit`,
/// quotes, and whatever would be an error; the serial reader takes it from there.
fn speculate(text: &str, cut: usize, limit: usize) -> Ahead<'_> {
    let mut src = Source::new(String::new(), text, PathBuf::new());
    src.pos = cut;
    src.cursor.set((cut, 1, cut));
    let mut table = SurfaceTable::default();
    let mut names: Vec<&str> = Vec::new();
    let mut reals: Vec<f64> = Vec::new();
    let mut last: Option<(&str, u32)> = None;
    src.skip_space();
    let (start, start_line) = (src.pos, src.line_col(src.pos).0);
    loop {
        src.skip_space();
        let rest = src.rest();
        if rest.is_empty() || src.pos >= limit {
            break;
        }
        if rest.starts_with('#') {
            if rest.starts_with(super::RFLUXMTX_DIRECTIVE) {
                break;
            }
            let n = rest.find('\n').unwrap_or(rest.len());
            src.pos += n;
            continue;
        }
        let (stmt, counted) = (src.pos, src.cursor.get());
        let pushed = (|| {
            let (mod_name, at) = src.plain_word()?;
            let (line, col) = src.line_col(at);
            let modifier = match mod_name {
                "void" => VOID,
                "inherit" => return None,
                name => match last {
                    Some((l, k)) if l == name => k,
                    _ => {
                        let k = match names.iter().position(|&n| n == name) {
                            Some(k) => k,
                            None => {
                                names.push(name);
                                names.len() - 1
                            }
                        };
                        let k = u32::try_from(k).ok()?;
                        last = Some((name, k));
                        k
                    }
                },
            };
            let otype = OType::from_name(src.plain_word()?.0).filter(|&t| is_plain_surface(t))?;
            let id = src.plain_word()?.0;
            if parse_count(src.plain_word()?.0) != Some(0) || !otype.string_count().accepts(0) {
                return None;
            }
            if parse_count(src.plain_word()?.0) != Some(0) {
                return None;
            }
            let nr = usize::try_from(parse_count(src.plain_word()?.0)?).ok()?;
            reals.clear();
            if !src.plain_reals(nr, &mut reals) {
                for _ in 0..nr {
                    let (w, _) = src.word(&String::new, &String::new).ok()?;
                    reals.push(parse_real(&w)?);
                }
            }
            if !otype.real_count().accepts(nr) {
                return None;
            }
            let modifier = (modifier != VOID).then_some(modifier as usize);
            table
                .push(otype, modifier, table.len(), &reals, id, 0, line, col)
                .ok()
        })();
        if pushed.is_none() {
            src.pos = stmt;
            src.cursor.set(counted);
            break;
        }
    }
    let end = src.pos;
    let (end_line, _) = src.line_col(end);
    let (_, _, end_line_start) = src.cursor.get();
    Ahead {
        start,
        start_line,
        end,
        end_line,
        end_line_start,
        table,
        names,
    }
}

/// Builds a [`Scene`] (or a [`super::CompactScene`]) from one or more pieces of text.
pub(crate) struct Loader<'o> {
    opts: &'o LoadOptions,
    objects: Vec<Object>,
    directives: Vec<super::Directive>,
    /// Most recent modifier with each id (`modobject.c` `modtab`).
    modifiers: HashMap<String, usize>,
    /// The last modifier looked up (a million surfaces name a handful of modifiers, mostly
    /// the same one in a row: one comparison instead of a hash).
    last_modifier: Option<(String, usize)>,
    /// Inline commands run so far, and the most allowed ([`MAX_COMMANDS`]).
    commands: usize,
    max_commands: usize,
    /// Plain surfaces go here instead of `objects` when set ([`Loader::compact`]).
    table: Option<SurfaceTable>,
    /// With a table: the position among all objects of each of `objects`.
    rest_index: Vec<u32>,
    /// The real arguments of the object being read (reused: one allocation per load).
    reals: Vec<f64>,
    /// Files read besides the inputs (`specfile` data).
    files: Vec<PathBuf>,
    /// Inline commands run (their text).
    ran: Vec<String>,
    /// Most pieces a large text is cut into, and their least size ([`Loader::parse`]).
    pieces: usize,
    min_piece: usize,
}

impl<'o> Loader<'o> {
    pub fn new(opts: &'o LoadOptions) -> Self {
        Loader {
            opts,
            objects: Vec::new(),
            directives: Vec::new(),
            modifiers: HashMap::new(),
            last_modifier: None,
            commands: 0,
            max_commands: MAX_COMMANDS,
            table: None,
            rest_index: Vec::new(),
            reals: Vec::new(),
            files: Vec::new(),
            ran: Vec::new(),
            pieces: rayon::current_num_threads(),
            min_piece: MIN_PIECE,
        }
    }

    /// A loader that keeps plain surfaces in a [`SurfaceTable`] ([`Loader::finish_compact`]).
    pub fn compact(opts: &'o LoadOptions) -> Self {
        Loader {
            table: Some(SurfaceTable::default()),
            ..Loader::new(opts)
        }
    }

    pub fn finish(self) -> Scene {
        Scene {
            objects: self.objects,
            directives: self.directives,
        }
    }

    pub fn finish_compact(self) -> super::CompactScene {
        super::CompactScene {
            rest: Scene {
                objects: self.objects,
                directives: self.directives,
            },
            rest_index: self.rest_index,
            surfaces: self.table.unwrap_or_default(),
            files: self.files,
            commands: self.ran,
        }
    }

    /// Objects read so far.
    pub fn len(&self) -> usize {
        self.objects.len() + self.table.as_ref().map_or(0, SurfaceTable::len)
    }

    /// Read one scene input as Radiance names them: `-` (stdin), `!command`, or a file.
    pub fn load_input(&mut self, input: &str) -> Result<()> {
        if input == "-" {
            let mut buf = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin(), &mut buf)
                .map_err(|e| Error::io("<stdin>", e))?;
            super::wrong_kind::check(&buf, "<stdin>")?;
            let text = String::from_utf8_lossy(&buf);
            self.parse(&text, "<stdin>".into(), PathBuf::new(), 0)
        } else if let Some(cmd) = input.strip_prefix('!') {
            self.count_command(&Location::file(input))?;
            let out = exec::run(cmd, Path::new(""), &Location::file(input), self.opts)?;
            self.parse(&out, input.to_string(), PathBuf::new(), 1)
        } else {
            let buf = std::fs::read(input).map_err(|e| Error::io(input, e))?;
            super::wrong_kind::check(&buf, input)?;
            // Valid UTF-8 is checked by the faster `from_utf8`; only bad bytes need `lossy`.
            let text = match std::str::from_utf8(&buf) {
                Ok(t) => Cow::Borrowed(t),
                Err(_) => String::from_utf8_lossy(&buf),
            };
            let dir = Path::new(input)
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default();
            self.parse(&text, input.to_string(), dir, 0)
        }
    }

    /// Parse `text` named `name`, whose `!` commands run in `base_dir`.
    ///
    /// A large text read column-wise is cut into pieces at line ends, one per core; while
    /// this thread reads the first piece as below, the others are read ahead on their own
    /// threads ([`speculate`]), each as if a statement began where its piece begins, and
    /// only where that is so are they taken over (see [`Loader::take`]). Everything else
    /// (modifiers, commands, aliases, anything that would be an error) is left to the
    /// reader here, in order, so objects, locations and errors are those of a serial read.
    pub fn parse(
        &mut self,
        text: &str,
        name: String,
        base_dir: PathBuf,
        depth: usize,
    ) -> Result<()> {
        let mut src = Source::new(name, text, base_dir);
        let cuts = match self.table {
            Some(_) => cuts(text, self.pieces, self.min_piece),
            None => Vec::new(),
        };
        if cuts.is_empty() {
            return self.parse_until(&mut src, depth, usize::MAX);
        }
        std::thread::scope(|scope| {
            let ahead: Vec<_> = cuts
                .iter()
                .enumerate()
                .map(|(j, &cut)| {
                    let limit = cuts.get(j + 1).copied().unwrap_or(usize::MAX);
                    scope.spawn(move || speculate(text, cut, limit))
                })
                .collect();
            for (&cut, piece) in cuts.iter().zip(ahead) {
                self.parse_until(&mut src, depth, cut)?;
                let piece = piece
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e));
                self.take(&mut src, piece)?;
            }
            self.parse_until(&mut src, depth, usize::MAX)
        })
    }

    /// Take over a piece read ahead ([`speculate`]) when the serial read stands where the
    /// piece's first statement starts (else the piece began inside a statement, and is
    /// dropped). Its surfaces' modifiers are looked up now: plain surfaces define none, so
    /// the names mean what they would have meant read in order. A name that is not defined
    /// (or columns that would overflow) drops the piece, and the serial read gives the error.
    fn take(&mut self, src: &mut Source, piece: Ahead<'_>) -> Result<()> {
        if src.pos != piece.start {
            return Ok(());
        }
        let Some(table) = &mut self.table else {
            return Ok(());
        };
        let mut modifiers = Vec::with_capacity(piece.names.len());
        for name in &piece.names {
            match self.modifiers.get(*name) {
                Some(&i) => modifiers.push(i),
                None => return Ok(()),
            }
        }
        // The piece's lines are counted from 1 at its cut, a line start.
        let (line, _) = src.line_col(piece.start);
        let first_line = line + 1 - piece.start_line;
        if !piece.table.is_empty() {
            let number = src.file_number_in(table)?;
            let base = self.objects.len() + table.len();
            if !table.append(&piece.table, &modifiers, base, first_line, number) {
                return Ok(());
            }
        }
        src.pos = piece.end;
        src.cursor.set((
            piece.end,
            first_line + piece.end_line - 1,
            piece.end_line_start,
        ));
        Ok(())
    }

    /// Read statements from `src` until one starts at or after byte `limit` (or the text
    /// ends).
    fn parse_until(&mut self, src: &mut Source, depth: usize, limit: usize) -> Result<()> {
        loop {
            src.skip_space();
            let rest = src.rest();
            if rest.is_empty() || src.pos >= limit {
                return Ok(());
            }
            if let Ok((r, text)) = comment(rest) {
                // rfluxmtx reads `#@rfluxmtx` (no space after '#') followed by white space.
                if let Some(args) = text.strip_prefix(super::RFLUXMTX_DIRECTIVE) {
                    if args.is_empty() || args.starts_with(char::is_whitespace) {
                        self.directives.push(super::Directive {
                            before: self.objects.len(),
                            text: args.trim().to_string(),
                            loc: src.at(src.pos),
                        });
                    }
                }
                src.advance(r);
            } else if let Ok((r, cmd)) = command_line(rest) {
                let loc = src.at(src.pos);
                src.advance(r);
                self.command(cmd, src, loc, depth)?;
            } else {
                self.object(src)?;
            }
        }
    }

    fn command(&mut self, cmd: &str, src: &Source, loc: Location, depth: usize) -> Result<()> {
        if depth >= MAX_COMMAND_DEPTH {
            return Err(Error::parse(
                loc,
                format!("'!' commands nested more than {MAX_COMMAND_DEPTH} deep"),
            ));
        }
        // Location of the command line itself: file:line (the column is always 1).
        let origin = Location::line(loc.file.clone(), loc.line.unwrap_or(1));
        self.count_command(&origin)?;
        self.ran.push(cmd.trim_end_matches('\r').to_string());
        let out = exec::run(
            cmd.trim_end_matches('\r'),
            &src.base_dir,
            &origin,
            self.opts,
        )?;
        let name = format!("{origin}: !{}", exec::display_command(cmd));
        self.parse(&out, name, src.base_dir.clone(), depth + 1)
    }

    /// Count one more inline command; an error at `origin` beyond the limit.
    fn count_command(&mut self, origin: &Location) -> Result<()> {
        self.commands += 1;
        if self.commands > self.max_commands {
            return Err(Error::parse(
                origin.clone(),
                format!(
                    "more than {} inline '!' commands in one scene (does a command include \
                     the scene itself?); expand the scene by hand",
                    self.max_commands
                ),
            ));
        }
        Ok(())
    }

    fn object(&mut self, src: &mut Source) -> Result<()> {
        let (mod_name, start) = src.word(&String::new, &|| "a modifier".into())?;
        let (line, col) = src.line_col(start);
        let file = src.name.clone();
        let loc = || Location::at(file.to_string(), line, col);
        if mod_name.contains('\t') {
            return Err(Error::parse(
                loc(),
                format!("illegal tab in modifier '{}'", mod_name.escape_debug()),
            ));
        }
        // Resolve the modifier first, like getobject(): None = void, Some(None) = inherit.
        let modifier: Option<Option<usize>> = match &*mod_name {
            "void" => Some(None),
            "inherit" => None,
            name => match &self.last_modifier {
                Some((last, i)) if last == name => Some(Some(*i)),
                _ => match self.modifiers.get(name) {
                    Some(&i) => {
                        self.last_modifier = Some((name.to_string(), i));
                        Some(Some(i))
                    }
                    None => {
                        return Err(Error::parse(loc(), format!("undefined modifier '{name}'")));
                    }
                },
            },
        };
        let ctx = || format!("after modifier '{mod_name}' (object starting at {})", loc());
        let (type_name, tloc) = src.word(&ctx, &|| "a primitive type".into())?;
        let otype = if type_name == "alias" {
            None
        } else {
            match OType::from_name(&type_name) {
                Some(t) => Some(t),
                None => {
                    return Err(Error::parse(
                        src.at(tloc),
                        format!("unknown primitive type '{type_name}'"),
                    ));
                }
            }
        };
        let (id, iloc) = src.word(&ctx, &|| format!("an identifier for the {type_name}"))?;
        if id.contains('\t') {
            return Err(Error::parse(
                src.at(iloc),
                format!("illegal tab in identifier '{}'", id.escape_debug()),
            ));
        }
        if otype.is_none_or(OType::is_modifier) && (id == "void" || id == "inherit") {
            return Err(Error::parse(
                src.at(iloc),
                format!("illegal modifier name '{id}'"),
            ));
        }
        let ctx = || format!("inside {type_name} '{id}' (started at {})", loc());

        let Some(otype) = otype else {
            let msg = ctx();
            return self.alias(
                src,
                loc(),
                mod_name.into_owned(),
                modifier,
                id.into_owned(),
                &move || msg.clone(),
            );
        };
        let Some(modifier) = modifier else {
            return Err(Error::parse(
                loc(),
                format!("{type_name} '{id}': 'inherit' can only be the modifier of an alias"),
            ));
        };

        // Arguments (readfargs.c).
        let (n, nloc) = src.word(&ctx, &|| "the number of string arguments".into())?;
        let ns = match parse_count(&n) {
            Some(v) if v >= 0 => v as usize,
            _ => {
                return Err(Error::parse(
                    src.at(nloc),
                    format!(
                        "{type_name} '{id}': expected the number of string arguments, found '{n}'"
                    ),
                ));
            }
        };
        let mut strings = Vec::new();
        for i in 0..ns {
            strings.push(
                src.word(&ctx, &|| format!("string argument {} of {ns}", i + 1))?
                    .0
                    .into_owned(),
            );
        }
        let (ni, niloc) = src.word(&ctx, &|| "the number of integer arguments (0)".into())?;
        if parse_count(&ni) != Some(0) {
            return Err(Error::parse(
                src.at(niloc),
                format!(
                    "{type_name} '{id}': expected 0 integer arguments (Radiance allows none), found '{ni}'"
                ),
            ));
        }
        let (m, mloc) = src.word(&ctx, &|| "the number of real arguments".into())?;
        let nr = match parse_count(&m) {
            Some(v) if v >= 0 => v as usize,
            _ => {
                return Err(Error::parse(
                    src.at(mloc),
                    format!(
                        "{type_name} '{id}': expected the number of real arguments, found '{m}'"
                    ),
                ));
            }
        };
        let mut reals = std::mem::take(&mut self.reals);
        reals.clear();
        let fast = src.plain_reals(nr, &mut reals);
        for i in (0..nr).filter(|_| !fast) {
            let what = || format!("real argument {} of {nr}", i + 1);
            let (w, wloc) = src.word(&ctx, &what)?;
            match parse_real(&w) {
                Some(v) => reals.push(v),
                None => {
                    return Err(Error::parse(
                        src.at(wloc),
                        format!(
                            "{type_name} '{id}': {}: expected a number, found '{w}'",
                            what()
                        ),
                    ));
                }
            }
        }
        if !otype.string_count().accepts(ns) {
            return Err(Error::parse(
                src.at(nloc),
                otype.string_count().mismatch(otype, &id, "string", ns),
            ));
        }
        if !otype.real_count().accepts(nr) {
            return Err(Error::parse(
                src.at(mloc),
                otype.real_count().mismatch(otype, &id, "real", nr),
            ));
        }
        if let Some(table) = &mut self.table {
            if is_plain_surface(otype) {
                let number = src.file_number_in(table)?;
                let index = self.objects.len() + table.len();
                table.push(otype, modifier, index, &reals, &id, number, line, col)?;
                self.reals = reals;
                return Ok(());
            }
        }
        let kind = Primitive::from_args(otype, strings, reals.clone())
            .ok_or_else(|| Error::parse(loc(), format!("{type_name} '{id}': bad arguments")))?;
        self.reals = reals;
        let mut kind = kind;
        if let Primitive::SpecFile { file, data } = &mut kind {
            *data = read_specfile(file, &src.base_dir, &mut self.files)?;
        }
        self.push(Object {
            modifier,
            modifier_name: mod_name.into_owned(),
            id: id.into_owned(),
            kind,
            alias: None,
            loc: loc(),
        });
        Ok(())
    }

    fn alias(
        &mut self,
        src: &mut Source,
        loc: Location,
        mod_name: String,
        modifier: Option<Option<usize>>,
        id: String,
        ctx: &dyn Fn() -> String,
    ) -> Result<()> {
        let (old, oloc) = src.word(ctx, &|| "the id of the aliased modifier".into())?;
        let Some(&target) = self.modifiers.get(&*old) else {
            return Err(Error::parse(
                src.at(oloc),
                format!("alias '{id}' refers to undefined modifier '{old}'"),
            ));
        };
        let Some(original) = self.objects.get(target) else {
            return Err(Error::parse(
                src.at(oloc),
                format!("alias '{id}': bad reference '{old}'"),
            ));
        };
        // readobj.c: with 'inherit' the alias passes straight through to the original (its
        // type, arguments and modifier); otherwise it is the original's type and arguments
        // under the given modifier.
        let modifier = modifier.unwrap_or(original.modifier);
        let obj = Object {
            modifier,
            modifier_name: mod_name,
            id,
            kind: original.kind.clone(),
            alias: Some(Alias {
                target,
                target_id: old.into_owned(),
            }),
            loc,
        };
        self.push(obj);
        Ok(())
    }

    fn push(&mut self, obj: Object) {
        let index = self.objects.len();
        if let Some(table) = &self.table {
            // Beyond u32::MAX objects (hundreds of GB of text) the position saturates;
            // the table refuses its own surfaces long before.
            self.rest_index
                .push(u32::try_from(index + table.len()).unwrap_or(u32::MAX));
        }
        if obj.kind.otype().is_modifier() {
            // insertobject(): an identical redefinition keeps the earlier index.
            let same = self
                .modifiers
                .get(&obj.id)
                .and_then(|&i| self.objects.get(i))
                .is_some_and(|prev| prev.kind == obj.kind && prev.modifier == obj.modifier);
            if !same {
                self.modifiers.insert(obj.id.clone(), index);
                self.last_modifier = None;
            }
        }
        self.objects.push(obj);
    }
}

/// Read the data file of a `specfile`: looked up in the scene file's folder, then in the
/// `RAYPATH` folders (Radiance's `getpath` search). `Ok(None)` if it is nowhere.
fn read_specfile(file: &str, base_dir: &Path, read: &mut Vec<PathBuf>) -> Result<Option<SpecData>> {
    let mut candidates = vec![base_dir.join(file)];
    if Path::new(file).is_relative() {
        if let Some(raypath) = std::env::var_os("RAYPATH") {
            candidates.extend(std::env::split_paths(&raypath).map(|d| d.join(file)));
        }
    }
    for path in candidates {
        if path.is_file() {
            let shown = path.display().to_string();
            let bytes = std::fs::read(&path).map_err(|e| Error::io(shown.clone(), e))?;
            read.push(path.clone());
            return SpecData::parse(&String::from_utf8_lossy(&bytes), &shown).map(Some);
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue #19: a scene whose commands include it again ran 11,110 commands; the count
    /// is bounded for the whole load, nested or not, with the command's file:line.
    #[test]
    fn inline_commands_are_counted() {
        let opts = LoadOptions {
            allow_exec: true,
            command_env: Vec::new(),
        };
        let mut loader = Loader::new(&opts);
        loader.max_commands = 3;
        let text = "!true\n!true\n!echo '!true'\n!true\n";
        let e = loader
            .parse(text, "many.rad".into(), PathBuf::new(), 0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 3 inline '!' commands"), "{e}");
        assert!(e.starts_with("many.rad:3: !echo '!true':1"), "{e}");
    }

    /// Read `text` column-wise in `pieces` pieces of any size (1: serially).
    fn compact_in(text: &str, pieces: usize) -> Result<crate::scene::CompactScene> {
        let opts = LoadOptions::default();
        let mut loader = Loader::compact(&opts);
        (loader.pieces, loader.min_piece) = (pieces, 1);
        loader.parse(text, "t.rad".into(), PathBuf::new(), 0)?;
        Ok(loader.finish_compact())
    }

    /// Pieces read ahead on other threads are taken over only where a statement starts at
    /// their cut: the columns, rest, locations and errors are the serial reader's, wherever
    /// the cuts fall (inside polygons spread over lines, quoted words, comments, after a
    /// redefined modifier, before an alias or a bad word).
    #[test]
    fn reading_ahead_reads_as_serially() {
        let mut text = String::from("void plastic m 0 0 5 .5 .5 .5 0 0\n# a comment\n");
        for i in 0..60 {
            match i % 6 {
                0 => text += &format!("m polygon p{i} 0 0 9\n 0 0 {i}\n 1 0 0\n\t1 1 0\n"),
                1 => text += &format!("m sphere s{i} 0 0 4 1 2 3 .{i}5 # not a comment\n"),
                2 => text += &format!("void ring r{i} 0 0 8 0 0 0 0 0 1 0 '1.5'\n"),
                3 => text += &format!("# comment {i}\nm cone c{i} 0 0 8 0 0 0 1e1 1 1 1 .5\n"),
                4 => {
                    text += &format!(
                        "void plastic m 0 0 5 .{i} .5 .5 0 0\nm bubble b{i} 0 0 4 0 0 0 1\n"
                    )
                }
                _ => text += &format!("m polygon q{i}\n0 0 9 0 0 0 1 0 0 1 1 {i}\n\n\n"),
            }
            if i == 40 {
                text +=
                    "#@rfluxmtx h=kf u=+Z\nm alias m2 m\nm2 polygon a 0 0 9 0 0 0 1 0 0 1 1 0\n";
            }
        }
        let serial = compact_in(&text, 1).unwrap();
        assert_eq!(serial.len(), 1 + 60 + 10 + 2);
        for pieces in [2, 3, 5, 8, 13, 40, 200] {
            assert_eq!(
                compact_in(&text, pieces).unwrap(),
                serial,
                "{pieces} pieces"
            );
        }
        // Errors: an undefined modifier, a bad number, an unterminated quote, a missing
        // count, an unknown type, anywhere: the message (file:line:col) is the serial one.
        let at = text.len() * 2 / 3;
        let at = at + text[at..].find('\n').unwrap() + 1;
        for bad in [
            "x polygon u 0 0 9 0 0 0 1 0 0 1 1 0\n",
            "m polygon u 0 0 9 0 0 0 1 0 0 1 z 0\n",
            "m polygon u 0 0 9 0 0 0 1 0 0 1 '1 0\n",
            "m polygon u 0 0\n",
            "m polyg u 0 0 9 0 0 0 1 0 0 1 1 0\n",
            "inherit polygon u 0 0 9 0 0 0 1 0 0 1 1 0\n",
        ] {
            let text = format!("{}{bad}{}", &text[..at], &text[at..]);
            let want = compact_in(&text, 1).unwrap_err().to_string();
            for pieces in [2, 3, 7, 30] {
                let got = compact_in(&text, pieces).unwrap_err().to_string();
                assert_eq!(got, want, "{pieces} pieces, {bad}");
            }
        }
    }

    #[test]
    fn cuts_fall_after_line_breaks() {
        let text = "a b\nc\n\nd e f\ng\n";
        for pieces in 1..10 {
            let cuts = cuts(text, pieces, 1);
            assert!(cuts.len() < pieces, "{cuts:?}");
            assert!(cuts.windows(2).all(|w| w[0] < w[1]), "{cuts:?}");
            assert!(
                cuts.iter()
                    .all(|&c| c < text.len() && text.as_bytes()[c - 1] == b'\n'),
                "{cuts:?}"
            );
        }
        assert!(cuts(text, 4, 100).is_empty());
    }

    #[test]
    fn words_follow_fgetword() {
        assert_eq!(word("abc def").unwrap(), (" def", "abc".into()));
        assert_eq!(word("'a b'c\"d e\" x").unwrap(), (" x", "a bcd e".into()));
        assert_eq!(
            word("'Atan2(Dy,Dx)/PI+1' 0").unwrap().1,
            "Atan2(Dy,Dx)/PI+1"
        );
        assert_eq!(word("''\n").unwrap(), ("\n", "".into()));
        // Unterminated quote: the word stops before it; the caller reports it.
        assert_eq!(word("ab'cd").unwrap(), ("'cd", "ab".into()));
    }

    #[test]
    fn reals_follow_isflt() {
        for (w, v) in [
            ("1", 1.0),
            ("-2.5", -2.5),
            ("+.5", 0.5),
            ("5.", 5.0),
            ("1e3", 1e3),
            ("1.5E-2", 0.015),
        ] {
            assert_eq!(parse_real(w), Some(v), "{w}");
        }
        for w in [
            ".", "e5", "1e", "1e+", "inf", "nan", "0x10", "1,5", "1e999", "--1", "1.2.3",
        ] {
            assert_eq!(parse_real(w), None, "{w}");
        }
    }

    #[test]
    fn plain_decimals_are_the_doubles_from_str_gives() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(18);
        for _ in 0..200_000 {
            let digits = rng.random_range(1..=16);
            let mut w: String = (0..digits)
                .map(|_| char::from(b'0' + rng.random_range(0..10u8)))
                .collect();
            if rng.random_bool(0.8) {
                w.insert(rng.random_range(0..=w.len()), '.');
            }
            match rng.random_range(0..3) {
                0 => w.insert(0, '-'),
                1 => w.insert(0, '+'),
                _ => {}
            }
            let want = w.parse::<f64>().ok().filter(|v| v.is_finite());
            let got = parse_real(&w);
            assert_eq!(
                got.map(f64::to_bits),
                want.map(f64::to_bits),
                "{w}: {got:?} vs {want:?}"
            );
        }
        assert_eq!(
            parse_real("-0").map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        assert_eq!(plain_decimal(b"9007199254740993"), None);
    }

    #[test]
    fn reals_in_any_form_read_alike_and_bad_ones_are_placed() {
        let parse =
            |text: &str| crate::scene::parse_str(text, "r.rad", Path::new(""), &Default::default());
        // Plain decimals, an exponent, a quoted number, signs: the one-pass reader hands
        // over to the general one at the first word it does not take.
        let s = parse("void plastic m 0 0 5 .5 1e-1 '0.3' +2 -0\n").unwrap();
        let (_, r) = s.objects[0].kind.to_args();
        assert_eq!(r, [0.5, 0.1, 0.3, 2.0, -0.0]);
        let s =
            parse("void polygon p 0 0 9\n 0 0 0\n 1 0 0\n 1 1 0\nvoid plastic q 0 0 5 1 1 1 0 0\n")
                .unwrap();
        assert_eq!(s.objects[1].loc.line, Some(5));
        let e = parse("void polygon p 0 0 9\n 0 0 0\n 1 x 0\n 1 1 0\n").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("r.rad:3:4: polygon 'p': real argument 5 of 9"),
            "{e}"
        );
        let e = parse("void polygon p 0 0 9\n 0 0 0\n 1 0")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.rad:3:5: unexpected end of file"), "{e}");
    }

    #[test]
    fn commands_join_continuations() {
        assert_eq!(command_line("!a \\\nb\nc").unwrap(), ("\nc", "a \\\nb"));
        assert_eq!(command_line("!a\\b").unwrap(), ("", "a\\b"));
    }

    #[test]
    fn rfluxmtx_directives_are_kept_with_their_place() {
        let text = "# a plain comment\n#@rfluxmtx h=kf u=+Z\nvoid glow g 0 0 4 1 1 1 0\n\
                    g polygon w 0 0 9 0 0 0 1 0 0 1 1 0\n#@rfluxmtxx no\n# @rfluxmtx no\n\
                    #@rfluxmtx o=b.mtx\n";
        let s = crate::scene::parse_str(text, "t.rad", Path::new(""), &Default::default()).unwrap();
        let kept: Vec<(usize, &str, Option<usize>)> = s
            .directives
            .iter()
            .map(|d| (d.before, d.text.as_str(), d.loc.line))
            .collect();
        assert_eq!(kept, [(0, "h=kf u=+Z", Some(2)), (2, "o=b.mtx", Some(7))]);
        // Written back before the objects they preceded, so a rewritten file keeps them.
        let again =
            crate::scene::parse_str(&s.to_string(), "u.rad", Path::new(""), &Default::default())
                .unwrap();
        assert_eq!(again.objects.len(), s.objects.len());
        assert!(
            again
                .objects
                .iter()
                .zip(&s.objects)
                .all(|(a, b)| a.same_content(b))
        );
        let texts: Vec<_> = again
            .directives
            .iter()
            .map(|d| (d.before, d.text.clone()))
            .collect();
        assert_eq!(
            texts,
            [(0, "h=kf u=+Z".to_string()), (2, "o=b.mtx".to_string())]
        );
    }
}
