//! The `.cal` grammar (Radiance's `calcomp` language), parsed with `nom` into a raw tree that
//! still holds names; [`super::Program`] links them to definitions.
//!
//! Grammar (from `src/common/calexpr.c`, `caldefn.c` and the `rcalc(1)` manual):
//!
//! ```text
//! file       := { statement }
//! statement  := ';' | definition [ ';' ]          (';' may only be left out at the end)
//! definition := name [ '(' name { ',' name } ')' ] ( '=' | ':' ) E1
//! E1 := E2 { ('+' | '-') E2 }                      left associative
//! E2 := E3 { ('*' | '/') E3 }                      left associative
//! E3 := E4 [ '^' E3 ]                              right associative
//! E4 := '-' E5 | ['+'] E5                          unary minus binds tighter than '^':
//!                                                  -2^2 = 4 (checked with rcalc)
//! E5 := '(' E1 ')' | '$' digits | number | name [ '(' E1 { ',' E1 } ')' ]
//! ```
//!
//! Names start with a letter or the context mark `` ` `` and continue with letters, digits,
//! `_`, `.` and `` ` `` (`isid` in `calcomp.h`); numbers are `digits [. digits] [e [+-]
//! digits]` or `. digits ...`. Comments are `{ ... }`, nested, anywhere whitespace may be.
//! `=` and `:` (constant) definitions behave the same here; later definitions replace
//! earlier ones (`egetstatement`). One deliberate difference: Radiance's scanner drops
//! whitespace *inside* names and numbers (`escan`), we end a token at whitespace.
//!
//! Nesting is capped at [`MAX_DEPTH`] levels so that hostile input cannot overflow the stack.

use nom::{
    IResult, Parser,
    bytes::complete::take_while,
    character::complete::{char, digit1, satisfy},
    combinator::recognize,
};

use crate::error::{Error, Location};

/// Deepest nesting of parentheses, unary minus and `^` chains the parser follows.
pub const MAX_DEPTH: usize = 100;

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// An expression before name resolution; `usize` fields are byte offsets into the source.
#[derive(Debug, Clone, PartialEq)]
pub enum Raw {
    Num(f64),
    Chan(usize),
    Name(String, usize),
    Call(String, usize, Vec<Raw>),
    Neg(Box<Raw>),
    Bin(Op, Box<Raw>, Box<Raw>),
}

/// One definition: `name = body`, `name(params) : body`, ...
#[derive(Debug, Clone, PartialEq)]
pub struct RawDef {
    pub name: String,
    /// `None` for a variable, the parameter names for a function.
    pub params: Option<Vec<String>>,
    pub constant: bool,
    pub body: Raw,
    /// Byte offset of the name.
    pub at: usize,
}

/// A parse failure: where (the rest of the input) and what was expected.
#[derive(Debug)]
pub struct PErr<'a> {
    pub at: &'a str,
    pub expected: String,
}

impl<'a> nom::error::ParseError<&'a str> for PErr<'a> {
    fn from_error_kind(input: &'a str, kind: nom::error::ErrorKind) -> Self {
        PErr {
            at: input,
            expected: format!("{kind:?}"),
        }
    }
    fn append(_: &'a str, _: nom::error::ErrorKind, other: Self) -> Self {
        other
    }
}

type R<'a, T> = IResult<&'a str, T, PErr<'a>>;

fn fail<'a, T>(at: &'a str, expected: impl Into<String>) -> R<'a, T> {
    Err(nom::Err::Failure(PErr {
        at,
        expected: expected.into(),
    }))
}

/// Whitespace and (nested) `{ }` comments.
fn ws(mut i: &str) -> R<'_, ()> {
    loop {
        i = i.trim_start();
        let Some(rest) = i.strip_prefix('{') else {
            return Ok((i, ()));
        };
        let mut depth = 1usize;
        let mut end = None;
        for (k, c) in rest.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(k + 1);
                        break;
                    }
                }
                _ => {}
            }
        }
        match end {
            Some(k) => i = &rest[k..],
            None => return fail(i, "'}' closing this comment"),
        }
    }
}

/// `c` after optional whitespace.
fn sym<'a>(c: char) -> impl Parser<&'a str, Output = char, Error = PErr<'a>> {
    move |i: &'a str| {
        let (i, ()) = ws(i)?;
        char(c).parse(i)
    }
}

fn is_id(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '`'
}

/// A name (no leading whitespace).
fn name(i: &str) -> R<'_, &str> {
    recognize((
        satisfy(|c| c.is_ascii_alphabetic() || c == '`'),
        take_while(is_id),
    ))
    .parse(i)
}

