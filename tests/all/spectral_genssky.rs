//! `rdaylight::sky::genssky` (and `rspecsky genssky`) against real Radiance 6 genssky, on
//! the references in `radiance-fixtures/spectral/genssky_*` (made once by
//! `make_genssky_fixtures.sh`; genssky needs about a minute per atmosphere).
//!
//! Issue 8's bounds, per case: every band of the sky radiance (hemisphere mean, zenith
//! cap, horizon band), of the horizontal sky irradiance and of the sun's disc radiance
//! within 5 % (clear skies; asserted for the cloudy ones too since the blend is exact),
//! correlated colour temperature (McCamy) within 300 K and Radiance photopic value within
//! 2 %. Our tables use the same aerosol profile as genssky (`mie_ca.dat` from Radiance's
//! library, found like the binaries); they are computed once per atmosphere into the test
//! target folder and reused.
//!
//! Run with `--nocapture` for the agreement table.

use crate::common;
use rdaylight::formats::picture::Picture;
use rdaylight::formats::weather::Site;
use rdaylight::sky::atmosphere::MieProfile;
use rdaylight::sky::atmosphere::cache::{self, CacheStatus};
use rdaylight::sky::genssky::{
    GensskyOptions, Hour, SpectralSky, cct, horizontal_irradiance, photopic, region_mean,
    spectral_sky,
};
use std::path::PathBuf;

const NSSAMP: usize = 20;

/// A named set of directions.
type Region = fn([f64; 3]) -> bool;

fn fixture(name: &str) -> PathBuf {
    common::repo().join("radiance-fixtures/spectral").join(name)
}

/// One fixture case: name and genssky's arguments.
struct Case {
    name: &'static str,
    when: (u32, u32, &'static str),
    lat: f64,
    lon: f64,
    mer: f64,
    aod: f64,
    cloud: f64,
    year: Option<i32>,
    lux: Option<(f64, f64)>,
}

const CASES: [Case; 6] = [
    Case {
        name: "boulder_mar",
        when: (3, 2, "15.25"),
        lat: 42.0,
        lon: 108.0,
        mer: 110.0,
        aod: 0.115,
        cloud: 0.0,
        year: None,
        lux: None,
    },
    Case {
        name: "boulder_jun_aod03",
        when: (6, 21, "12"),
        lat: 42.0,
        lon: 108.0,
        mer: 110.0,
        aod: 0.3,
        cloud: 0.0,
        year: None,
        lux: None,
    },
    Case {
        name: "london_dec_c05",
        when: (12, 21, "9.5"),
        lat: 51.5,
        lon: 0.1,
        mer: 0.0,
        aod: 0.115,
        cloud: 0.5,
        year: None,
        lux: None,
    },
    Case {
        name: "london_jun_c1",
        when: (6, 21, "10"),
        lat: 51.5,
        lon: 0.1,
        mer: 0.0,
        aod: 0.115,
        cloud: 1.0,
        year: None,
        lux: None,
    },
    Case {
        name: "london_jun_L",
        when: (6, 21, "10"),
        lat: 51.5,
        lon: 0.1,
        mer: 0.0,
        aod: 0.115,
        cloud: 0.0,
        year: None,
        lux: Some((80000.0, 8000.0)),
    },
    Case {
        name: "tropic_jan_y",
        when: (1, 15, "11"),
        lat: 10.0,
        lon: -80.0,
        mer: -75.0,
        aod: 0.115,
        cloud: 0.0,
        year: Some(2024),
        lux: None,
    },
];

impl Case {
    fn options(&self) -> GensskyOptions {
        let mut o =
            GensskyOptions::new(self.when.0, self.when.1, Hour::parse(self.when.2).unwrap());
        // The cases give genssky's `-o`/`-m` (degrees west); the site is east positive.
        o.site = Site {
            latitude_deg_n: self.lat,
            longitude_deg_e: -self.lon,
            meridian_deg_e: -self.mer,
            ..Site::default()
        };
        o.aod = self.aod;
        o.cloud_cover = self.cloud;
        o.year = self.year;
        o.illuminance = self.lux;
        o.resolution = 48;
        o
    }
}

/// genssky's sun from its .rad: direction, spectrum x intensity (band radiance x 400).
struct RadSun {
    dir: [f64; 3],
    bands: [f64; NSSAMP],
    intensity: f64,
}

fn read_rad(text: &str) -> RadSun {
    let words: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .flat_map(|l| l.split_whitespace())
        .collect();
    let at = |w: &str| words.iter().position(|x| *x == w).unwrap();
    let s = at("390") + 2;
    let spec: Vec<f64> = words[s..s + NSSAMP]
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    let l = at("solar") + 4;
    let intensity: f64 = words[l].parse().unwrap();
    let d = at("sun") + 4;
    let dir = [0, 1, 2].map(|k| words[d + k].parse::<f64>().unwrap());
    RadSun {
        dir,
        bands: std::array::from_fn(|k| spec[k] * intensity),
        intensity,
    }
}

fn mie() -> Option<MieProfile> {
    let (_, lib) = common::radiance_dirs()?;
    MieProfile::read(&lib.join("mie_ca.dat")).ok()
}

fn cache_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("genssky_tables")
}

