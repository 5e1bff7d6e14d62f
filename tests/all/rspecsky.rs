//! `rspecsky` against real Radiance: sky matrices against `gendaymtx` (run live on the
//! London IWEC year and on short periods from `radiance-fixtures/weather/`), point-in-time
//! skies against `gendaylit`'s printed arguments, `oconv` and `rtrace`, and bad input.

use crate::common;

use std::path::{Path, PathBuf};

fn epw() -> PathBuf {
    common::repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw")
}

fn fixture(name: &str) -> PathBuf {
    common::repo().join("radiance-fixtures").join(name)
}

/// A matrix as header text, shape and row-major values.
struct Mtx {
    header: String,
    nrows: usize,
    ncols: usize,
    data: Vec<f32>,
}

impl Mtx {
    fn get(&self, r: usize, c: usize, k: usize) -> f64 {
        f64::from(self.data[(r * self.ncols + c) * 3 + k])
    }
    fn var(&self, key: &str) -> Option<String> {
        self.header
            .lines()
            .find_map(|l| l.strip_prefix(key))
            .map(|v| v.trim().to_string())
    }
}

/// Parse a `-of` (float) or ascii matrix with a header.
fn parse(out: &[u8]) -> Mtx {
    let end = out.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let header = String::from_utf8_lossy(&out[..end]).to_string();
    let get = |k: &str| -> usize {
        header
            .lines()
            .find_map(|l| l.strip_prefix(k))
            .unwrap_or_else(|| panic!("{k} missing in {header}"))
            .trim()
            .parse()
            .unwrap()
    };
    let (nrows, ncols) = (get("NROWS="), get("NCOLS="));
    assert_eq!(get("NCOMP="), 3);
    let data: Vec<f32> = if header.contains("FORMAT=float") {
        assert!(header.contains("BigEndian=0"), "{header}");
        out[end..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    } else {
        assert!(header.contains("FORMAT=ascii"), "{header}");
        String::from_utf8_lossy(&out[end..])
            .split_whitespace()
            .map(|w| w.parse::<f64>().unwrap() as f32)
            .collect()
    };
    assert_eq!(data.len(), nrows * ncols * 3, "{header}");
    Mtx {
        header,
        nrows,
        ncols,
        data,
    }
}

fn gendaymtx(args: &[&str], weather: &Path) -> Mtx {
    parse(&common::run_ok(
        common::radiance("gendaymtx").args(args).arg(weather),
        b"",
    ))
}

fn rspecsky(args: &[&str], weather: &Path) -> Mtx {
    parse(&common::run_ok(
        common::ours("rspecsky").args(args).arg(weather),
        b"",
    ))
}

fn median_max(mut v: Vec<f64>) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    v.sort_by(|a, b| a.total_cmp(b));
    (v[v.len() / 2], v[v.len() - 1])
}

