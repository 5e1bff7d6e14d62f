//! Annual (climate-based) daylight metrics of one sensor and of the room.
//!
//! Definitions (seed = the dissertation in `shared/seed`; E = illuminance in lux at one
//! sensor, t = an occupied time step of length dt hours, H = number of occupied steps):
//!
//! - **TAI**, Total Annual Illumination. Per sensor, seed Eq. 4.1: `TAI_g = sum_t E_t`,
//!   in lx·h over the period (we multiply by dt so sub-hourly data also gives lx·h). Room,
//!   seed Eq. 2.2: `TAI = 1/(1000 G) sum_i sum_j E_ij`, in klx·h: the grid mean of Eq. 4.1
//!   divided by 1000. We report the per-sensor value in klx·h (`TAI_klxh` = Eq. 4.1 / 1000)
//!   so that the room row, the mean over sensors, *is* Eq. 2.2. "Per year" only when the
//!   weather covers a year: nothing is annualised.
//! - **UDI**, Useful Daylight Illuminance (Mardaljevic et al. 2012), percent of occupied
//!   time in four bins split at `low` (100), `mid` (300) and `high` (3000 lx):
//!   UDI-n (fell short) `E < low`, UDI-s (supplementary) `low <= E < mid`, UDI-a
//!   (autonomous) `mid <= E <= high`, UDI-e (exceeded) `E > high`; they sum to 100. The
//!   seed's chapters 3-5 use three bins at 300 and 3000 lx ("insufficient" UDI_i, UDI_a,
//!   UDI_e; chapter 5 calls the first one UDI_n): that bin is our UDI-n + UDI-s, or set
//!   `low = mid` (`--udi 300,300,3000`) and UDI-s stays empty.
//! - **DA**, Daylight Autonomy: percent of occupied time with `E >= da` (300 lx).
//! - **sDA**, spatial Daylight Autonomy (seed section 4.3.5, IES LM-83): percent of sensors
//!   whose DA is at least `sda_fraction` (50 %), i.e. `DA >= 50` with both boundaries
//!   included ("at least 300 lx for at least 50 % of occupied hours"). Sensors stand for
//!   equal floor areas (a regular grid); per sensor we report 100 (passes) or 0, so the room
//!   mean is sDA.
//! - **ASE**, Annual Sunlight Exposure (seed section 4.3.5, LM-83): percent of sensors where
//!   the *direct-sun-only* illuminance exceeds `ase_lux` (1000 lx, strictly) for more than
//!   `ase_hours` (250 h, strictly) of the occupied steps. It needs a separate direct-sun
//!   matrix (e.g. `-ab 0` coefficients times a sun-only sky, `gendaymtx -d`); the total
//!   illuminance would count skylight and inter-reflections as sun. Per sensor we report the
//!   sunlit hours `ASE_h` and 100/0 for passing; the room mean is ASE. Without the direct
//!   matrix there is no ASE at all (never a zero).
//!
//! Every percentage is over the occupied steps; a schedule with no occupied step is an error
//! (the percentages would be 0/0).

use serde::Serialize;

/// Thresholds, with the defaults of the seed and LEED v4 / IES LM-83.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Thresholds {
    /// UDI lower bound (lx): below it UDI-n.
    pub udi_low: f64,
    /// UDI middle bound (lx): between low and it UDI-s, from it UDI-a.
    pub udi_mid: f64,
    /// UDI upper bound (lx): above it UDI-e.
    pub udi_high: f64,
    /// DA threshold (lx).
    pub da: f64,
    /// sDA: a sensor passes when DA >= this percentage.
    pub sda_percent: f64,
    /// ASE direct-sun threshold (lx, exceeded strictly).
    pub ase_lux: f64,
    /// ASE hour count (exceeded strictly).
    pub ase_hours: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            udi_low: 100.0,
            udi_mid: 300.0,
            udi_high: 3000.0,
            da: 300.0,
            sda_percent: 50.0,
            ase_lux: 1000.0,
            ase_hours: 250.0,
        }
    }
}

