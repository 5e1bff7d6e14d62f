//! # The seam between the driver and the tracer: [`Estimator`]
//!
//! The driver ([`super::run`]) owns everything around the light transport: reading records,
//! seeding one random stream per record, batching samples, deciding when a record has
//! converged (`--target-se`), binning and writing. An [`Estimator`] owns the light transport
//! and nothing else: asked for ONE sample of one record ([`Query`]) in one [`Mode`], it adds
//! that sample's contributions to a [`Tally`], column by column.
//!
//! ```text
//! record value (column c, channel k) = (1/N) sum over samples s of  x_s[c][k]
//! ```
//!
//! so an estimator only has to produce unbiased single-sample contributions `x_s`; the mean,
//! its sample variance and the stopping rule are the driver's. This is the `-ad` sampling of
//! `rcontrib -I+` (one hemisphere sample per ambient division) written as a plain Monte Carlo
//! average: `-ad N` means N samples per record and batch.
//!
//! Statistics: besides the channel sums, a [`Tally`] keeps per column the sum of squares of
//! each sample's scalar contribution `y_s[c] = sum_k w_k x_s[c][k]` (`w` = photopic weights
//! for RGB, equal weights otherwise), so the standard error of every column is known:
//! `SE[c]^2 = (sum y^2 - N mean^2) / (N (N - 1))`. A record's relative standard error is the
//! RMS of its columns' SEs over the mean of its columns' values ([`Tally::relative_se`]); for
//! a one-column record (a point-in-time value) that is the ordinary relative SE.
//!
//! The implementation is [`super::traced::Traced`], the path tracer of `crate::trace`
//! behind this trait; a scene without surfaces is its analytic special case (each
//! coefficient of an upward sensor is its patch's projected solid angle, the row sums to
//! pi), which the tests compare with and with real rcontrib/rtrace.

use crate::geometry::vec3::normalized;
use crate::sky::SkyPatches;
use crate::trace::reweight::{Signature, TermTally};
use rand::Rng as _;
use std::f64::consts::PI;

/// The random number generator of one record: a PCG-64 stream derived from (seed, record).
pub type Rng = rand_pcg::Pcg64;

/// A record's generator, a pure function of the seed and the record's index so that the
/// output does not depend on how records are spread over threads. The state is spread with
/// SplitMix64 (Steele et al. 2014) because PCG streams that share a state are correlated.
pub fn record_rng(seed: u64, index: u64) -> Rng {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let a = mix(seed ^ mix(index));
    let b = mix(a ^ 0x5851_f42d_4c95_7f2d);
    let state = (u128::from(a) << 64) | u128::from(b);
    Rng::new(state, u128::from(index) << 1 | 1)
}

/// The generator of chunk `chunk` of record `index` ([`super::run::Job::compute`] cuts a
/// record's samples into chunks): chunk 0 is [`record_rng`]`(seed, index)` itself, so a
/// record of one chunk draws exactly what it drew before records were cut; the others are
/// spread from (seed, index, chunk) with SplitMix64 like it.
pub fn chunk_rng(seed: u64, index: u64, chunk: u64) -> Rng {
    if chunk == 0 {
        return record_rng(seed, index);
    }
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let a = mix(seed ^ mix(index ^ mix(chunk ^ 0x243f_6a88_85a3_08d3)));
    let b = mix(a ^ 0x1319_8a2e_0370_7344);
    let state = (u128::from(a) << 64) | u128::from(b);
    Rng::new(state, u128::from(index) << 1 | 1)
}

/// What a record measures at its ray.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Irradiance on a surface at the origin facing the direction (`-I`, rcontrib `-I+`).
    Irradiance,
    /// Radiance arriving along the ray (plain rtrace/rcontrib rays, picture pixels).
    Radiance,
}

/// One record's ray: a sensor (origin, normal) or a view ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Query {
    pub org: [f64; 3],
    /// Unit direction (sensor normal, or view direction).
    pub dir: [f64; 3],
    pub quantity: Quantity,
}

/// One sun of a sun-coefficient run: a disc of unit radiance toward `dir`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunDisc {
    pub dir: [f64; 3],
    /// Cosine of the disc's half angle.
    pub cos_half: f64,
    /// Solid angle `2 pi (1 - cos_half)`.
    pub solid_angle: f64,
}

impl SunDisc {
    /// A disc of full apex angle `angle_deg` (Radiance `source` convention) toward `dir`.
    pub fn new(dir: [f64; 3], angle_deg: f64) -> SunDisc {
        let cos_half = (angle_deg.to_radians() * 0.5).cos();
        SunDisc {
            dir: normalized(dir),
            cos_half,
            solid_angle: 2.0 * PI * (1.0 - cos_half),
        }
    }
}

