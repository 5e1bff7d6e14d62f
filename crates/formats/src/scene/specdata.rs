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

/// The words of a data file with their (1-based) lines.
fn tokens(text: &str) -> Vec<(&str, usize)> {
    let mut words: Vec<(&str, usize)> = Vec::new();
    let mut rest = text;
    let mut line = 1;
    let mut counted = 0; // bytes of `text` whose newlines are in `line`
    while let Ok((r, ())) = gap(rest) {
        rest = r;
        match word(rest) {
            Ok((r, w)) => {
                let offset = text.len() - rest.len();
                line += text[counted..offset].matches('\n').count();
                counted = offset;
                words.push((w, line));
                rest = r;
            }
            Err(_) => break,
        }
    }
    words
}

/// The numbers of a data file in order, each with its line, for the two parsers below.
struct Numbers<'t> {
    words: std::vec::IntoIter<(&'t str, usize)>,
    name: &'t str,
    end_line: usize,
}

impl<'t> Numbers<'t> {
    fn new(text: &'t str, name: &'t str) -> Self {
        Numbers {
            words: tokens(text).into_iter(),
            name,
            end_line: text.matches('\n').count() + 1,
        }
    }

    /// The next number and its line, or an error saying `what` was expected.
    fn next(&mut self, what: &str) -> Result<(f64, usize)> {
        match self.words.next() {
            None => Err(Error::parse(
                Location::line(self.name, self.end_line),
                format!("unexpected end of data file; expected {what}"),
            )),
            Some((w, line)) => match super::parse::parse_real(w) {
                Some(v) => Ok((v, line)),
                None => Err(Error::parse(
                    Location::line(self.name, line),
                    format!("expected {what} (a number), found '{w}'"),
                )),
            },
        }
    }
}

impl SpecData {
    /// Parse a one-dimensional data file; `name` is used in error locations.
    pub fn parse(text: &str, name: &str) -> Result<SpecData> {
        let mut numbers = Numbers::new(text, name);
        let mut next = |what: &str| numbers.next(what);
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

/// Most dimensions a data file may have (Radiance's `MAXDDIM`, `src/common/data.h`).
pub const MAX_DIMS: usize = 5;

/// One axis of a [`DataArray`]: `n` points from `org` spanning `siz` (negative when
/// decreasing), or explicit, monotonic `points` (Radiance's `0 0 n p1..pn` form).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub org: f64,
    pub siz: f64,
    pub n: usize,
    pub points: Option<Vec<f64>>,
}

/// An N-dimensional Radiance data file (`getdata`, `src/common/data.c`): the number of
/// dimensions (1 to [`MAX_DIMS`]), one `begin end n` (or `0 0 n p1..pn`) per axis, then the
/// values with the last axis varying fastest. `specdata` takes the last axis as wavelength
/// (`p_specdata` interpolates the first N-1 axes at the coordinates, `datavector`, and keeps
/// the last as a spectrum).
#[derive(Debug, Clone, PartialEq)]
pub struct DataArray {
    pub axes: Vec<Axis>,
    pub values: Vec<f64>,
}

impl DataArray {
    /// Parse a data file; `name` is used in error locations.
    pub fn parse(text: &str, name: &str) -> Result<DataArray> {
        let mut numbers = Numbers::new(text, name);
        let mut next = |what: &str| numbers.next(what);
        let (nd, line) = next("the number of dimensions")?;
        if nd.fract() != 0.0 || !(1.0..=MAX_DIMS as f64).contains(&nd) {
            return Err(Error::parse(
                Location::line(name, line),
                format!("expected 1 to {MAX_DIMS} dimensions, found {nd}"),
            ));
        }
        // A cap on counts: there cannot be more numbers than bytes.
        let cap = text.len() as f64;
        let mut axes = Vec::new();
        let mut total = 1usize;
        for d in 1..=nd as usize {
            let (org, _) = next(&format!("the start of axis {d}"))?;
            let (end, _) = next(&format!("the end of axis {d}"))?;
            let (n, line) = next(&format!("the point count of axis {d}"))?;
            if n.fract() != 0.0 || n < 2.0 || n > cap || total as f64 * n > cap {
                return Err(Error::parse(
                    Location::line(name, line),
                    format!(
                        "axis {d}: expected a point count of at least 2 that the file can hold, found {n}"
                    ),
                ));
            }
            let n = n as usize;
            total *= n;
            if end == org {
                let mut p = Vec::with_capacity(n);
                for i in 0..n {
                    p.push(next(&format!("point {} of axis {d}", i + 1))?.0);
                }
                if !p.windows(3).all(|t| (t[0] < t[1]) == (t[1] < t[2])) {
                    return Err(Error::parse(
                        Location::line(name, line),
                        format!("axis {d}: irregular points must be monotonic"),
                    ));
                }
                let (first, last) = (p[0], p[n - 1]);
                axes.push(Axis {
                    org: first,
                    siz: last - first,
                    n,
                    points: Some(p),
                });
            } else {
                axes.push(Axis {
                    org,
                    siz: end - org,
                    n,
                    points: None,
                });
            }
        }
        let mut values = Vec::with_capacity(total);
        for i in 0..total {
            values.push(next(&format!("value {} of {total}", i + 1))?.0);
        }
        Ok(DataArray { axes, values })
    }

