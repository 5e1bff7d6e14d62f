//! The hit-rate table of `rcalib explain` on hidden-effect cases: every hidden effect of
//! [`hidden_effects`] in every room and climate. Slow (minutes): `cargo test --release
//! --test rcalib_hits -- --ignored --nocapture`, or `benches/rcalib_hits.sh`.

use rdaylight::calib::cases::*;
use rdaylight::calib::score::DEFAULT_SENSOR_SIGMA;
use rdaylight::calib::session::Options;
use rdaylight::calib::simulate::Settings;
use rdaylight::formats::weather::Weather;

fn london() -> Weather {
    Weather::read_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/weather/GBR_London.Gatwick.037760_IWEC.epw"
    ))
    .unwrap()
}

#[test]
#[ignore]
fn hit_rate_table() {
    let only = std::env::var("RCALIB_ONLY").ok();
    let cache = std::env::temp_dir().join("rcalib-hits-cache");
    let mut settings = Settings::model();
    if let Some(mf) = std::env::var("RCALIB_MF").ok().and_then(|s| s.parse().ok()) {
        settings.mf = mf;
    }
    let opts = Options {
        cache: Some(cache.clone()),
        settings: settings.clone(),
        ..Options::default()
    };
    let steps: usize = std::env::var("RCALIB_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    println!(
        "| room | climate | hidden | ranked first / selected | hit | RMSE_rel before | after apply | noise-only | after/noise | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let (mut hits, mut passes, mut total) = (0, 0, 0);
    // RCALIB_ONLY, RCALIB_ROOM and RCALIB_CLIMATE: comma-separated substrings of the
    // effect, room and climate names to keep (quick subsets of the table).
    let keep = |var: &Option<String>, name: &str| {
        var.as_deref()
            .is_none_or(|o| o.split(',').any(|x| name.contains(x)))
    };
    let only_room = std::env::var("RCALIB_ROOM").ok();
    let only_climate = std::env::var("RCALIB_CLIMATE").ok();
    for kind in RoomKind::ALL {
        for climate in [Climate::London, Climate::Sunny] {
            if !keep(&only_room, kind.name()) || !keep(&only_climate, climate.name()) {
                continue;
            }
            for (name, hidden) in hidden_effects(kind) {
                if !keep(&only, &name) {
                    continue;
                }
                let w = match climate {
                    Climate::London => london(),
                    Climate::Sunny => sunny_weather(),
                };
                let case = generate(
                    &name,
                    kind,
                    w,
                    hidden,
                    steps,
                    1,
                    &Settings::model(),
                    Some(cache.clone()),
                )
                .unwrap();
                let o = evaluate(&case, &opts, DEFAULT_SENSOR_SIGMA).unwrap();
                total += 1;
                hits += o.hit as usize;
                passes += o.passes(1.3) as usize;
                println!(
                    "| {} | {} | {} | {} / {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1} |",
                    kind.name(),
                    climate.name(),
                    name,
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
                    o.seconds
                );
            }
        }
    }
    println!("\nhits {hits}/{total}; hit and after <= 1.3 x noise: {passes}/{total}");
}