/// Every value above 1 % of its column's (hour's) maximum within `tol` relative; smaller
/// values within 1 % of that maximum absolutely; annual (row) totals within `tot_tol`.
/// Returns (median, max) of the per-value and of the per-total relative differences.
fn agree(real: &Mtx, ours: &Mtx, what: &str, tol: f64, tot_tol: f64) -> [(f64, f64); 2] {
    assert_eq!(
        (real.nrows, real.ncols),
        (ours.nrows, ours.ncols),
        "{what}: shape"
    );
    let mut colmax = vec![0f64; real.ncols];
    for r in 0..real.nrows {
        for (c, m) in colmax.iter_mut().enumerate() {
            for k in 0..3 {
                *m = m.max(real.get(r, c, k));
            }
        }
    }
    let mut rel = Vec::new();
    let mut tot_rel = Vec::new();
    for r in 0..real.nrows {
        let mut tot = [0f64; 2];
        for (c, &m) in colmax.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (real.get(r, c, k), ours.get(r, c, k));
                tot[0] += a;
                tot[1] += b;
                if a > 0.01 * m {
                    let e = (b - a).abs() / a;
                    assert!(
                        e < tol,
                        "{what}: row {r} col {c} ch {k}: ours {b}, real {a}"
                    );
                    rel.push(e);
                } else {
                    assert!(
                        (b - a).abs() <= 0.01 * m + 1e-6,
                        "{what}: row {r} col {c} ch {k}: ours {b}, real {a} (column max {m})"
                    );
                }
            }
        }
        if tot[0] > 0.0 {
            let e = (tot[1] - tot[0]).abs() / tot[0];
            assert!(
                e < tot_tol,
                "{what}: row {r} total: ours {}, real {}",
                tot[1],
                tot[0]
            );
            tot_rel.push(e);
        } else {
            assert_eq!(tot[1], 0.0, "{what}: row {r} total");
        }
    }
    let n = rel.len();
    let out = [median_max(rel), median_max(tot_rel)];
    eprintln!(
        "{what}: {n} values: median rel diff {:.2e}, max {:.2e}; row totals: median {:.2e}, \
         max {:.2e}",
        out[0].0, out[0].1, out[1].0, out[1].1
    );
    assert!(n > 0, "{what}: nothing compared");
    out
}

fn check_header(real: &Mtx, ours: &Mtx, what: &str) {
    for k in ["LATLONG=", "NROWS=", "NCOLS=", "NCOMP=", "NAVERAGED="] {
        let (a, b) = (real.var(k), ours.var(k));
        match (k, &a, &b) {
            ("LATLONG=", Some(a), Some(b)) => {
                let pa: Vec<f64> = a.split_whitespace().map(|w| w.parse().unwrap()).collect();
                let pb: Vec<f64> = b.split_whitespace().map(|w| w.parse().unwrap()).collect();
                assert_eq!(pa, pb, "{what}: LATLONG");
            }
            _ => assert_eq!(a, b, "{what}: {k}"),
        }
    }
}

#[test]
fn full_year_epw_matches_gendaymtx_mf1_and_mf4() {
    if !common::have_radiance("full_year_epw_matches_gendaymtx_mf1_and_mf4") {
        return;
    }
    for mf in ["1", "4"] {
        let args = ["-m", mf, "-of"];
        let real = gendaymtx(&args, &epw());
        let ours = rspecsky(&args, &epw());
        assert_eq!(real.ncols, 8760);
        check_header(&real, &ours, "EPW");
        // gendaymtx computes in C float (measured: per-value max 2e-6 relative); 1e-4 and
        // 1e-5 would still fail on any model slip, the brief's 1 % and 0.5 % are the bounds.
        let [(_, vmax), (_, tmax)] =
            agree(&real, &ours, &format!("full year EPW -m {mf}"), 0.01, 0.005);
        assert!(vmax < 1e-4 && tmax < 1e-5, "-m {mf}: {vmax} {tmax}");
    }
}

#[test]
fn full_year_wea_from_epw2wea_matches_gendaymtx() {
    if !common::have_radiance("full_year_wea_from_epw2wea_matches_gendaymtx") {
        return;
    }
    let tmp = common::tmpdir();
    let wea = tmp.path().join("london.wea");
    common::run_ok(common::radiance("epw2wea").arg(epw()).arg(&wea), b"");
    let args = ["-m", "1", "-of"];
    let real = gendaymtx(&args, &wea);
    let ours = rspecsky(&args, &wea);
    check_header(&real, &ours, "wea");
    agree(&real, &ours, "full year epw2wea .wea -m 1", 0.01, 0.005);
}

