//! Radiance views: the `-vt? -vp -vd -vu -vh -vv -vo -va -vs -vl -vf` options, the `VIEW=`
//! header variable, view files, and the ray of every image point.
//!
//! Sources: Radiance `src/common/view.h` (the `VIEW` record and `STDVIEW` defaults),
//! `src/common/image.c` (`setview`, `viewray`, `viewloc`, `normaspect`, `pix2loc`,
//! `getviewopt`, `sscanview`, `fprintview`, `viewfile`), man `rpict.1` (option meanings),
//! `src/util/evalglare.c`/`pictool.c` (`pict_get_sangle`: pixel solid angles).
//!
//! | option | field | default | meaning |
//! |---|---|---|---|
//! | `-vt?` | [`View::vtype`] | `v` | `v` perspective, `l` parallel, `a` angular fisheye, `h` hemispherical fisheye, `s` planisphere (stereographic), `c` cylindrical panorama |
//! | `-vp x y z` | [`View::vp`] | `0 0 0` | view point |
//! | `-vd x y z` | [`View::vd`] | `0 1 0` | view direction; its *length* is the focal distance (see below) |
//! | `-vu x y z` | [`View::vu`] | `0 0 1` | view up |
//! | `-vh deg` | [`View::vh`] | `45` | horizontal size: degrees, or world units for `-vtl` |
//! | `-vv deg` | [`View::vv`] | `45` | vertical size |
//! | `-vo d` | [`View::vo`] | `0` | fore clipping distance (plane for `v`/`l`, sphere otherwise) |
//! | `-va d` | [`View::va`] | `0` | aft clipping distance, 0 = none |
//! | `-vs s` | [`View::vs`] | `0` | view shift, in image widths (to the right) |
//! | `-vl l` | [`View::vl`] | `0` | view lift, in image heights (up) |
//! | `-vf file` | | | read options from a view file or a picture's header |
//!
//! Length of `-vd`: Radiance keeps it as the "view distance" (`vdist`, the focal distance for
//! depth of field, `rpict -pd`) and writes it back in `VIEW=` as `vdir * vdist`. It does
//! **not** scale the clipping distances: `viewray` uses the unit direction, so `-vo`/`-va`
//! are world distances whatever `-vd`'s length (checked against `vwrays` in `tests/all/view.rs`).
//!
//! Ray formulas (`viewray`; image point `(x, y)` in `[0,1]²`, origin bottom left, shifted by
//! `vs`/`vl` and centred: `x' = x + vs - ½`, `y' = y + vl - ½`; `D` unit view direction,
//! `H = D × U` normalised, `V = H × D`):
//! - perspective: `dir = D + x'·2tan(h/2)·H + y'·2tan(v/2)·V`, normalised;
//! - parallel: `org = vp + x'·h·H + y'·v·V`, `dir = D`;
//! - hemispherical: `z = √(1 − x'²(2 sin(h/2))² − y'²(2 sin(v/2))²)` (none if negative),
//!   `dir = z·D + x'·2 sin(h/2)·H + y'·2 sin(v/2)·V`;
//! - angular: `(a, b) = (x'·h/180°, y'·v/180°)`, `r = |(a,b)|` (none if `r > 1`),
//!   `dir = cos(πr)·D + sin(πr)/r·(a·H + b·V)`;
//! - planisphere: `(a, b) = (x'·2tan(h/4), y'·2tan(v/4))`, `d = a² + b²`,
//!   `z = (1−d)/(1+d)`, `dir = z·D + (1+z)(a·H + b·V)`;
//! - cylindrical: `φ = x'·h`, `dir = cos φ·D + sin φ·H + y'·2tan(v/2)·V`, normalised.
//!
//! Every ray starts at `vp + vo·dir` (parallel: `vp + vo·D + offsets`); with `-va` the ray
//! ends `va − vo` further along the view axis (scaled to the ray length for `v` and `c`).
//!
//! ```
//! use rdaylight_formats::view::{View, ViewType};
//! let mut v = View::default();
//! v.apply_str("-vta -vh 180 -vv 180 -vd 0 0 1 -vu 0 1 0", "example").unwrap();
//! let cam = v.setup().unwrap();
//! let ray = cam.view_ray(0.5, 0.5).unwrap();
//! assert!((ray.dir[2] - 1.0).abs() < 1e-12);
//! assert_eq!(v.vtype, ViewType::Angular);
//! assert_eq!(cam.view().to_string(),
//!     "-vta -vp 0 0 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180 -vo 0 -va 0 -vs 0 -vl 0");
//! ```

mod camera;
mod parse;

pub use camera::{Camera, ImageLoc, ViewRay, column_solid_angles, quad_solid_angle};
pub use parse::is_view_line;

use std::fmt;

/// Projection of a view (`-vt?`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewType {
    /// `-vtv`: perspective (pinhole); sizes below 180°.
    Perspective,
    /// `-vth`: hemispherical fisheye (orthographic projection of the hemisphere); sizes up to
    /// 180°.
    Hemispherical,
    /// `-vta`: angular fisheye (equidistant); sizes up to 360°.
    Angular,
    /// `-vtl`: parallel (orthographic); sizes are world lengths.
    Parallel,
    /// `-vtc`: cylindrical panorama; horizontal size up to 360°, vertical below 180°.
    Cylindrical,
    /// `-vts`: planisphere (stereographic fisheye); sizes below 360°.
    Planisphere,
}

impl ViewType {
    /// The letter after `-vt`.
    pub fn letter(self) -> char {
        match self {
            ViewType::Perspective => 'v',
            ViewType::Hemispherical => 'h',
            ViewType::Angular => 'a',
            ViewType::Parallel => 'l',
            ViewType::Cylindrical => 'c',
            ViewType::Planisphere => 's',
        }
    }

