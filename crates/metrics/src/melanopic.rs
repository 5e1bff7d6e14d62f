//! Melanopic quantities from spectral irradiance matrices (CIE S 026:2018).
//!
//! Input: a Radiance matrix of spectral irradiance, rows = sensors, columns = time steps,
//! `NCOMP = N > 3` bands with `WAVELENGTH_SPLITS` (e.g. `rmtx dc18.mtx sky18.smx`, or
//! `rtrace -I -cs 18 -co`). Radiance's channel convention (radiance-notes.md 3.5 and 10.3):
//! a band value is the spectral irradiance times 400 nm, so equal-energy light of 1 W/m2
//! over 380-780 nm is 1 in every band; band `i` holds `E(l) = v_i / 400` W m^-2 nm^-1 over
//! its wavelengths. Then, with the CIE tables of [`crate::colour::cie`] integrated
//! exactly over each band ([`crate::colour::bands::band_integrals`]):
//!
//! ```text
//! Ev     = 683 lm/W sum_i (v_i/400) int_band ybar dl        photopic illuminance (lx), CIE 1931
//! E_mel  = sum_i (v_i/400) int_band s_mel dl                melanopic irradiance (W/m2)
//! m-EDI  = E_mel / K,  K = 1.3262e-3 W/lm                   CIE S 026 eq. 7 (lx)
//! M/P    = m-EDI / Ev                                       melanopic daylight efficacy ratio
//! M_rad  = 179 sum_i v_i (int_band s_mel / int_380^780 s_mel)   Radiance's `-pM`/`rcomb -c M`
//! ```
//!
//! Radiance's `M` normalises the melanopic curve to unit area and uses 179 lm/W, so it is
//! *not* m-EDI; for any spectrum `m-EDI = M_rad x A_mel / (400 K 179)` where
//! `A_mel = int s_mel dl` over 380-780 nm (87.7 nm with these tables): 0.9233 (the
//! conversion of radiance-notes.md 10.3), given by [`radiance_m_to_medi`].
//!
//! Daytime recommendation (Brown et al. 2022, *PLoS Biol.* 20(3): e3001571): m-EDI at
//! least 250 lx at the eye during the day; [`Summary`] counts the steps that reach a
//! threshold per sensor and, with time stamps, the days that pass a [`DailyRule`] (by
//! default: at least 4 hours at or above 250 lx between 8 and 12 h, i.e. the whole
//! morning).

use crate::colour::bands::band_integrals;
use crate::colour::cie::{WL_MAX, WL_MIN, tables};
use crate::colour::melanopic::{K_MEL_D65, KM};
use crate::error::{Error, Result};
use crate::formats::matrix::reader::{MatrixReader, ReadOptions};
use crate::radiometry::Channels;
use crate::schedule::Stamp;
use std::io::BufRead;

/// Radiance's span: band values are spectral irradiance times this (nm).
pub const RADIANCE_SPAN_NM: f64 = 400.0;

/// Brown et al. (2022): recommended minimum daytime m-EDI at the eye (lx).
pub const DAYTIME_MEDI_LX: f64 = 250.0;

/// One spectral value reduced to the photopic and melanopic quantities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Melanopic {
    /// Photopic illuminance (lx), CIE 1931 ybar x 683.
    pub ev: f64,
    /// Melanopic irradiance (W/m2).
    pub e_mel: f64,
    /// Melanopic equivalent daylight (D65) illuminance (lx).
    pub medi: f64,
    /// Radiance's equal-energy normalised melanopic value (`rcomb -c M`).
    pub radiance_m: f64,
}

impl Melanopic {
    /// M/P: m-EDI over illuminance (the melanopic DER); 0 where there is no light.
    pub fn mp(&self) -> f64 {
        if self.ev > 0.0 {
            self.medi / self.ev
        } else {
            0.0
        }
    }
}

/// Per-band weights for one channel layout.
#[derive(Debug, Clone)]
pub struct BandWeights {
    ybar: Vec<f64>,
    smel: Vec<f64>,
    smel_total: f64,
}

/// The factor taking Radiance's `M` to m-EDI (`A_mel / (400 K 179)`, about 0.9233).
pub fn radiance_m_to_medi() -> f64 {
    smel_area() / (RADIANCE_SPAN_NM * K_MEL_D65 * crate::radiometry::WHITE_EFFICACY)
}