#[test]
fn options_match_gendaymtx_on_short_periods() {
    if !common::have_radiance("options_match_gendaymtx_on_short_periods") {
        return;
    }
    let six = fixture("weather/london_6hours.wea");
    let days = fixture("weather/london_4days.wea");
    let cases: &[(&[&str], &Path)] = &[
        (&["-m", "1", "-d"], &six),
        (&["-m", "1", "-s"], &six),
        (&["-5", "0.533", "-d", "-m", "6"], &six),
        (&["-5", "0.533", "-m", "2"], &days),
        (&["-m", "1", "-O1"], &days),
        (&["-m", "2", "-r", "30"], &days),
        (&["-m", "1", "-r", "-45"], &days),
        (&["-m", "1", "-g", "0.1", "0.3", "0.5"], &days),
        (&["-m", "1", "-c", "1", "1", "1"], &days),
        (&["-m", "1", "-d", "-g", "0.5", "0.5", "0.5"], &six),
        (&["-m", "1", "-g", "0.5", "0.5", "0.5", "-d"], &six),
        (&["-m", "1", "-A"], &days),
        (&["-m", "4", "-A", "-u"], &days),
        (&["-m", "1", "-u"], &days),
        (&["-m", "1", "-i", "60"], &days),
        (&["-m", "4"], &days),
    ];
    for (args, w) in cases {
        let mut a = args.to_vec();
        a.push("-of");
        let real = gendaymtx(&a, w);
        let ours = rspecsky(&a, w);
        check_header(&real, &ours, &format!("{args:?}"));
        let all_zero = real.data.iter().all(|&v| v == 0.0);
        if all_zero {
            assert!(ours.data.iter().all(|&v| v == 0.0), "{args:?}: zero matrix");
            continue;
        }
        let [(_, vmax), _] = agree(&real, &ours, &format!("{args:?}"), 0.01, 0.005);
        assert!(vmax < 1e-4, "{args:?}: {vmax}");
    }
    // The committed fixtures (made by the same gendaymtx) agree too.
    for (args, w, f) in [
        (&["-m", "1"][..], &days, "sky/london_4days_m1.smx"),
        (&["-m", "1", "-d"][..], &six, "sky/london_6hours_m1_d.smx"),
        (
            &["-5", "0.533", "-d", "-m", "6"][..],
            &six,
            "sky/london_6hours_m6_5d.smx",
        ),
    ] {
        let real = parse(&std::fs::read(fixture(f)).unwrap());
        let mut a = args.to_vec();
        a.push("-of");
        let ours = rspecsky(&a, w);
        agree(&real, &ours, f, 0.01, 0.005);
    }
}

#[test]
fn ascii_and_double_output_carry_full_precision() {
    let days = fixture("weather/london_4days.wea");
    let f = rspecsky(&["-m", "1", "-of"], &days);
    let a = rspecsky(&["-m", "1"], &days);
    assert!(a.header.contains("FORMAT=ascii"));
    // %.7e of the same f64 values: equal to float rounding, not gendaymtx's 3 digits.
    for (x, y) in f.data.iter().zip(&a.data) {
        assert!((x - y).abs() <= 1e-6 * x.abs(), "{x} {y}");
    }
    let d = common::run_ok(
        common::ours("rspecsky")
            .args(["-m", "1", "-od", "-h"])
            .arg(&days),
        b"",
    );
    assert_eq!(d.len(), 146 * 96 * 3 * 8, "headerless doubles");
    let first_nonzero = d
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .zip(&f.data)
        .find(|(x, _)| *x != 0.0)
        .unwrap();
    assert!((first_nonzero.0 - f64::from(*first_nonzero.1)).abs() < 1e-6 * first_nonzero.0);
}