    /// The type for a `-vt` letter (Radiance's `VT_*` codes in `view.h`).
    pub fn from_letter(c: char) -> Option<ViewType> {
        Some(match c {
            'v' => ViewType::Perspective,
            'h' => ViewType::Hemispherical,
            'a' => ViewType::Angular,
            'l' => ViewType::Parallel,
            'c' => ViewType::Cylindrical,
            's' => ViewType::Planisphere,
            _ => return None,
        })
    }
}

/// View parameters as given (Radiance's `VIEW` before `setview`). Call [`View::setup`] to
/// validate them and get a [`Camera`] that generates rays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// `-vt?`
    pub vtype: ViewType,
    /// `-vp`: view point.
    pub vp: [f64; 3],
    /// `-vd`: view direction, not necessarily unit (its length is the focal distance).
    pub vd: [f64; 3],
    /// `-vu`: view up, not necessarily unit.
    pub vu: [f64; 3],
    /// `-vh`: horizontal size (degrees; world units for parallel views).
    pub vh: f64,
    /// `-vv`: vertical size.
    pub vv: f64,
    /// `-vs`: view shift (image widths).
    pub vs: f64,
    /// `-vl`: view lift (image heights).
    pub vl: f64,
    /// `-vo`: fore clipping distance.
    pub vo: f64,
    /// `-va`: aft clipping distance (0 = none).
    pub va: f64,
}

impl Default for View {
    /// Radiance's `STDVIEW` (`view.h`): `-vtv -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45
    /// -vo 0 -va 0 -vs 0 -vl 0`.
    fn default() -> Self {
        View {
            vtype: ViewType::Perspective,
            vp: [0.0, 0.0, 0.0],
            vd: [0.0, 1.0, 0.0],
            vu: [0.0, 0.0, 1.0],
            vh: 45.0,
            vv: 45.0,
            vs: 0.0,
            vl: 0.0,
            vo: 0.0,
            va: 0.0,
        }
    }
}

impl fmt::Display for View {
    /// The layout of Radiance's `fprintview` without its leading blank:
    /// `-vta -vp %.7g×3 -vd %.7g×3 -vu %.5g×3 -vh %.5g -vv %.5g -vo %.5g -va %.5g -vs %.5g
    /// -vl %.5g`. A header line is `VIEW=` followed by a blank and this text (see
    /// [`View::header_line`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let g7 = |v: f64| format_g(v, 7);
        let g5 = |v: f64| format_g(v, 5);
        write!(
            f,
            "-vt{} -vp {} {} {} -vd {} {} {} -vu {} {} {} -vh {} -vv {} -vo {} -va {} -vs {} -vl {}",
            self.vtype.letter(),
            g7(self.vp[0]),
            g7(self.vp[1]),
            g7(self.vp[2]),
            g7(self.vd[0]),
            g7(self.vd[1]),
            g7(self.vd[2]),
            g5(self.vu[0]),
            g5(self.vu[1]),
            g5(self.vu[2]),
            g5(self.vh),
            g5(self.vv),
            g5(self.vo),
            g5(self.va),
            g5(self.vs),
            g5(self.vl),
        )
    }
}

impl View {
    /// `VIEW= -vt...`, the header line rpict writes (value with its leading blank).
    pub fn header_line(&self) -> String {
        format!("VIEW= {self}")
    }
}

/// C's `printf("%.*g", prec, v)` for finite values (what Radiance uses to write views).
pub(crate) fn format_g(v: f64, prec: usize) -> String {
    let prec = prec.max(1);
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return if v.is_sign_negative() { "-0" } else { "0" }.into();
    }
    // Round to `prec` significant digits first: the exponent after rounding decides between
    // fixed and scientific notation, exactly as C does.
    let sci = format!("{:.*e}", prec - 1, v);
    let (mant, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if exp < -4 || exp >= prec as i32 {
        let mant = strip_zeros(mant);
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{mant}e{sign}{:02}", exp.abs())
    } else {
        let decimals = (prec as i32 - 1 - exp).max(0) as usize;
        strip_zeros(&format!("{v:.decimals$}")).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_g_matches_c() {
        // Expected strings from C printf("%.7g") / ("%.5g").
        assert_eq!(format_g(0.0, 7), "0");
        assert_eq!(format_g(-0.0, 7), "-0");
        assert_eq!(format_g(1.0, 7), "1");
        assert_eq!(format_g(-2.5, 7), "-2.5");
        assert_eq!(format_g(0.1, 7), "0.1");
        assert_eq!(format_g(1.0 / 3.0, 7), "0.3333333");
        assert_eq!(format_g(1.0 / 3.0, 5), "0.33333");
        assert_eq!(format_g(123456.7, 5), "1.2346e+05");
        assert_eq!(format_g(99999.5, 5), "1e+05");
        assert_eq!(format_g(0.0001, 5), "0.0001");
        assert_eq!(format_g(0.00001234, 5), "1.234e-05");
        assert_eq!(format_g(1234567.0, 7), "1234567");
        assert_eq!(format_g(12345678.0, 7), "1.234568e+07");
        assert_eq!(format_g(0.62831853, 5), "0.62832");
        assert_eq!(format_g(1e-300, 5), "1e-300");
    }

    #[test]
    fn default_is_stdview() {
        assert_eq!(
            View::default().to_string(),
            "-vtv -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45 -vo 0 -va 0 -vs 0 -vl 0"
        );
    }

    #[test]
    fn type_letters_round_trip() {
        for c in "vhalcs".chars() {
            assert_eq!(ViewType::from_letter(c).map(|t| t.letter()), Some(c));
        }
        assert_eq!(ViewType::from_letter('q'), None);
    }
}