    /// Number of dimensions.
    pub fn dims(&self) -> usize {
        self.axes.len()
    }

    /// Interpolated value at `pt` (one coordinate per axis): Radiance's `datavalue`.
    pub fn value(&self, pt: &[f64]) -> f64 {
        self.interp(0, 0, pt, 1.0, None)
    }

    /// The last axis's values interpolated at `pt` over the other axes (`pt.len()` =
    /// dimensions - 1): Radiance's `datavector`. Needs at least two dimensions.
    pub fn vector(&self, pt: &[f64]) -> Vec<f64> {
        let n = self.axes.last().map_or(0, |a| a.n);
        let mut out = vec![0.0; n];
        if self.axes.len() >= 2 {
            self.interp(0, 0, pt, 1.0, Some(&mut out));
        }
        out
    }

    /// Radiance's `data_interp`: linear in each axis; beyond the ends it extrapolates up
    /// to one division, then tapers off harmonically to zero. `base` is the offset of the
    /// sub-array for axis `d`, `coef` the weight accumulated so far.
    fn interp(&self, d: usize, base: usize, pt: &[f64], coef: f64, out: Option<&mut [f64]>) -> f64 {
        const FTINY: f64 = 1e-6; // Radiance's FTINY for float builds (fvect.h)
        if coef.abs() <= FTINY {
            return 0.0;
        }
        let Some(ax) = self.axes.get(d) else {
            return 0.0;
        };
        let p = pt.get(d).copied().unwrap_or(0.0);
        let stride: usize = self.axes[d + 1..].iter().map(|a| a.n).product();
        let last = ax.n as isize - 2;
        let (i, x) = match &ax.points {
            None => {
                let x = (p - ax.org) / ax.siz * (ax.n as f64 - 1.0);
                // C's (int) truncation, then clamping to the last division.
                let i = if x.is_nan() {
                    0
                } else {
                    (x as isize).clamp(0, last)
                };
                (i, x)
            }
            Some(pts) => {
                // Radiance's bisection (works for either direction of the axis).
                let (mut lower, mut upper) = if ax.siz > 0.0 { (0, ax.n) } else { (ax.n, 0) };
                let mut i;
                loop {
                    i = (lower + upper) >> 1;
                    if p >= pts[i.min(ax.n - 1)] {
                        lower = i;
                    } else {
                        upper = i;
                    }
                    if i == (lower + upper) >> 1 {
                        break;
                    }
                }
                let i = (i as isize).min(last).max(0);
                let (a, b) = (pts[i as usize], pts[i as usize + 1]);
                (i, i as f64 + (p - a) / (b - a))
            }
        };
        let (mut c0, mut c1) = data_interp_weights(i as f64, x);
        c0 *= coef;
        c1 *= coef;
        let i = i as usize;
        let at0 = base + i * stride;
        let at1 = at0 + stride;
        let remaining = self.axes.len() - d;
        if remaining == 2 {
            if let Some(out) = out {
                for (k, o) in out.iter_mut().enumerate() {
                    let y0 = self.values.get(at0 + k).copied().unwrap_or(0.0);
                    let y1 = self.values.get(at1 + k).copied().unwrap_or(0.0);
                    *o += c0 * y0 + c1 * y1;
                }
                return 0.0;
            }
        }
        if remaining > 1 {
            match out {
                Some(out) => {
                    self.interp(d + 1, at0, pt, c0, Some(&mut *out));
                    self.interp(d + 1, at1, pt, c1, Some(out));
                    0.0
                }
                None => {
                    self.interp(d + 1, at0, pt, c0, None) + self.interp(d + 1, at1, pt, c1, None)
                }
            }
        } else {
            let y0 = self.values.get(at0).copied().unwrap_or(0.0);
            let y1 = self.values.get(at1).copied().unwrap_or(0.0);
            c0 * y0 + c1 * y1
        }
    }
}

/// The two weights of Radiance's `data.c: data_interp` on one axis, for the lower node `i`
/// of the division used and the fractional index `x`: linear between neighbours, linear
/// extrapolation up to one division beyond the ends, then tapering to zero as 1/distance.
/// One home for the rule: data files here, and the atmosphere tables of `sky::atmosphere`.
pub fn data_interp_weights(i: f64, x: f64) -> (f64, f64) {
    if x > i + 2.0 {
        let c0 = 1.0 / (i - 1.0 - x);
        (c0, -2.0 * c0)
    } else if x < i - 1.0 {
        let c1 = 1.0 / (x - i);
        (-2.0 * c1, c1)
    } else {
        (i + 1.0 - x, x - i)
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

    #[test]
    fn n_dimensional_interpolation() {
        // 2 x 3: axis 1 at 0 and 1, axis 2 (fastest) at 400, 500, 600.
        let d = DataArray::parse("2\n0 1 2\n400 600 3\n1 2 3\n10 20 30\n", "d.dat").unwrap();
        assert_eq!(d.dims(), 2);
        assert_eq!(d.value(&[0.0, 400.0]), 1.0);
        assert!((d.value(&[0.5, 450.0]) - 0.5 * (1.5 + 15.0)).abs() < 1e-12);
        assert_eq!(d.vector(&[0.25]), vec![3.25, 6.5, 9.75]);
        // One division beyond the end: linear extrapolation; further: harmonic taper.
        assert!((d.value(&[2.0, 400.0]) - 19.0).abs() < 1e-12);
        let far = d.value(&[10.0, 400.0]);
        assert!(
            (far - (1.0 / (0.0 - 1.0 - 10.0) * 1.0 + -2.0 / (0.0 - 1.0 - 10.0) * 10.0)).abs()
                < 1e-12
        );
        // Irregular axes, increasing and decreasing.
        let d = DataArray::parse("1\n0 0 3 1 2 4\n10 20 40\n", "i.dat").unwrap();
        assert!((d.value(&[3.0]) - 30.0).abs() < 1e-12);
        let d = DataArray::parse("1\n0 0 3 4 2 1\n40 20 10\n", "i.dat").unwrap();
        assert!(
            (d.value(&[3.0]) - 30.0).abs() < 1e-12,
            "{}",
            d.value(&[3.0])
        );
    }

    #[test]
    fn data_array_errors_and_truncation() {
        let e = DataArray::parse("7\n", "d.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "d.dat:1: expected 1 to 5 dimensions, found 7"
        );
        let e = DataArray::parse("2\n0 1 2\n0 1 2\n1 2 3\n", "d.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "d.dat:5: unexpected end of data file; expected value 4 of 4"
        );
        let e = DataArray::parse("2\n0 1 99999\n0 1 99999\n1\n", "d.dat").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("d.dat:2: axis 1: expected a point count"),
            "{e}"
        );
        let text = "2 # dims\n0 1 2\n0 0 3 400 500 600\n1 2 3\n4 5 6\n";
        for i in 0..text.len() - 1 {
            assert!(DataArray::parse(&text[..i], "d.dat").is_err(), "prefix {i}");
        }
        assert!(DataArray::parse(text, "d.dat").is_ok());
    }
}
