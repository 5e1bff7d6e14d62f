//! # Tregenza / Reinhart sky subdivision
//!
//! The sky hemisphere is cut into bands of equal altitude height, each band into patches of
//! equal azimuth width (Tregenza 1987; Reinhart's subdivision by a factor `MF`). This is the
//! patch layout of `gendaymtx -m MF`, of `reinhart.cal` (`rbin`) and of `reinsrc.cal`
//! (`LBNL-ETA/Radiance: src/gen/gendaymtx.c: rh_init`, `src/cal/cal/reinhart.cal`).
//!
//! Geometry (+X east, +Y north, +Z zenith; altitude `alt` above the horizon, azimuth `azi`
//! measured from +Y (north) toward +X (east)):
//!
//! ```text
//! alpha      = 90 deg / (7 MF + 0.5)                 row height (MF = 1: 12 deg)
//! rows r     = 0 .. 7 MF - 1, spanning alt in [r alpha, (r+1) alpha)
//! n(r)       = MF * [30, 30, 24, 24, 18, 12, 6][r / MF]   patches in row r
//! zenith cap = alt in [7 MF alpha, 90 deg]           (a disc of half-angle alpha / 2)
//! count      = 144 MF^2 + 1 sky patches, + 1 ground bin = gendaymtx's NROWS
//! ```
//!
//! Index order (`gendaymtx` rows, `rbin`): 0 = ground (any direction with `Dz < 0`), then
//! rows from the horizon up; within a row, patch `j` has its centre at azimuth
//! `360 j / n` and covers `[(j - 0.5) w, (j + 0.5) w)` with `w = 360 / n`; the last index is
//! the zenith cap.
//!
//! Exact boundary behaviour of `reinhart.cal` (reproduced by [`SkyPatches::bin_of`]): the
//! row is `floor(alt_deg / alpha)` and the column `floor((azi_deg + w/2) / w)`, except that
//! an azimuth at or above `359.9999 - w/2` degrees wraps to column 0. Patch 0 of a row
//! therefore starts 1e-4 deg before its nominal edge, and the last patch ends 1e-4 deg early.
//! A direction exactly on the horizon (`Dz = 0`) belongs to row 0, not to the ground.
//!
//! Patch centres ([`SkyPatches::centre`]) are gendaymtx's: altitude `alpha (r + 0.5)`,
//! azimuth `2 pi j / n`; zenith `(0, 0, 1)`; ground `(0, 0, -1)`. `reinsrc.cal` with
//! `x1 = x2 = 0.5` gives the same directions for every sky patch, but its ground "centre" is
//! altitude `asin(-0.5) = -30 deg` at azimuth 180 deg, i.e. `(0, -0.866, -0.5)`
//! ([`SkyPatches::reinsrc_dir`] reproduces that too). Solid angles are
//! `2 pi (sin((r+1) alpha) - sin(r alpha)) / n`, zenith `2 pi (1 - cos(alpha / 2))`,
//! ground `2 pi`; the sky ones sum to `2 pi`.
//!
//! gendaymtx stores patch angles as C `float`; we keep `f64` (differences ~1e-7 relative).

use std::f64::consts::PI;

/// Patches per row of the Tregenza (MF = 1) sky, from the horizon up (zenith cap excluded).
const TREGENZA_ROWS: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];

/// `reinhart.cal`'s wrap-around threshold: azimuths `>= 359.9999 - w/2` (degrees) go to
/// column 0 (the `359.9999` literal in `r_azn`).
const WRAP_DEG: f64 = 359.9999;

/// Relative margin kept from patch edges by [`SkyPatches::sample`] so that rounding can never
/// push a sample into a neighbouring bin (the lost measure, 2e-9 of the patch, is negligible).
const SAMPLE_MARGIN: f64 = 1e-9;

/// A Reinhart sky subdivision with multiplication factor `MF` (`MF = 1`: Tregenza's 145).
#[derive(Debug, Clone)]
pub struct SkyPatches {
    mf: usize,
    /// Row height in degrees (`alpha` of reinhart.cal).
    alpha_deg: f64,
    /// First patch index of each row (row 0 starts at 1), plus the zenith index at the end.
    row_start: Vec<usize>,
    /// Per-bin geometry, computed on first use ([`SkyPatches::geometry`]).
    geometry: std::sync::OnceLock<Vec<PatchGeometry>>,
}

/// What a sky model evaluated at every patch for every time step needs of bin `i`,
/// computed once per subdivision instead of per step (a year at MF 4 evaluates 20 million
/// patch-steps; recomputing these took most of gendaymtx-style sky generation's time).
#[derive(Debug, Clone, Copy)]
pub struct PatchGeometry {
    /// Centre altitude and azimuth (radians, [`SkyPatches::centre_angles`]).
    pub alt: f64,
    pub azi: f64,
    /// Unit direction of the centre ([`SkyPatches::centre`]).
    pub dir: [f64; 3],
    /// Sine of the altitude; cosine and sine of the azimuth.
    pub sin_alt: f64,
    pub cos_azi: f64,
    pub sin_azi: f64,
    /// Cosine and sine of the centre's zenith angle.
    pub cos_zenith: f64,
    pub sin_zenith: f64,
    /// [`SkyPatches::solid_angle`].
    pub solid_angle: f64,
}

