//! Sky groundwork vs real Radiance: patch bins (`reinhart.cal`, `reinsrc.cal`), solar
//! position (`gensky`), CIE skies (`gensky`, `skybright.cal`) and Perez skies (`gendaymtx`,
//! `gendaylit`, `perezlum.cal`).

use crate::common;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight::formats::weather::Site;
use rdaylight::sky::patches::SkyPatches;
use rdaylight::sky::solar::{LeapDayTracker, SunPosition, day_of_year};
use std::f64::consts::PI;

/// A site given as gensky's `-a lat -o lon -m meridian` (longitude and meridian in degrees
/// west), converted once into the east-positive [`Site`].
fn west(latitude: f64, longitude_west: f64, meridian_west: f64) -> Site {
    Site {
        latitude_deg_n: latitude,
        longitude_deg_e: -longitude_west,
        meridian_deg_e: -meridian_west,
        ..Site::default()
    }
}

/// Parse whitespace-separated numbers, one row per line, skipping blank lines.
fn numbers(text: &[u8]) -> Vec<Vec<f64>> {
    String::from_utf8_lossy(text)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split_whitespace()
                .map(|w| {
                    w.parse::<f64>()
                        .unwrap_or_else(|_| panic!("not a number: {l}"))
                })
                .collect()
        })
        .collect()
}

fn random_unit(rng: &mut Pcg64) -> [f64; 3] {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random_range(0.0..2.0 * PI);
    let r = (1.0 - z * z).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Median and maximum of a list of non-negative errors.
fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(|a, b| a.total_cmp(b));
    if v.is_empty() {
        return (0.0, 0.0);
    }
    (v[v.len() / 2], v[v.len() - 1])
}

// ---------------------------------------------------------------------------------------
// Patches
// ---------------------------------------------------------------------------------------

#[test]
fn patch_counts_match_gendaymtx_rows() {
    for (mf, rows) in [(1, 146), (2, 578), (4, 2306), (6, 5186)] {
        let p = SkyPatches::new(mf);
        assert_eq!(p.len(), rows, "MF {mf}");
        assert_eq!(p.sky_len(), 144 * mf * mf + 1);
        assert_eq!(p.row_of(0), None);
        assert_eq!(p.row_of(1), Some(0));
        assert_eq!(p.row_of(p.zenith()), Some(7 * mf));
        assert_eq!(p.row_of(p.len()), None);
    }
    // Tregenza: rows of 30,30,24,24,18,12,6 then the zenith.
    let p = SkyPatches::new(1);
    let per_row: Vec<usize> = (0..=7).map(|r| p.row_len(r)).collect();
    assert_eq!(per_row, [30, 30, 24, 24, 18, 12, 6, 1]);
    assert_eq!(p.row_of(30), Some(0));
    assert_eq!(p.row_of(31), Some(1));
    assert_eq!(p.row_of(144), Some(6));
}

#[test]
fn sky_solid_angles_sum_to_2pi() {
    for mf in 1..=8 {
        let p = SkyPatches::new(mf);
        let sum: f64 = (1..p.len()).map(|i| p.solid_angle(i)).sum();
        assert!((sum - 2.0 * PI).abs() < 1e-12, "MF {mf}: {sum}");
        assert_eq!(p.solid_angle(0), 2.0 * PI);
    }
}

#[test]
fn centres_and_samples_map_back_to_their_bin() {
    let mut rng = Pcg64::seed_from_u64(7);
    for mf in [1, 2, 4, 6] {
        let p = SkyPatches::new(mf);
        for i in 0..p.len() {
            if i > 0 {
                assert_eq!(p.bin_of(p.centre(i)), i, "centre of {i}, MF {mf}");
            }
            let edges = [0.0, 1e-17, 0.5, 1.0 - 1e-16, 1.0];
            for &u in &edges {
                for &v in &edges {
                    let d = p.sample(i, u, v);
                    assert!((dot(d, d) - 1.0).abs() < 1e-12);
                    assert_eq!(p.bin_of(d), i, "sample({i}, {u}, {v}) MF {mf}: {d:?}");
                }
            }
            for _ in 0..20 {
                let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
                assert_eq!(
                    p.bin_of(p.sample(i, u, v)),
                    i,
                    "sample({i}, {u}, {v}) MF {mf}"
                );
            }
        }
    }
}

#[test]
fn samples_are_uniform_by_solid_angle() {
    // The mean of z over a row patch sampled uniformly by solid angle is
    // (sin^2 hi - sin^2 lo) / (2 (sin hi - sin lo)); a sampler uniform in altitude misses it.
    let p = SkyPatches::new(1);
    let mut rng = Pcg64::seed_from_u64(3);
    let i = 1; // row 0: 0-12 deg
    let n = 200_000;
    let mean: f64 = (0..n)
        .map(|_| p.sample(i, rng.random(), rng.random())[2])
        .sum::<f64>()
        / n as f64;
    let (s0, s1) = (0.0f64, 12f64.to_radians().sin());
    let expect = (s1 * s1 - s0 * s0) / (2.0 * (s1 - s0));
    assert!((mean - expect).abs() < 5e-4, "{mean} vs {expect}");
    // Ground: mean z over the lower hemisphere = -1/2.
    let mean: f64 = (0..n)
        .map(|_| p.sample(0, rng.random(), rng.random())[2])
        .sum::<f64>()
        / n as f64;
    assert!((mean + 0.5).abs() < 5e-3, "{mean}");
}

#[test]
fn bin_of_boundaries_follow_reinhart_cal() {
    let p = SkyPatches::new(1);
    assert_eq!(
        p.bin_of([0.0, 1.0, 0.0]),
        1,
        "horizon north is row 0, not ground"
    );
    assert_eq!(p.bin_of([0.0, 1.0, -1e-12]), 0);
    assert_eq!(p.bin_of([0.0, 0.0, 1.0]), 145);
    // Row 0 has 12 deg patches; 6 deg east of north is the edge -> patch 2.
    let d =
        |alt: f64, azi: f64| rdaylight::sky::patches::direction(alt.to_radians(), azi.to_radians());
    assert_eq!(p.bin_of(d(5.0, 6.0 + 1e-9)), 2);
    assert_eq!(p.bin_of(d(5.0, 5.9)), 1);
    // The wrap sliver: 359.9999 - 6 deg and above belongs to patch 0 (index 1).
    assert_eq!(p.bin_of(d(5.0, 353.99995)), 1);
    assert_eq!(p.bin_of(d(5.0, 353.9998)), 30);
}