#[test]
fn bad_input_gives_one_line_errors_and_no_output() {
    let tmp = common::tmpdir();
    let bad = tmp.path().join("bad.wea");
    std::fs::write(&bad, "latitude 5\n").unwrap();
    let trunc = tmp.path().join("trunc.wea");
    std::fs::write(
        &trunc,
        "place X_Y\nlatitude 51\nlongitude 0\ntime_zone 0\nsite_elevation 0\n\
         weather_data_file_units 1\n3 2 12.5 800\n",
    )
    .unwrap();
    let days = fixture("weather/london_4days.wea");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec![bad.display().to_string()], "bad.wea:1: "),
        (vec![trunc.display().to_string()], "trunc.wea:7"),
        (
            vec!["-m".into(), "0".into(), days.display().to_string()],
            "-m 0: expected",
        ),
        (
            vec!["-m".into(), "x".into(), days.display().to_string()],
            "-m x: expected",
        ),
        (
            vec!["-ox".into(), days.display().to_string()],
            "-ox: expected",
        ),
        (
            vec![tmp.path().join("none.wea").display().to_string()],
            "none.wea",
        ),
        (vec![], "expected a weather file"),
        (
            vec!["--at".into(), "3 2".into(), days.display().to_string()],
            "--at",
        ),
        (
            vec![
                "--at".into(),
                "3 2 12.25".into(),
                days.display().to_string(),
            ],
            "no record at month 3 day 2 hour 12.25",
        ),
    ];
    for (args, want) in cases {
        let out = common::run(common::ours("rspecsky").args(&args), b"");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("rspecsky: "), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err} lacks {want}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

/// Numbers of the line starting with `prefix` (after it), from a sky description.
fn numbers_after(text: &str, prefix: &str, nth: usize) -> Vec<f64> {
    text.lines()
        .filter(|l| l.starts_with(prefix))
        .nth(nth)
        .unwrap_or_else(|| panic!("no line {prefix} in {text}"))
        .split_whitespace()
        .skip(1)
        .map(|w| w.parse().unwrap())
        .collect()
}

/// Our --at sky and gendaylit's for the same inputs: A1..A10 and the sun radiance agree to
/// gendaylit's printed precision (4 significant digits, directions 6 decimals).
fn compare_with_gendaylit(ours: &str, real: &str, what: &str) {
    let a = numbers_after(ours, "10 ", 0);
    let b = numbers_after(real, "10 ", 0);
    assert_eq!(a.len(), 10);
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        let tol = if i < 2 { 5e-4 * y.abs() } else { 6e-6 };
        assert!(
            (x - y).abs() <= tol,
            "{what}: A{}: ours {x}, gendaylit {y}",
            i + 1
        );
    }
    let sa = ours.contains("void light solar");
    assert_eq!(sa, real.contains("void light solar"), "{what}: sun");
    if sa {
        let x = numbers_after(ours, "3 ", 0)[0];
        let y = numbers_after(real, "3 ", 0)[0];
        assert!(
            (x - y).abs() <= 5e-4 * y.abs().max(1.0),
            "{what}: sun {x} {y}"
        );
        let dx = numbers_after(ours, "4 ", 0);
        let dy = numbers_after(real, "4 ", 0);
        for k in 0..3 {
            assert!((dx[k] - dy[k]).abs() < 6e-6, "{what}: sun direction");
        }
    }
}

#[test]
fn point_skies_match_gendaylit() {
    if !common::have_radiance("point_skies_match_gendaylit") {
        return;
    }
    let site = ["-a", "51.15", "-o", "0.18", "-m", "0"];
    for (date, dni, dhi) in [
        ("3 2 12.5", "838", "79"),
        ("3 21 12.5", "297", "265"),
        ("4 21 11.5", "0", "155"),
        ("3 2 2.5", "0", "0"),
        ("6 21 7.5", "500", "120"),
    ] {
        let d: Vec<&str> = date.split(' ').collect();
        let real = common::run_ok(
            common::radiance("gendaylit")
                .args(&d)
                .args(site)
                .args(["-W", dni, dhi]),
            b"",
        );
        let ours = common::run_ok(
            common::ours("rspecsky")
                .args(["--at", date, "-W", dni, dhi])
                .args(site),
            b"",
        );
        compare_with_gendaylit(
            &String::from_utf8_lossy(&ours),
            &String::from_utf8_lossy(&real),
            date,
        );
    }
    // The same sky from the weather file (the EPW's 2 March 12:30 record: 838, 79) and
    // from the epw2wea .wea (gendaylit -O1 for the solar variant).
    let wea = fixture("weather/london_6hours.wea");
    for (file, extra) in [(epw(), None), (wea.clone(), Some("-O1"))] {
        let real = common::run_ok(
            common::radiance("gendaylit")
                .args(["3", "2", "12.5"])
                .args(site)
                .args(["-W", "838", "79"])
                // gendaylit 6.0a reads `-O 1` (a separate word) after -W only; `-O1`
                // is refused and crashes it after -W.
                .args(extra.map(|_| ["-O", "1"]).into_iter().flatten()),
            b"",
        );
        let ours = common::run_ok(
            common::ours("rspecsky")
                .args(["--at", "3 2 12.5"])
                .args(extra)
                .arg(&file),
            b"",
        );
        compare_with_gendaylit(
            &String::from_utf8_lossy(&ours),
            &String::from_utf8_lossy(&real),
            &format!("{} {extra:?}", file.display()),
        );
    }
}