impl SkyPatches {
    /// The subdivision for `mf >= 1` (values below 1 are treated as 1).
    pub fn new(mf: usize) -> SkyPatches {
        let mf = mf.max(1);
        let nrows = 7 * mf;
        let mut row_start = Vec::with_capacity(nrows + 1);
        let mut next = 1;
        for r in 0..nrows {
            row_start.push(next);
            next += mf * TREGENZA_ROWS[r / mf];
        }
        row_start.push(next); // zenith
        SkyPatches {
            mf,
            alpha_deg: 90.0 / (mf as f64 * 7.0 + 0.5),
            row_start,
            geometry: std::sync::OnceLock::new(),
        }
    }

    /// [`PatchGeometry`] of every bin (index = bin), computed once.
    pub fn geometry(&self) -> &[PatchGeometry] {
        self.geometry.get_or_init(|| {
            (0..self.len())
                .map(|i| {
                    let (alt, azi) = self.centre_angles(i);
                    let zenith = PI / 2.0 - alt;
                    PatchGeometry {
                        alt,
                        azi,
                        dir: direction(alt, azi),
                        sin_alt: alt.sin(),
                        cos_azi: azi.cos(),
                        sin_azi: azi.sin(),
                        cos_zenith: zenith.cos(),
                        sin_zenith: zenith.sin(),
                        solid_angle: self.solid_angle(i),
                    }
                })
                .collect()
        })
    }

    /// The subdivision factor.
    pub fn mf(&self) -> usize {
        self.mf
    }

    /// Number of bins including the ground bin 0 (gendaymtx's `NROWS`, `Nrbins`).
    pub fn len(&self) -> usize {
        self.zenith() + 1
    }

    /// Never empty (there is always ground and zenith); provided for clippy's sake.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Number of sky patches (`144 MF^2 + 1`), excluding the ground bin.
    pub fn sky_len(&self) -> usize {
        self.len() - 1
    }

    /// Index of the zenith cap (the last bin).
    pub fn zenith(&self) -> usize {
        *self.row_start.last().unwrap_or(&1)
    }

    /// Number of altitude rows below the zenith cap (`7 MF`).
    pub fn rows(&self) -> usize {
        7 * self.mf
    }

    /// Row height in radians.
    pub fn alpha(&self) -> f64 {
        self.alpha_deg.to_radians()
    }

    /// Patches in row `r` (`r == rows()` is the zenith cap: 1).
    pub fn row_len(&self, r: usize) -> usize {
        if r >= self.rows() {
            1
        } else {
            self.mf * TREGENZA_ROWS[r / self.mf]
        }
    }

    /// Row of bin `i`: `None` for the ground, `Some(rows())` for the zenith cap.
    pub fn row_of(&self, i: usize) -> Option<usize> {
        if i == 0 || i > self.zenith() {
            return None;
        }
        // row_start is sorted; the row is the last start <= i.
        Some(self.row_start.partition_point(|&s| s <= i) - 1)
    }

    /// Bin of direction `dir` (unit vector pointing toward the sky), with `reinhart.cal`'s
    /// `rbin` semantics: 0 for `Dz < 0`, exact boundary behaviour documented in the module.
    /// The arithmetic follows the `.cal` file step by step (degrees, `floor`) so that
    /// directions on boundaries land in the same bin as real Radiance.
    pub fn bin_of(&self, dir: [f64; 3]) -> usize {
        // calcomp (rcalc, rtrace's .cal evaluation) folds constant definitions (`:`) into
        // the expression tree and rewrites division by a constant as multiplication by its
        // reciprocal (`src/common/calexpr.c: getE2`), so `x/DEGREE` is `x * (1/DEGREE)`
        // there. Doing the same here keeps directions on boundaries in the same bin.
        let to_deg = 1.0 / (PI / 180.0);
        let z = dir[2];
        let alt = if z - 1.0 > 0.0 {
            PI / 2.0
        } else if -1.0 - z > 0.0 {
            -PI / 2.0
        } else {
            z.asin()
        } * to_deg;
        if -alt > 0.0 {
            return 0;
        }
        let mut azi = dir[0].atan2(dir[1]);
        if -azi > 0.0 {
            azi += 2.0 * PI;
        }
        let azi = azi * to_deg;
        let row = ((alt * (1.0 / self.alpha_deg)).floor() as usize).min(self.rows());
        let n = self.row_len(row) as f64;
        let inc = 360.0 / n;
        let col = if WRAP_DEG - 0.5 * inc - azi > 0.0 {
            ((azi + 0.5 * inc) / inc).floor() as usize
        } else {
            0
        };
        self.row_start[row] + col.min(self.row_len(row) - 1)
    }

