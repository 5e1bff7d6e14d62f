//! # Explain: which physical effect is missing?
//!
//! 1. Every family of [`super::effects`] is fitted alone to the residuals of the model as
//!    given; each gets its parameters, an uncertainty of its main parameter (curvature of
//!    -2 ln L), the error it removes (RMSE_rel before and after), its BIC change, and its
//!    evidence (the sensors and the kind of hours it explains).
//! 2. The families are ranked by BIC.
//! 3. Greedy forward selection: the best family is kept if it lowers the BIC by more than
//!    [`SIGNIFICANT`] and removes at least [`MIN_GAIN`] of the squared error; then all remaining families are fitted again on top of the kept ones
//!    (and the kept ones re-fitted given each other), until nothing significant is left or
//!    [`MAX_EFFECTS`] are kept. When the first step finds nothing, the report says "no
//!    significant missing effect" and gives the residual noise levels.
//! 4. [`refine`]: the coefficient model's effects are approximations (an overhang or an
//!    obstruction changes where the sun lands inside, not only what enters; a glazing
//!    scale is applied per sky direction). The kept effects are applied to the model as
//!    `rcalib apply` writes them, re-simulated, and the ratio of that re-simulation to the
//!    coefficient model's prediction of it becomes a per-reading correction under which
//!    the kept effects are fitted again (a defect-correction step). In the hidden-effect
//!    tests this moves, e.g., a glazing scale fitted at 0.734 for a true 0.70 to the truth.

use super::effects::{self, Effect, FAMILIES};
use super::fit::{Fitter, without};
use super::model::Model;
use super::room::SurfaceClass;
use super::score::{SIGNIFICANT, Score};
use super::stats::{Stats, rel_error};
use serde::Serialize;

/// Most effects selected together.
pub const MAX_EFFECTS: usize = 4;

/// Besides the BIC, a kept effect must remove at least this share of the remaining squared
/// relative error: with hundreds of readings the BIC alone accepts changes that chase the
/// model's own Monte Carlo noise (a few percent of RMSE_rel) rather than physics.
pub const MIN_GAIN: f64 = 0.3;

/// One fitted candidate.
#[derive(Debug, Clone, Serialize)]
pub struct Candidate {
    pub family: String,
    pub effect: Effect,
    /// `NAME:params` for `rcalib apply`.
    pub spec: String,
    /// The spec's parameters with names and units.
    pub params: String,
    pub description: String,
    pub parameter: String,
    pub value: f64,
    /// Standard uncertainty of `value` (None when the likelihood is flat there).
    pub uncertainty: Option<f64>,
    pub rmse_before: f64,
    pub rmse_after: f64,
    /// BIC change against the base (negative = better).
    pub delta_bic: f64,
    pub evidence: String,
}

/// The outcome of `explain`.
#[derive(Debug, Clone, Serialize)]
pub struct Explanation {
    pub base: Stats,
    pub base_score: Score,
    /// Single-effect fits on the model as given, best first.
    pub ranking: Vec<Candidate>,
    /// Effects kept by forward selection, in order.
    pub selected: Vec<Candidate>,
    pub final_stats: Stats,
    pub final_score: Score,
    /// The readings predicted with the selected effects (`final_stats` are theirs; after
    /// [`refine`], corrected towards the re-simulation), in observation order.
    #[serde(skip)]
    pub final_sim: Vec<f64>,
    /// The selected effects as `--effect` arguments.
    pub specs: Vec<String>,
    /// The families that were considered.
    pub families: Vec<String>,
    pub verdict: String,
}

