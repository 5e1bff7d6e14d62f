//! A precomputed table of Jakob & Hanika coefficients with trilinear lookup (Jakob & Hanika
//! 2019, section 5: "we precompute a 3D table of coefficients ... and interpolate").
//!
//! Parametrisation (as in the paper): for an RGB colour in [0, 1]^3 with largest component
//! `i`, the table of that component is indexed by
//!
//! ```text
//! z = rgb[i],   x = rgb[(i + 1) % 3] / z,   y = rgb[(i + 2) % 3] / z
//! ```
//!
//! `x` and `y` on a uniform grid of `res` values in [0, 1]; `z` on the non-uniform grid
//! `z_k = smoothstep(smoothstep(k / (res - 1)))`, `smoothstep(t) = t^2 (3 - 2t)`, which is
//! dense near black and near white where the coefficients change fastest. Each entry holds
//! the Gauss-Newton fit ([`Jakob::fit`]) of its colour; a lookup interpolates the three
//! coefficients trilinearly. Colours outside [0, 1]^3 are fitted directly.
//!
//! File (`--table FILE`): the text line `ruplift-jakob-table 1 SPACE RES\n` (SPACE =
//! `radiance`, `srgb` or `srgb-linear`), then `3 res^3` entries of three little-endian
//! `f32`, component `i` major, then `z`, `y`, `x`.

use nom::{
    Parser,
    branch::alt,
    bytes::complete::tag,
    character::complete::{alpha1, digit1, space1},
    combinator::{map_res, recognize},
    multi::many1,
};
use rayon::prelude::*;
use std::io::Write;

use super::Jakob;
use super::solve::levenberg_marquardt;
use crate::colour::cie::{Observer, RgbSpace};
use crate::error::{Error, Location, Result};

/// Levenberg-Marquardt iterations after a lookup.
pub const POLISH_ITERS: usize = 8;

/// Delta E*ab at which the polish stops and below which it is accepted (else the full fit
/// runs): a hundredth of a just-noticeable difference, ten times below the 0.1 asked of a
/// table lookup, and reached in one or two iterations from a res-32 table.
pub const POLISH_ACCEPT: f64 = 0.01;

/// Largest accepted resolution (3 x 128^3 entries = 75 MB of f32: beyond any use).
pub const MAX_RES: usize = 128;

/// The table.
#[derive(Debug, Clone, PartialEq)]
pub struct JakobTable {
    pub space: RgbSpace,
    pub res: usize,
    /// `3 res^3` coefficient triples.
    pub coeffs: Vec<[f32; 3]>,
    /// The `z` grid ([`JakobTable::z_grid`]), kept for lookups.
    z: Vec<f64>,
}

fn smoothstep(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

fn space_name(s: RgbSpace) -> &'static str {
    match s {
        RgbSpace::Radiance => "radiance",
        RgbSpace::Srgb => "srgb",
        RgbSpace::SrgbLinear => "srgb-linear",
    }
}

