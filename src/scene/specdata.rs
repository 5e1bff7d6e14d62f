//! The data file behind a `specfile` primitive (Radiance 6): a one-dimensional Radiance data
//! file whose axis is wavelength in nm.
//!
//! Format (`src/common/data.c:getdata`, comment block there; `src/rt/p_data.c:p_specfile`
//! requires `nd == 1`): whitespace-separated words, `#` starts a comment to end of line
//! (`src/common/fgetval.c`):
//!
//! ```text
//! 1                      number of dimensions (must be 1 for specfile)
//! 380 780 21             first wavelength, last wavelength, number of samples (>= 2)
//! v1 v2 ... v21          values, evenly spaced from first to last
//! ```
//!
//! or, for irregular spacing, `0 0 n w1 w2 ... wn` instead of `begin end n` (Radiance takes
//! any `begin == end` as "irregular" and requires the wavelengths to be monotonic). This is
//! what Radiance reads; a plain two-column "wavelength value" table is *not* accepted by
//! Radiance (`getdata` would read the first wavelength as the dimension count), so it is not
//! accepted here either. Example: `test/renders/copper_spec.dat` in Radiance's sources.

use nom::{
    IResult, Parser,
    bytes::complete::{take_till, take_while1},
    character::complete::{char, multispace1},
    combinator::value,
    multi::many0,
};

use crate::error::{Error, Location, Result};

/// A sampled spectrum: `values[i]` at `wavelengths[i]` nm.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecData {
    pub wavelengths: Vec<f64>,
    pub values: Vec<f64>,
}

/// Whitespace and `#` comments between words.
fn gap(input: &str) -> IResult<&str, ()> {
    value(
        (),
        many0(nom::branch::alt((
            value((), multispace1),
            value((), (char('#'), take_till(|c| c == '\n'))),
        ))),
    )
    .parse(input)
}

fn word(input: &str) -> IResult<&str, &str> {
    take_while1(|c: char| !c.is_whitespace() && c != '#').parse(input)
}

impl SpecData {
    /// Parse a one-dimensional data file; `name` is used in error locations.
    pub fn parse(text: &str, name: &str) -> Result<SpecData> {
        // Tokenise first, remembering each word's line.
        let mut words: Vec<(&str, usize)> = Vec::new();
        let mut rest = text;
        while let Ok((r, ())) = gap(rest) {
            rest = r;
            match word(rest) {
                Ok((r, w)) => {
                    let offset = text.len() - rest.len();
                    let line = text[..offset].matches('\n').count() + 1;
                    words.push((w, line));
                    rest = r;
                }
                Err(_) => break,
            }
        }
        let end_line = text.matches('\n').count() + 1;
        let mut it = words.into_iter();
        let mut next = |what: &str| -> Result<(f64, usize)> {
            match it.next() {
                None => Err(Error::parse(
                    Location::line(name, end_line),
                    format!("unexpected end of data file; expected {what}"),
                )),
                Some((w, line)) => match super::parse::parse_real(w) {
                    Some(v) => Ok((v, line)),
                    None => Err(Error::parse(
                        Location::line(name, line),
                        format!("expected {what} (a number), found '{w}'"),
                    )),
                },
            }
        };
        let (nd, line) = next("the number of dimensions")?;
        if nd != 1.0 {
            return Err(Error::parse(
                Location::line(name, line),
                format!("a specfile data file must be 1-dimensional, found {nd} dimensions"),
            ));
        }
        let (begin, _) = next("the first wavelength")?;
        let (end, _) = next("the last wavelength")?;
        let (n, line) = next("the number of samples")?;
        let remaining = text.len(); // a cap: there cannot be more samples than bytes
        if n.fract() != 0.0 || n < 2.0 || n > remaining as f64 {
            return Err(Error::parse(
                Location::line(name, line),
                format!("expected a sample count of at least 2, found {n}"),
            ));
        }
        let n = n as usize;
        let wavelengths: Vec<f64> = if begin == end {
            // Irregular axis: n explicit, monotonic wavelengths (data.c checks monotonicity).
            let mut w = Vec::with_capacity(n);
            for i in 0..n {
                w.push(next(&format!("wavelength {} of {n}", i + 1))?.0);
            }
            let monotonic = w.windows(3).all(|t| (t[0] < t[1]) == (t[1] < t[2]));
            if !monotonic {
                return Err(Error::parse(
                    Location::line(name, line),
                    "irregular wavelengths must be monotonic",
                ));
            }
            w
        } else {
            let step = (end - begin) / (n as f64 - 1.0);
            (0..n).map(|i| begin + i as f64 * step).collect()
        };
        let mut values = Vec::with_capacity(n);
        for i in 0..n {
            values.push(next(&format!("value {} of {n}", i + 1))?.0);
        }
        Ok(SpecData {
            wavelengths,
            values,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_axis_with_comments() {
        let d = SpecData::parse("# copper\n1\n380 780 3 # axis\n0.5\n0.25 1\n", "c.dat").unwrap();
        assert_eq!(d.wavelengths, vec![380.0, 580.0, 780.0]);
        assert_eq!(d.values, vec![0.5, 0.25, 1.0]);
    }

    #[test]
    fn irregular_axis() {
        let d = SpecData::parse("1\n0 0 3 400 500 700\n1 2 3\n", "c.dat").unwrap();
        assert_eq!(d.wavelengths, vec![400.0, 500.0, 700.0]);
        let e = SpecData::parse("1\n0 0 3 400 700 500\n1 2 3\n", "c.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.dat:2: irregular wavelengths must be monotonic"
        );
    }

    #[test]
    fn errors_name_line_and_expectation() {
        let e = SpecData::parse("2\n380 780 3\n", "c.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.dat:1: a specfile data file must be 1-dimensional, found 2 dimensions"
        );
        let e = SpecData::parse("1\n380 780 3\n1 x 3\n", "c.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.dat:3: expected value 2 of 3 (a number), found 'x'"
        );
        let e = SpecData::parse("1\n380 780 1000000000\n1\n", "c.dat").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("c.dat:2: expected a sample count"),
            "{e}"
        );
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        let text = "# c\n1\n380 780 4\n0.5 0.25\n1 2\n";
        // Every prefix before the last value's final digit lacks a value.
        for i in 0..text.len() - 1 {
            let r = SpecData::parse(&text[..i], "c.dat");
            assert!(r.is_err(), "prefix {i} should be incomplete");
        }
        assert!(SpecData::parse(text, "c.dat").is_ok());
    }
}