/// Fit one family on top of `base`.
pub fn fit_family(f: &Fitter, base: &[Effect], family: &str) -> Option<Effect> {
    match family {
        "transmittance" => effects::transmittance::fit(f, base),
        "obstruction" => effects::skyline::fit_obstruction(f, base),
        "walls" => effects::reflectance::fit(f, base, SurfaceClass::Walls),
        "ceiling" => effects::reflectance::fit(f, base, SurfaceClass::Ceiling),
        "floor" => effects::reflectance::fit(f, base, SurfaceClass::Floor),
        "ground-albedo" => effects::reflectance::fit(f, base, SurfaceClass::Ground),
        "overhang" => effects::overhang::fit(f, base),
        "local-obstruction" => effects::local::fit(f, base),
        "sensor-fault" => effects::sensor::fit(f, base),
        // Level only from photopic readings; the shape: crate::spectral::explain.
        "tint" => effects::tint::fit(f, base),
        _ => None,
    }
}

fn stats_of(m: &Model, sim: &[f64]) -> Stats {
    let pairs: Vec<(f64, f64)> = sim.iter().zip(&m.obs).map(|(y, o)| (*y, o.value)).collect();
    Stats::of(&pairs)
}

fn step_for(e: &Effect) -> f64 {
    match e {
        Effect::Obstruction { .. } | Effect::Skyline { .. } => 1.0,
        Effect::Overhang { .. } => 0.05,
        _ => 0.01,
    }
}

/// Which sensors and hours an effect explains: the sensors whose mean squared relative
/// error falls most, and the error change in sun hours against the rest.
fn evidence(m: &Model, before: &[f64], after: &[f64], ids: &[String]) -> String {
    let ns = m.nsens();
    let mut b = vec![(0.0, 0usize); ns];
    let mut a = vec![0.0; ns];
    let (mut sun_b, mut sun_a, mut dif_b, mut dif_a) = (0.0, 0.0, 0.0, 0.0);
    for ((o, yb), ya) in m.obs.iter().zip(before).zip(after) {
        let (Some(eb), Some(ea)) = (rel_error(*yb, o.value), rel_error(*ya, o.value)) else {
            continue;
        };
        b[o.sensor].0 += eb * eb;
        b[o.sensor].1 += 1;
        a[o.sensor] += ea * ea;
        let sunny =
            m.comps.sun_direct[o.sensor * m.nsteps() + o.step] > 0.0 || m.skies[o.step].dni > 200.0;
        if sunny {
            sun_b += eb * eb;
            sun_a += ea * ea;
        } else {
            dif_b += eb * eb;
            dif_a += ea * ea;
        }
    }
    let mut gains: Vec<(usize, f64)> = (0..ns)
        .filter(|&s| b[s].1 > 0 && b[s].0 > 0.0)
        .map(|s| (s, 1.0 - a[s] / b[s].0))
        .collect();
    gains.sort_by(|x, y| y.1.total_cmp(&x.1));
    let total_b: f64 = b.iter().map(|x| x.0).sum();
    let total_a: f64 = a.iter().sum();
    let share = |x: f64, y: f64| if x > 0.0 { 100.0 * (1.0 - y / x) } else { 0.0 };
    let broad = gains.iter().filter(|g| g.1 > 0.3).count();
    // Only sensors the effect improves are named (an effect confined to two sensors must
    // not list a third whose error did not move).
    let top: Vec<String> = gains
        .iter()
        .filter(|g| g.1 > 0.01)
        .take(3)
        .map(|(s, g)| {
            format!(
                "{} {:+.0}%",
                ids.get(*s).map_or("?", |x| x.as_str()),
                -100.0 * g
            )
        })
        .collect();
    format!(
        "squared error {:+.0}% overall, {:+.0}% in sun hours, {:+.0}% otherwise; improves {} of {} sensors by >30% (most: {})",
        -share(total_b, total_a),
        -share(sun_b, sun_a),
        -share(dif_b, dif_a),
        broad,
        ns,
        if top.is_empty() {
            "none".to_string()
        } else {
            top.join(", ")
        }
    )
}