/// What the columns of a record are.
#[derive(Debug, Clone, Copy)]
pub enum Mode<'a> {
    /// Sky coefficients: column `i` is patch `i` of `patches` (0 = ground), each patch a
    /// unit-radiance emitter (rcontrib `-V-` coefficients with `reinhart.cal`'s `rbin`).
    /// `direct_only`: only light that reaches the sensor straight from the sky, no
    /// inter-reflection (`C_dcd`, Radiance's `-ab 1` for a glow sky).
    Sky {
        patches: &'a SkyPatches,
        direct_only: bool,
        /// Columns `len..2 len`: escapes below the horizon binned by their mirror image
        /// (z -> -z), the lower hemisphere resolved as the sky ([`crate::rdc::Target::Sky`]).
        below_horizon: bool,
    },
    /// Sun coefficients: column `i` is the unit-radiance disc `suns[i]`, seen directly, or
    /// with `bounces` also through every inter-reflection up to `-ab` (`--suns-ab`).
    Suns { suns: &'a [SunDisc], bounces: bool },
    /// Point-in-time values under the scene's own sky and suns
    /// ([`crate::trace::sources`]): one column.
    Values,
    /// Flux transfer (`--flux`, [`crate::rdc::flux`]): every path that ends on a receiver
    /// surface or escapes into a receiver source counts its throughput in the receiver's
    /// bin for its direction.
    Flux {
        receivers: &'a crate::rdc::flux::Receivers,
    },
}

impl Mode<'_> {
    /// Number of columns of every record.
    pub fn ncols(&self) -> usize {
        match self {
            Mode::Sky {
                patches,
                below_horizon,
                ..
            } => patches.len() * if *below_horizon { 2 } else { 1 },
            Mode::Suns { suns, .. } => suns.len(),
            Mode::Values => 1,
            Mode::Flux { receivers } => receivers.ncols(),
        }
    }
}

/// The light transport behind the driver. `Sync`: one estimator serves every thread.
pub trait Estimator: Sync {
    /// Count `n` rays cast for a finished record (the samples count theirs in their
    /// [`Tally`], so threads do not share a counter per sample).
    fn add_rays(&self, _n: u64) {}

    /// Trace ONE sample of record `query` and add its contributions with [`Tally::add`]
    /// (any number of calls, any columns, each `ncomp` values). The driver closes the sample
    /// ([`Tally::end_sample`]) afterwards; adding nothing is a zero sample. `stratum` is the
    /// sample's index in its batch of `-ad` samples, for stratified first bounces (as
    /// Radiance stratifies its ambient hemisphere).
    fn sample(
        &self,
        query: &Query,
        mode: &Mode,
        stratum: Stratum,
        rng: &mut Rng,
        tally: &mut Tally,
    );
}

/// Sample `index` of a batch of `count` (`-ad`) samples of one record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stratum {
    pub index: usize,
    pub count: usize,
}

impl Stratum {
    /// A point of the unit square: jittered on an `m x m` grid (`m = floor(sqrt(count))`)
    /// for the first `m^2` samples of a batch, uniform for the rest.
    pub fn unit_square(&self, rng: &mut Rng) -> (f64, f64) {
        let (a, b): (f64, f64) = (rng.random(), rng.random());
        let m = (self.count as f64).sqrt().floor() as usize;
        if self.index < m * m {
            let (i, j) = (self.index / m, self.index % m);
            ((i as f64 + a) / m as f64, (j as f64 + b) / m as f64)
        } else {
            (a, b)
        }
    }
}

/// Per-record accumulators: channel sums per column and, per column, the sum of squared
/// per-sample scalar contributions (for the standard error).
#[derive(Debug, Clone)]
pub struct Tally {
    ncols: usize,
    ncomp: usize,
    weights: Vec<f64>,
    sum: Vec<f64>,
    sumsq: Vec<f64>,
    /// Scalar contribution of the open sample to each column, and the columns it touched.
    open: Vec<f64>,
    touched: Vec<usize>,
    samples: u64,
    /// Sum of squares of each sample's row total (all columns' scalars): the standard
    /// error of the row sum, e.g. a sensor under a uniform sky ([`Tally::row_relative_se`]).
    row_sumsq: f64,
    /// Re-weighting terms per (column, signature), when the run records them.
    terms: Option<TermTally>,
    /// Rays cast ([`Tally::rays`]).
    rays: u64,
}

