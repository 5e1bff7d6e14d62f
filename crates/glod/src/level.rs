//! The five Geometrical Levels of Detail and their OBB-area thresholds.
//!
//! Seed section 2.3.1: GLoD0 holds the permanent shell only (walls, floor, ceiling, windows);
//! GLoD1, GLoD2 and GLoD3 add the non-permanent objects whose OBB surface area is at least
//! 3.0, 2.4 and 0.5 m2, the 75th, 50th and 25th percentiles of the object-size distribution
//! over the seed's nine spaces (Fig. 2.2); GLoD4 holds everything. "An object with OBB size of
//! 2.2 m2 appears in GLoDs 3 and 4, but not in 2, 1, and 0": an object's level is the lowest
//! GLoD that contains it, and a level contains every object of a lower level.

use rdaylight_base::{Error, Result, stats};
use serde::Serialize;

/// Relative rounding allowance when an area is compared with a threshold (1e-9: far below
/// any modelling precision, far above the OBB's floating-point rounding).
pub const AREA_RTOL: f64 = 1e-9;

/// The highest level (complete geometry).
pub const MAX_LEVEL: u8 = 4;

/// Minimum OBB areas (m2) for GLoD1, GLoD2 and GLoD3.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Thresholds {
    pub glod1: f64,
    pub glod2: f64,
    pub glod3: f64,
}

impl Default for Thresholds {
    /// The seed's thresholds (section 2.3.1): 3.0, 2.4 and 0.5 m2.
    fn default() -> Self {
        Thresholds {
            glod1: 3.0,
            glod2: 2.4,
            glod3: 0.5,
        }
    }
}

impl Thresholds {
    /// Thresholds must be finite, non-negative and non-increasing from GLoD1 to GLoD3 (each
    /// level must contain the one below it).
    pub fn validate(&self) -> Result<()> {
        let t = [self.glod1, self.glod2, self.glod3];
        if t.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(Error::Usage(format!(
                "--thresholds {},{},{}: areas must be finite and >= 0 m2",
                t[0], t[1], t[2]
            )));
        }
        if !(t[0] >= t[1] && t[1] >= t[2]) {
            return Err(Error::Usage(format!(
                "--thresholds {},{},{}: give GLoD1 >= GLoD2 >= GLoD3 (e.g. 3.0,2.4,0.5)",
                t[0], t[1], t[2]
            )));
        }
        Ok(())
    }

    /// The lowest GLoD (1..=4) that contains a non-permanent object of OBB area `area`.
    /// Comparisons are `>=`: an object exactly at a threshold belongs to that level. "Exactly"
    /// allows [`AREA_RTOL`]: a box found along a rotated axis carries rounding of a few ulps,
    /// and a 1.5 x 1 m desk top must not drop below 3.0 m2 by 4e-16.
    pub fn level(&self, area: f64) -> u8 {
        let reaches = |t: f64| area >= t * (1.0 - AREA_RTOL);
        if reaches(self.glod1) {
            1
        } else if reaches(self.glod2) {
            2
        } else if reaches(self.glod3) {
            3
        } else {
            4
        }
    }
}

/// Thresholds derived from a sample of OBB areas as the seed derived its own: the 75th, 50th
/// and 25th percentiles (linear interpolation, [`stats::percentile`]). `None` for no finite
/// area.
pub fn percentiles(areas: &[f64]) -> Option<Thresholds> {
    if !areas.iter().any(|a| a.is_finite()) {
        return None;
    }
    Some(Thresholds {
        glod1: stats::percentile(areas, 75.0),
        glod2: stats::percentile(areas, 50.0),
        glod3: stats::percentile(areas, 25.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_at_and_around_the_seed_thresholds() {
        let t = Thresholds::default();
        assert_eq!(t.level(3.0), 1);
        assert_eq!(t.level(2.999_999), 2);
        assert_eq!(t.level(3.0 - 4e-16), 1);
        assert_eq!(t.level(2.4), 2);
        assert_eq!(t.level(2.399_999), 3);
        assert_eq!(t.level(0.5), 3);
        assert_eq!(t.level(0.499_999), 4);
        assert_eq!(t.level(0.0), 4);
        assert_eq!(t.level(100.0), 1);
        // The seed's own example: 2.2 m2 appears in GLoD3 and 4, not in 2, 1 or 0.
        assert_eq!(t.level(2.2), 3);
    }

    #[test]
    fn percentiles_of_a_known_sample() {
        let areas = [0.0, 1.0, 2.0, 3.0, 4.0, f64::NAN];
        let t = percentiles(&areas).unwrap();
        assert_eq!((t.glod1, t.glod2, t.glod3), (3.0, 2.0, 1.0));
        assert!(t.validate().is_ok());
        assert!(percentiles(&[]).is_none());
    }

    #[test]
    fn thresholds_out_of_order_are_refused_with_the_fix() {
        let bad = Thresholds {
            glod1: 0.5,
            glod2: 2.4,
            glod3: 3.0,
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("GLoD1 >= GLoD2 >= GLoD3"), "{e}");
    }
}