/// A non-negative number (no leading whitespace; the sign is an operator):
/// `digits [. digits] [e [+-] digits]` or `. digits ...` (`getnum` in calexpr.c).
fn number(i: &str) -> R<'_, f64> {
    let digits = |s: &str| s.bytes().take_while(u8::is_ascii_digit).count();
    let b = i.as_bytes();
    let mut k = digits(i);
    let int = k;
    let mut frac = 0;
    if b.get(k) == Some(&b'.') {
        frac = digits(&i[k + 1..]);
        k += 1 + frac;
    }
    if int + frac == 0 {
        return fail(i, "a digit in this number");
    }
    if matches!(b.get(k), Some(b'e' | b'E')) {
        let mut e = k + 1;
        if matches!(b.get(e), Some(b'+' | b'-')) {
            e += 1;
        }
        let n = digits(&i[e..]);
        if n == 0 {
            return fail(&i[e..], "digits of an exponent");
        }
        k = e + n;
    }
    match i[..k].parse::<f64>() {
        Ok(v) => Ok((&i[k..], v)),
        Err(_) => fail(i, "a number"),
    }
}

/// Parser state: the whole source (for offsets).
struct P<'s> {
    src: &'s str,
}

impl<'s> P<'s> {
    fn off(&self, i: &str) -> usize {
        self.src.len() - i.len()
    }

    fn deeper<'a>(&self, i: &'a str, depth: usize) -> Result<(), nom::Err<PErr<'a>>> {
        if depth > MAX_DEPTH {
            return Err(nom::Err::Failure(PErr {
                at: i,
                expected: format!("at most {MAX_DEPTH} levels of nesting"),
            }));
        }
        Ok(())
    }

    fn e1<'a>(&self, i: &'a str, d: usize) -> R<'a, Raw> {
        self.deeper(i, d)?;
        let (mut i, mut lhs) = self.e2(i, d)?;
        loop {
            let (j, ()) = ws(i)?;
            let op = match j.chars().next() {
                Some('+') => Op::Add,
                Some('-') => Op::Sub,
                _ => return Ok((i, lhs)),
            };
            let (j, rhs) = self.e2(&j[1..], d)?;
            lhs = fold(op, lhs, rhs);
            i = j;
        }
    }

    fn e2<'a>(&self, i: &'a str, d: usize) -> R<'a, Raw> {
        let (mut i, mut lhs) = self.e3(i, d)?;
        loop {
            let (j, ()) = ws(i)?;
            let op = match j.chars().next() {
                Some('*') => Op::Mul,
                Some('/') => Op::Div,
                _ => return Ok((i, lhs)),
            };
            let at = &j[1..];
            let (j, rhs) = self.e3(at, d)?;
            // Radiance refuses a literal zero divisor when parsing ("divide by zero
            // constant", calexpr.c getE2).
            if op == Op::Div && rhs == Raw::Num(0.0) {
                return fail(at, "a divisor other than the constant 0");
            }
            lhs = fold(op, lhs, rhs);
            i = j;
        }
    }

    fn e3<'a>(&self, i: &'a str, d: usize) -> R<'a, Raw> {
        self.deeper(i, d)?;
        let (i, lhs) = self.e4(i, d)?;
        let (j, ()) = ws(i)?;
        if let Some(j) = j.strip_prefix('^') {
            let (j, rhs) = self.e3(j, d + 1)?;
            return Ok((j, fold(Op::Pow, lhs, rhs)));
        }
        Ok((i, lhs))
    }

    fn e4<'a>(&self, i: &'a str, d: usize) -> R<'a, Raw> {
        let (i, ()) = ws(i)?;
        if let Some(j) = i.strip_prefix('-') {
            let (j, e) = self.e5(j, d)?;
            return Ok((
                j,
                match e {
                    Raw::Num(v) => Raw::Num(-v),
                    Raw::Neg(inner) => *inner,
                    e => Raw::Neg(Box::new(e)),
                },
            ));
        }
        let i = i.strip_prefix('+').unwrap_or(i);
        self.e5(i, d)
    }

    fn e5<'a>(&self, i: &'a str, d: usize) -> R<'a, Raw> {
        self.deeper(i, d)?;
        let (i, ()) = ws(i)?;
        if let Some(j) = i.strip_prefix('(') {
            let (j, e) = self.e1(j, d + 1)?;
            let (j, _) = sym(')').parse(j).or_else(|_| fail(j, "')'"))?;
            return Ok((j, e));
        }
        if let Some(j) = i.strip_prefix('$') {
            let (j, digits) =
                digit1::<_, PErr>(j).or_else(|_| fail(j, "a channel number after '$'"))?;
            let n = digits.parse::<usize>().unwrap_or(usize::MAX);
            return Ok((j, Raw::Chan(n)));
        }
        if let Ok((j, n)) = name(i) {
            let at = self.off(i);
            let (k, ()) = ws(j)?;
            if let Some(mut k) = k.strip_prefix('(') {
                let mut args = Vec::new();
                loop {
                    let (k2, a) = self.e1(k, d + 1)?;
                    args.push(a);
                    let (k2, ()) = ws(k2)?;
                    if let Some(k3) = k2.strip_prefix(',') {
                        k = k3;
                    } else if let Some(k3) = k2.strip_prefix(')') {
                        return Ok((k3, Raw::Call(n.to_string(), at, args)));
                    } else {
                        return fail(k2, "',' or ')' in the argument list");
                    }
                }
            }
            return Ok((j, Raw::Name(n.to_string(), at)));
        }
        if i.starts_with(|c: char| c.is_ascii_digit() || c == '.') {
            let (j, v) = number(i)?;
            return Ok((j, Raw::Num(v)));
        }
        fail(i, "a number, a name, '$N', '-' or '('")
    }

    fn definition<'a>(&self, i: &'a str) -> R<'a, RawDef> {
        let at = self.off(i);
        let (i, n) = name(i).or_else(|_| fail(i, "a variable or function name"))?;
        let (i, ()) = ws(i)?;
        let mut params = None;
        let mut i = i;
        if let Some(mut j) = i.strip_prefix('(') {
            let mut ps = Vec::new();
            loop {
                let (k, ()) = ws(j)?;
                let (k, p) = name(k).or_else(|_| fail(k, "a parameter name"))?;
                if p.contains('`') {
                    return fail(k, "a parameter name without '`'");
                }
                ps.push(p.to_string());
                let (k, ()) = ws(k)?;
                if let Some(k2) = k.strip_prefix(',') {
                    j = k2;
                } else if let Some(k2) = k.strip_prefix(')') {
                    i = k2;
                    break;
                } else {
                    return fail(k, "',' or ')' in the parameter list");
                }
            }
            params = Some(ps);
        }
        let (i, ()) = ws(i)?;
        let (i, constant) = match i.chars().next() {
            Some('=') => (&i[1..], false),
            Some(':') => (&i[1..], true),
            _ => return fail(i, "'=' or ':'"),
        };
        let (i, body) = self.e1(i, 0)?;
        Ok((
            i,
            RawDef {
                name: n.to_string(),
                params,
                constant,
                body,
                at,
            },
        ))
    }

    fn file<'a>(&self, mut i: &'a str) -> Result<Vec<RawDef>, nom::Err<PErr<'a>>> {
        let mut defs = Vec::new();
        loop {
            let (j, ()) = ws(i)?;
            if j.is_empty() {
                return Ok(defs);
            }
            if let Some(j) = j.strip_prefix(';') {
                i = j;
                continue;
            }
            let (j, def) = self.definition(j)?;
            defs.push(def);
            let (j, ()) = ws(j)?;
            if j.is_empty() {
                return Ok(defs);
            }
            match j.strip_prefix(';') {
                Some(k) => i = k,
                None => return Err(fail::<()>(j, "';' or an operator").unwrap_err()),
            }
        }
    }
}

