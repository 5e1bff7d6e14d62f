//! # The Klems hemisphere bases (full, half, quarter)
//!
//! Klems (1994, "A new method for predicting the solar heat gain of complex fenestration
//! systems", ASHRAE Trans. 100(1)) cuts a hemisphere into rings of polar angle, each ring
//! into patches of equal azimuth width. LBNL WINDOW's BSDF XML files, Radiance's `BSDF`
//! material, `rfluxmtx -c`/`#@rfluxmtx h=kf|kh|kq` and `dctimestep`'s 3-phase matrices all
//! index directions by these patches. The rings are published facts (WINDOW 6 XML
//! `<AngleBasis>` blocks; Radiance `lib/klems_full.cal`, `klems_half.cal`,
//! `klems_quarter.cal`):
//!
//! | basis | ring upper bounds (deg) | patches per ring | total |
//! |---|---|---|---|
//! | full (`kf`) | 5 15 25 35 45 55 65 75 90 | 1 8 16 20 24 24 24 16 12 | 145 |
//! | half (`kh`) | 6.5 19.5 32.5 46.5 61.5 76.5 90 | 1 8 12 16 20 12 4 | 73 |
//! | quarter (`kq`) | 9 27 46 66 90 | 1 8 12 12 8 | 41 |
//!
//! ## Local frame (as `klems_*.cal`'s `kbin(N, U)` builds it)
//! A patch is found for the direction `v` pointing *away* from the surface (for a ray
//! arriving with direction `D`, `v = -D`). With the surface normal `N` and the "up" vector
//! `U`: polar angle `acos(v . N)`; azimuth `atan2(v . U_perp, v . (U x N))`, i.e. the frame
//! is `x = normalize(U x N)`, `y = N x x` (the part of `U` across `N`), `z = N`, azimuth
//! counted from `x` toward `y` in `[0, 360)`. [`KlemsFrame`] holds those axes; a basis works
//! on local vectors.
//!
//! ## Bins (the `.cal` files' `kfindrow`/`kazn`)
//! Ring `r` is the first whose upper bound is `>= theta`. Patch `j` of a ring of `n` has its
//! centre at azimuth `360 j / n` and covers `[(j - 1/2) w, (j + 1/2) w)`, `w = 360 / n`;
//! azimuths at or beyond `360 - w/2` wrap to patch 0. Indices run over rings from the
//! normal outward, patches in azimuth order within a ring.
//!
//! ## Measures
//! Solid angle of a patch: `2 pi (cos t0 - cos t1) / n`. Projected solid angle ("lambda",
//! the cosine-weighted measure WINDOW and `dctimestep` multiply BSDF values by):
//! `pi (sin^2 t1 - sin^2 t0) / n`; a basis's lambdas sum to `pi`. Patch centres are at the
//! ring's middle polar angle (`0` for the central disc), as WINDOW lists them.

use std::f64::consts::PI;

/// The three standard bases (`#@rfluxmtx h=kf|kh|kq`, WINDOW's "LBNL/Klems Full/Half/
/// Quarter").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KlemsKind {
    Full,
    Half,
    Quarter,
}

impl KlemsKind {
    /// `(ring upper bounds in degrees, patches per ring)` (the table in the module docs).
    pub fn rings(self) -> (&'static [f64], &'static [usize]) {
        match self {
            KlemsKind::Full => (
                &[5., 15., 25., 35., 45., 55., 65., 75., 90.],
                &[1, 8, 16, 20, 24, 24, 24, 16, 12],
            ),
            KlemsKind::Half => (
                &[6.5, 19.5, 32.5, 46.5, 61.5, 76.5, 90.],
                &[1, 8, 12, 16, 20, 12, 4],
            ),
            KlemsKind::Quarter => (&[9., 27., 46., 66., 90.], &[1, 8, 12, 12, 8]),
        }
    }

    /// Rfluxmtx's hemisphere letters (`kf`, `kh`, `kq`).
    pub fn code(self) -> &'static str {
        match self {
            KlemsKind::Full => "kf",
            KlemsKind::Half => "kh",
            KlemsKind::Quarter => "kq",
        }
    }

    /// The name WINDOW's XML uses in `<AngleBasisName>`.
    pub fn window_name(self) -> &'static str {
        match self {
            KlemsKind::Full => "LBNL/Klems Full",
            KlemsKind::Half => "LBNL/Klems Half",
            KlemsKind::Quarter => "LBNL/Klems Quarter",
        }
    }
}

