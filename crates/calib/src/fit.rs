//! # Scoring effect combinations against the readings
//!
//! [`Fitter`] binds a [`Model`] to its readings and scores any list of effects with the
//! noise-aware BIC of [`super::score`]. The effect fits call it inside one-dimensional
//! searches; families that only rescale the final values (glazing, local obstruction,
//! sensor factors) reuse the per-observation parts ([`Model::parts`]) of the other effects.

use super::effects::Effect;
use super::model::{Model, Weights};
use super::score::{Score, score};

/// A model and its readings.
pub struct Fitter<'a> {
    pub m: &'a Model,
    pub meas: Vec<f64>,
    pub sensor: Vec<usize>,
    /// Assumed per-sensor spread (see [`super::score`]).
    pub sigma_sensor: f64,
    /// Per-reading factor on the inter-reflected part of every prediction
    /// ([`super::explain::refine`]: what makes the coefficient model's prediction of the
    /// applied effects equal a re-simulation of them). The direct part is left as the
    /// model computes it: it is exact geometry, and an effect that blocks direct light
    /// (overhang, obstruction) switches it on and off from one parameter value to the next,
    /// which a fixed factor would freeze.
    pub correction: Option<Vec<f64>>,
    /// The skyline profile's distance, when it is fixed ([`super::explain::refine`]: a
    /// correction made by re-simulating a profile at one distance holds for that distance
    /// only). `None`: the profile fit chooses it.
    pub skyline_distance: Option<f64>,
}

impl<'a> Fitter<'a> {
    pub fn new(m: &'a Model, sigma_sensor: f64) -> Fitter<'a> {
        Fitter {
            m,
            sigma_sensor,
            meas: m.measured(),
            sensor: m.obs.iter().map(|o| o.sensor).collect(),
            correction: None,
            skyline_distance: None,
        }
    }

    /// [`Fitter::new`] with the inter-reflected part of predictions multiplied by
    /// `correction` (one factor a reading).
    pub fn with_correction(mut self, correction: Vec<f64>) -> Fitter<'a> {
        self.correction = Some(correction);
        self
    }

    /// Simulated readings from parts and weights, the correction applied.
    pub fn finish(&self, parts: &[(f64, f64)], w: &Weights) -> Vec<f64> {
        match &self.correction {
            Some(c) => {
                let p: Vec<(f64, f64)> = parts
                    .iter()
                    .zip(c)
                    .map(|(&(ind, dir), k)| (ind * k, dir))
                    .collect();
                self.m.finish(&p, w)
            }
            None => self.m.finish(parts, w),
        }
    }

    /// Simulated readings with `effects` applied ([`Model::predict`] with the correction).
    pub fn predict(&self, effects: &[Effect]) -> Vec<f64> {
        let w = self.m.weights(effects);
        self.finish(&self.m.parts(&w), &w)
    }

    /// Score of simulated readings.
    pub fn score_sim(&self, sim: &[f64]) -> Score {
        score(
            sim,
            &self.meas,
            &self.sensor,
            self.m.nsens(),
            self.sigma_sensor,
        )
    }

    /// Score of a list of effects.
    pub fn score(&self, effects: &[Effect]) -> Score {
        self.score_sim(&self.predict(effects))
    }

    /// BIC of a list of effects (k = their parameters).
    pub fn bic(&self, effects: &[Effect]) -> f64 {
        let k: f64 = effects.iter().map(Effect::n_params).sum();
        self.score(effects).bic(k)
    }

    /// -2 ln L from precomputed parts and final weights.
    pub fn m2ll_parts(&self, parts: &[(f64, f64)], w: &Weights) -> f64 {
        self.score_sim(&self.finish(parts, w)).m2ll
    }

    /// -2 ln L of `e` added to precomputed weights `w0` of the other effects (fits call
    /// this in their searches instead of re-computing every effect's weights).
    pub fn m2ll_on(&self, w0: &Weights, e: &Effect) -> f64 {
        let mut w = w0.clone();
        self.m.add_effect(e, &mut w);
        self.m2ll_parts(&self.m.parts(&w), &w)
    }

    /// Standard uncertainty of the main parameter of `effects[i]` from the curvature of
    /// -2 ln L (Fisher information: var = 2 / second derivative), `None` when flat.
    pub fn uncertainty(&self, effects: &[Effect], i: usize, step: f64) -> Option<f64> {
        let (_, v) = effects.get(i)?.primary();
        let at = |x: f64| {
            let mut e = effects.to_vec();
            e[i] = e[i].with_primary(x);
            self.score(&e).m2ll
        };
        let (lo, mid, hi) = (at(v - step), at(v), at(v + step));
        let curv = (lo - 2.0 * mid + hi) / (step * step);
        (curv > 0.0).then(|| (2.0 / curv).sqrt())
    }
}

/// `base` with every effect of `family` removed.
pub fn without(base: &[Effect], family: &str) -> Vec<Effect> {
    base.iter()
        .filter(|e| e.family() != family)
        .cloned()
        .collect()
}