fn candidate(
    f: &Fitter,
    base: &[Effect],
    e: Effect,
    base_bic: f64,
    before: &[f64],
    ids: &[String],
    windows: &[String],
) -> Candidate {
    let mut all = base.to_vec();
    all.push(e.clone());
    let sim = f.predict(&all);
    let after = stats_of(f.m, &sim);
    let k: f64 = all.iter().map(Effect::n_params).sum();
    let bic = f.score_sim(&sim).bic(k);
    let (parameter, value) = e.primary();
    let uncertainty = f.uncertainty(&all, all.len() - 1, step_for(&e));
    Candidate {
        family: e.family().to_string(),
        spec: e.spec(ids, windows),
        params: e.named_params(ids, windows),
        description: e.describe(ids, windows),
        parameter: parameter.to_string(),
        value,
        uncertainty,
        rmse_before: stats_of(f.m, before).rmse_rel,
        rmse_after: after.rmse_rel,
        delta_bic: bic - base_bic,
        evidence: evidence(f.m, before, &sim, ids),
        effect: e,
    }
}

/// Rank and select effects.
pub fn explain(m: &Model, families: &[&str], sigma_sensor: f64) -> Explanation {
    let f = Fitter::new(m, sigma_sensor);
    let ids: Vec<String> = m.sensors.iter().map(|s| s.id.clone()).collect();
    let windows: Vec<String> = m.room.windows.iter().map(|w| w.id.clone()).collect();
    let base_sim = m.predict(&[]);
    let base_score = f.score_sim(&base_sim);
    let base_bic = base_score.bic(0.0);
    let fams: Vec<&str> = FAMILIES
        .iter()
        .copied()
        .filter(|x| families.is_empty() || families.contains(x))
        .collect();
    // 1-2: single fits, ranked.
    let mut ranking: Vec<Candidate> = fams
        .iter()
        .filter_map(|fam| fit_family(&f, &[], fam))
        .map(|e| candidate(&f, &[], e, base_bic, &base_sim, &ids, &windows))
        .collect();
    ranking.sort_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    // 3: forward selection.
    let mut chosen: Vec<Effect> = Vec::new();
    let mut selected: Vec<Candidate> = Vec::new();
    forward(&f, &fams, Some(&ranking), &mut chosen, &mut selected);
    prune(&f, &mut chosen, &mut selected);
    let cur_sim = f.predict(&chosen);
    // Report the kept effects with their re-fitted parameters.
    for (c, e) in selected.iter_mut().zip(&chosen) {
        c.effect = e.clone();
        c.spec = e.spec(&ids, &windows);
        c.params = e.named_params(&ids, &windows);
        c.description = e.describe(&ids, &windows);
        let (p, v) = e.primary();
        c.parameter = p.to_string();
        c.value = v;
        let i = chosen.iter().position(|x| x == e).unwrap_or(0);
        c.uncertainty = f.uncertainty(&chosen, i, step_for(e));
    }
    let final_score = f.score_sim(&cur_sim);
    let final_stats = stats_of(m, &cur_sim);
    let base = stats_of(m, &base_sim);
    let verdict = verdict(
        &selected,
        &base,
        &base_score,
        &final_stats,
        &final_score,
        sigma_sensor,
    );
    Explanation {
        base,
        base_score,
        specs: selected.iter().map(|c| c.spec.clone()).collect(),
        families: fams.iter().map(|x| x.to_string()).collect(),
        ranking,
        selected,
        final_stats,
        final_score,
        final_sim: cur_sim,
        verdict,
    }
}

fn verdict(
    selected: &[Candidate],
    base: &Stats,
    base_score: &Score,
    final_stats: &Stats,
    final_score: &Score,
    sigma_sensor: f64,
) -> String {
    if selected.is_empty() {
        format!(
            "no significant missing effect: the residual is at the noise level \
             ({:.1} % per reading, {:.1} % per sensor assumed)",
            100.0 * base_score.sigma_reading,
            100.0 * sigma_sensor
        )
    } else {
        format!(
            "missing: {}; RMSE_rel {:.1} % -> {:.1} %; left: {:.1} % per reading",
            selected
                .iter()
                .map(|c| c.description.clone())
                .collect::<Vec<_>>()
                .join("; "),
            base.rmse_rel,
            final_stats.rmse_rel,
            100.0 * final_score.sigma_reading,
        )
    }
}