/// A Klems-type hemisphere basis: one of the standard three or any ring layout an XML file
/// defines (`<AngleBasisBlock>`).
#[derive(Debug, Clone, PartialEq)]
pub struct KlemsBasis {
    /// Ring bounds in degrees, `len = rings + 1`, from 0 to 90.
    bounds: Vec<f64>,
    /// Patches per ring.
    nphi: Vec<usize>,
    /// First index of each ring, plus the total at the end.
    start: Vec<usize>,
}

impl KlemsBasis {
    /// One of the standard bases.
    pub fn new(kind: KlemsKind) -> KlemsBasis {
        let (upper, nphi) = kind.rings();
        KlemsBasis::from_rings(upper, nphi).expect("the standard Klems bases are valid")
    }

    /// A basis from ring upper bounds (degrees, increasing, the last 90) and patches per
    /// ring (each >= 1). The error says what is wrong, for the caller to place.
    pub fn from_rings(upper_deg: &[f64], nphi: &[usize]) -> Result<KlemsBasis, String> {
        if upper_deg.is_empty() || upper_deg.len() != nphi.len() {
            return Err(format!(
                "a Klems basis needs as many ring bounds as patch counts (got {} and {})",
                upper_deg.len(),
                nphi.len()
            ));
        }
        let mut bounds = vec![0.0];
        for &b in upper_deg {
            let last = *bounds.last().unwrap_or(&0.0);
            if !(b.is_finite() && b > last && b <= 90.0) {
                return Err(format!(
                    "Klems ring bounds must increase within (0, 90] degrees (got {b} after {last})"
                ));
            }
            bounds.push(b);
        }
        if (bounds[bounds.len() - 1] - 90.0).abs() > 1e-9 {
            return Err("the last Klems ring must end at 90 degrees".to_string());
        }
        if let Some(&n) = nphi.iter().find(|&&n| n == 0 || n > 10_000) {
            return Err(format!(
                "each Klems ring needs 1 to 10000 patches (got {n})"
            ));
        }
        let mut start = vec![0];
        for &n in nphi {
            start.push(start[start.len() - 1] + n);
        }
        Ok(KlemsBasis {
            bounds,
            nphi: nphi.to_vec(),
            start,
        })
    }

    /// The standard basis this one equals, if any.
    pub fn kind(&self) -> Option<KlemsKind> {
        [KlemsKind::Full, KlemsKind::Half, KlemsKind::Quarter]
            .into_iter()
            .find(|&k| {
                let (u, n) = k.rings();
                n == self.nphi.as_slice()
                    && u.iter()
                        .zip(&self.bounds[1..])
                        .all(|(a, b)| (a - b).abs() < 1e-6)
            })
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.start[self.start.len() - 1]
    }

    /// Never true (every ring has a patch); for clippy's `len` rule.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of rings.
    pub fn rings(&self) -> usize {
        self.nphi.len()
    }

    /// `(theta_lo, theta_hi)` of ring `r` in degrees.
    pub fn ring_bounds(&self, r: usize) -> (f64, f64) {
        (self.bounds[r], self.bounds[r + 1])
    }

    /// Patches in ring `r`.
    pub fn ring_len(&self, r: usize) -> usize {
        self.nphi[r]
    }

    /// `(ring, patch within ring)` of index `i < len()`.
    pub fn ring_of(&self, i: usize) -> (usize, usize) {
        let r = self.start.partition_point(|&s| s <= i) - 1;
        (r, i - self.start[r])
    }