fn smel_area() -> f64 {
    let all = Channels::spectral(3, WL_MIN, WL_MAX)
        .map(|c| band_integrals(&tables().melanopic, &c).iter().sum::<f64>());
    all.unwrap_or(0.0)
}

impl BandWeights {
    /// Weights for spectral channels (`ncomp > 3`).
    pub fn new(ch: &Channels) -> Result<BandWeights> {
        if ch.ncomp <= 3 {
            return Err(Error::Mismatch(format!(
                "NCOMP={}: melanopic quantities need spectral bands (NCOMP > 3, e.g. rdc -cs \
                 18 coefficients times rspecsky -cs 18 skies); RGB has no spectrum",
                ch.ncomp
            )));
        }
        let t = tables();
        Ok(BandWeights {
            ybar: band_integrals(&t.cmf[1], ch),
            smel: band_integrals(&t.melanopic, ch),
            smel_total: smel_area(),
        })
    }

    /// Reduce one spectral value (`ncomp` bands, Radiance convention).
    pub fn eval(&self, v: &[f64]) -> Melanopic {
        let dot = |w: &[f64]| v.iter().zip(w).map(|(a, b)| a * b).sum::<f64>();
        let (y, m) = (dot(&self.ybar), dot(&self.smel));
        let e_mel = m / RADIANCE_SPAN_NM;
        Melanopic {
            ev: KM * y / RADIANCE_SPAN_NM,
            e_mel,
            medi: e_mel / K_MEL_D65,
            radiance_m: if self.smel_total > 0.0 {
                crate::radiometry::WHITE_EFFICACY * m / self.smel_total
            } else {
                0.0
            },
        }
    }
}

/// Which number per sensor and step [`convert`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// m-EDI (lx).
    Medi,
    /// Photopic illuminance (lx).
    Ev,
    /// M/P ratio (melanopic DER).
    Mp,
    /// Melanopic irradiance (W/m2).
    Emel,
    /// Radiance's `M` (equal-energy normalised, x 179).
    RadianceM,
}

impl std::str::FromStr for Quantity {
    type Err = String;

    /// The command-line spellings: `medi`, `ev`, `mp`, `emel`, `radiance-m`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Ok(match s {
            "medi" => Quantity::Medi,
            "ev" => Quantity::Ev,
            "mp" => Quantity::Mp,
            "emel" => Quantity::Emel,
            "radiance-m" => Quantity::RadianceM,
            _ => return Err(format!("'{s}': expected medi, ev, mp, emel or radiance-m")),
        })
    }
}

impl Quantity {
    pub fn of(self, m: &Melanopic) -> f64 {
        match self {
            Quantity::Medi => m.medi,
            Quantity::Ev => m.ev,
            Quantity::Mp => m.mp(),
            Quantity::Emel => m.e_mel,
            Quantity::RadianceM => m.radiance_m,
        }
    }
}

/// A day passes when m-EDI reaches `threshold` for at least `min_hours` inside the
/// window `start <= hour < end` (decimal local hours).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DailyRule {
    pub threshold: f64,
    pub start: f64,
    pub end: f64,
    pub min_hours: f64,
}

impl Default for DailyRule {
    fn default() -> Self {
        DailyRule {
            threshold: DAYTIME_MEDI_LX,
            start: 8.0,
            end: 12.0,
            min_hours: 4.0,
        }
    }
}

/// (days passing, days with a step in the window) for one sensor's row.
pub fn daily_pass(
    vals: &[Melanopic],
    stamps: &[Stamp],
    step_hours: f64,
    r: &DailyRule,
) -> (usize, usize) {
    let (mut pass, mut days) = (0, 0);
    let mut i = 0;
    while i < stamps.len().min(vals.len()) {
        let (m, d) = (stamps[i].month, stamps[i].day);
        let (mut hours, mut seen) = (0.0, false);
        while i < stamps.len().min(vals.len()) && stamps[i].month == m && stamps[i].day == d {
            let h = stamps[i].hour;
            if h >= r.start && h < r.end {
                seen = true;
                if vals[i].medi >= r.threshold {
                    hours += step_hours;
                }
            }
            i += 1;
        }
        if seen {
            days += 1;
            if hours + 1e-9 >= r.min_hours {
                pass += 1;
            }
        }
    }
    (pass, days)
}