/// Greedy forward selection from the kept effects `chosen` (step 3): the best family on
/// top of them is kept while it is significant and removes at least [`MIN_GAIN`] of the
/// squared error, then the kept ones are re-fitted given each other. `first`: the ranked
/// single-effect fits to start from when nothing is kept yet.
fn forward(
    f: &Fitter,
    fams: &[&str],
    first: Option<&[Candidate]>,
    chosen: &mut Vec<Effect>,
    selected: &mut Vec<Candidate>,
) {
    let m = f.m;
    let ids: Vec<String> = m.sensors.iter().map(|s| s.id.clone()).collect();
    let windows: Vec<String> = m.room.windows.iter().map(|w| w.id.clone()).collect();
    let bic_of = |effects: &[Effect], sim: &[f64]| {
        let k: f64 = effects.iter().map(Effect::n_params).sum();
        f.score_sim(sim).bic(k)
    };
    let mut cur_sim = f.predict(chosen);
    let mut cur_bic = bic_of(chosen, &cur_sim);
    while chosen.len() < MAX_EFFECTS {
        let cands: Vec<(Vec<Effect>, Candidate)> = match first {
            Some(r) if chosen.is_empty() => r.iter().map(|c| (Vec::new(), c.clone())).collect(),
            _ => fams
                .iter()
                .filter(|fam| !chosen.iter().any(|c| c.family() == **fam))
                .filter_map(|fam| fit_family(f, chosen, fam))
                .map(|e| joint(f, chosen, e, cur_bic, &cur_sim, &ids, &windows))
                .collect(),
        };
        let Some((kept, best)) = cands
            .into_iter()
            .min_by(|a, b| a.1.delta_bic.total_cmp(&b.1.delta_bic))
        else {
            break;
        };
        let gain = 1.0 - (best.rmse_after / best.rmse_before.max(1e-12)).powi(2);
        if best.delta_bic > -SIGNIFICANT || gain < MIN_GAIN {
            break;
        }
        *chosen = kept;
        chosen.push(best.effect.clone());
        // Re-fit the kept effects given each other (one coordinate pass).
        for i in 0..chosen.len() {
            let fam = chosen[i].family();
            let others = without(chosen, fam);
            if let Some(e) = fit_family(f, &others, fam) {
                chosen[i] = e;
            }
        }
        cur_sim = f.predict(chosen);
        cur_bic = bic_of(chosen, &cur_sim);
        selected.push(best);
    }
}

/// Candidate `e` (fitted on top of the kept effects `chosen`) tested jointly with them:
/// the kept effects re-fitted given it, then it given them (one coordinate pass). A kept
/// geometric effect fitted alone absorbs part of a uniform scale (a skyline's altitudes
/// rise to darken every hour a little); tested only on top of it, the glazing scale
/// explains little and a floor or ground scale takes the rest (issue 22). Returns the
/// better of the plain and the joint fit by BIC, with the kept effects it goes with.
fn joint(
    f: &Fitter,
    chosen: &[Effect],
    e: Effect,
    cur_bic: f64,
    cur_sim: &[f64],
    ids: &[String],
    windows: &[String],
) -> (Vec<Effect>, Candidate) {
    let plain = candidate(f, chosen, e.clone(), cur_bic, cur_sim, ids, windows);
    if chosen.is_empty() {
        return (Vec::new(), plain);
    }
    // Starting points of the candidate: as fitted, and for a scale (the glazing's, a
    // surface class's reflectance) a grid, the kept effects re-fitted at each. A
    // coordinate pass from the scale fitted on top of a kept effect that already absorbed
    // it stays where it is: a skyline that rose to darken every hour leaves the glazing
    // scale near 1, and so do walls darkened to 0.44 for walls at 0.6 and a ceiling at
    // 0.75 (both lower the inter-reflected light; issue 22's surfaces-deep case).
    let mut starts = vec![e.clone()];
    match e {
        Effect::Transmittance { .. } => starts.extend(
            JOINT_SCALES
                .iter()
                .map(|&scale| Effect::Transmittance { scale }),
        ),
        Effect::Reflectance { class, .. } => starts.extend(
            JOINT_REFLECTANCES
                .iter()
                .map(|&scale| Effect::Reflectance { class, scale }),
        ),
        _ => {}
    }
    let mut best: (Vec<Effect>, Candidate) = (chosen.to_vec(), plain);
    for start in starts {
        let mut all = chosen.to_vec();
        all.push(start);
        for i in 0..all.len() {
            let fam = all[i].family();
            let others = without(&all, fam);
            if let Some(x) = fit_family(f, &others, fam) {
                all[i] = x;
            }
        }
        let Some(last) = all.pop() else {
            continue;
        };
        let c = candidate(f, &all, last, cur_bic, cur_sim, ids, windows);
        if c.delta_bic < best.1.delta_bic {
            best = (all, c);
        }
    }
    best
}