    /// The patch of the local direction `v` (unit, `z` along the normal); `None` below the
    /// surface (`v.z < 0`). Boundary rules as `klems_full.cal` (module docs).
    pub fn bin_of(&self, v: [f64; 3]) -> Option<usize> {
        if v[2] < 0.0 {
            return None;
        }
        let theta = v[2].clamp(-1.0, 1.0).acos().to_degrees();
        let r = self.bounds[1..]
            .iter()
            .position(|&b| theta <= b)
            .unwrap_or(self.rings() - 1);
        let mut phi = v[1].atan2(v[0]).to_degrees();
        if phi < 0.0 {
            phi += 360.0;
        }
        let n = self.nphi[r];
        let w = 360.0 / n as f64;
        let j = if phi < 360.0 - 0.5 * w {
            (((phi + 0.5 * w) / w).floor() as usize).min(n - 1)
        } else {
            0
        };
        Some(self.start[r] + j)
    }

    /// `(theta, phi)` of patch `i`'s centre in degrees: the ring's middle polar angle (0 for
    /// the central disc) and azimuth `360 j / n`.
    pub fn centre_angles(&self, i: usize) -> (f64, f64) {
        let (r, j) = self.ring_of(i);
        let theta = if r == 0 && self.bounds[0] == 0.0 && self.nphi[0] == 1 {
            0.0
        } else {
            0.5 * (self.bounds[r] + self.bounds[r + 1])
        };
        (theta, 360.0 * j as f64 / self.nphi[r] as f64)
    }

    /// Patch `i`'s centre as a local unit vector.
    pub fn centre(&self, i: usize) -> [f64; 3] {
        let (t, p) = self.centre_angles(i);
        let (t, p) = (t.to_radians(), p.to_radians());
        [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
    }

    /// Solid angle of patch `i` (sr).
    pub fn solid_angle(&self, i: usize) -> f64 {
        let (r, _) = self.ring_of(i);
        let (t0, t1) = (self.bounds[r].to_radians(), self.bounds[r + 1].to_radians());
        2.0 * PI * (t0.cos() - t1.cos()) / self.nphi[r] as f64
    }

    /// Projected solid angle ("lambda") of patch `i`: `pi (sin^2 t1 - sin^2 t0) / n`.
    pub fn lambda(&self, i: usize) -> f64 {
        let (r, _) = self.ring_of(i);
        let (t0, t1) = (self.bounds[r].to_radians(), self.bounds[r + 1].to_radians());
        PI * (t1.sin().powi(2) - t0.sin().powi(2)) / self.nphi[r] as f64
    }

    /// A cosine-weighted direction within patch `i` from two uniforms in `[0, 1)`: `sin^2
    /// theta` uniform over the ring, azimuth uniform over the patch (pdf `cos theta /
    /// lambda(i)` per steradian). Local vector.
    pub fn sample(&self, i: usize, u: f64, v: f64) -> [f64; 3] {
        let (r, j) = self.ring_of(i);
        let (s0, s1) = (
            self.bounds[r].to_radians().sin().powi(2),
            self.bounds[r + 1].to_radians().sin().powi(2),
        );
        let s2 = s0 + (s1 - s0) * u;
        let n = self.nphi[r] as f64;
        let w = 2.0 * PI / n;
        let phi = if self.nphi[r] == 1 {
            2.0 * PI * v
        } else {
            (j as f64 - 0.5 + v) * w
        };
        let sin_t = s2.max(0.0).sqrt();
        let cos_t = (1.0 - s2).max(0.0).sqrt();
        [sin_t * phi.cos(), sin_t * phi.sin(), cos_t]
    }
}

/// The orthonormal frame `klems_*.cal`'s `kbin(N, U)` uses (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KlemsFrame {
    pub x: [f64; 3],
    pub y: [f64; 3],
    pub z: [f64; 3],
}

impl KlemsFrame {
    /// From the (not necessarily unit) normal and up vector; `None` when they are parallel
    /// or zero.
    pub fn new(normal: [f64; 3], up: [f64; 3]) -> Option<KlemsFrame> {
        use crate::vec3::{cross, dot, normalized};
        let nl = dot(normal, normal).sqrt();
        if nl.is_nan() || nl <= 0.0 {
            return None;
        }
        let z = normalized(normal);
        let ux = cross(up, z);
        let l = dot(ux, ux).sqrt();
        if l.is_nan() || l <= 1e-9 * dot(up, up).sqrt().max(1e-300) {
            return None;
        }
        let x = normalized(ux);
        let y = cross(z, x);
        Some(KlemsFrame { x, y, z })
    }