impl Thresholds {
    /// Check the thresholds are ordered and finite.
    pub fn check(&self) -> crate::Result<()> {
        let t = self;
        let ok = [
            t.udi_low,
            t.udi_mid,
            t.udi_high,
            t.da,
            t.ase_lux,
            t.ase_hours,
        ]
        .iter()
        .all(|v| v.is_finite() && *v >= 0.0)
            && t.udi_low <= t.udi_mid
            && t.udi_mid <= t.udi_high
            && (0.0..=100.0).contains(&t.sda_percent);
        if ok {
            Ok(())
        } else {
            Err(crate::Error::Usage(format!(
                "thresholds must be finite, >= 0 and ordered (UDI {} <= {} <= {}, sDA {} % in \
                 0-100)",
                t.udi_low, t.udi_mid, t.udi_high, t.sda_percent
            )))
        }
    }
}

/// Metrics of one sensor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorMetrics {
    /// Eq. 4.1 / 1000: klx·h over the occupied steps.
    #[serde(rename = "TAI_klxh")]
    pub tai_klxh: f64,
    #[serde(rename = "UDI_n")]
    pub udi_n: f64,
    #[serde(rename = "UDI_s")]
    pub udi_s: f64,
    #[serde(rename = "UDI_a")]
    pub udi_a: f64,
    #[serde(rename = "UDI_e")]
    pub udi_e: f64,
    /// Percent of occupied time at or above the DA threshold.
    #[serde(rename = "DA")]
    pub da: f64,
    /// 100 when DA >= the sDA percentage, else 0.
    #[serde(rename = "sDA")]
    pub sda: f64,
    /// Occupied hours with direct-sun illuminance above the ASE threshold.
    #[serde(rename = "ASE_h", skip_serializing_if = "Option::is_none")]
    pub ase_h: Option<f64>,
    /// 100 when `ase_h` exceeds the ASE hours, else 0.
    #[serde(rename = "ASE", skip_serializing_if = "Option::is_none")]
    pub ase: Option<f64>,
}

/// Column names in output order (ASE columns only with a direct-sun matrix).
pub fn column_names(with_ase: bool) -> Vec<&'static str> {
    let mut v = vec!["TAI_klxh", "UDI_n", "UDI_s", "UDI_a", "UDI_e", "DA", "sDA"];
    if with_ase {
        v.extend(["ASE_h", "ASE"]);
    }
    v
}

impl SensorMetrics {
    /// Values in [`column_names`] order.
    pub fn values(&self) -> Vec<f64> {
        let mut v = vec![
            self.tai_klxh,
            self.udi_n,
            self.udi_s,
            self.udi_a,
            self.udi_e,
            self.da,
            self.sda,
        ];
        if let (Some(h), Some(a)) = (self.ase_h, self.ase) {
            v.extend([h, a]);
        }
        v
    }
}

/// Metrics of one sensor from its illuminance row (lux, one value per column), the
/// occupancy flags, the step length, and optionally its direct-sun row.
///
/// Callers guarantee equal lengths and at least one occupied step.
pub fn sensor_metrics(
    lux: &[f64],
    direct: Option<&[f64]>,
    occupied: &[bool],
    step_hours: f64,
    t: &Thresholds,
) -> SensorMetrics {
    let mut n = 0usize;
    let (mut sum, mut un, mut us, mut ua, mut ue, mut da, mut sun) = (0.0, 0, 0, 0, 0, 0, 0);
    for (j, (&e, &occ)) in lux.iter().zip(occupied).enumerate() {
        if !occ {
            continue;
        }
        n += 1;
        sum += e;
        if e < t.udi_low {
            un += 1;
        } else if e < t.udi_mid {
            us += 1;
        } else if e <= t.udi_high {
            ua += 1;
        } else {
            ue += 1;
        }
        if e >= t.da {
            da += 1;
        }
        if let Some(d) = direct {
            if d.get(j).is_some_and(|&v| v > t.ase_lux) {
                sun += 1;
            }
        }
    }
    let pct = |k: usize| {
        if n == 0 {
            f64::NAN
        } else {
            100.0 * k as f64 / n as f64
        }
    };
    let da_pct = pct(da);
    let ase_h = direct.map(|_| sun as f64 * step_hours);
    SensorMetrics {
        tai_klxh: sum * step_hours / 1000.0,
        udi_n: pct(un),
        udi_s: pct(us),
        udi_a: pct(ua),
        udi_e: pct(ue),
        da: da_pct,
        sda: if da_pct >= t.sda_percent { 100.0 } else { 0.0 },
        ase_h,
        ase: ase_h.map(|h| if h > t.ase_hours { 100.0 } else { 0.0 }),
    }
}