    /// (altitude, azimuth east of north) of bin `i`'s centre in radians, as gendaymtx's
    /// `rh_init` (ground: `-pi/2`, zenith: `pi/2`).
    pub fn centre_angles(&self, i: usize) -> (f64, f64) {
        match self.row_of(i) {
            None => (-PI / 2.0, 0.0),
            Some(r) if r >= self.rows() => (PI / 2.0, 0.0),
            Some(r) => {
                let j = i - self.row_start[r];
                (
                    self.alpha() * (r as f64 + 0.5),
                    2.0 * PI * j as f64 / self.row_len(r) as f64,
                )
            }
        }
    }

    /// Unit direction of bin `i`'s centre, as gendaymtx (ground: straight down).
    pub fn centre(&self, i: usize) -> [f64; 3] {
        let (alt, azi) = self.centre_angles(i);
        direction(alt, azi)
    }

    /// `reinsrc.cal`'s direction for `Rbin = i` with its subsampling variables `x1`
    /// (altitude fraction) and `x2` (azimuth fraction); `x1 = x2 = 0.5` is the patch centre
    /// except for the ground (see module doc). Not uniform in solid angle: use
    /// [`SkyPatches::sample`] for Monte Carlo.
    pub fn reinsrc_dir(&self, i: usize, x1: f64, x2: f64) -> [f64; 3] {
        let alpha = self.alpha();
        match self.row_of(i) {
            None => direction((-x1).asin(), 2.0 * PI * x2),
            Some(r) => {
                let j = i - self.row_start[r];
                let w = 2.0 * PI / self.row_len(r) as f64;
                direction((r as f64 + x1) * alpha, (j as f64 + x2 - 0.5) * w)
            }
        }
    }

    /// Solid angle of bin `i` in steradians, as gendaymtx (ground `2 pi`).
    pub fn solid_angle(&self, i: usize) -> f64 {
        let alpha = self.alpha();
        match self.row_of(i) {
            None => 2.0 * PI,
            Some(r) if r >= self.rows() => 2.0 * PI * (1.0 - (alpha * 0.5).cos()),
            Some(r) => {
                2.0 * PI * ((alpha * (r + 1) as f64).sin() - (alpha * r as f64).sin())
                    / self.row_len(r) as f64
            }
        }
    }

    /// A direction uniformly distributed by solid angle inside bin `i`, from two numbers
    /// `u, v` in `[0, 1)` (`u` picks the altitude, `v` the azimuth). The ground bin samples
    /// the lower hemisphere. The region sampled is the one [`SkyPatches::bin_of`] assigns
    /// (with `reinhart.cal`'s 1e-4 deg wrap shift), so `bin_of(sample(i, u, v)) == i`.
    pub fn sample(&self, i: usize, u: f64, v: f64) -> [f64; 3] {
        let shrink = |t: f64| SAMPLE_MARGIN + t.clamp(0.0, 1.0) * (1.0 - 2.0 * SAMPLE_MARGIN);
        let (u, v) = (shrink(u), shrink(v));
        match self.row_of(i) {
            None => {
                let z = -(1.0 - u).max(SAMPLE_MARGIN);
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * v;
                [r * phi.sin(), r * phi.cos(), z]
            }
            Some(r) if r >= self.rows() => {
                // Uniform in cos(theta) between cos(alpha/2) and 1; keep a margin from the
                // lower edge so the altitude never rounds into the last row.
                let cmin = (self.alpha() * 0.5).cos();
                let z = cmin + (1.0 - cmin) * u;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * v;
                [s * phi.sin(), s * phi.cos(), z]
            }
            Some(r) => {
                let alpha = self.alpha();
                let (s0, s1) = ((alpha * r as f64).sin(), (alpha * (r + 1) as f64).sin());
                let z = s0 + (s1 - s0) * u;
                let n = self.row_len(r);
                let j = i - self.row_start[r];
                let w = 360.0 / n as f64;
                // reinhart.cal's edges in degrees: column 0 gains the 1e-4 deg sliver below
                // 360 - w/2, the last column loses it.
                let shift = 360.0 - WRAP_DEG;
                let lo = if j == 0 {
                    -0.5 * w - shift
                } else {
                    (j as f64 - 0.5) * w
                };
                let hi = if j == n - 1 {
                    (j as f64 + 0.5) * w - shift
                } else {
                    (j as f64 + 0.5) * w
                };
                let azi = (lo + (hi - lo) * v).to_radians();
                let c = (1.0 - z * z).max(0.0).sqrt();
                [c * azi.sin(), c * azi.cos(), z]
            }
        }
    }
}

/// Unit vector from altitude and azimuth east of north (gendaymtx's `vector` macro).
pub fn direction(alt: f64, azi: f64) -> [f64; 3] {
    let c = alt.cos();
    [c * azi.sin(), c * azi.cos(), alt.sin()]
}