impl Tally {
    /// Accumulators for `ncols` columns of `ncomp` channels; `weights` (length `ncomp`) turn a
    /// contribution into the scalar whose variance is tracked.
    pub fn new(ncols: usize, ncomp: usize, weights: &[f64]) -> Tally {
        Tally {
            ncols,
            ncomp,
            weights: weights.to_vec(),
            sum: vec![0.0; ncols * ncomp],
            sumsq: vec![0.0; ncols],
            open: vec![0.0; ncols],
            touched: Vec::new(),
            samples: 0,
            row_sumsq: 0.0,
            terms: None,
            rays: 0,
        }
    }

    /// Also keep re-weighting terms ([`Tally::add_term`], [`crate::trace::reweight`]).
    pub fn with_terms(mut self) -> Tally {
        self.terms = Some(TermTally::default());
        self
    }

    /// Whether re-weighting terms are kept.
    pub fn keeps_terms(&self) -> bool {
        self.terms.is_some()
    }

    /// [`Tally::add`] for a contribution whose path had signature `sig`: the same sums,
    /// plus the per-signature term when terms are kept.
    pub fn add_term(&mut self, col: usize, sig: Signature, value: &[f64]) {
        if col >= self.ncols {
            return;
        }
        self.add(col, value);
        if let Some(t) = &mut self.terms {
            t.add(col as u32, sig, value);
        }
    }

    /// The record's re-weighting terms (means over the samples so far), sorted; empty when
    /// terms are not kept.
    pub fn terms(&self) -> Vec<(u32, Signature, Vec<f64>)> {
        match &self.terms {
            Some(t) => t.terms(self.ncomp, self.samples),
            None => Vec::new(),
        }
    }

    /// A zeroed tally of the same shape and weights (keeping terms if this one does).
    pub fn empty_like(&self) -> Tally {
        let t = Tally::new(self.ncols, self.ncomp, &self.weights);
        if self.terms.is_some() {
            t.with_terms()
        } else {
            t
        }
    }

    /// Add the closed samples of `other` (same shape) to this tally: the result is the tally
    /// of both sets of samples (sums, sums of squares, counts, terms).
    pub fn merge(&mut self, other: &Tally) {
        for (a, b) in self.sum.iter_mut().zip(&other.sum) {
            *a += b;
        }
        for (a, b) in self.sumsq.iter_mut().zip(&other.sumsq) {
            *a += b;
        }
        self.samples += other.samples;
        self.row_sumsq += other.row_sumsq;
        self.rays += other.rays;
        if let (Some(a), Some(b)) = (&mut self.terms, &other.terms) {
            a.merge(b);
        }
    }

    /// Rays cast for this tally's samples (closest-hit and shadow queries of paths).
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Count `n` more rays ([`Tally::rays`]).
    pub fn add_rays(&mut self, n: u64) {
        self.rays += n;
    }

    /// Forget everything (next record).
    pub fn clear(&mut self) {
        self.sum.iter_mut().for_each(|v| *v = 0.0);
        self.sumsq.iter_mut().for_each(|v| *v = 0.0);
        for &c in &self.touched {
            self.open[c] = 0.0;
        }
        self.touched.clear();
        self.samples = 0;
        self.row_sumsq = 0.0;
        self.rays = 0;
        if let Some(t) = &mut self.terms {
            t.clear();
        }
    }

    pub fn ncols(&self) -> usize {
        self.ncols
    }

    pub fn ncomp(&self) -> usize {
        self.ncomp
    }

    /// Add a contribution of the open sample to column `col` (`value.len() == ncomp`; a
    /// column out of range is ignored, as rcontrib ignores bins `>= -bn`).
    pub fn add(&mut self, col: usize, value: &[f64]) {
        if col >= self.ncols {
            return;
        }
        let base = col * self.ncomp;
        let mut y = 0.0;
        for (k, (&v, &w)) in value.iter().zip(&self.weights).enumerate() {
            self.sum[base + k] += v;
            y += w * v;
        }
        if self.open[col] == 0.0 && !self.touched.contains(&col) {
            self.touched.push(col);
        }
        self.open[col] += y;
    }

    /// Add the same contribution `value` to every channel of column `col`.
    pub fn add_grey(&mut self, col: usize, value: f64) {
        if col >= self.ncols {
            return;
        }
        let base = col * self.ncomp;
        for k in 0..self.ncomp {
            self.sum[base + k] += value;
        }
        let y = value * self.weights.iter().sum::<f64>();
        if self.open[col] == 0.0 && !self.touched.contains(&col) {
            self.touched.push(col);
        }
        self.open[col] += y;
    }

    /// Close the open sample.
    pub fn end_sample(&mut self) {
        let mut row = 0.0;
        for &c in &self.touched {
            self.sumsq[c] += self.open[c] * self.open[c];
            row += self.open[c];
            self.open[c] = 0.0;
        }
        self.row_sumsq += row * row;
        self.touched.clear();
        self.samples += 1;
    }