/// Glazing scales the joint test of [`joint`] starts from.
const JOINT_SCALES: [f64; 3] = [0.6, 0.75, 0.9];

/// Reflectance scales the joint test of [`joint`] starts from (finishes darker or lighter
/// than modelled).
const JOINT_REFLECTANCES: [f64; 5] = [0.6, 0.75, 0.9, 1.15, 1.3];

/// Backward check after the kept effects were re-fitted given each other: an effect whose
/// removal now raises the BIC by less than [`SIGNIFICANT`] is dropped (e.g. a floor scale
/// that the glazing scale has made redundant and that re-fitting moved to 0.999).
fn prune(f: &Fitter, chosen: &mut Vec<Effect>, selected: &mut Vec<Candidate>) {
    let bic = |effects: &[Effect]| {
        let k: f64 = effects.iter().map(Effect::n_params).sum();
        f.score_sim(&f.predict(effects)).bic(k)
    };
    let mut i = chosen.len();
    while i > 0 {
        i -= 1;
        if chosen.len() < 2 {
            break;
        }
        let mut without_i = chosen.clone();
        without_i.remove(i);
        if bic(&without_i) - bic(chosen) < SIGNIFICANT {
            chosen.remove(i);
            if i < selected.len() {
                selected.remove(i);
            }
        }
    }
}