    /// World vector to local.
    pub fn to_local(&self, v: [f64; 3]) -> [f64; 3] {
        use crate::vec3::dot;
        [dot(v, self.x), dot(v, self.y), dot(v, self.z)]
    }

    /// Local vector to world.
    pub fn to_world(&self, v: [f64; 3]) -> [f64; 3] {
        [
            v[0] * self.x[0] + v[1] * self.y[0] + v[2] * self.z[0],
            v[0] * self.x[1] + v[1] * self.y[1] + v[2] * self.z[1],
            v[0] * self.x[2] + v[1] * self.y[2] + v[2] * self.z[2],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_measures() {
        for (k, n) in [
            (KlemsKind::Full, 145),
            (KlemsKind::Half, 73),
            (KlemsKind::Quarter, 41),
        ] {
            let b = KlemsBasis::new(k);
            assert_eq!(b.len(), n);
            assert_eq!(b.kind(), Some(k));
            let omega: f64 = (0..n).map(|i| b.solid_angle(i)).sum();
            let lambda: f64 = (0..n).map(|i| b.lambda(i)).sum();
            assert!((omega - 2.0 * PI).abs() < 1e-12, "{omega}");
            assert!((lambda - PI).abs() < 1e-12, "{lambda}");
        }
        // WINDOW's full-basis lambda of the central patch: pi sin^2(5 deg) = 0.0238.
        let b = KlemsBasis::new(KlemsKind::Full);
        assert!((b.lambda(0) - 0.023_786).abs() < 1e-5);
    }

    #[test]
    fn centres_and_samples_fall_in_their_own_bins() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for k in [KlemsKind::Full, KlemsKind::Half, KlemsKind::Quarter] {
            let b = KlemsBasis::new(k);
            for i in 0..b.len() {
                assert_eq!(b.bin_of(b.centre(i)), Some(i), "{k:?} centre {i}");
                for _ in 0..20 {
                    let v = b.sample(i, rng.random(), rng.random());
                    assert_eq!(b.bin_of(v), Some(i), "{k:?} sample in {i}");
                    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    assert!((l - 1.0).abs() < 1e-12);
                }
            }
            assert_eq!(b.bin_of([0.0, 0.0, -1.0]), None);
        }
    }

    #[test]
    fn kbin_conventions() {
        // klems_full.cal's kbinS: N = (0, 1, 0) (into the room behind a south window),
        // U = +Z. A ray leaving the room southward, D = (0, -1, 0), has v = -D = N: patch 0;
        // a ray going north has v behind the normal: no patch.
        let f = KlemsFrame::new([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
        let b = KlemsBasis::new(KlemsKind::Full);
        assert_eq!(b.bin_of(f.to_local([0.0, 1.0, 0.0])), Some(0));
        assert_eq!(b.bin_of(f.to_local([0.0, -1.0, 0.0])), None);
        // x = U x N = (0,0,1) x (0,1,0) = (-1,0,0): azimuth 0 points west (-X); y = +Z, so
        // 90 deg is up. v 20 deg off the normal toward +Z: ring 2 (15-25), azimuth 90 deg of
        // 16 patches: patch 4.
        let t = 20f64.to_radians();
        let v = [0.0, t.cos(), t.sin()];
        assert_eq!(b.bin_of(f.to_local(v)), Some(1 + 8 + 4));
        let w = f.to_world(f.to_local(v));
        assert!((w[1] - v[1]).abs() < 1e-12 && (w[2] - v[2]).abs() < 1e-12);
        assert!(KlemsFrame::new([0.0, 0.0, 1.0], [0.0, 0.0, 2.0]).is_none());
    }

    #[test]
    fn bad_rings_are_refused() {
        assert!(KlemsBasis::from_rings(&[5.0, 4.0, 90.0], &[1, 2, 3]).is_err());
        assert!(KlemsBasis::from_rings(&[5.0, 80.0], &[1, 2]).is_err());
        assert!(KlemsBasis::from_rings(&[5.0, 90.0], &[1, 0]).is_err());
        assert!(KlemsBasis::from_rings(&[90.0], &[1, 2]).is_err());
    }
}