/// Real `rcalc -f reinhart.cal` bins for `dirs`.
fn real_rbin(mf: usize, dirs: &[[f64; 3]]) -> Vec<usize> {
    let mut input = String::new();
    for d in dirs {
        input.push_str(&format!("{:.17e} {:.17e} {:.17e}\n", d[0], d[1], d[2]));
    }
    let out = common::run_ok(
        common::radiance("rcalc").args([
            "-e",
            &format!("Dx=$1;Dy=$2;Dz=$3;MF:{mf}"),
            "-f",
            "reinhart.cal",
            "-e",
            "$1=rbin",
        ]),
        input.as_bytes(),
    );
    numbers(&out).iter().map(|r| r[0] as usize).collect()
}

#[test]
fn live_bin_of_matches_reinhart_cal() {
    if !common::have_radiance("live_bin_of_matches_reinhart_cal") {
        return;
    }
    let mut rng = Pcg64::seed_from_u64(11);
    for mf in [1, 2, 4] {
        let p = SkyPatches::new(mf);
        let mut dirs: Vec<[f64; 3]> = (0..4000).map(|_| random_unit(&mut rng)).collect();
        // Directions on and next to every nominal boundary, plus centres.
        for i in 1..p.len() {
            dirs.push(p.centre(i));
            dirs.push(p.sample(i, 0.0, 0.0));
            dirs.push(p.sample(i, 1.0, 1.0));
            let (alt, azi) = p.centre_angles(i);
            let half = PI / p.row_len(p.row_of(i).unwrap()) as f64;
            dirs.push(rdaylight::sky::patches::direction(alt, azi + half));
            dirs.push(rdaylight::sky::patches::direction(alt, azi - half));
            dirs.push(rdaylight::sky::patches::direction(
                alt - p.alpha() / 2.0,
                azi,
            ));
        }
        let real = real_rbin(mf, &dirs);
        assert_eq!(real.len(), dirs.len());
        let mut mismatches = 0;
        for (k, (d, &r)) in dirs.iter().zip(&real).enumerate() {
            let ours = p.bin_of(*d);
            if ours != r {
                // Allowed only within 1e-9 of a boundary (libm asin/atan2 may differ in the
                // last bit from rcalc's): a nudge of at most 1e-9 must reach rcalc's bin.
                let near = (0..=40).any(|s| {
                    let e = 1e-9 * (s as f64 - 20.0) / 20.0;
                    (0..3).any(|c| {
                        let mut t = *d;
                        t[c] += e;
                        p.bin_of(t) == r
                    })
                });
                assert!(near, "MF {mf}: {d:?}: ours {ours}, reinhart.cal {r}");
                assert!(k >= 4000, "MF {mf}: random direction {d:?} on a boundary?");
                eprintln!("  boundary case {d:?}: ours {ours}, reinhart.cal {r}");
                mismatches += 1;
            }
        }
        eprintln!(
            "MF {mf}: {} directions ({} on constructed boundaries), {mismatches} boundary \
             mismatches vs reinhart.cal",
            dirs.len(),
            dirs.len() - 4000
        );
    }
}

#[test]
fn live_centres_and_solid_angles_match_reinsrc_cal() {
    if !common::have_radiance("live_centres_and_solid_angles_match_reinsrc_cal") {
        return;
    }
    for mf in [1, 2, 4] {
        let p = SkyPatches::new(mf);
        let out = common::run_ok(common::radiance("cnt").arg(p.len().to_string()), b"");
        let out = common::run_ok(
            common::radiance("rcalc").args([
                "-e",
                &format!("MF:{mf}"),
                "-f",
                "reinsrc.cal",
                "-e",
                "Rbin=$1;$1=Dx;$2=Dy;$3=Dz;$4=Romega",
                "-e",
                "$5=Rmax",
            ]),
            &out,
        );
        let rows = numbers(&out);
        assert_eq!(rows.len(), p.len());
        let (mut ddir, mut dom) = (0f64, 0f64);
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(r[4] as usize, p.len() - 1, "Rmax");
            let ours = p.reinsrc_dir(i, 0.5, 0.5);
            let centre = p.centre(i);
            for k in 0..3 {
                ddir = ddir.max((ours[k] - r[k]).abs());
                if i > 0 {
                    ddir = ddir.max((centre[k] - r[k]).abs());
                }
            }
            dom = dom.max((p.solid_angle(i) - r[3]).abs() / r[3]);
        }
        eprintln!("MF {mf}: reinsrc.cal max |ddir| {ddir:.2e}, max rel dOmega {dom:.2e}");
        // rcalc prints 9 significant digits.
        assert!(ddir < 2e-9, "MF {mf}: {ddir}");
        assert!(dom < 1e-8, "MF {mf}: {dom}");
        // reinsrc's ground "centre" is 30 deg below the southern horizon.
        assert!((rows[0][2] + 0.5).abs() < 1e-9 && (rows[0][1] + 0.75f64.sqrt()).abs() < 1e-8);
    }
}

// ---------------------------------------------------------------------------------------
// Solar position
// ---------------------------------------------------------------------------------------

/// Solar altitude/azimuth (degrees, as printed) and the sun direction from real gensky.
fn real_gensky(args: &[String]) -> (Vec<f64>, Option<[f64; 3]>, String) {
    let out = common::run_ok(common::radiance("gensky").args(args), b"");
    let text = String::from_utf8_lossy(&out).to_string();
    let mut alt_azi = vec![];
    let mut dir = None;
    let lines: Vec<&str> = text.lines().collect();
    for (k, l) in lines.iter().enumerate() {
        if let Some(rest) = l.strip_prefix("# Solar altitude and azimuth:") {
            alt_azi = rest
                .split_whitespace()
                .map(|w| w.parse().unwrap())
                .collect();
        }
        if l.starts_with("solar source sun") {
            let v: Vec<f64> = lines[k + 3]
                .split_whitespace()
                .map(|w| w.parse().unwrap())
                .collect();
            dir = Some([v[1], v[2], v[3]]);
        }
    }
    (alt_azi, dir, text)
}