impl JakobTable {
    /// The `z` grid.
    pub fn z_grid(res: usize) -> Vec<f64> {
        (0..res)
            .map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64)))
            .collect()
    }

    /// Fit every entry (in parallel).
    pub fn build(space: RgbSpace, res: usize) -> Result<JakobTable> {
        Self::build_reporting(space, res, &crate::progress::QUIET)
    }

    /// [`JakobTable::build`], its fits reported as one stage of `progress`.
    pub fn build_reporting(
        space: RgbSpace,
        res: usize,
        progress: &dyn crate::progress::Progress,
    ) -> Result<JakobTable> {
        if !(2..=MAX_RES).contains(&res) {
            return Err(Error::Usage(format!(
                "table resolution must be 2..{MAX_RES}, got {res}"
            )));
        }
        let obs = Observer::new(space);
        let z = Self::z_grid(res);
        let stage = crate::progress::Stage::new(
            progress,
            "Jakob-Hanika coefficient table",
            Some((3 * res * res * res) as u64),
            "fits",
        );
        let coeffs = (0..3 * res * res * res)
            .into_par_iter()
            .map(|idx| {
                let i = idx / (res * res * res);
                let k = idx / (res * res) % res;
                let j = idx / res % res;
                let l = idx % res;
                let zz = z[k];
                let step = 1.0 / (res - 1) as f64;
                let mut rgb = [0.0; 3];
                rgb[i] = zz;
                rgb[(i + 1) % 3] = l as f64 * step * zz;
                rgb[(i + 2) % 3] = j as f64 * step * zz;
                // Encoded values for sRGB: the table is indexed by what the user gives.
                let (m, _) = Jakob::fit(&obs, obs.rgb_to_xyz(rgb));
                stage.advance(1);
                m.c.map(|v| v as f32)
            })
            .collect();
        Ok(JakobTable {
            space,
            res,
            coeffs,
            z: Self::z_grid(res),
        })
    }

    /// The interpolated model for `rgb` (values as given in the table's space), or `None`
    /// outside [0, 1]^3.
    pub fn lookup(&self, rgb: [f64; 3]) -> Option<Jakob> {
        if rgb.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return None;
        }
        let res = self.res;
        let i = (0..3)
            .max_by(|&a, &b| rgb[a].total_cmp(&rgb[b]))
            .unwrap_or(0);
        let zz = rgb[i];
        let (x, y) = if zz > 0.0 {
            (rgb[(i + 1) % 3] / zz, rgb[(i + 2) % 3] / zz)
        } else {
            (0.0, 0.0)
        };
        let zg = &self.z;
        // Cell along z (binary search on the monotone grid), and its fraction.
        let k = zg.partition_point(|v| *v <= zz).clamp(1, res - 1) - 1;
        let fz = ((zz - zg[k]) / (zg[k + 1] - zg[k])).clamp(0.0, 1.0);
        let cell = |v: f64| {
            let p = v * (res - 1) as f64;
            let c = (p.floor() as usize).min(res - 2);
            (c, (p - c as f64).clamp(0.0, 1.0))
        };
        let (l, fx) = cell(x);
        let (j, fy) = cell(y);
        let at = |k: usize, j: usize, l: usize| self.coeffs[((i * res + k) * res + j) * res + l];
        let mut c = [0.0; 3];
        for (dk, wk) in [(0, 1.0 - fz), (1, fz)] {
            for (dj, wj) in [(0, 1.0 - fy), (1, fy)] {
                for (dl, wl) in [(0, 1.0 - fx), (1, fx)] {
                    let w = wk * wj * wl;
                    let e = at(k + dk, j + dj, l + dl);
                    for m in 0..3 {
                        c[m] += w * e[m] as f64;
                    }
                }
            }
        }
        Some(Jakob { c })
    }

    /// The fit for `rgb` warm-started from the table: the lookup, then Levenberg-Marquardt
    /// on the CIELAB difference until Delta E*ab < [`POLISH_ACCEPT`] (at most
    /// [`POLISH_ITERS`] iterations; a pure trilinear lookup of a res-64 table still leaves
    /// Delta E up to 0.15). Falls back to the full
    /// [`Jakob::fit`] outside the cube or when the polish does not converge. Returns the
    /// model and its Delta E*ab to the target.
    pub fn fit(&self, obs: &Observer, rgb: [f64; 3]) -> (Jakob, f64) {
        let xyz = obs.rgb_to_xyz(rgb);
        let Some(start) = self.lookup(rgb) else {
            return Jakob::fit(obs, xyz);
        };
        let target = obs.lab(xyz);
        let resid = |c: &[f64]| {
            let s = Jakob {
                c: [c[0], c[1], c[2]],
            }
            .spectrum();
            let l = obs.lab(obs.spectrum_xyz(&s));
            vec![l[0] - target[0], l[1] - target[1], l[2] - target[2]]
        };
        let r = levenberg_marquardt(&resid, &start.c, POLISH_ACCEPT, POLISH_ITERS);
        if r.cost < POLISH_ACCEPT {
            (
                Jakob {
                    c: [r.x[0], r.x[1], r.x[2]],
                },
                r.cost,
            )
        } else {
            Jakob::fit(obs, xyz)
        }
    }

    /// Write the table file.
    pub fn write(&self, w: &mut dyn Write) -> std::io::Result<()> {
        writeln!(
            w,
            "ruplift-jakob-table 1 {} {}",
            space_name(self.space),
            self.res
        )?;
        let mut buf = Vec::with_capacity(self.coeffs.len() * 12);
        for c in &self.coeffs {
            for v in c {
                buf.extend_from_slice(&v.to_le_bytes());
            }
        }
        w.write_all(&buf)
    }

    /// Read a table file (`name` for messages).
    pub fn read(bytes: &[u8], name: &str) -> Result<JakobTable> {
        let end = bytes
            .iter()
            .take(200)
            .position(|b| *b == b'\n')
            .ok_or_else(|| {
                Error::parse(
                    Location::line(name, 1),
                    "expected the header line 'ruplift-jakob-table 1 SPACE RES'",
                )
            })?;
        let head = std::str::from_utf8(&bytes[..end]).unwrap_or("");
        let parsed: nom::IResult<&str, (&str, usize)> = (
            tag("ruplift-jakob-table 1"),
            space1,
            recognize(many1(alt((alpha1, tag("-"))))),
            space1,
            map_res(digit1, str::parse::<usize>),
        )
            .map(|(_, _, s, _, r)| (s, r))
            .parse(head);
        let (space, res) = match parsed {
            Ok(("", v)) => v,
            _ => {
                return Err(Error::parse(
                    Location::line(name, 1),
                    format!("expected 'ruplift-jakob-table 1 SPACE RES', found '{head}'"),
                ));
            }
        };
        let space = match space {
            "radiance" => RgbSpace::Radiance,
            "srgb" => RgbSpace::Srgb,
            "srgb-linear" => RgbSpace::SrgbLinear,
            other => {
                return Err(Error::parse(
                    Location::line(name, 1),
                    format!("expected space radiance, srgb or srgb-linear, found '{other}'"),
                ));
            }
        };
        if !(2..=MAX_RES).contains(&res) {
            return Err(Error::parse(
                Location::line(name, 1),
                format!("resolution must be 2..{MAX_RES}, found {res}"),
            ));
        }
        let data = &bytes[end + 1..];
        let n = 3 * res * res * res;
        if data.len() != 12 * n {
            return Err(Error::parse(
                Location::file(name),
                format!(
                    "expected {} bytes of coefficients for resolution {res}, found {}",
                    12 * n,
                    data.len()
                ),
            ));
        }
        let coeffs = data
            .chunks_exact(12)
            .map(|c| {
                let f = |o: usize| f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
                [f(0), f(4), f(8)]
            })
            .collect();
        Ok(JakobTable {
            space,
            res,
            coeffs,
            z: Self::z_grid(res),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::cie::delta_e;

    #[test]
    fn z_grid_is_monotone_from_0_to_1() {
        let z = JakobTable::z_grid(9);
        assert_eq!((z[0], z[8]), (0.0, 1.0));
        assert!(z.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn table_fits_reproduce_the_gauss_newton_colour() {
        // Even a coarse table (res 10) gives dE*ab < 0.1 after the polish: the polish stops
        // at 0.01 or the full fit takes over.
        let t = JakobTable::build(RgbSpace::Radiance, 10).unwrap();
        let obs = Observer::new(RgbSpace::Radiance);
        let u = crate::uplift::Uplifter::new(RgbSpace::Radiance, crate::uplift::Method::Jakob)
            .with_table(t.clone())
            .unwrap();
        for &r in &[0.05, 0.3, 0.6, 0.95] {
            for &g in &[0.05, 0.3, 0.6, 0.95] {
                for &b in &[0.05, 0.3, 0.6, 0.95] {
                    let (m, de) = t.fit(&obs, [r, g, b]);
                    let real = delta_e(
                        obs.lab(obs.spectrum_xyz(&m.spectrum())),
                        obs.lab(obs.rgb_to_xyz([r, g, b])),
                    );
                    assert!(
                        real < 0.1 && (real - de).abs() < 1e-9,
                        "{r} {g} {b}: {real}"
                    );
                    let up = u.uplift_rgb([r, g, b]);
                    assert!(up.delta_e < 0.1);
                    assert!(up.spectrum.iter().all(|v| (0.0..=1.0).contains(v)));
                }
            }
        }
        // The table is for one space and the Jakob method only.
        let srgb = crate::uplift::Uplifter::new(RgbSpace::Srgb, crate::uplift::Method::Jakob);
        assert!(srgb.with_table(t.clone()).is_err());
        let basis = crate::uplift::Uplifter::new(RgbSpace::Radiance, crate::uplift::Method::Basis);
        assert!(basis.with_table(t).is_err());
    }

    #[test]
    fn lookup_reproduces_grid_entries_and_round_trips_the_file() {
        let t = JakobTable::build(RgbSpace::Radiance, 5).unwrap();
        let obs = Observer::new(RgbSpace::Radiance);
        // A grid node: the lookup is the stored fit itself.
        let z = JakobTable::z_grid(5)[3];
        let rgb = [z * 0.5, z, z * 0.25];
        let m = t.lookup(rgb).unwrap();
        let de = delta_e(
            obs.lab(obs.spectrum_xyz(&m.spectrum())),
            obs.lab(obs.rgb_to_xyz(rgb)),
        );
        assert!(de < 1e-3, "{de}");
        assert!(t.lookup([1.2, 0.5, 0.5]).is_none());
        let mut buf = Vec::new();
        t.write(&mut buf).unwrap();
        let back = JakobTable::read(&buf, "t.tab").unwrap();
        assert_eq!(back, t);
        let e = JakobTable::read(&buf[..buf.len() - 1], "t.tab")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.tab: expected 4500 bytes"), "{e}");
        let e = JakobTable::read(b"ruplift-jakob-table 1 cmyk 5\n", "t.tab")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.tab:1: expected space"), "{e}");
        for cut in (0..buf.len()).step_by(37) {
            let _ = JakobTable::read(&buf[..cut], "cut");
        }
    }

    /// Accuracy and speed of lookups against the Gauss-Newton fit: in-gamut colours on a
    /// grid strictly inside the cube (what `docs/uplift-validation.md` reports).
    pub fn accuracy(t: &JakobTable, steps: usize) -> (f64, f64, f64, f64, f64, f64) {
        let obs = Observer::new(t.space);
        let mut des = Vec::new();
        let v: Vec<f64> = (0..steps)
            .map(|k| 0.05 + 0.9 * k as f64 / (steps - 1) as f64)
            .collect();
        let mut colours: Vec<[f64; 3]> = Vec::new();
        for &r in &v {
            for &g in &v {
                for &b in &v {
                    colours.push([r, g, b]);
                }
            }
        }
        let t0 = std::time::Instant::now();
        let models: Vec<Jakob> = colours.iter().map(|c| t.lookup(*c).unwrap()).collect();
        let lookup = t0.elapsed().as_secs_f64() / colours.len() as f64;
        let t0 = std::time::Instant::now();
        for c in &colours {
            std::hint::black_box(Jakob::fit(&obs, obs.rgb_to_xyz(*c)));
        }
        let fit = t0.elapsed().as_secs_f64() / colours.len() as f64;
        let t0 = std::time::Instant::now();
        let polished: Vec<f64> = colours.iter().map(|c| t.fit(&obs, *c).1).collect();
        let polish = t0.elapsed().as_secs_f64() / colours.len() as f64;
        let polished_max = polished.iter().copied().fold(0.0, f64::max);
        for (c, m) in colours.iter().zip(&models) {
            des.push(delta_e(
                obs.lab(obs.spectrum_xyz(&m.spectrum())),
                obs.lab(obs.rgb_to_xyz(*c)),
            ));
        }
        let p = |q: f64| rdaylight_base::stats::percentile(&des, q);
        (
            p(50.0),
            p(99.0),
            des.iter().copied().fold(0.0, f64::max),
            fit / lookup,
            polished_max,
            fit / polish,
        )
    }

    /// The accuracy rows of `docs/uplift-validation.md` (lookup dE*ab median / p99 / max and
    /// the polished maximum, which Levenberg-Marquardt stops at 0.01). Times are printed, not
    /// asserted (speed is measured by benchmarks, not tests).
    fn check_table_row(res: usize, med_p99_max: [f64; 3]) {
        let t0 = std::time::Instant::now();
        let t = JakobTable::build(RgbSpace::Radiance, res).unwrap();
        let build = t0.elapsed().as_secs_f64();
        let (med, p99, max, speed, pmax, pspeed) = accuracy(&t, 12);
        eprintln!(
            "res {res}: build {build:.1} s, lookup dE median {med:.2e} p99 {p99:.2e} \
             max {max:.2e}, {speed:.0}x faster than the fit; polished max dE {pmax:.2e}, \
             {pspeed:.1}x faster"
        );
        // The table is deterministic: the documented figures (two digits) to 5 %.
        for (got, want) in [med, p99, max].into_iter().zip(med_p99_max) {
            assert!(
                (got - want).abs() <= 0.05 * want,
                "res {res}: {got} vs {want}"
            );
        }
        assert!(pmax <= 0.0101, "res {res}: polished max dE {pmax}");
    }

    #[test]
    fn table_res16_matches_the_documented_accuracy() {
        check_table_row(16, [0.40, 1.40, 3.65]);
    }

    #[test]
    #[ignore = "about a minute: res 32 and 64 tables (docs/uplift-validation.md)"]
    fn table_res32_res64_match_the_documented_accuracy() {
        check_table_row(32, [0.095, 0.34, 0.67]);
        check_table_row(64, [0.023, 0.085, 0.15]);
    }
}
