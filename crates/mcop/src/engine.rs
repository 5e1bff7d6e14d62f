//! # One traced level, many material draws: the re-weighting engine
//!
//! Each GLoD is traced once ([`LevelModel::trace`]: sky coefficients over the Reinhart
//! patches with path re-weighting records, [`rdaylight_trace::trace::reweight`]); a draw
//! scales each tracked material's colour by `s_m` and the coefficient of every record and
//! column becomes `sum over signatures c_sig prod_m s_m^n_m(sig)`. The sky matrix (sun in
//! the patches, as gendaymtx writes it) carries the direct sun and its inter-reflection in
//! the same coefficients, so one trace covers sky, sun and both bounces.
//!
//! Two products per draw, by what the metric needs:
//!
//! - **TAI** is linear in the coefficients, so the year and the columns collapse before
//!   any draw: per record and signature `a_sig = (dt/1000) sum_col 179 w . (c_sig,col o
//!   S_col)` with `S` the occupied sky summed over the year; a draw is then
//!   `TAI = sum_sig a_sig f_sig(s)`, a few thousand multiply-adds per room
//!   ([`LevelModel::tai`]).
//! - **Hour-based metrics** (UDI, DA, sDA, the seed's Eq. A.3 RMSE) need the illuminance of
//!   every occupied hour: the draw's coefficients (records x 3 patches, f32) times the
//!   occupied sky (3 patches x hours, f32, with 179 w folded in), one single-precision
//!   matrix product ([`LevelModel::hourly`]). f32 is what the Radiance matrix files hold;
//!   the products are accumulated in f32 by the blocked kernel of `matrixmultiply` (via
//!   nalgebra).

use nalgebra::DMatrix;
use rdaylight_base::Result;
use rdaylight_base::progress::Progress;
use rdaylight_base::radiometry::{RGB_PHOTOPIC_ROUNDED, WHITE_EFFICACY};
use rdaylight_formats::scene::Scene;
use rdaylight_formats::sensors::SensorRay;
use rdaylight_glod::study::OccupiedSky;
use rdaylight_trace::rdc::{Config, Reweight, Tracer};
use rdaylight_trace::trace::reweight::Reweighting;

/// A traced level, ready for draws.
#[derive(Debug, Clone)]
pub struct LevelModel {
    /// Tracked material names (factor `i` of a draw scales `materials[i]`).
    pub materials: Vec<String>,
    pub nrecords: usize,
    /// Sky columns.
    pub npatches: usize,
    rw: Reweighting,
    /// Per tracked material, a glass pane's normal transmittance and index (`None`: not
    /// glass): its angle-binned entries get `T'(c) / T(c)` of the re-made pane.
    panes: Vec<Option<(f64, f64)>>,
    /// Per signature, its entry numbers (0-based), for the factor product.
    sig_events: Vec<Vec<u16>>,
    /// TAI part per record: `tai_start[r]..tai_start[r + 1]` into `tai_sig`/`tai_val`.
    tai_start: Vec<usize>,
    tai_sig: Vec<u32>,
    tai_val: Vec<f64>,
    /// Wall-clock seconds of the trace (compile included).
    pub trace_seconds: f64,
}

/// Per-hour results of one draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Hourly {
    /// Illuminance (lx), `lux[r * hours + h]`.
    pub lux: Vec<f32>,
    pub hours: usize,
}

impl LevelModel {
    /// Trace `scene`'s sky coefficients at `sensors` (irradiance) with re-weighting records
    /// for every reflecting or transmitting material (or `cfg.materials`), with the study's
    /// sampling, sky subdivision, seed and threads; each sensor advances `progress`.
    pub fn trace(
        scene: &Scene,
        sensors: &[SensorRay],
        cfg: &crate::study::StudyConfig,
        sky: &OccupiedSky,
        progress: &dyn Progress,
    ) -> Result<LevelModel> {
        let config = Config {
            seed: cfg.trace.seed,
            threads: cfg.trace.threads,
            reweight: Some(Reweight {
                path: None,
                materials: cfg.materials.clone(),
            }),
            ..Config::sky_coefficients(cfg.trace.mf, cfg.trace.sampling)
        };
        let t0 = std::time::Instant::now();
        let tracer = Tracer::new(&config, scene)?;
        let names = tracer.tracked_materials().to_vec();
        let rows = tracer.compute_reporting(sensors, progress)?;
        let trace_seconds = t0.elapsed().as_secs_f64();
        let panes = names
            .iter()
            .map(|n| {
                crate::classes::property(scene, n)
                    .ok()
                    .and_then(|p| p.index.map(|i| (p.value, i)))
            })
            .collect();
        let mut rw = Reweighting::new(names, sky.npatches, 3)
            .with_entries(tracer.tracked_entries().to_vec())?;
        for r in &rows {
            rw.push_row(&r.terms);
        }
        Ok(LevelModel::from_reweighting(rw, panes, sky, trace_seconds))
    }

