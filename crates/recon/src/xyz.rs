//! XYZ text point clouds: one point per line, values separated by white space, commas or
//! semicolons, `#` or `//` comment lines, blank lines ignored. Columns (the layouts
//! CloudCompare and most scanner software export):
//!
//! | columns | meaning |
//! |---|---|
//! | 3 | `x y z` |
//! | 4 | `x y z intensity` (intensity dropped) |
//! | 6 | `x y z nx ny nz` when the first row's last three are within [-1, 1] and not all integers above 1, else `x y z r g b` |
//! | 7 | `x y z intensity r g b` |
//! | 9 | `x y z r g b nx ny nz` |
//!
//! Every row must have the first row's column count. Errors name `file:line:column`.

use super::cloud::PointCloud;
use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    character::complete::{one_of, space0},
    combinator::opt,
    number::complete::double,
    sequence::{delimited, preceded},
};

/// One value and its separator.
fn value(i: &str) -> IResult<&str, f64> {
    preceded(space0, double).parse(i)
}

fn separator(i: &str) -> IResult<&str, Option<char>> {
    delimited(space0, opt(one_of(",;")), space0).parse(i)
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Layout {
    Xyz,
    XyzI,
    XyzNormal,
    XyzRgb,
    XyzIRgb,
    XyzRgbNormal,
}

/// Read XYZ text; `name` is used in error messages.
pub fn read(data: &[u8], name: &str) -> Result<PointCloud> {
    let text = std::str::from_utf8(data).map_err(|e| {
        let line = data[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        Error::parse(
            Location::line(name, line),
            "not text; expected numbers (XYZ format)",
        )
    })?;
    let mut cloud = PointCloud::default();
    let mut layout = None;
    let mut row = Vec::with_capacity(9);
    cloud.points.reserve(text.len() / 24);
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') || t.starts_with("//") {
            continue;
        }
        row.clear();
        let mut rest = line;
        while !rest.trim().is_empty() {
            let col = line.len() - rest.len() + 1;
            let (r, v) = value(rest).map_err(|_| {
                Error::parse(
                    Location::at(name, ln + 1, col),
                    format!(
                        "'{}' is not a number; expected x y z [...] values",
                        rest.trim()
                            .split([' ', '\t', ',', ';'])
                            .next()
                            .unwrap_or("")
                    ),
                )
            })?;
            let (r, _) = separator(r).map_err(|_| {
                Error::parse(Location::at(name, ln + 1, col), "expected a separator")
            })?;
            row.push(v);
            rest = r;
            if row.len() > 9 {
                break;
            }
        }
        let lay = match layout {
            Some(l) => l,
            None => {
                let l = match row.len() {
                    3 => Layout::Xyz,
                    4 => Layout::XyzI,
                    6 if row[3..6].iter().all(|v| v.abs() <= 1.0) => Layout::XyzNormal,
                    6 => Layout::XyzRgb,
                    7 => Layout::XyzIRgb,
                    9 => Layout::XyzRgbNormal,
                    n => {
                        return Err(Error::parse(
                            Location::line(name, ln + 1),
                            format!("{n} values; expected 3, 4, 6, 7 or 9 columns"),
                        ));
                    }
                };
                if matches!(l, Layout::XyzNormal | Layout::XyzRgbNormal) {
                    cloud.normals = Some(Vec::new());
                }
                if matches!(l, Layout::XyzRgb | Layout::XyzIRgb | Layout::XyzRgbNormal) {
                    cloud.colors = Some(Vec::new());
                }
                layout = Some(l);
                l
            }
        };
        let want = match lay {
            Layout::Xyz => 3,
            Layout::XyzI => 4,
            Layout::XyzNormal | Layout::XyzRgb => 6,
            Layout::XyzIRgb => 7,
            Layout::XyzRgbNormal => 9,
        };
        if row.len() != want {
            return Err(Error::parse(
                Location::line(name, ln + 1),
                format!("{} values; expected {want} like the first point", row.len()),
            ));
        }
        cloud.points.push([row[0], row[1], row[2]]);
        let rgb =
            |k: usize| [row[k], row[k + 1], row[k + 2]].map(|v| v.round().clamp(0.0, 255.0) as u8);
        let (normal_at, rgb_at) = match lay {
            Layout::XyzNormal => (Some(3), None),
            Layout::XyzRgb => (None, Some(3)),
            Layout::XyzIRgb => (None, Some(4)),
            Layout::XyzRgbNormal => (Some(6), Some(3)),
            Layout::Xyz | Layout::XyzI => (None, None),
        };
        if let (Some(k), Some(n)) = (normal_at, cloud.normals.as_mut()) {
            n.push([row[k], row[k + 1], row[k + 2]]);
        }
        if let (Some(k), Some(c)) = (rgb_at, cloud.colors.as_mut()) {
            c.push(rgb(k));
        }
    }
    Ok(cloud)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_and_separators() {
        let c = read(b"# scan\n1 2 3\n4,5,6\n\n7;8;9\n", "a.xyz").unwrap();
        assert_eq!(c.points, vec![[1., 2., 3.], [4., 5., 6.], [7., 8., 9.]]);
        let c = read(b"1 2 3 0 0 1\n1 2 3 0 1 0\n", "a.xyz").unwrap();
        assert_eq!(c.normals.unwrap()[1], [0., 1., 0.]);
        let c = read(b"1 2 3 255 128 0\n", "a.xyz").unwrap();
        assert_eq!(c.colors.unwrap()[0], [255, 128, 0]);
        let c = read(b"1 2 3 10 1 2 3 0 0 -1\n", "a.xyz")
            .unwrap_err()
            .to_string();
        assert_eq!(c, "a.xyz:1: 10 values; expected 3, 4, 6, 7 or 9 columns");
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = read(b"1 2 3\n1 2 x\n", "b.xyz").unwrap_err().to_string();
        assert_eq!(
            e,
            "b.xyz:2:5: 'x' is not a number; expected x y z [...] values"
        );
        let e = read(b"1 2 3\n1 2 3 4\n", "b.xyz").unwrap_err().to_string();
        assert_eq!(e, "b.xyz:2: 4 values; expected 3 like the first point");
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        let f = b"1.5 2.25 3 0 0 1\n-4e-1 5 6 1 0 0\n";
        for n in 0..f.len() {
            // Prefixes either parse (a shorter number is still a number) or fail cleanly;
            // a second row cut inside its columns must fail (the first row sets the layout).
            let r = read(&f[..n], "t.xyz");
            let cut_row = !f[..n].ends_with(b"\n") && n > 17 && {
                let last = f[..n].split(|&b| b == b'\n').next_back().unwrap();
                last.split(|&b| b == b' ').filter(|w| !w.is_empty()).count() < 6
            };
            if cut_row {
                assert!(r.is_err(), "prefix {n} accepted");
            }
        }
    }
}