#[test]
fn live_solar_position_matches_gensky() {
    if !common::have_radiance("live_solar_position_matches_gensky") {
        return;
    }
    let site = west(51.15, 0.18, 0.0);
    let mut rng = Pcg64::seed_from_u64(5);
    let (mut dang, mut ddir, mut ndir) = (0f64, 0f64, 0);
    for k in 0..50 {
        let month: u32 = rng.random_range(1..=12);
        let day: u32 = rng.random_range(1..=28);
        let hour: f64 = (rng.random_range(5.0..19.0f64) * 100.0).round() / 100.0;
        let solar = k % 10 == 9;
        let year = (k % 7 == 3).then_some(2000 + k);
        let mut args = vec![
            month.to_string(),
            day.to_string(),
            format!("{}{hour}", if solar { "+" } else { "" }),
        ];
        if let Some(y) = year {
            args.extend(["-y".to_string(), y.to_string()]);
        }
        args.extend(["-a", "51.15", "-o", "0.18", "-m", "0"].map(String::from));
        let (alt_azi, dir, text) = real_gensky(&args);
        let pos = SunPosition::gensky(&site, month, day, hour, solar, year);
        let (alt, azi) = (pos.altitude.to_degrees(), pos.azimuth.to_degrees());
        // gensky prints %.1f: agreement within half a unit in the last place (+ rounding).
        dang = dang
            .max((alt - alt_azi[0]).abs())
            .max((azi - alt_azi[1]).abs());
        assert!(
            (alt - alt_azi[0]).abs() <= 0.05 + 1e-9 && (azi - alt_azi[1]).abs() <= 0.05 + 1e-9,
            "{args:?}: ours {alt:.4} {azi:.4}\n{text}"
        );
        if let Some(real) = dir {
            if pos.altitude < 87f64.to_radians() {
                let ours = pos.direction();
                for c in 0..3 {
                    ddir = ddir.max((ours[c] - real[c]).abs());
                }
                ndir += 1;
            }
        }
    }
    eprintln!(
        "gensky: max |d angle| {dang:.3} deg (printed %.1f), {ndir} directions max {ddir:.2e}"
    );
    assert!(ndir > 20);
    // Directions are printed with %f (6 decimals).
    assert!(ddir <= 5e-7 + 1e-12, "{ddir}");
}

#[test]
fn leap_day_follows_gendaymtx() {
    let mut t = LeapDayTracker::new();
    assert_eq!(t.day_of_year(2, 28), 59);
    assert_eq!(t.day_of_year(2, 29), 60);
    assert_eq!(t.day_of_year(3, 1), 61);
    assert_eq!(t.day_of_year(12, 31), 366);
    assert_eq!(day_of_year(3, 1), 60);
    assert_eq!(day_of_year(12, 31), 365);
}

// ---------------------------------------------------------------------------------------
// CIE skies (gensky, skybright.cal)
// ---------------------------------------------------------------------------------------

use rdaylight::sky::cie::{Brightness, CieSky, CieSkyDescription, GenskyOptions, skybright};

/// gensky argument lists and the matching options.
fn gensky_cases() -> Vec<(Vec<&'static str>, GenskyOptions)> {
    let o = GenskyOptions::default();
    vec![
        (vec!["3", "21", "12"], o),
        (
            vec!["6", "21", "13.5", "-s"],
            GenskyOptions { sun: false, ..o },
        ),
        (
            vec!["12", "5", "9.25", "+s", "-t", "4"],
            GenskyOptions {
                turbidity: 4.0,
                ..o
            },
        ),
        (vec!["6", "21", "12", "+s"], o), // near the 87 deg cap? (no: London)
        (
            vec!["9", "1", "16", "-c"],
            GenskyOptions {
                sky: CieSky::Overcast,
                sun: false,
                ..o
            },
        ),
        (
            vec!["1", "10", "11", "-u", "-g", "0.35"],
            GenskyOptions {
                sky: CieSky::Uniform,
                ground_reflectance: 0.35,
                ..o
            },
        ),
        (
            vec!["4", "30", "8", "+i"],
            GenskyOptions {
                sky: CieSky::Intermediate,
                ..o
            },
        ),
        (
            vec!["10", "3", "14", "-i"],
            GenskyOptions {
                sky: CieSky::Intermediate,
                sun: false,
                ..o
            },
        ),
        (
            vec!["3", "21", "12", "-c", "-B", "100"],
            GenskyOptions {
                sky: CieSky::Overcast,
                zenith: Brightness::Irradiance(100.0),
                ..o
            },
        ),
        (
            vec!["5", "17", "10", "+s", "-b", "22", "-r", "5e6"],
            GenskyOptions {
                zenith: Brightness::Radiance(22.0),
                solar: Brightness::Radiance(5e6),
                ..o
            },
        ),
        (
            vec!["8", "8", "15", "+s", "-B", "80", "-R", "600"],
            GenskyOptions {
                zenith: Brightness::Irradiance(80.0),
                solar: Brightness::Irradiance(600.0),
                ..o
            },
        ),
        (
            vec!["7", "4", "+12", "+i", "-g", "0.1"],
            GenskyOptions {
                sky: CieSky::Intermediate,
                ground_reflectance: 0.1,
                ..o
            },
        ),
        (vec!["2", "14", "17.5", "+s"], o), // sun low
        (vec!["11", "20", "7", "+s"], o),   // sun below the horizon
    ]
}

#[test]
fn live_cie_description_matches_gensky() {
    if !common::have_radiance("live_cie_description_matches_gensky") {
        return;
    }
    let site = west(51.15, 0.18, 0.0);
    let mut site_args = vec!["-a", "51.15", "-o", "0.18", "-m", "0"];
    let mut exact = 0;
    let cases = gensky_cases();
    for (args, o) in &cases {
        let mut all: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        all.extend(site_args.iter().map(|s| s.to_string()));
        let (_, _, text) = real_gensky(&all);
        let hour: f64 = args[2].trim_start_matches('+').parse().unwrap();
        let (_, sky) = CieSkyDescription::for_date(
            &site,
            args[0].parse().unwrap(),
            args[1].parse().unwrap(),
            hour,
            args[2].starts_with('+'),
            None,
            o,
        );
        // Comment lines: ground ambient level.
        let amb = text
            .lines()
            .find_map(|l| l.strip_prefix("# Ground ambient level: "))
            .unwrap();
        assert_eq!(amb, format!("{:.1}", sky.ambient), "{args:?}\n{text}");
        // Scene text after the comments.
        let body: String = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| format!("{l}\n"))
            .collect();
        let ours = sky.to_rad();
        if body == ours {
            exact += 1;
        } else {
            // Allow one unit in the last printed place (binary rounding of a tie).
            let a = numbers_loose(&body);
            let b = numbers_loose(&ours);
            assert_eq!(a.len(), b.len(), "{args:?}\nreal:\n{body}\nours:\n{ours}");
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x - y).abs() <= 1.001e-6 + 1.001e-3 * x.abs(),
                    "{args:?}\nreal:\n{body}\nours:\n{ours}"
                );
            }
        }
    }
    eprintln!(
        "gensky: {exact}/{} descriptions textually identical",
        cases.len()
    );
    assert!(exact * 10 >= cases.len() * 9, "only {exact} exact");
    site_args.clear();
}