/// Room values: the mean over sensors of every column. For `TAI_klxh` that is Eq. 2.2, for
/// `sDA` and `ASE` the share of passing sensors in percent.
pub fn room_means(sensors: &[SensorMetrics]) -> Vec<f64> {
    let Some(first) = sensors.first() else {
        return Vec::new();
    };
    let mut acc = vec![0.0; first.values().len()];
    for s in sensors {
        for (a, v) in acc.iter_mut().zip(s.values()) {
            *a += v;
        }
    }
    acc.iter().map(|a| a / sensors.len() as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: Thresholds = Thresholds {
        udi_low: 100.0,
        udi_mid: 300.0,
        udi_high: 3000.0,
        da: 300.0,
        sda_percent: 50.0,
        ase_lux: 1000.0,
        ase_hours: 250.0,
    };

    #[test]
    fn bins_and_boundaries_by_hand() {
        // 10 steps, the last 2 unoccupied (their values must not count).
        let lux = [
            0.0, 99.9, 100.0, 299.9, 300.0, 3000.0, 3000.1, 5000.0, 1e6, 1e6,
        ];
        let mut occ = [true; 10];
        occ[8] = false;
        occ[9] = false;
        let m = sensor_metrics(&lux, None, &occ, 1.0, &T);
        // n: 0, 99.9; s: 100, 299.9; a: 300, 3000; e: 3000.1, 5000 -> 25 % each.
        assert_eq!(
            (m.udi_n, m.udi_s, m.udi_a, m.udi_e),
            (25.0, 25.0, 25.0, 25.0)
        );
        // DA: 300 counts (>=): 300, 3000, 3000.1, 5000 -> 4 of 8.
        assert_eq!(m.da, 50.0);
        // exactly 50 % passes sDA.
        assert_eq!(m.sda, 100.0);
        let sum: f64 = lux[..8].iter().sum();
        assert!((m.tai_klxh - sum / 1000.0).abs() < 1e-12);
        assert_eq!(m.ase, None);
        assert_eq!(m.ase_h, None);
    }

    #[test]
    fn ase_counts_strictly_above_both_thresholds() {
        let occ = vec![true; 600];
        let mut direct = vec![0.0; 600];
        for d in direct.iter_mut().take(250) {
            *d = 1000.1;
        }
        direct[250] = 1000.0; // not above 1000 lx
        let lux = vec![500.0; 600];
        let m = sensor_metrics(&lux, Some(&direct), &occ, 1.0, &T);
        assert_eq!(m.ase_h, Some(250.0));
        assert_eq!(m.ase, Some(0.0), "250 h is not more than 250 h");
        direct[250] = 1000.1;
        let m = sensor_metrics(&lux, Some(&direct), &occ, 1.0, &T);
        assert_eq!((m.ase_h, m.ase), (Some(251.0), Some(100.0)));
        // Half-hour steps halve the hours.
        let m = sensor_metrics(&lux, Some(&direct), &occ, 0.5, &T);
        assert_eq!((m.ase_h, m.ase), (Some(125.5), Some(0.0)));
    }

    #[test]
    fn room_row_is_eq_2_2_and_sensor_shares() {
        let occ = [true; 4];
        let a = sensor_metrics(&[100.0, 200.0, 300.0, 400.0], None, &occ, 1.0, &T);
        let b = sensor_metrics(&[1000.0; 4], None, &occ, 1.0, &T);
        let c = sensor_metrics(&[0.0; 4], None, &occ, 1.0, &T);
        let room = room_means(&[a.clone(), b, c]);
        // Eq. 2.2: (1000 + 4000 + 0) / (1000 * 3) klx·h.
        assert!((room[0] - 5000.0 / 3000.0).abs() < 1e-12);
        // DA of a is 50 % (300 and 400): passes; b passes; c fails -> sDA 66.7 %.
        assert_eq!(a.da, 50.0);
        assert!((room[6] - 200.0 / 3.0).abs() < 1e-12);
        assert!(room_means(&[]).is_empty());
    }

    #[test]
    fn bad_thresholds_are_refused() {
        let mut t = T;
        assert!(t.check().is_ok());
        t.udi_low = 400.0;
        assert!(t.check().is_err());
    }
}