    /// Samples closed so far.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// The record's values: channel means per column, into `out` (`ncols * ncomp`).
    pub fn mean_into(&self, out: &mut [f64]) {
        let n = self.samples.max(1) as f64;
        for (o, s) in out.iter_mut().zip(&self.sum) {
            *o = s / n;
        }
    }

    /// Standard error of column `c`'s scalar mean (0 with fewer than 2 samples).
    pub fn column_se(&self, c: usize) -> f64 {
        if self.samples < 2 || c >= self.ncols {
            return 0.0;
        }
        let n = self.samples as f64;
        let mean = self.column_scalar_mean(c);
        ((self.sumsq[c] - n * mean * mean).max(0.0) / (n * (n - 1.0))).sqrt()
    }

    fn column_scalar_mean(&self, c: usize) -> f64 {
        let n = self.samples.max(1) as f64;
        let base = c * self.ncomp;
        self.sum[base..base + self.ncomp]
            .iter()
            .zip(&self.weights)
            .map(|(s, w)| s * w)
            .sum::<f64>()
            / n
    }

    /// Relative standard error of the record's row sum (the scalar summed over columns):
    /// for sky coefficients the error of the sensor's value under a uniform sky, which
    /// is what a weighted sum over many patches inherits, where each column's own error
    /// is large. 0 for a zero record, infinite with fewer than 2 samples.
    pub fn row_relative_se(&self) -> f64 {
        if self.samples < 2 {
            return f64::INFINITY;
        }
        let n = self.samples as f64;
        let mean = (0..self.ncols)
            .map(|c| self.column_scalar_mean(c))
            .sum::<f64>();
        if mean.abs() <= f64::MIN_POSITIVE {
            return 0.0;
        }
        ((self.row_sumsq - n * mean * mean).max(0.0) / (n * (n - 1.0))).sqrt() / mean.abs()
    }

    /// Relative standard error of the record: RMS of the column SEs over the mean column
    /// value. 0 for a record that is zero everywhere (nothing to refine), infinite with
    /// fewer than 2 samples.
    pub fn relative_se(&self) -> f64 {
        if self.samples < 2 {
            return f64::INFINITY;
        }
        let nc = self.ncols.max(1) as f64;
        let mean = (0..self.ncols)
            .map(|c| self.column_scalar_mean(c))
            .sum::<f64>()
            / nc;
        let ms = (0..self.ncols)
            .map(|c| self.column_se(c).powi(2))
            .sum::<f64>()
            / nc;
        if mean.abs() <= f64::MIN_POSITIVE {
            0.0
        } else {
            ms.sqrt() / mean.abs()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_are_unit_and_above_the_surface() {
        use crate::geometry::vec3::dot;
        use crate::material::sampling::cosine_hemisphere;
        let mut rng = record_rng(1, 2);
        let n = normalized([0.3, -0.5, 0.8]);
        let mut mean_cos = 0.0;
        let k = 20000;
        for _ in 0..k {
            let d = cosine_hemisphere(n, rng.random(), rng.random());
            assert!((dot(d, d) - 1.0).abs() < 1e-12);
            assert!(dot(d, n) >= -1e-12);
            mean_cos += dot(d, n);
        }
        // E[cos] under cos/pi density = 2/3; sd of cos is sqrt(1/2 - 4/9) = 0.236.
        mean_cos /= k as f64;
        assert!((mean_cos - 2.0 / 3.0).abs() < 5.0 * 0.236 / (k as f64).sqrt());
    }

    #[test]
    fn streams_depend_only_on_seed_and_index() {
        let a: f64 = record_rng(7, 3).random();
        let b: f64 = record_rng(7, 3).random();
        let c: f64 = record_rng(7, 4).random();
        let d: f64 = record_rng(8, 3).random();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(a, d);
    }

    #[test]
    fn tally_standard_error_matches_the_textbook_formula() {
        let mut t = Tally::new(2, 1, &[1.0]);
        let xs = [1.0, 2.0, 4.0, 7.0];
        for &x in &xs {
            t.add(0, &[x]);
            t.add(0, &[x]); // two adds in one sample count as one sample of 2x
            t.end_sample();
        }
        let n = xs.len() as f64;
        let ys: Vec<f64> = xs.iter().map(|x| 2.0 * x).collect();
        let m = ys.iter().sum::<f64>() / n;
        let var = ys.iter().map(|y| (y - m).powi(2)).sum::<f64>() / (n - 1.0);
        assert!((t.column_se(0) - (var / n).sqrt()).abs() < 1e-12);
        assert_eq!(t.column_se(1), 0.0);
        let mut out = [0.0; 2];
        t.mean_into(&mut out);
        assert_eq!(out, [m, 0.0]);
    }
}