/// Every token that parses as a number, in order.
fn numbers_loose(s: &str) -> Vec<f64> {
    s.split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// Evaluate a real `.cal` sky function with `rcalc -od` on `dirs`.
fn real_cal(file: &str, func: &str, args: &[f64], dirs: &[[f64; 3]]) -> Vec<f64> {
    let mut defs = String::from(
        "Dx=$1;Dy=$2;Dz=$3;bound(a,x,b):if(a-x,a,if(x-b,b,x));\
         Acos(x):acos(bound(-1,x,1));Exp(x):if(-x-100,0,exp(x));",
    );
    for (i, a) in args.iter().enumerate() {
        defs.push_str(&format!("A{}={:.17e};", i + 1, a));
    }
    let mut input = String::new();
    for d in dirs {
        input.push_str(&format!("{:.17e} {:.17e} {:.17e}\n", d[0], d[1], d[2]));
    }
    let out = common::run_ok(
        common::radiance("rcalc").args([
            "-od",
            "-e",
            &defs,
            "-f",
            file,
            "-e",
            &format!("$1={func}"),
        ]),
        input.as_bytes(),
    );
    out.chunks_exact(8)
        .map(|c| f64::from_ne_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn live_skybright_matches_skybright_cal() {
    if !common::have_radiance("live_skybright_matches_skybright_cal") {
        return;
    }
    let mut rng = Pcg64::seed_from_u64(17);
    let mut dirs: Vec<[f64; 3]> = (0..3000).map(|_| random_unit(&mut rng)).collect();
    dirs.extend([
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.6, 0.0, 0.008],
    ]);
    let mut all_rel = vec![];
    for (args, _) in gensky_cases() {
        let mut a: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        a.extend(["-a", "51.15", "-o", "0.18", "-m", "0"].map(String::from));
        let (_, _, text) = real_gensky(&a);
        // The printed skybright arguments (after "0" real-args count line: "n A1 ...").
        let line = text.lines().last().unwrap();
        let v = numbers_loose(line);
        let fargs = &v[1..];
        assert_eq!(v[0] as usize, fargs.len());
        let real = real_cal("skybright.cal", "skybr", fargs, &dirs);
        assert_eq!(real.len(), dirs.len());
        let mut rel = vec![];
        for (d, r) in dirs.iter().zip(&real) {
            let ours = skybright(*d, fargs);
            let e = (ours - r).abs() / r.abs().max(1e-30);
            // rcalc -od evaluates the same double formulas (measured max 7e-16).
            assert!(e < 1e-9, "{args:?} {d:?}: ours {ours}, skybright.cal {r}");
            rel.push(e);
        }
        all_rel.extend(rel);
    }
    let (med, max) = stats(all_rel);
    eprintln!("skybright.cal: median rel diff {med:.2e}, max {max:.2e}");
}

#[test]
fn cie_uniform_sky_irradiance_is_pi_l() {
    // Oracle: gensky -u -B E makes a sky of radiance E / pi (horizontal irradiance E), except
    // that skybright.cal blends toward the ground brightness close to the horizon.
    let sky = CieSkyDescription::new(
        0.5,
        0.0,
        &GenskyOptions {
            sky: CieSky::Uniform,
            zenith: Brightness::Irradiance(100.0),
            ..GenskyOptions::default()
        },
    );
    assert!((sky.radiance([0.0, 0.0, 1.0]) - 100.0 / PI).abs() < 1e-3);
    assert!((sky.ground - 0.2 * 100.0 / PI).abs() < 1e-12);
    let n = 20000;
    let e: f64 = (0..n)
        .map(|k| {
            let z = (k as f64 + 0.5) / n as f64;
            2.0 * PI * sky.radiance([(1.0 - z * z).sqrt(), 0.0, z]) * z / n as f64
        })
        .sum();
    // The blend removes a few per cent near the horizon, never adds.
    assert!(e < 100.0 && e > 97.0, "{e}");
}

// ---------------------------------------------------------------------------------------
// Perez skies (gendaymtx, gendaylit, perezlum.cal)
// ---------------------------------------------------------------------------------------

use rdaylight::sky::perez::{
    GENDAYMTX_GROUND_REFLECTANCE, GENDAYMTX_SKY_COLOUR, InputUnits, PerezOptions, TimeStep,
    perez_sky_vector, perezlum,
};

/// The bundled real weather file (London Gatwick IWEC), relative to the repository.
fn epw_path() -> std::path::PathBuf {
    common::repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw")
}

/// A WEA file made by real `epw2wea` from the London EPW, optionally cut to some days
/// (month, day) and rewritten to other units. Returns (header lines, records).
/// A WEA data record: month, day, hour, direct, diffuse.
type WeaRecord = (u32, u32, f64, f64, f64);

fn london_wea(dir: &std::path::Path, days: Option<&[(u32, u32)]>) -> (Vec<String>, Vec<WeaRecord>) {
    let epw_buf = epw_path();
    let epw = epw_buf.as_path();
    assert!(epw.exists(), "weather file {} missing", epw.display());
    let full = dir.join("full.wea");
    common::run_ok(common::radiance("epw2wea").arg(epw).arg(&full), b"");
    let text = std::fs::read_to_string(&full).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<String> = lines[..6].iter().map(|s| s.to_string()).collect();
    let recs = lines[6..]
        .iter()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v = numbers_loose(l);
            (v[0] as u32, v[1] as u32, v[2], v[3], v[4])
        })
        .filter(|r| days.is_none_or(|d| d.contains(&(r.0, r.1))))
        .collect();
    (header, recs)
}

fn write_wea(
    path: &std::path::Path,
    header: &[String],
    units: u32,
    recs: &[WeaRecord],
    scale: f64,
) {
    let mut s = String::new();
    for h in header {
        if h.starts_with("weather_data_file_units") {
            s.push_str(&format!("weather_data_file_units {units}\n"));
        } else {
            s.push_str(h);
            s.push('\n');
        }
    }
    for r in recs {
        s.push_str(&format!(
            "{} {} {} {} {}\n",
            r.0,
            r.1,
            r.2,
            r.3 * scale,
            r.4 * scale
        ));
    }
    std::fs::write(path, s).unwrap();
}