    /// A model from re-weighting records (`ncols` = the sky's patches, 3 channels); `panes`
    /// as [`LevelModel::panes`] (empty: no glass).
    pub fn from_reweighting(
        rw: Reweighting,
        panes: Vec<Option<(f64, f64)>>,
        sky: &OccupiedSky,
        trace_seconds: f64,
    ) -> Self {
        let sig_events = rw
            .signatures()
            .iter()
            .map(|s| s.events().map(|e| u16::from(e) - 1).collect())
            .collect();
        let w = RGB_PHOTOPIC_ROUNDED;
        let scale = WHITE_EFFICACY * sky.step_hours / 1000.0;
        let (mut tai_start, mut tai_sig, mut tai_val) = (vec![0], Vec::new(), Vec::new());
        for r in 0..rw.nrows() {
            let mut parts: std::collections::BTreeMap<u32, f64> = Default::default();
            for (col, sig, v) in rw.row_terms(r) {
                let s = &sky.sums[col * 3..col * 3 + 3];
                let a = scale * (w[0] * v[0] * s[0] + w[1] * v[1] * s[1] + w[2] * v[2] * s[2]);
                *parts.entry(sig as u32).or_insert(0.0) += a;
            }
            for (sig, a) in parts {
                tai_sig.push(sig);
                tai_val.push(a);
            }
            tai_start.push(tai_sig.len());
        }
        LevelModel {
            materials: rw.materials.clone(),
            nrecords: rw.nrows(),
            npatches: rw.ncols,
            rw,
            panes,
            sig_events,
            tai_start,
            tai_sig,
            tai_val,
            trace_seconds,
        }
    }

    /// The re-weighting records (e.g. to write them with [`Reweighting::write`]).
    pub fn reweighting(&self) -> &Reweighting {
        &self.rw
    }

    /// The factor of every tracked number: the material's scale, or for an angle bin of a
    /// glass pane the re-made pane's transmission over the traced one at the bin's centre
    /// (Radiance's glass law, both polarisations), `T(c; t') / T(c; t)` with `t, t'` the
    /// transmissivities of normal transmittances `Tn` and `s Tn`.
    pub fn entry_factors(&self, scales: &[f64]) -> Vec<f64> {
        use rdaylight_physics::material::glass::transmissivity_for_index;
        use rdaylight_physics::material::{Color, Glass};
        self.rw
            .entries
            .iter()
            .map(|e| {
                let s = scales.get(e.material).copied().unwrap_or(1.0);
                match (e.cos, self.panes.get(e.material).copied().flatten()) {
                    (Some(c), Some((tn, n))) if s != 1.0 => {
                        let t = |tn: f64| {
                            let g = Glass::new(Color::splat(1, transmissivity_for_index(tn, n)), n);
                            f64::from(g.coefficients(c).0.as_slice()[0])
                        };
                        let before = t(tn);
                        if before > 0.0 { t(s * tn) / before } else { s }
                    }
                    _ => s,
                }
            })
            .collect()
    }

    /// `f_sig(s)` for every signature.
    fn factors(&self, scales: &[f64]) -> Vec<f64> {
        let f = self.entry_factors(scales);
        self.sig_events
            .iter()
            .map(|ev| {
                ev.iter()
                    .map(|&e| f.get(usize::from(e)).copied().unwrap_or(1.0))
                    .product()
            })
            .collect()
    }

    /// TAI (klx h) per record with tracked material `i`'s colour scaled by `scales[i]`.
    pub fn tai(&self, scales: &[f64]) -> Vec<f64> {
        let f = self.factors(scales);
        (0..self.nrecords)
            .map(|r| {
                (self.tai_start[r]..self.tai_start[r + 1])
                    .map(|t| self.tai_val[t] * f[self.tai_sig[t] as usize])
                    .sum()
            })
            .collect()
    }