/// Horizontal irradiance at the origin under a sky (rtrace -I, one ambient bounce).
fn irradiance(sky: &[u8], dir: &Path) -> f64 {
    let rad = dir.join("sky.rad");
    std::fs::write(&rad, sky).unwrap();
    let oct = common::run_ok(common::radiance("oconv").arg(&rad), b"");
    let octf = dir.join("sky.oct");
    std::fs::write(&octf, oct).unwrap();
    let out = common::run_ok(
        common::radiance("rtrace")
            .args([
                "-h", "-I", "-ab", "1", "-ad", "4096", "-aa", "0", "-as", "0",
            ])
            .arg(&octf),
        b"0 0 0 0 0 1\n",
    );
    let v: Vec<f64> = String::from_utf8_lossy(&out)
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    v[0]
}

#[test]
fn point_sky_is_a_scene_rtrace_reads_like_gendaylit() {
    if !common::have_radiance("point_sky_is_a_scene_rtrace_reads_like_gendaylit") {
        return;
    }
    let tmp = common::tmpdir();
    let glow = std::fs::read(fixture("skies/skyglow.rad")).unwrap();
    for case in ["clear", "intermediate", "overcast"] {
        let mut real = std::fs::read(fixture(&format!("skies/{case}_gendaylit.rad"))).unwrap();
        real.extend_from_slice(&glow);
        let cmd = String::from_utf8_lossy(&real)
            .lines()
            .next()
            .unwrap()
            .to_string();
        // "# gendaylit M D H -a .. -o .. -m .. -W dni dhi"
        let w: Vec<&str> = cmd.split_whitespace().collect();
        let date = w[2..5].join(" ");
        let ours = common::run_ok(
            common::ours("rspecsky").args(["--at", &date]).args(&w[5..]),
            b"",
        );
        let e_real = irradiance(&real, tmp.path());
        let e_ours = irradiance(&ours, tmp.path());
        eprintln!("{case}: horizontal irradiance ours {e_ours}, gendaylit {e_real}");
        // -ad 4096 ambient sampling of the sky: measured spread about 1 %; 4 % bound.
        assert!(
            (e_ours - e_real).abs() < 0.04 * e_real,
            "{case}: ours {e_ours}, gendaylit {e_real}"
        );
    }
}

#[test]
fn help_names_the_radiance_counterparts() {
    let out = common::run_ok(common::ours("rspecsky").arg("--help"), b"");
    let h = String::from_utf8_lossy(&out);
    for want in [
        "gendaymtx -m",
        "gendaymtx -d",
        "gendaymtx -s",
        "gendaymtx -5",
        "gendaymtx -g",
        "gendaymtx -c",
        "gendaymtx -r",
        "gendaymtx -u",
        "gendaymtx -A",
        "gendaymtx -i",
        "gendaymtx -h",
        "gendaylit -W",
        "-of",
        "--at",
        "oconv sky.rad",
    ] {
        assert!(h.contains(want), "--help lacks {want}");
    }
}