/// Step 4 of the module documentation: re-fit the kept effects of `ex` under the
/// per-reading correction `exact / predicted`, where `exact` is the re-simulation of the
/// model with those effects applied (sensor faults as factors on it, as in
/// [`Model::predict`]) and `predicted` the coefficient model's value for the same effects.
/// Two coordinate passes; the ranking is kept as it was.
pub fn refine(m: &Model, ex: &Explanation, exact: &[f64], sigma_sensor: f64) -> Explanation {
    let mut chosen: Vec<Effect> = ex.selected.iter().map(|c| c.effect.clone()).collect();
    if chosen.is_empty() || exact.len() != m.obs.len() {
        return ex.clone();
    }
    // The factor on the inter-reflected part that turns the prediction into the
    // re-simulation: exact = cal tau (ind k local_ind + local dir) (see Model::finish).
    let w = m.weights(&chosen);
    let parts = m.parts(&w);
    let corr: Vec<f64> = m
        .obs
        .iter()
        .zip(&parts)
        .zip(exact)
        .map(|((o, &(ind, dir)), x)| {
            let scale = w.cal[o.sensor] * w.tau;
            let ind = ind * w.local_ind[o.sensor];
            let k = (x / scale - w.local[o.sensor] * dir) / ind;
            if scale > 0.0 && ind > 1e-9 && k.is_finite() {
                k.clamp(0.2, 5.0)
            } else {
                1.0
            }
        })
        .collect();
    let mut f = Fitter::new(m, sigma_sensor).with_correction(corr);
    // The correction holds for the re-simulated profile's distance only.
    f.skyline_distance = chosen.iter().find_map(|e| match e {
        Effect::Skyline { distance, .. } => Some(*distance),
        _ => None,
    });
    for _ in 0..2 {
        for i in 0..chosen.len() {
            let fam = chosen[i].family();
            let others = without(&chosen, fam);
            // A furniture panel moves from where it is (see effects::local::refit).
            if let Some(e) = effects::local::refit(&f, &others, &chosen[i])
                .or_else(|| fit_family(&f, &others, fam))
            {
                chosen[i] = e;
            }
        }
    }
    let ids: Vec<String> = m.sensors.iter().map(|s| s.id.clone()).collect();
    let windows: Vec<String> = m.room.windows.iter().map(|w| w.id.clone()).collect();
    let mut out = ex.clone();
    // Neither forward selection nor the backward check under the correction: a factor
    // made for the kept effects is no guide to others, nor to dropping one of them (both
    // tried: in the sunny office one added a local obstruction and a steep narrow
    // obstruction to an overhang, the other dropped the obstruction it was made with).
    for (i, (c, e)) in out.selected.iter_mut().zip(&chosen).enumerate() {
        c.effect = e.clone();
        c.spec = e.spec(&ids, &windows);
        c.params = e.named_params(&ids, &windows);
        c.description = e.describe(&ids, &windows);
        let (p, v) = e.primary();
        c.parameter = p.to_string();
        c.value = v;
        c.uncertainty = f.uncertainty(&chosen, i, step_for(e));
    }
    let sim = f.predict(&chosen);
    out.final_score = f.score_sim(&sim);
    out.final_stats = stats_of(m, &sim);
    out.final_sim = sim;
    out.specs = out.selected.iter().map(|c| c.spec.clone()).collect();
    out.verdict = verdict(
        &out.selected,
        &out.base,
        &out.base_score,
        &out.final_stats,
        &out.final_score,
        sigma_sensor,
    );
    out
}

/// [`refine`] `rounds` times, each against `simulate(effects)`: the re-simulated readings
/// of the model with `effects` applied (see [`simulate_applied`]). Nothing to refine when
/// only sensor factors are kept.
pub fn refined(
    m: &Model,
    ex: Explanation,
    sigma_sensor: f64,
    rounds: usize,
    simulate: &dyn Fn(&[Effect]) -> crate::error::Result<Vec<f64>>,
) -> crate::error::Result<Explanation> {
    let mut ex = ex;
    for _ in 0..rounds {
        let effects: Vec<Effect> = ex.selected.iter().map(|c| c.effect.clone()).collect();
        if effects
            .iter()
            .all(|e| matches!(e, Effect::SensorFault { .. }))
        {
            break;
        }
        let exact = simulate(&effects)?;
        ex = refine(m, &ex, &exact, sigma_sensor);
    }
    Ok(ex)
}

/// The readings of `scene` with `effects` applied as `rcalib apply` writes them
/// (geometry and materials re-simulated with `opts`; sensor faults as factors on the
/// simulation, as [`Model::predict`] applies them).
pub fn simulate_applied(
    scene: &crate::scene::Scene,
    m: &Model,
    weather: &crate::formats::weather::Weather,
    readings: &[super::measurements::Bound],
    opts: &super::session::Options,
    effects: &[Effect],
) -> crate::error::Result<Vec<f64>> {
    let (faults, geometric): (Vec<Effect>, Vec<Effect>) = effects
        .iter()
        .cloned()
        .partition(|e| matches!(e, Effect::SensorFault { .. }));
    let text = super::apply::apply(scene, &m.room, &m.sensors, &geometric, "refinement")?;
    let applied = crate::scene::parse_str(
        &text,
        "<applied>",
        std::path::Path::new(""),
        &crate::scene::LoadOptions::default(),
    )?;
    let opts = super::session::Options {
        reflectance: false,
        ..opts.clone()
    };
    let am = super::session::build(&applied, m.sensors.clone(), weather, readings, &opts)?;
    Ok(am.predict(&faults))
}