    /// The draw's coefficients, `records x (patches * 3)` row-major f32.
    pub fn coefficients(&self, scales: &[f64]) -> Vec<f32> {
        let f = self.factors(scales);
        let width = self.npatches * 3;
        let mut c = vec![0f64; self.nrecords * width];
        for r in 0..self.nrecords {
            let row = &mut c[r * width..(r + 1) * width];
            for (col, sig, v) in self.rw.row_terms(r) {
                for k in 0..3 {
                    row[col * 3 + k] += v[k] * f[sig];
                }
            }
        }
        c.into_iter().map(|x| x as f32).collect()
    }

    /// Illuminance of every record at every occupied hour for the draw `scales`.
    pub fn hourly(&self, scales: &[f64], sky: &WeightedSky) -> Hourly {
        let c = self.coefficients(scales);
        let width = self.npatches * 3;
        // Column-major views without copies: C^T is (width x records) and the weighted sky
        // transposed is (hours x width); their product E^T (hours x records) holds each
        // record's hours contiguously.
        let ct = DMatrix::from_vec(width, self.nrecords, c);
        let mut et = DMatrix::<f32>::zeros(sky.hours, self.nrecords);
        et.gemm(1.0, &sky.t, &ct, 0.0);
        Hourly {
            lux: et.data.into(),
            hours: sky.hours,
        }
    }
}

/// The occupied sky with `179 w_c` folded into each channel's rows, stored transposed
/// (hours x patches*3, column-major) for [`LevelModel::hourly`].
#[derive(Debug, Clone)]
pub struct WeightedSky {
    pub hours: usize,
    t: DMatrix<f32>,
}

impl WeightedSky {
    pub fn new(sky: &OccupiedSky) -> WeightedSky {
        let w = RGB_PHOTOPIC_ROUNDED;
        let mut v = sky.values.clone();
        for (j, chunk) in v.chunks_mut(sky.hours.max(1)).enumerate() {
            let k = (WHITE_EFFICACY * w[j % 3]) as f32;
            for x in chunk {
                *x *= k;
            }
        }
        WeightedSky {
            hours: sky.hours,
            t: DMatrix::from_vec(sky.hours, sky.npatches * 3, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rdaylight_trace::trace::reweight::Signature;

    /// Two patches, two occupied hours, one record met by a wall (material 0) path.
    fn fixture() -> (LevelModel, OccupiedSky) {
        let sky = OccupiedSky {
            npatches: 2,
            hours: 2,
            // (p * 3 + c) * hours + h
            values: vec![
                1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 10.0, 0.0, 10.0, 0.0, 10.0, 0.0,
            ],
            sums: vec![3.0, 3.0, 3.0, 10.0, 10.0, 10.0],
            step_hours: 1.0,
        };
        let mut rw = Reweighting::new(vec!["wall".into()], 2, 3);
        rw.push_row(&[
            (0, Signature::from_events(&[]), vec![0.5; 3]),
            (1, Signature::from_events(&[1]), vec![0.2; 3]),
        ]);
        (LevelModel::from_reweighting(rw, Vec::new(), &sky, 0.0), sky)
    }

    #[test]
    fn tai_and_hourly_are_the_same_polynomial() {
        let (m, sky) = fixture();
        let ws = WeightedSky::new(&sky);
        for s in [0.5, 1.0, 1.7] {
            // Grey channels: 179 x (0.5 x 3 + 0.2 s x 10) lx h.
            let want = 179.0 * (1.5 + 2.0 * s) / 1000.0;
            let tai = m.tai(&[s]);
            assert!((tai[0] - want).abs() < 1e-12, "{tai:?} {want}");
            let h = m.hourly(&[s], &ws);
            let lux: Vec<f64> = h.lux.iter().map(|&x| f64::from(x)).collect();
            assert!((lux[0] - 179.0 * (0.5 + 2.0 * s)).abs() < 1e-3, "{lux:?}");
            assert!((lux[1] - 179.0 * 1.0).abs() < 1e-3, "{lux:?}");
            assert!((lux.iter().sum::<f64>() / 1000.0 - want).abs() < 1e-5);
        }
        // The all-ones draw is the traced model.
        assert_eq!(m.coefficients(&[1.0])[0], 0.5);
    }
}