/// Fold operations on two constants (Radiance's `rconst` under `E_RCONST`); division by a
/// zero constant was refused before.
fn fold(op: Op, a: Raw, b: Raw) -> Raw {
    if let (Raw::Num(x), Raw::Num(y)) = (&a, &b) {
        return Raw::Num(super::eval::binop(op, *x, *y));
    }
    Raw::Bin(op, Box::new(a), Box::new(b))
}

/// 1-based line and column of byte offset `off` in `src`.
pub fn line_col(src: &str, off: usize) -> (usize, usize) {
    let off = off.min(src.len());
    let before = src.get(..off).unwrap_or(src);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

fn to_error(src: &str, file: &str, e: nom::Err<PErr<'_>>) -> Error {
    let (at, expected) = match e {
        nom::Err::Error(p) | nom::Err::Failure(p) => (p.at, p.expected),
        nom::Err::Incomplete(_) => ("", "more input".to_string()),
    };
    let (line, col) = line_col(src, src.len() - at.len());
    let found = match at.chars().next() {
        None => "the end of the input".to_string(),
        Some(c) => format!("'{c}'"),
    };
    Error::parse(
        Location::at(file, line, col),
        format!("expected {expected}, found {found}"),
    )
}

/// Parse a whole `.cal` file; `file` names it in errors.
pub fn parse_file(src: &str, file: &str) -> crate::Result<Vec<RawDef>> {
    P { src }.file(src).map_err(|e| to_error(src, file, e))
}

/// Parse one expression (e.g. a pattern's coordinate argument); all of `src` must be used.
pub fn parse_expr(src: &str, file: &str) -> crate::Result<Raw> {
    let p = P { src };
    let r = p.e1(src, 0).and_then(|(i, e)| {
        let (i, ()) = ws(i)?;
        if i.is_empty() {
            Ok(e)
        } else {
            fail(i, "an operator or the end of the expression").map(|(_, e)| e)
        }
    });
    r.map_err(|e| to_error(src, file, e))
}