fn header_value(header: &[String], key: &str) -> f64 {
    header
        .iter()
        .find_map(|h| h.strip_prefix(key))
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

/// Real gendaymtx `-of` output as [step][patch][channel].
fn real_gendaymtx(args: &[&str], wea: &std::path::Path) -> Vec<Vec<[f64; 3]>> {
    let out = common::run_ok(
        common::radiance("gendaymtx").args(args).arg("-of").arg(wea),
        b"",
    );
    let end = out.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let head = String::from_utf8_lossy(&out[..end]).to_string();
    let get = |k: &str| -> usize {
        head.lines()
            .find_map(|l| l.strip_prefix(k))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let (nrows, ncols) = (get("NROWS="), get("NCOLS="));
    assert!(head.contains("BigEndian=0"), "{head}");
    let f: Vec<f64> = out[end..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
        .collect();
    assert_eq!(f.len(), nrows * ncols * 3);
    (0..ncols)
        .map(|t| {
            (0..nrows)
                .map(|p| {
                    let o = (p * ncols + t) * 3;
                    [f[o], f[o + 1], f[o + 2]]
                })
                .collect()
        })
        .collect()
}

/// Compare our columns with gendaymtx's: every value above 1 % of its step's maximum.
/// Returns (median, max) relative difference and the number of values compared.
fn compare_columns(
    real: &[Vec<[f64; 3]>],
    ours: &[Vec<[f64; 3]>],
    what: &str,
    tol: f64,
) -> (f64, f64, usize) {
    assert_eq!(real.len(), ours.len(), "{what}: step count");
    let mut rel = vec![];
    for (t, (r, o)) in real.iter().zip(ours).enumerate() {
        assert_eq!(r.len(), o.len());
        let max = r.iter().flatten().fold(0f64, |a, &b| a.max(b));
        for (p, (rv, ov)) in r.iter().zip(o).enumerate() {
            for c in 0..3 {
                if rv[c] > 0.01 * max {
                    let e = (ov[c] - rv[c]).abs() / rv[c];
                    assert!(
                        e < tol,
                        "{what}: step {t} patch {p} channel {c}: ours {}, gendaymtx {}",
                        ov[c],
                        rv[c]
                    );
                    rel.push(e);
                } else {
                    // Small values: absolute agreement relative to the step maximum.
                    assert!(
                        (ov[c] - rv[c]).abs() <= 0.01 * max.max(1e-6) + 1e-6,
                        "{what}: step {t} patch {p} channel {c}: ours {}, gendaymtx {}",
                        ov[c],
                        rv[c]
                    );
                }
            }
        }
    }
    let n = rel.len();
    let (med, max) = stats(rel);
    eprintln!("{what}: {n} values, median rel diff {med:.2e}, max {max:.2e}");
    (med, max, n)
}

struct Variant {
    args: Vec<&'static str>,
    mf: usize,
    options: PerezOptions,
    sky: [f64; 3],
    ground: [f64; 3],
    sun: [f64; 3],
}

fn variant(args: &[&'static str], mf: usize) -> Variant {
    let mut v = Variant {
        args: args.to_vec(),
        mf,
        options: PerezOptions::default(),
        sky: GENDAYMTX_SKY_COLOUR,
        ground: GENDAYMTX_GROUND_REFLECTANCE,
        sun: [1.0; 3],
    };
    let mut i = 0;
    while i < args.len() {
        match args[i] {
            "-d" => {
                v.sky = [0.0; 3];
                v.ground = [0.0; 3];
            }
            "-s" => v.sun = [0.0; 3],
            "-5" => {
                v.options.five_phase_sun_deg = Some(args[i + 1].parse().unwrap());
                i += 1;
            }
            "-r" => {
                v.options.rotation_deg = args[i + 1].parse().unwrap();
                i += 1;
            }
            "-O1" => v.options.solar_radiance = true,
            "-i" => {
                v.options.interval_minutes = args[i + 1].parse().unwrap();
                i += 1;
            }
            "-c" | "-g" => {
                let c: [f64; 3] = std::array::from_fn(|k| args[i + 1 + k].parse().unwrap());
                if args[i] == "-c" {
                    v.sky = c
                } else {
                    v.ground = c
                }
                i += 3;
            }
            "-m" => i += 1,
            other => panic!("variant option {other}"),
        }
        i += 1;
    }
    v
}

fn our_gendaymtx(
    v: &Variant,
    header: &[String],
    units: InputUnits,
    recs: &[WeaRecord],
    scale: f64,
) -> Vec<Vec<[f64; 3]>> {
    let site = west(
        header_value(header, "latitude"),
        header_value(header, "longitude"),
        header_value(header, "time_zone"),
    );
    let patches = SkyPatches::new(v.mf);
    let mut leap = LeapDayTracker::new();
    recs.iter()
        .map(|&(m, d, h, dir, dif)| {
            let mut step = TimeStep::new(m, d, h, dir * scale, dif * scale);
            step.jd = leap.day_of_year(m, d);
            step.units = units;
            let col = perez_sky_vector(&patches, &step, &site, &v.options)
                .to_channels(&v.sky, &v.ground, &v.sun);
            col.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        })
        .collect()
}

#[test]
fn live_perez_matches_gendaymtx_three_days() {
    if !common::have_radiance("live_perez_matches_gendaymtx_three_days") {
        return;
    }
    let tmp = common::tmpdir();
    let days = [(1, 17), (4, 22), (7, 9), (10, 14)];
    let (header, recs) = london_wea(tmp.path(), Some(&days));
    assert_eq!(recs.len(), 96);
    let wea = tmp.path().join("days.wea");
    write_wea(&wea, &header, 1, &recs, 1.0);
    let variants = [
        variant(&["-m", "1"], 1),
        variant(&["-m", "1", "-d"], 1),
        variant(&["-m", "1", "-s"], 1),
        variant(&["-m", "1", "-5", "0.533"], 1),
        variant(&["-m", "1", "-d", "-5", "0.533"], 1),
        variant(&["-m", "1", "-r", "30", "-O1"], 1),
        variant(
            &["-m", "1", "-c", "1", "1", "1", "-g", "0.1", "0.3", "0.5"],
            1,
        ),
        variant(&["-m", "1", "-i", "60"], 1),
        variant(&["-m", "4"], 4),
        variant(&["-m", "4", "-d"], 4),
        variant(&["-m", "4", "-s"], 4),
        variant(&["-m", "4", "-5", "0.533"], 4),
    ];
    for v in &variants {
        let real = real_gendaymtx(&v.args, &wea);
        let ours = our_gendaymtx(v, &header, InputUnits::DirectNormalIrradiance, &recs, 1.0);
        let (_, max, n) = compare_columns(&real, &ours, &format!("gendaymtx {:?}", v.args), 1e-2);
        assert!(n > 0);
        // gendaymtx keeps patch angles and results in C float (measured max 2.2e-6
        // relative); 1e-5 still catches any formula or coefficient slip (>= 1e-3).
        assert!(max < 1e-5, "{:?}: max rel diff {max}", v.args);
    }
    // Other WEA units: direct horizontal (2) and photometric (3, values scaled to lux).
    for (units, ours_units, scale) in [
        (2, InputUnits::DirectHorizontalIrradiance, 1.0),
        (3, InputUnits::DirectNormalIlluminance, 110.0),
    ] {
        let wea = tmp.path().join(format!("units{units}.wea"));
        write_wea(&wea, &header, units, &recs, scale);
        let v = variant(&["-m", "1"], 1);
        let real = real_gendaymtx(&v.args, &wea);
        let ours = our_gendaymtx(&v, &header, ours_units, &recs, scale);
        let (_, max, _) = compare_columns(&real, &ours, &format!("gendaymtx units {units}"), 1e-2);
        // gendaymtx keeps patch angles and results in C float (measured max 2.2e-6
        // relative); 1e-5 still catches any formula or coefficient slip (>= 1e-3).
        assert!(max < 1e-5, "units {units}: max rel diff {max}");
    }
}

#[test]
fn live_perez_matches_gendaymtx_full_year() {
    if !common::have_radiance("live_perez_matches_gendaymtx_full_year") {
        return;
    }
    let tmp = common::tmpdir();
    let (header, recs) = london_wea(tmp.path(), None);
    assert_eq!(recs.len(), 8760);
    let wea = tmp.path().join("year.wea");
    write_wea(&wea, &header, 1, &recs, 1.0);
    let v = variant(&["-m", "1"], 1);
    let real = real_gendaymtx(&v.args, &wea);
    let ours = our_gendaymtx(&v, &header, InputUnits::DirectNormalIrradiance, &recs, 1.0);
    // Which clearness categories did the year exercise?
    let site = west(
        header_value(&header, "latitude"),
        header_value(&header, "longitude"),
        header_value(&header, "time_zone"),
    );
    let p = SkyPatches::new(1);
    let mut cats = [0usize; 8];
    for &(m, d, h, dir, dif) in &recs {
        let sv = perez_sky_vector(&p, &TimeStep::new(m, d, h, dir, dif), &site, &v.options);
        if let Some(s) = sv.state {
            cats[s.category] += 1;
        }
    }
    eprintln!("clearness categories over the year: {cats:?}");
    assert!(
        cats.iter().all(|&c| c > 0),
        "every Perez category exercised: {cats:?}"
    );
    let (_, max, _) = compare_columns(&real, &ours, "gendaymtx -m 1 full year", 1e-2);
    // gendaymtx keeps patch angles and results in C float (measured max 2.2e-6
    // relative); 1e-5 still catches any formula or coefficient slip (>= 1e-3).
    assert!(max < 1e-5, "max rel diff {max}");
}

/// gendaylit's skyfunc arguments A1..A10.
fn real_gendaylit(args: &[&str]) -> [f64; 10] {
    let out = common::run_ok(common::radiance("gendaylit").args(args), b"");
    let text = String::from_utf8_lossy(&out);
    let line = text.lines().find(|l| l.starts_with("10 ")).unwrap();
    let v = numbers_loose(line);
    std::array::from_fn(|i| v[i + 1])
}

#[test]
fn live_perezlum_matches_perezlum_cal() {
    if !common::have_radiance("live_perezlum_matches_perezlum_cal") {
        return;
    }
    let mut rng = Pcg64::seed_from_u64(23);
    let mut dirs: Vec<[f64; 3]> = (0..3000).map(|_| random_unit(&mut rng)).collect();
    dirs.extend([
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.6, 0.0, 0.008],
    ]);
    let site = ["-a", "51.15", "-o", "0.18", "-m", "0"];
    let mut all = vec![];
    for cond in [
        ["6", "21", "12.5", "-W", "600", "150"], // clear summer noon
        ["12", "21", "10.5", "-W", "0", "80"],   // overcast winter
        ["4", "2", "17.5", "-W", "250", "200"],  // intermediate, low sun
    ] {
        let mut args: Vec<&str> = cond.to_vec();
        args.extend(site);
        let a = real_gendaylit(&args);
        let sun_dir = [a[7], a[8], a[9]];
        // The sun direction is gensky's for the same date/time.
        let pos = SunPosition::gensky(
            &west(51.15, 0.18, 0.0),
            cond[0].parse().unwrap(),
            cond[1].parse().unwrap(),
            cond[2].parse().unwrap(),
            false,
            None,
        );
        for (ours, real) in pos.direction().iter().zip(sun_dir) {
            assert!((ours - real).abs() < 1e-6, "{cond:?}");
        }
        let real = real_cal("perezlum.cal", "skybright", &a, &dirs);
        for (d, r) in dirs.iter().zip(&real) {
            let ours = perezlum(*d, &a);
            let e = (ours - r).abs() / r.abs().max(1e-30);
            // rcalc -od evaluates the same double formulas (measured max 7e-16).
            assert!(e < 1e-9, "{cond:?} {d:?}: ours {ours}, perezlum.cal {r}");
            all.push(e);
        }
    }
    let (med, max) = stats(all);
    eprintln!("perezlum.cal: median rel diff {med:.2e}, max {max:.2e}");
}

#[test]
fn live_perez_matches_gendaymtx_reading_epw_with_dew_point() {
    // gendaymtx reads EPW directly and then uses a 3-hour running mean of the dew point for
    // the precipitable water (WEA files fall back to 11 deg C): exercises DewPointMean.
    if !common::have_radiance("live_perez_matches_gendaymtx_reading_epw_with_dew_point") {
        return;
    }
    use rdaylight::sky::efficacy::DewPointMean;
    let text = std::fs::read_to_string(epw_path()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let loc: Vec<&str> = lines[0].split(',').collect();
    let site = Site {
        latitude_deg_n: loc[6].trim().parse().unwrap(),
        longitude_deg_e: loc[7].trim().parse().unwrap(),
        meridian_deg_e: Site::meridian_from_hours(loc[8].trim().parse().unwrap()),
        ..Site::default()
    };
    let patches = SkyPatches::new(1);
    let mut dew = DewPointMean::new();
    let mut leap = LeapDayTracker::new();
    let (mut dews, mut ours) = (vec![], vec![]);
    for l in &lines[8..] {
        let f: Vec<&str> = l.split(',').collect();
        let num = |i: usize| f[i].trim().parse::<f64>().unwrap();
        let (m, d, h) = (num(1) as u32, num(2) as u32, num(3) - 1.0 + 0.5);
        let mut step = TimeStep::new(m, d, h, num(14) as f32 as f64, num(15) as f32 as f64);
        step.jd = leap.day_of_year(m, d);
        step.dew_point = dew.next(Some(num(7)));
        dews.push(step.dew_point);
        let col = perez_sky_vector(&patches, &step, &site, &PerezOptions::default()).to_channels(
            &GENDAYMTX_SKY_COLOUR,
            &GENDAYMTX_GROUND_REFLECTANCE,
            &[1.0; 3],
        );
        ours.push(col.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    assert_eq!(ours.len(), 8760);
    let (lo, hi) = dews
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &b| (a.0.min(b), a.1.max(b)));
    assert!(hi - lo > 10.0, "dew point varies over the year: {lo}..{hi}");
    let real = real_gendaymtx(&["-m", "1"], &epw_path());
    let (_, max, _) = compare_columns(&real, &ours, "gendaymtx -m 1 on the EPW", 1e-2);
    // gendaymtx keeps patch angles and results in C float (measured max 2.2e-6
    // relative); 1e-5 still catches any formula or coefficient slip (>= 1e-3).
    assert!(max < 1e-5, "max rel diff {max}");
}

// ---------------------------------------------------------------------------------------
// Oracles and invariants (no Radiance needed)
// ---------------------------------------------------------------------------------------

#[test]
fn solar_position_closed_forms() {
    // jd 81 (22 March) has declination exactly 0; at solar noon the sun is due south at
    // altitude 90 - latitude, and at solar 6:00 it rises due east.
    let site = west(51.15, 0.18, 0.0);
    assert_eq!(rdaylight::sky::solar::declination(81), 0.0);
    let noon = SunPosition::from_declination(&site, 0.0, 12.0);
    assert!((noon.altitude.to_degrees() - (90.0 - 51.15)).abs() < 1e-12);
    assert!(noon.azimuth.abs() < 1e-12);
    let d = noon.direction();
    assert!(d[0].abs() < 1e-12 && d[1] < 0.0, "due south: {d:?}");
    let six = SunPosition::from_declination(&site, 0.0, 6.0);
    assert!(six.altitude.abs() < 1e-12);
    let d = six.direction();
    assert!((d[0] - 1.0).abs() < 1e-12, "due east: {d:?}");
    assert!((six.azimuth_east_of_north(0.0) - PI / 2.0).abs() < 1e-12);
    // gendaymtx -r 90 rotates the sun azimuth by -90 deg.
    assert!(six.azimuth_east_of_north(90.0).abs() < 1e-12);
}

#[test]
fn perez_vector_reproduces_its_illuminances() {
    // By construction: the sky patches integrate (cosine-weighted) to the diffuse horizontal
    // illuminance, the sun patches (radiance x solid angle) to the direct normal
    // illuminance, and the ground is the global horizontal illuminance / pi, all / 179.
    let site = west(51.15, 0.18, 0.0);
    for mf in [1, 2] {
        let p = SkyPatches::new(mf);
        for (m, d, h, dir, dif) in [
            (6, 21, 12.5, 700.0, 120.0),
            (12, 21, 11.5, 0.0, 60.0),
            (3, 10, 8.5, 300.0, 90.0),
        ] {
            let sv = perez_sky_vector(
                &p,
                &TimeStep::new(m, d, h, dir, dif),
                &site,
                &PerezOptions::default(),
            );
            let st = sv.state.unwrap();
            let e_sky: f64 = (1..p.len())
                .map(|i| sv.sky[i] * p.centre_angles(i).0.sin() * p.solid_angle(i))
                .sum();
            assert!((e_sky * 179.0 - st.diff_illum).abs() < 1e-9 * st.diff_illum);
            let e_sun: f64 = sv.sun.iter().map(|&(i, v)| v * p.solid_angle(i)).sum();
            assert!((e_sun * 179.0 - st.dir_illum).abs() < 1e-9 * st.dir_illum.max(1.0));
            assert_eq!(sv.sun.len(), if st.dir_illum > 1e-4 { 4 } else { 0 });
            let alt = sv.sun_position.altitude;
            let g = (st.diff_illum + st.dir_illum * alt.sin().max(0.0)) / PI / 179.0;
            assert!((sv.ground - g).abs() < 1e-12 * g);
            // Colours scale each part independently and keep the channel count generic.
            let five = sv.to_channels(&[1.0; 5], &[0.5; 5], &[0.0; 5]);
            assert_eq!(five.len(), 5 * p.len());
            assert!((five[0] - 0.5 * sv.ground).abs() < 1e-15);
            assert!((five[5 * p.zenith() + 4] - sv.sky[p.zenith()]).abs() < 1e-15);
        }
    }
    // Night: everything zero.
    let sv = perez_sky_vector(
        &SkyPatches::new(1),
        &TimeStep::new(1, 1, 0.5, 0.0, 0.0),
        &site,
        &PerezOptions::default(),
    );
    assert!(sv.state.is_none() && sv.ground == 0.0 && sv.sun.is_empty());
    assert!(sv.sky.iter().all(|&v| v == 0.0));
}

#[test]
fn clearness_categories_and_efficacy_edges() {
    use rdaylight::sky::efficacy::{category, eccentricity, precipitable_water};
    assert_eq!(category(1.0), 0);
    assert_eq!(category(1.0649), 0);
    assert_eq!(category(1.065), 1);
    assert_eq!(category(6.2), 7);
    assert_eq!(category(12.0), 7);
    assert_eq!(category(12.01), 8);
    assert_eq!(category(0.99), 8);
    // Perez 1990 eq. 3 at the 11 deg C default: W = exp(0.695) ~ 2.0 cm (gendaylit prints
    // "2.0000" as the precipitable water).
    assert!((precipitable_water(11.0) - 2.0).abs() < 4e-3);
    // Eccentricity: ~+3.5 % in early January, ~-3.3 % in early July.
    assert!((eccentricity(3.0) - 1.035).abs() < 1e-3);
    assert!((eccentricity(185.0) - 0.967).abs() < 1e-3);
}

#[test]
fn cie_overcast_and_clear_shapes() {
    // CIE overcast: zenith three times brighter than the horizon (before the ground blend).
    let o = CieSkyDescription::new(
        0.6,
        0.0,
        &GenskyOptions {
            sky: CieSky::Overcast,
            ..GenskyOptions::default()
        },
    );
    assert!((o.radiance([0.0, 0.0, 1.0]) - o.zenith).abs() < 1e-3 * o.zenith);
    assert!(o.solar.is_none() && o.args().len() == 3);
    // Clear sky: brightest around the sun, and the 87 deg cap.
    let c = CieSkyDescription::new(1.55, 0.3, &GenskyOptions::default());
    assert!(c.capped && (c.altitude - 87f64.to_radians()).abs() < 1e-15);
    let c = CieSkyDescription::new(0.5, 0.3, &GenskyOptions::default());
    let sun = c.sun_dir;
    let away = [-sun[0], -sun[1], sun[2]];
    assert!(c.radiance(sun) > 3.0 * c.radiance(away));
    assert_eq!(c.args().len(), 7);
    assert_eq!(rdaylight::sky::cie::c_exp(6.879e6, 3), "6.879e+06");
    assert_eq!(rdaylight::sky::cie::c_exp(0.0123, 3), "1.230e-02");
}

// ---------------------------------------------------------------------------------------
// gendaylit natively
// ---------------------------------------------------------------------------------------

use rdaylight::sky::gendaylit::{GendaylitInput, GendaylitOptions, GendaylitOutput, GendaylitSky};

/// Half a unit in the last place of C's `%.3e` for `x`.
fn half_ulp_e3(x: f64) -> f64 {
    if x == 0.0 {
        return 5e-4;
    }
    0.5e-3 * 10f64.powf(x.abs().log10().floor())
}

#[test]
fn live_gendaylit_arguments_match_gendaylit() {
    if !common::have_radiance("live_gendaylit_arguments_match_gendaylit") {
        return;
    }
    use GendaylitInput::*;
    let site = west(51.15, 0.18, 0.0);
    // (command line, date or -ang, options)
    let w = |d, f| DirectNormalIrradiance {
        direct: d,
        diffuse: f,
    };
    let cases: Vec<(&str, GendaylitOptions)> = vec![
        (
            "6 21 12.5 -W 600 150",
            GendaylitOptions::new(w(600.0, 150.0)),
        ),
        ("12 21 10.5 -W 0 80", GendaylitOptions::new(w(0.0, 80.0))),
        (
            "4 2 17.5 -W 250 200",
            GendaylitOptions::new(w(250.0, 200.0)),
        ),
        ("10 10 7.5 -W 50 40", GendaylitOptions::new(w(50.0, 40.0))),
        ("8 3 9.25 -W 820 90", GendaylitOptions::new(w(820.0, 90.0))),
        (
            "3 15 9 -L 60000 20000",
            GendaylitOptions::new(DirectNormalIlluminance {
                direct: 60000.0,
                diffuse: 20000.0,
            }),
        ),
        (
            "9 10 14 -G 300 100",
            GendaylitOptions::new(DirectHorizontalIrradiance {
                direct: 300.0,
                diffuse: 100.0,
            }),
        ),
        (
            "7 1 13 -E 700",
            GendaylitOptions::new(GlobalHorizontalIrradiance(700.0)),
        ),
        (
            "5 5 11 -P 3.2 0.25",
            GendaylitOptions::new(Perez {
                epsilon: 3.2,
                delta: 0.25,
            }),
        ),
        (
            "5 5 11 -P 1.1 0.1",
            GendaylitOptions::new(Perez {
                epsilon: 1.1,
                delta: 0.1,
            }),
        ),
        (
            "6 21 12.5 -W 600 150 -O 1",
            GendaylitOptions {
                output: GendaylitOutput::Solar,
                ..GendaylitOptions::new(w(600.0, 150.0))
            },
        ),
        (
            "6 21 12.5 -W 600 150 -O 2",
            GendaylitOptions {
                output: GendaylitOutput::Luminance,
                ..GendaylitOptions::new(w(600.0, 150.0))
            },
        ),
        (
            "6 21 12.5 -W 600 150 -s",
            GendaylitOptions {
                sun: false,
                ..GendaylitOptions::new(w(600.0, 150.0))
            },
        ),
        (
            "8 15 10 -W 400 100 -g 0.35 -d 18",
            GendaylitOptions {
                ground_reflectance: 0.35,
                dew_point: 18.0,
                ..GendaylitOptions::new(w(400.0, 100.0))
            },
        ),
        (
            "2 14 12 -c -W 200 100",
            GendaylitOptions {
                cloudy: true,
                sun: false,
                ..GendaylitOptions::new(w(200.0, 100.0))
            },
        ),
        ("12 21 3 -W 0 0", GendaylitOptions::new(w(0.0, 0.0))),
        ("11 5 12 -W 1400 50", GendaylitOptions::new(w(1400.0, 50.0))),
        (
            "-ang 70 20 -W 800 100",
            GendaylitOptions::new(w(800.0, 100.0)),
        ),
        (
            "-ang 88.5 10 -W 800 100",
            GendaylitOptions::new(w(800.0, 100.0)),
        ),
    ];
    let mut exact_fields = 0;
    let mut total_fields = 0;
    let mut rel_a1 = vec![];
    for (cmd, o) in &cases {
        let mut args: Vec<&str> = cmd.split_whitespace().collect();
        let ang = args[0] == "-ang";
        if !ang {
            args.extend(["-a", "51.15", "-o", "0.18", "-m", "0"]);
        }
        let out = common::run_ok(common::radiance("gendaylit").args(&args), b"");
        let text = String::from_utf8_lossy(&out).to_string();
        let sky = if ang {
            let alt: f64 = args[1].parse().unwrap();
            let azi: f64 = args[2].parse().unwrap();
            GendaylitSky::new(alt.to_radians(), azi.to_radians(), 0.0, o)
        } else {
            GendaylitSky::for_date(
                &site,
                args[0].parse().unwrap(),
                args[1].parse().unwrap(),
                args[2].parse().unwrap(),
                false,
                None,
                o,
            )
            .1
        };
        let line = text.lines().find(|l| l.starts_with("10 ")).unwrap();
        let real: Vec<f64> = numbers_loose(line)[1..].to_vec();
        let msg = format!("gendaylit {cmd}\n{text}\nours: {sky:?}");
        assert_eq!(real.len(), 10, "{msg}");
        for (k, (&ours, &r)) in sky.args.iter().zip(&real).enumerate() {
            let tol = if k < 2 { half_ulp_e3(r) } else { 0.5e-6 };
            let err = (ours - r).abs();
            // One unit in the last printed place for rounding ties of float-rounded values.
            assert!(err <= 2.0 * tol + 1e-12, "A{}: {msg}", k + 1);
            total_fields += 1;
            if err <= tol * 1.0000001 {
                exact_fields += 1;
            }
        }
        if real[0] > 0.0 {
            rel_a1.push((sky.args[0] - real[0]).abs() / real[0]);
        }
        assert_eq!(sky.error, real[0] == 0.0 && real[2] == 0.0, "{msg}");
        // Sun source.
        let lines: Vec<&str> = text.lines().collect();
        let real_sun = lines
            .iter()
            .position(|l| *l == "void light solar")
            .map(|k| numbers_loose(lines[k + 3])[1]);
        match (real_sun, sky.solar) {
            (None, None) => {}
            (Some(r), Some(s)) => assert!((r - s).abs() <= 2.0 * half_ulp_e3(r), "sun: {msg}"),
            _ => panic!("sun presence differs: {msg}"),
        }
        // The comment's epsilon, delta and precipitable water (%.4f).
        if let Some(c) = text.lines().find_map(|l| {
            l.strip_prefix("# epsilon, delta, atmospheric precipitable water content : ")
        }) {
            let v = numbers_loose(c);
            assert!((v[0] - sky.epsilon).abs() <= 1e-4, "epsilon: {msg}");
            assert!((v[1] - sky.delta).abs() <= 1e-4, "delta: {msg}");
            assert!((v[2] - sky.precip_water).abs() <= 1e-4, "W: {msg}");
        }
    }
    let (med, max) = stats(rel_a1);
    eprintln!(
        "gendaylit: {} cases, {exact_fields}/{total_fields} arguments within half a printed \
         unit; A1 rel diff median {med:.2e}, max {max:.2e}",
        cases.len()
    );
    assert!(exact_fields * 100 >= total_fields * 97);
}
