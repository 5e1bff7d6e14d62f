//! rcalib on rooms it was not built on (issue 22): the hidden-effect cases of
//! `radiance-fixtures/calib-cases/`, written by `make_cases.py` (rooms, effects, sites and
//! sensors of their own, southern hemisphere included) with every reading simulated by
//! real Radiance (`gendaylit` + `rtrace -I`, two independent runs). rcalib sees only what
//! a user has (model, sensors, weather, readings); explain, apply and a re-simulation of
//! the applied model follow, as `make calib-example` runs them.
//!
//! `independent_cases_meet_the_issue_thresholds` runs every case and asserts the issue's
//! thresholds: the hidden effect ranked (and selected) first in >= 90 % of the single-effect
//! cases, every hidden effect found in the combined ones, nothing selected on the controls,
//! and RMSE_rel after apply within 1.3x the noise-only error in >= 80 % of all cases.
//! `make calib-cases` runs it (release; 15-40 min on 2 cores, most of it tracing the
//! models, their refinements and the applied models, cached in
//! `$TMPDIR/rcalib-independent-cache`). It is not in `make test`: the coefficients it needs
//! are about 10 MB per case, too much to commit as a fixture, and tracing them in the test
//! profile would take CI past its 30 minutes.
//!
//! Diagnostics: `cargo test --release --test all rcalib_independent::diagnose -- --ignored
//! --nocapture` with RCALIB_ONLY=name,... (a subset), RCALIB_WORST=1 (the readings the
//! applied model misses most), RCALIB_TARGET_SE=0.005 (the model simulated more finely).

use rdaylight::calib::cases::{Case, Outcome, evaluate};
use rdaylight::calib::score::DEFAULT_SENSOR_SIGMA;
use rdaylight::calib::session::Options;
use std::path::Path;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/radiance-fixtures/calib-cases");

fn case_names(only: Option<&str>) -> Vec<String> {
    // Every case directory (one with a case.json), in name order.
    let mut names: Vec<String> = std::fs::read_dir(DIR)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("case.json").exists())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| only.is_none_or(|o| o.split(',').any(|x| n.contains(x))))
        .collect();
    names.sort();
    names
}

fn cache() -> std::path::PathBuf {
    crate::common::seeded_cache(
        "rcalib-independent-cache",
        &crate::common::repo().join("tests/data/calib-cases-cache"),
    )
}

/// Evaluate `names` (explain, apply, re-simulation) and print the per-case table.
fn table(names: &[String], opts: &Options, worst: bool) -> Vec<Outcome> {
    println!(
        "| case | hidden | ranked first | selected | hit | RMSE_rel before | after | noise-only | after/noise | truth simulated | fitted vs applied | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut out = Vec::new();
    for name in names {
        let case = Case::from_dir(&Path::new(DIR).join(name)).unwrap();
        let o = evaluate(&case, opts, DEFAULT_SENSOR_SIGMA).unwrap();
        println!(
            "| {name} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} | {:.0} |",
            if o.hidden.is_empty() {
                "nothing".to_string()
            } else {
                o.hidden.join("+")
            },
            o.ranking.first().cloned().unwrap_or_default(),
            if o.specs.is_empty() {
                "none".to_string()
            } else {
                o.specs.join(" ")
            },
            if o.hit { "yes" } else { "no" },
            o.rmse_before,
            o.rmse_after,
            o.rmse_noise,
            o.rmse_after / o.rmse_noise,
            o.rmse_sim,
            o.rmse_fit_vs_apply,
            o.seconds
        );
        if worst {
            println!("|   before refinement: {}", o.unrefined.join(" "));
            for w in &o.worst {
                println!("|   worst: {w}");
            }
        }
        out.push(o);
    }
    out
}

/// The issue's thresholds over every committed case (see the module doc).
#[test]
#[ignore]
fn independent_cases_meet_the_issue_thresholds() {
    let names = case_names(None);
    assert!(names.len() >= 14, "cases missing: {names:?}");
    let opts = Options {
        cache: Some(cache()),
        ..Options::default()
    };
    let all = table(&names, &opts, false);
    let single: Vec<&Outcome> = all.iter().filter(|o| o.hidden.len() == 1).collect();
    let combined: Vec<&Outcome> = all.iter().filter(|o| o.hidden.len() > 1).collect();
    let controls: Vec<&Outcome> = all.iter().filter(|o| o.hidden.is_empty()).collect();
    let first = single.iter().filter(|o| o.hit).count();
    let within = all
        .iter()
        .filter(|o| o.rmse_after <= 1.3 * o.rmse_noise)
        .count();
    println!(
        "\nranked first {first}/{}; combined found {}/{}; controls nothing {}/{}; after apply \
         within 1.3x the noise-only error {within}/{}",
        single.len(),
        combined.iter().filter(|o| o.hit).count(),
        combined.len(),
        controls.iter().filter(|o| o.hit).count(),
        controls.len(),
        all.len()
    );
    assert!(!single.is_empty() && !combined.is_empty() && !controls.is_empty());
    assert!(
        10 * first >= 9 * single.len(),
        "hidden effect ranked first in {first}/{}",
        single.len()
    );
    for o in combined.iter().chain(&controls) {
        assert!(
            o.hit,
            "{}: hidden {:?}, selected {:?}",
            o.name, o.hidden, o.selected
        );
    }
    assert!(
        10 * within >= 8 * all.len(),
        "within 1.3x in {within}/{} cases",
        all.len()
    );
}

/// The table for a subset or other settings (see the module doc); asserts only that the
/// subset is not empty: the thresholds are the test above's.
#[test]
#[ignore]
fn diagnose() {
    let only = std::env::var("RCALIB_ONLY").ok();
    let names = case_names(only.as_deref());
    assert!(!names.is_empty(), "no case matched RCALIB_ONLY");
    let mut opts = Options {
        cache: Some(cache()),
        ..Options::default()
    };
    if let Some(se) = std::env::var("RCALIB_TARGET_SE")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        opts.settings.target_se = Some(se);
        opts.settings.max_samples *= 4;
    }
    table(&names, &opts, std::env::var("RCALIB_WORST").is_ok());
}