/// Our sky for a case (tables from the shared test cache).
fn ours(c: &Case, mie: &MieProfile) -> SpectralSky {
    let o = c.options();
    let atm = o.atmosphere(mie.clone());
    let (t, status) = cache::load_or_compute(&cache_dir(), &atm).unwrap();
    if let CacheStatus::Recomputed(p, why) = &status {
        eprintln!("{}: recomputed ({why})", p.display());
    }
    spectral_sky(&t, &o)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b) / b
}

fn worst(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| rel(*x, *y).abs())
        .fold(0.0, f64::max)
}

/// Band values longest first -> the sun's (shortest first) order and back.
fn reversed(v: &[f64]) -> Vec<f64> {
    v.iter().rev().cloned().collect()
}

#[test]
fn agrees_with_genssky_fixtures() {
    if !common::have_radiance("agrees_with_genssky_fixtures") {
        return;
    }
    let Some(mie) = mie() else {
        panic!("mie_ca.dat not found in Radiance's lib folder");
    };
    println!(
        "\n| case | sky band worst (hemi/zenith/horizon) | E_h band worst | sun band worst | \
         CCT sky ours/gs (K) | CCT sun ours/gs (K) | photopic E_h | photopic sun |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut failures = Vec::new();
    for c in &CASES {
        let theirs_pic = Picture::open(fixture(&format!("genssky_{}_sky.hsr", c.name))).unwrap();
        let theirs_sun = read_rad(
            &std::fs::read_to_string(fixture(&format!("genssky_{}.rad", c.name))).unwrap(),
        );
        let sky = ours(c, &mie);
        let p = &sky.picture;
        assert_eq!((p.width, p.height), (theirs_pic.width, theirs_pic.height));
        // Sun position (genssky prints 6 decimals).
        for k in 0..3 {
            assert!(
                (sky.sun_direction[k] - theirs_sun.dir[k]).abs() < 2e-6,
                "{}: sun {:?} vs genssky {:?}",
                c.name,
                sky.sun_direction,
                theirs_sun.dir
            );
        }
        let regions: [(&str, Region); 3] = [
            ("hemisphere", |d| d[2] > 0.0),
            ("zenith", |d| d[2] > 0.8),
            ("horizon", |d| d[2] > 0.0 && d[2] < 0.2),
        ];
        let mut sky_worst = Vec::new();
        for (what, keep) in regions {
            let a = region_mean(p, keep);
            let b = region_mean(&theirs_pic, keep);
            let w = worst(&a, &b);
            if w > 0.05 {
                failures.push(format!("{}: {what} band off by {:.1} %", c.name, 100.0 * w));
            }
            sky_worst.push(w);
        }
        let ea = horizontal_irradiance(p);
        let eb = horizontal_irradiance(&theirs_pic);
        let e_worst = worst(&ea, &eb);
        // The sun's spectrum is printed with 3 decimals (0.300 is +-0.17 %).
        let sun_ours: Vec<f64> = (0..NSSAMP)
            .map(|k| sky.sun_spectrum[k] * sky.sun_intensity)
            .collect();
        let sun_worst = worst(&sun_ours, &theirs_sun.bands);
        let (cct_a, cct_b) = (cct(&ea), cct(&eb));
        let (sct_a, sct_b) = (cct(&reversed(&sun_ours)), cct(&reversed(&theirs_sun.bands)));
        let ph_e = rel(photopic(&ea), photopic(&eb));
        let ph_s = rel(
            photopic(&reversed(&sun_ours)),
            photopic(&reversed(&theirs_sun.bands)),
        );
        println!(
            "| {} | {:.2} / {:.2} / {:.2} % | {:.2} % | {:.2} % | {:.0} / {:.0} | {:.0} / {:.0} | {:+.2} % | {:+.2} % |",
            c.name,
            100.0 * sky_worst[0],
            100.0 * sky_worst[1],
            100.0 * sky_worst[2],
            100.0 * e_worst,
            100.0 * sun_worst,
            cct_a,
            cct_b,
            sct_a,
            sct_b,
            100.0 * ph_e,
            100.0 * ph_s
        );
        if e_worst > 0.05 {
            failures.push(format!(
                "{}: E_h band off by {:.1} %",
                c.name,
                100.0 * e_worst
            ));
        }
        if sun_worst > 0.05 {
            failures.push(format!(
                "{}: sun band off by {:.1} %",
                c.name,
                100.0 * sun_worst
            ));
        }
        if (cct_a - cct_b).abs() > 300.0 || (sct_a - sct_b).abs() > 300.0 {
            failures.push(format!(
                "{}: CCT sky {cct_a:.0}/{cct_b:.0}, sun {sct_a:.0}/{sct_b:.0}",
                c.name
            ));
        }
        if ph_e.abs() > 0.02 || ph_s.abs() > 0.02 {
            failures.push(format!(
                "{}: photopic E_h {:+.2} %, sun {:+.2} %",
                c.name,
                100.0 * ph_e,
                100.0 * ph_s
            ));
        }
        if let Some((dn, _)) = c.lux {
            assert!(
                (sky.sun_intensity - theirs_sun.intensity).abs() < 0.1,
                "{}: -L sun {} vs {}",
                c.name,
                sky.sun_intensity,
                theirs_sun.intensity
            );
            assert!((sky.sun_intensity - dn / 6.7967e-5 / 179.0).abs() < 0.1);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The binary writes genssky's .rad and picture; its sky equals the library's.
#[test]
fn binary_writes_genssky_outputs() {
    if !common::have_radiance("binary_writes_genssky_outputs") {
        return;
    }
    let Some((_, lib)) = common::radiance_dirs() else {
        return;
    };
    let c = &CASES[0];
    let t = common::tmpdir();
    // -p . puts the picture and atmos_data/ here: seed it with the test cache's tables.
    let atm = c.options().atmosphere(mie().unwrap());
    let _ = cache::load_or_compute(&cache_dir(), &atm).unwrap();
    let seeded = cache::path(t.path(), &atm);
    std::fs::create_dir_all(seeded.parent().unwrap()).unwrap();
    std::fs::copy(cache::path(&cache_dir(), &atm), &seeded).unwrap();
    let out = common::run_ok(
        common::ours("rspecsky")
            .current_dir(t.path())
            .env("RAYPATH", &lib)
            .args([
                "genssky", "3", "2", "15.25", "-a", "42", "-o", "108", "-m", "110", "-r", "48",
                "-f", "sky1", "-p", ".",
            ]),
        b"",
    );
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains(
            "void specpict skyfunc\n5 noop ./sky1_sky.hsr . 'Atan2(Dy,Dx)/PI+1' '1-Acos(Dz)/PI'"
        ),
        "{text}"
    );
    assert!(
        text.contains("#Aerosol profile: ") && text.contains("mie_ca.dat"),
        "{text}"
    );
    assert!(text.contains("(cached)"), "{text}");
    let sun = read_rad(&text);
    let pic = Picture::open(t.path().join("sky1_sky.hsr")).unwrap();
    assert_eq!(pic.ncomp(), NSSAMP);
    assert_eq!(
        pic.header
            .get("WAVELENGTH_SPLITS")
            .map(|s| s.trim().to_string()),
        Some("780 588 480 380".into())
    );
    let lib_sky = ours(c, &mie().unwrap());
    assert_eq!(pic.width, 48);
    let d = worst(
        &horizontal_irradiance(&pic),
        &horizontal_irradiance(&lib_sky.picture),
    );
    assert!(d < 0.01, "binary vs library sky: {d}");
    assert!((sun.intensity - lib_sky.sun_intensity).abs() < 0.1);
}

/// rdc traces both skies (ours and genssky's fixture): the horizontal global irradiance
/// of an upward sensor per band agrees within the issue's 5 %.
#[test]
fn rdc_traces_our_sky_like_genssky_sky() {
    if !common::have_radiance("rdc_traces_our_sky_like_genssky_sky") {
        return;
    }
    let mie = mie().unwrap();
    let c = &CASES[0];
    let t = common::tmpdir();
    let sky = ours(c, &mie);
    sky.picture
        .save(t.path().join("ours_sky.hsr"), false)
        .unwrap();
    let glows = "skyfunc glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
                 skyfunc glow groundglow 0 0 4 1 1 1 0\ngroundglow source ground 0 0 4 0 0 -1 180\n";
    let ours_rad = rdaylight::sky::genssky::rad_text(&sky, &[], "ours_sky.hsr");
    std::fs::write(t.path().join("ours.rad"), format!("{ours_rad}{glows}")).unwrap();
    std::fs::copy(
        fixture(&format!("genssky_{}_sky.hsr", c.name)),
        t.path().join(format!("{}_sky.hsr", c.name)),
    )
    .unwrap();
    let theirs_rad = std::fs::read_to_string(fixture(&format!("genssky_{}.rad", c.name))).unwrap();
    std::fs::write(t.path().join("theirs.rad"), format!("{theirs_rad}{glows}")).unwrap();
    let run = |scene: &str| -> Vec<f64> {
        let out = common::run_ok(
            common::ours("rdc").current_dir(t.path()).args([
                "-h", "-I", "-ab", "1", "-ad", "4096", "-cs", "20", "-s", "7", scene,
            ]),
            b"0 0 0.1 0 0 1\n",
        );
        String::from_utf8(out)
            .unwrap()
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let a = run("ours.rad");
    let b = run("theirs.rad");
    assert_eq!(a.len(), NSSAMP);
    let w = worst(&a, &b);
    println!("rdc horizontal irradiance, worst band: {:.2} %", 100.0 * w);
    // And rdc saw both sun and sky: the picture's sky integral plus the sun's disc.
    let sky_e = horizontal_irradiance(&sky.picture);
    for b in 0..NSSAMP {
        let k = NSSAMP - 1 - b;
        let sun_e = sky.sun_spectrum[k] * sky.sun_intensity * 6.7967e-5 * sky.sun_direction[2];
        let want = sky_e[b] + sun_e;
        assert!(
            (a[b] / want - 1.0).abs() < 0.05,
            "band {b}: rdc {} vs sky {} + sun {sun_e}",
            a[b],
            sky_e[b]
        );
    }
    assert!(w < 0.05, "ours {a:?}\ngenssky {b:?}");
}

/// A truncated or corrupt cache file is detected and recomputed, never trusted.
#[test]
fn corrupt_cache_is_recomputed() {
    let Some(mie) = mie() else {
        return;
    };
    let o = CASES[0].options();
    let atm = o.atmosphere(mie);
    let (good, _) = cache::load_or_compute(&cache_dir(), &atm).unwrap();
    let file = cache::path(&cache_dir(), &atm);
    let bytes = std::fs::read(&file).unwrap();
    let key = cache::key(&atm);
    assert_eq!(cache::decode(&bytes, &key, &cache::DIMS).unwrap(), good);
    // Every kind of damage is refused with a reason (not a panic).
    for n in [0, 5, 8, 100, bytes.len() / 2, bytes.len() - 1] {
        assert!(
            cache::decode(&bytes[..n], &key, &cache::DIMS).is_err(),
            "prefix {n}"
        );
    }
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 3] ^= 0x40;
    let e = cache::decode(&flipped, &key, &cache::DIMS).unwrap_err();
    assert!(e.contains("checksum"), "{e}");
    let e = cache::decode(&bytes, "another key", &cache::DIMS).unwrap_err();
    assert!(e.starts_with("stale"), "{e}");
    // On disk: a truncated copy in a scratch folder is recomputed and replaced.
    let t = common::tmpdir();
    let scratch = cache::path(t.path(), &atm);
    std::fs::create_dir_all(scratch.parent().unwrap()).unwrap();
    std::fs::write(&scratch, &bytes[..bytes.len() / 2]).unwrap();
    let (again, status) = cache::load_or_compute(t.path(), &atm).unwrap();
    assert!(
        matches!(status, CacheStatus::Recomputed(_, _)),
        "{status:?}"
    );
    assert_eq!(again, good, "recomputed tables differ from the cached ones");
    assert_eq!(std::fs::read(&scratch).unwrap(), bytes);
}

/// Bad input to the binary: one line naming the problem, exit status 1.
#[test]
fn bad_input_is_reported() {
    let t = common::tmpdir();
    std::fs::write(
        t.path().join("bad.dat"),
        "2\n0 0 3 0 1000 60000\n0 19 20\n1e-5 oops\n",
    )
    .unwrap();
    for (args, want) in [
        (vec!["2", "30", "12"], "day 30 of month 2: no such date"),
        (vec!["13", "1", "12"], "month 13: expected 1 to 12"),
        (vec!["2", "29", "12", "-y", "2023"], "no such date"),
        (vec!["3", "2", "25"], "hour \"25\""),
        (vec!["3", "2", "12", "-c", "1.5"], "-c 1.5: cloud cover"),
        (
            vec!["3", "2", "12", "-l", "bad.dat"],
            "bad.dat:4: \"oops\"; expected a scattering coefficient",
        ),
        (vec!["3", "2", "12", "-l", "missing.dat"], "missing.dat"),
    ] {
        let mut full = vec!["genssky"];
        full.extend(args.iter());
        let out = common::run(
            common::ours("rspecsky").current_dir(t.path()).args(&full),
            b"",
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{full:?}: {err}");
        assert!(err.contains(want), "{full:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(
            !t.path().join("out_sky.hsr").exists(),
            "{full:?} wrote a picture"
        );
    }
}

/// How far the documented fallback aerosol profile (no `mie_ca.dat`: exponential, 1.2 km,
/// Angstrom 1.3) lands from genssky's OPAC profile: the figures of the `genssky` module
/// documentation (2.9 % per band, photopic -0.1 %, CCT 9 K, sun 1.8 % per band), each held
/// with a margin (a different atmosphere, so these are its documented distances, not
/// accuracy bounds): `cargo test --test all -- --ignored --nocapture spectral_genssky::fallback`.
#[test]
#[ignore = "needs its own precomputation (about 20 s of CPU)"]
fn fallback_profile_against_genssky() {
    let c = &CASES[0];
    let o = c.options();
    let atm = o.atmosphere(MieProfile::fallback());
    let (t, _) = cache::load_or_compute(&cache_dir(), &atm).unwrap();
    let sky = spectral_sky(&t, &o);
    let theirs = Picture::open(fixture(&format!("genssky_{}_sky.hsr", c.name))).unwrap();
    let theirs_sun =
        read_rad(&std::fs::read_to_string(fixture(&format!("genssky_{}.rad", c.name))).unwrap());
    let (ea, eb) = (
        horizontal_irradiance(&sky.picture),
        horizontal_irradiance(&theirs),
    );
    let sun: Vec<f64> = (0..NSSAMP)
        .map(|k| sky.sun_spectrum[k] * sky.sun_intensity)
        .collect();
    let (band, phot, sun_band) = (
        100.0 * worst(&ea, &eb),
        100.0 * rel(photopic(&ea), photopic(&eb)),
        100.0 * worst(&sun, &theirs_sun.bands),
    );
    let dcct = (cct(&ea) - cct(&eb)).abs();
    println!(
        "fallback profile, {}: E_h worst band {:.1} %, photopic E_h {:+.1} %, CCT {:.0}/{:.0} K; \
         sun worst band {:.1} %, photopic sun {:+.1} %",
        c.name,
        band,
        phot,
        cct(&ea),
        cct(&eb),
        sun_band,
        100.0
            * rel(
                photopic(&reversed(&sun)),
                photopic(&reversed(&theirs_sun.bands))
            )
    );
    assert!(band < 3.5, "E_h worst band {band:.2} % (documented 2.9 %)");
    assert!(
        phot.abs() < 0.5,
        "photopic E_h {phot:+.2} % (documented -0.1 %)"
    );
    assert!(dcct < 20.0, "CCT {dcct:.0} K apart (documented 9 K)");
    assert!(
        sun_band < 2.5,
        "sun worst band {sun_band:.2} % (documented 1.8 %)"
    );
}