/// Per-sensor summary over the columns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Mean m-EDI and Ev over the steps with light (Ev > 0).
    pub mean_medi: f64,
    pub mean_ev: f64,
    /// Mean M/P over the steps with light.
    pub mean_mp: f64,
    /// Steps with m-EDI at or above the threshold.
    pub steps_above: usize,
    /// Steps with light.
    pub lit_steps: usize,
    /// Days passing the [`DailyRule`] and days counted (0, 0 without time stamps).
    pub days_pass: usize,
    pub days: usize,
}

impl Summary {
    /// Percentage of counted days that pass (0 without days).
    pub fn days_share(&self) -> f64 {
        100.0 * self.days_pass as f64 / self.days.max(1) as f64
    }
}

/// Stream a spectral matrix: `each(row, values)` receives every sensor row reduced to
/// [`Melanopic`] per column; returns the per-sensor summaries (threshold in lx m-EDI).
pub fn reduce<R: BufRead>(
    reader: &mut MatrixReader<R>,
    threshold: f64,
    daily: Option<(&[Stamp], f64, &DailyRule)>,
    mut each: impl FnMut(usize, &[Melanopic]) -> Result<()>,
) -> Result<Vec<Summary>> {
    let w = BandWeights::new(&reader.info().channels).map_err(|e| match e {
        Error::Mismatch(m) => Error::Mismatch(format!("{}: {m}", reader.name())),
        other => other,
    })?;
    let n = reader.ncomp();
    let mut buf = vec![0.0; reader.row_len()];
    let mut vals = Vec::with_capacity(reader.ncols());
    let mut out = Vec::new();
    while reader.read_row(&mut buf)? {
        vals.clear();
        vals.extend(buf.chunks_exact(n).map(|v| w.eval(v)));
        each(out.len(), &vals)?;
        let lit: Vec<&Melanopic> = vals.iter().filter(|m| m.ev > 0.0).collect();
        let k = lit.len().max(1) as f64;
        let (days_pass, days) = match daily {
            Some((st, step, rule)) => daily_pass(&vals, st, step, rule),
            None => (0, 0),
        };
        out.push(Summary {
            mean_medi: lit.iter().map(|m| m.medi).sum::<f64>() / k,
            mean_ev: lit.iter().map(|m| m.ev).sum::<f64>() / k,
            mean_mp: lit.iter().map(|m| m.mp()).sum::<f64>() / k,
            steps_above: vals.iter().filter(|m| m.medi >= threshold).count(),
            lit_steps: lit.len(),
            days_pass,
            days,
        });
    }
    Ok(out)
}

/// The per-sensor summary as TSV: `sensor [x y z] mean_mEDI_lx mean_Ev_lx mean_MP
/// lit_steps steps_mEDI_ge_T share_ge_T_percent` (means over steps with light).
/// Sensors are numbered from 1 in matrix row order, as in rmetrics' `metrics.tsv`, rtrace's
/// and rcontrib's row order and every rdaylight table.
pub fn write_summary(
    w: &mut dyn std::io::Write,
    name: &str,
    s: &[Summary],
    threshold: f64,
    pos: Option<&[[f64; 3]]>,
) -> Result<()> {
    let io = |e| Error::io(name, e);
    let xyz = if pos.is_some() { "\tx\ty\tz" } else { "" };
    writeln!(
        w,
        "sensor{xyz}\tmean_mEDI_lx\tmean_Ev_lx\tmean_MP\tlit_steps\tsteps_mEDI_ge_{threshold}\tshare_ge_{threshold}_percent\tdays_pass\tdays\tdays_pass_percent"
    )
    .map_err(io)?;
    for (i, x) in s.iter().enumerate() {
        let p = match pos.and_then(|p| p.get(i)) {
            Some(p) => format!("\t{}\t{}\t{}", p[0], p[1], p[2]),
            None => String::new(),
        };
        let share = 100.0 * x.steps_above as f64 / x.lit_steps.max(1) as f64;
        writeln!(
            w,
            "{}{p}\t{:.2}\t{:.2}\t{:.4}\t{}\t{}\t{share:.1}\t{}\t{}\t{:.1}",
            i + 1,
            x.mean_medi,
            x.mean_ev,
            x.mean_mp,
            x.lit_steps,
            x.steps_above,
            x.days_pass,
            x.days,
            x.days_share()
        )
        .map_err(io)?;
    }
    Ok(())
}

