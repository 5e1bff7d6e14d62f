//! # The one CSV reader of calibration inputs
//!
//! Readings ([`crate::measurements`]), spectral readings ([`crate::spectral::readings`]) and
//! channel response curves ([`crate::spectral::channels`]) are the same kind of file: comma
//! separated fields (blanks around them ignored), blank lines and lines starting with `#`
//! skipped, a header line first, then rows. This module reads that shape once: the files
//! differ only in what their header and rows must hold, which their parsers check with
//! the messages here (file:line, what was found, what was expected).

use crate::error::{Error, Location, Result};
use nom::Parser;
use nom::bytes::complete::take_while;
use nom::character::complete::{char, space0};
use nom::multi::separated_list1;
use nom::sequence::delimited;

/// Text of the file at `path` (invalid UTF-8 replaced, so that its errors name a line).
pub fn read_text(path: &str) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// One header or data line: its fields, trimmed, and where it is.
pub struct Line<'a> {
    pub file: &'a str,
    /// 1-based line number.
    pub no: usize,
    /// The line, trimmed.
    pub text: &'a str,
    pub fields: Vec<&'a str>,
}

impl Line<'_> {
    pub fn at(&self) -> Location {
        Location::line(self.file, self.no)
    }

    /// An error at this line.
    pub fn error(&self, message: impl Into<String>) -> Error {
        Error::parse(self.at(), message)
    }

    /// Field `k` as a finite number, or "expected a number {what}, found ..." (`what` as
    /// `for lux` or `in column 3`).
    pub fn number(&self, k: usize, what: &str) -> Result<f64> {
        let w = self.fields.get(k).copied().unwrap_or("");
        number(w).ok_or_else(|| {
            let found = if w.is_empty() {
                "a missing value".to_string()
            } else {
                format!("'{}'", shorten(w))
            };
            self.error(format!("expected a number {what}, found {found}"))
        })
    }
}

/// Read `text` (named `file`): `header` checks the first line and returns what the rows
/// need; `row` turns each further line into a record. A file without a header line is the
/// error "expected the header '`pattern`', found an empty file" at line 1. Returns the
/// header's value, its line and the records.
pub fn read<H, R>(
    text: &str,
    file: &str,
    pattern: &str,
    header: impl FnOnce(&Line) -> Result<H>,
    mut row: impl FnMut(&mut H, &Line) -> Result<R>,
) -> Result<(H, usize, Vec<R>)> {
    let mut header = Some(header);
    let mut head: Option<(H, usize)> = None;
    let mut rows = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let text = raw.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let line = Line {
            file,
            no: i + 1,
            text,
            fields: fields(text),
        };
        match (&mut head, header.take()) {
            (None, Some(h)) => head = Some((h(&line)?, line.no)),
            (Some((h, _)), _) => rows.push(row(h, &line)?),
            (None, None) => unreachable!("the header closure is taken with the first line"),
        }
    }
    match head {
        Some((h, no)) => Ok((h, no, rows)),
        None => Err(Error::parse(
            Location::line(file, 1),
            format!("expected the header '{pattern}', found an empty file"),
        )),
    }
}

/// Comma-separated fields of a line, trimmed.
pub fn fields(line: &str) -> Vec<&str> {
    let r: nom::IResult<&str, Vec<&str>> = separated_list1(
        char(','),
        delimited(space0, take_while(|c: char| c != ','), space0),
    )
    .parse(line);
    r.map(|(_, f)| f.into_iter().map(str::trim).collect())
        .unwrap_or_default()
}

/// A finite number filling the whole word.
pub fn number(word: &str) -> Option<f64> {
    let r: nom::IResult<&str, f64> =
        nom::combinator::all_consuming(nom::number::complete::double).parse(word);
    match r {
        Ok((_, v)) if v.is_finite() => Some(v),
        _ => None,
    }
}

/// At most 40 characters of `s` for messages.
pub fn shorten(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(37).collect::<String>())
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skips_blank_and_comment_lines_and_names_lines() {
        let text = "\n# c\na,b\n\n1, 2\n#x\n3,x\n";
        let r = read(
            text,
            "f.csv",
            "a,b",
            |h| Ok(h.fields.len()),
            |n, l| {
                assert_eq!(l.fields.len(), *n);
                l.number(1, "for b").map(|v| (l.no, v))
            },
        );
        let e = r.unwrap_err().to_string();
        assert_eq!(e, "f.csv:7: expected a number for b, found 'x'");
        let (n, head, rows) = read(
            "a,b\n1,2\n",
            "f.csv",
            "a,b",
            |h| Ok(h.fields.len()),
            |_, l| l.number(0, "for a"),
        )
        .unwrap();
        assert_eq!((n, head, rows), (2, 1, vec![1.0]));
        let e = read("# only\n", "f.csv", "a,b", |_| Ok(()), |_, _| Ok(()))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "f.csv:1: expected the header 'a,b', found an empty file");
    }
}