/// How spectral matrices are read: NCOMP from the header (no default override).
pub fn read_options() -> ReadOptions {
    ReadOptions {
        undo_exposure: true,
        ..ReadOptions::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::cie::{N, WL_STEP};

    fn ch(n: usize) -> Channels {
        Channels::spectral(n, 380.0, 780.0).unwrap()
    }

    /// Band values (Radiance convention) of a spectrum given per nm on the 5 nm grid.
    fn bands(per_nm: &[f64; N], c: &Channels) -> Vec<f64> {
        band_integrals(per_nm, c)
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let (hi, lo) = c.band(i);
                a / (hi - lo) * RADIANCE_SPAN_NM
            })
            .collect()
    }

    #[test]
    fn d65_at_1000_lx_has_medi_1000_lx() {
        // CIE S 026 defines K so that D65 has m-EDI = Ev (melanopic DER 1). Scale D65 to
        // 1000 lx on the 5 nm grid, then reduce its 24- and 18-band versions.
        let d65 = tables().d65;
        let ybar = &tables().cmf[1];
        let ev1: f64 = (0..N).map(|i| d65[i] * ybar[i]).sum::<f64>() * WL_STEP * KM;
        let e: [f64; N] = std::array::from_fn(|i| d65[i] * 1000.0 / ev1);
        // Band-averaging the spectrum before weighting costs a little accuracy: 1 % at 18
        // and 24 bands, 2 % at 9.
        for (n, tol) in [(24, 0.01), (18, 0.01), (9, 0.02)] {
            let c = ch(n);
            let m = BandWeights::new(&c).unwrap().eval(&bands(&e, &c));
            assert!(
                (m.ev - 1000.0).abs() < 1000.0 * tol,
                "{n} bands: Ev {}",
                m.ev
            );
            assert!(
                (m.medi - 1000.0).abs() < 1000.0 * tol,
                "{n} bands: m-EDI {}",
                m.medi
            );
            assert!((m.mp() - 1.0).abs() < tol, "{n} bands: M/P {}", m.mp());
        }
    }

    #[test]
    fn radiance_m_converts_to_medi_by_a_constant() {
        // radiance-notes.md 10.3: m-EDI = 0.9233 M for any spectrum.
        let k = radiance_m_to_medi();
        assert!((k - 0.9233).abs() < 2e-3, "{k}");
        let w = BandWeights::new(&ch(18)).unwrap();
        for v in [vec![1.0; 18], (0..18).map(|i| i as f64).collect::<Vec<_>>()] {
            let m = w.eval(&v);
            assert!((m.medi - k * m.radiance_m).abs() < 1e-9 * m.medi.max(1.0));
        }
        // Equal-energy white: Radiance's M is 179 x the band value.
        let m = w.eval(&[1.0; 18]);
        assert!((m.radiance_m - 179.0).abs() < 1e-9, "{}", m.radiance_m);
    }

    #[test]
    fn a_day_passes_with_four_morning_hours_at_250_lx() {
        let m = |medi: f64| Melanopic {
            ev: medi,
            e_mel: 0.0,
            medi,
            radiance_m: 0.0,
        };
        let st = |day: u8, hour: f64| Stamp {
            month: 1,
            day,
            hour,
        };
        // Day 1: 8.5 .. 11.5 all >= 250 (passes); day 2: 10.5 below (fails); day 3: only
        // afternoon steps (not counted).
        let stamps = [
            st(1, 8.5),
            st(1, 9.5),
            st(1, 10.5),
            st(1, 11.5),
            st(1, 12.5),
            st(2, 8.5),
            st(2, 9.5),
            st(2, 10.5),
            st(2, 11.5),
            st(3, 14.5),
        ];
        let v = [300., 250., 400., 260., 0., 300., 300., 249., 300., 999.].map(m);
        assert_eq!(daily_pass(&v, &stamps, 1.0, &DailyRule::default()), (1, 2));
    }

    #[test]
    fn rgb_input_is_refused() {
        let e = BandWeights::new(&Channels::rgb()).unwrap_err().to_string();
        assert!(e.contains("NCOMP=3"), "{e}");
    }
}
