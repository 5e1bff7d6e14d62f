//! `rmetrics` end to end: hand-computed cases for every metric, boundaries, schedules, ASE
//! refusal, maps, Appendix-A comparisons, and an illuminance matrix made by real Radiance
//! (`dctimestep | rmtxop -c 47.4 119.9 11.6`) checked against an independent computation.

use crate::common;

use common::{ours, repo, run, tmpdir};
use std::path::Path;

/// An ascii Radiance matrix with a header.
fn matrix(rows: &[Vec<f64>], ncomp: usize) -> String {
    let ncols = rows[0].len() / ncomp;
    let mut s = format!(
        "#?RADIANCE\nNROWS={}\nNCOLS={ncols}\nNCOMP={ncomp}\nFORMAT=ascii\n\n",
        rows.len()
    );
    for r in rows {
        let t: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
        s.push_str(&t.join(" "));
        s.push('\n');
    }
    s
}

/// The hand case: 3 sensors x 10 hourly steps on 21 June, stamps 6.5 ... 15.5; with the
/// default 8-18 schedule the first two steps (6.5, 7.5) are unoccupied.
fn hand_rows() -> Vec<Vec<f64>> {
    vec![
        vec![
            9999.0, 9999.0, 0.0, 50.0, 100.0, 200.0, 300.0, 1000.0, 3000.0, 4000.0,
        ],
        vec![
            0.0, 0.0, 299.9, 299.9, 299.9, 299.9, 299.9, 299.9, 299.9, 299.9,
        ],
        vec![0.0, 0.0, 300.0, 300.0, 300.0, 50.0, 50.0, 50.0, 50.0, 50.0],
    ]
}

fn hours_text() -> String {
    (0..10)
        .map(|i| format!("6 21 {}\n", 6.5 + i as f64))
        .collect()
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Parse our TSV: (header names, rows as (first field, numbers)).
fn tsv(text: &str) -> (Vec<String>, Vec<(String, Vec<f64>)>) {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split('\t')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            let v = f[1..]
                .iter()
                .map(|x| x.parse::<f64>().unwrap_or(f64::NAN))
                .collect();
            (f[0].to_string(), v)
        })
        .collect();
    (head, rows)
}

fn col(head: &[String], name: &str) -> usize {
    head.iter().position(|h| h == name).unwrap() - 1
}

fn stdout_ok(cmd: &mut std::process::Command) -> String {
    let out = run(cmd, b"");
    assert!(
        out.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn hand_computed_metrics_and_boundaries() {
    let d = tmpdir();
    let m = write(d.path(), "e.mtx", &matrix(&hand_rows(), 1));
    let h = write(d.path(), "h.txt", &hours_text());
    let text = stdout_ok(ours("rmetrics").args(["--hours", &h, &m]));
    assert!(text.contains("# occupied steps: 8 (8 h)"), "{text}");
    let (head, rows) = tsv(&text);
    assert_eq!(
        head,
        [
            "sensor", "TAI_klxh", "UDI_n", "UDI_s", "UDI_a", "UDI_e", "DA", "sDA"
        ]
    );
    assert_eq!(rows.len(), 4);
    // Sensor 1: 0 50 | 100 200 | 300 1000 3000 | 4000 (the two 9999 are unoccupied).
    assert_eq!(rows[0].1, [8.65, 25.0, 25.0, 37.5, 12.5, 50.0, 100.0]);
    // Sensor 2: 299.9 lx throughout: supplementary, never DA.
    assert_eq!(rows[1].1, [2.3992, 0.0, 100.0, 0.0, 0.0, 0.0, 0.0]);
    // Sensor 3: exactly 300 lx counts as DA and UDI-a; DA 37.5 % fails sDA.
    assert_eq!(rows[2].1, [1.15, 62.5, 0.0, 37.5, 0.0, 37.5, 0.0]);
    // Room row: Eq. 2.2 TAI = mean; sDA = 1 of 3 sensors.
    assert_eq!(rows[3].0, "room");
    let r = &rows[3].1;
    assert!((r[col(&head, "TAI_klxh")] - (8.65 + 2.3992 + 1.15) / 3.0).abs() < 1e-6);
    assert!((r[col(&head, "sDA")] - 100.0 / 3.0).abs() < 1e-6);
    assert!((r[col(&head, "DA")] - 87.5 / 3.0).abs() < 1e-6);
    // No ASE column without a direct-sun matrix, and the header says why.
    assert!(!head.iter().any(|c| c.starts_with("ASE")));
    assert!(text.contains("# ASE not computed: ASE needs a direct-sun-only illuminance matrix"));
}

#[test]
fn schedule_filtering_changes_what_counts() {
    let d = tmpdir();
    let m = write(d.path(), "e.mtx", &matrix(&hand_rows(), 1));
    let h = write(d.path(), "h.txt", &hours_text());
    // 6-9: steps 6.5 7.5 8.5 of sensor 1: 9999 9999 0 -> TAI 19.998, UDI-e 2/3.
    let text = stdout_ok(ours("rmetrics").args(["--hours", &h, "--occupied", "6-9", &m]));
    let (head, rows) = tsv(&text);
    assert!((rows[0].1[col(&head, "TAI_klxh")] - 19.998).abs() < 1e-9);
    assert!((rows[0].1[col(&head, "UDI_e")] - 200.0 / 3.0).abs() < 1e-5);
    // Flags file: only the last step (4000 lx).
    let flags = "0\n0\n0\n0\n0\n0\n0\n0\n0\n1\n";
    let f = write(d.path(), "f.txt", flags);
    let text = stdout_ok(ours("rmetrics").args(["--hours", &h, "--schedule", &f, &m]));
    let (head, rows) = tsv(&text);
    assert_eq!(rows[0].1[col(&head, "TAI_klxh")], 4.0);
    assert_eq!(rows[0].1[col(&head, "UDI_e")], 100.0);
    // Weekdays: 21 June 2023 was a Wednesday (1 Jan 2023 a Sunday): unchanged; with 1 Jan
    // on a Wednesday, 21 June falls on a Saturday: nothing occupied -> refused.
    let a = stdout_ok(ours("rmetrics").args(["--hours", &h, "--weekdays", "--jan1", "sunday", &m]));
    assert_eq!(tsv(&a).1[0].1[0], 8.65);
    let out = run(
        ours("rmetrics").args(["--hours", &h, "--weekdays", "--jan1", "wed", &m]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("rmetrics: no occupied time step among the 10 columns"),
        "{err}"
    );
    // --weekdays with a .wea and no --jan1 is refused with the reason.
    let out = run(
        ours("rmetrics").args(["--hours", &h, "--weekdays", &m]),
        b"",
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("--jan1 DAY"));
    // No time stamps at all: refused unless --all-steps.
    let out = run(ours("rmetrics").arg(&m), b"");
    assert!(String::from_utf8_lossy(&out.stderr).contains("no time stamps"));
    let text = stdout_ok(ours("rmetrics").args(["--all-steps", &m]));
    assert!(text.contains("# occupied steps: 10 (10 h)"));
}

#[test]
fn ase_with_direct_sun_and_refusal_without() {
    let d = tmpdir();
    let m = write(d.path(), "e.mtx", &matrix(&hand_rows(), 1));
    let h = write(d.path(), "h.txt", &hours_text());
    let mut s1 = vec![5000.0, 5000.0, 1001.0, 1001.0, 1001.0];
    s1.extend([0.0; 5]);
    let s2 = vec![1000.0; 10]; // never strictly above 1000 lx
    let mut s3 = vec![2000.0, 2000.0, 2000.0, 2000.0]; // 2 occupied hours: not > 2
    s3.extend([0.0; 6]);
    let sun = write(d.path(), "sun.mtx", &matrix(&[s1, s2, s3], 1));
    let text = stdout_ok(ours("rmetrics").args([
        "--hours",
        &h,
        "--ase",
        "1000,2",
        "--direct-sun",
        &sun,
        &m,
    ]));
    let (head, rows) = tsv(&text);
    let (ah, a) = (col(&head, "ASE_h"), col(&head, "ASE"));
    assert_eq!((rows[0].1[ah], rows[0].1[a]), (3.0, 100.0));
    assert_eq!((rows[1].1[ah], rows[1].1[a]), (0.0, 0.0));
    assert_eq!((rows[2].1[ah], rows[2].1[a]), (2.0, 0.0));
    assert!((rows[3].1[a] - 100.0 / 3.0).abs() < 1e-6);
    assert!(!text.contains("ASE not computed"));
    // Asking for an ASE map without the direct-sun matrix: exit 1, the explanation, no file.
    let png = d.path().join("ase.png");
    let pts = write(
        d.path(),
        "s.pts",
        "0 0 0.8 0 0 1\n1 0 0.8 0 0 1\n2 0 0.8 0 0 1\n",
    );
    let out = run(
        ours("rmetrics").args([
            "--hours",
            &h,
            "--pts",
            &pts,
            "--map",
            "ASE",
            "--png",
            png.to_str().unwrap(),
            &m,
        ]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with(
            "rmetrics: ASE needs a direct-sun-only illuminance matrix (--direct-sun FILE"
        ),
        "{err}"
    );
    assert!(!png.exists());
}

#[test]
fn rgb_input_is_converted_and_noted() {
    let d = tmpdir();
    let h = write(d.path(), "h.txt", &hours_text());
    let lux = hand_rows();
    // RGB irradiance with R = G = B = E / 179: the photopic weights sum to 1.
    let rgb: Vec<Vec<f64>> = lux
        .iter()
        .map(|r| r.iter().flat_map(|&e| [e / 179.0; 3]).collect())
        .collect();
    let m1 = write(d.path(), "lux.mtx", &matrix(&lux, 1));
    let m3 = write(d.path(), "rgb.mtx", &matrix(&rgb, 3));
    let a = stdout_ok(ours("rmetrics").args(["--hours", &h, &m1]));
    let out = run(ours("rmetrics").args(["--hours", &h, &m3]), b"");
    assert!(out.status.success());
    let b = String::from_utf8(out.stdout).unwrap();
    assert!(b.contains("# input was RGB irradiance (NCOMP=3): converted to lux as 179 x (0.265 R"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("note: input was RGB"));
    let (ha, ra) = tsv(&a);
    let (_, rb) = tsv(&b);
    let k = col(&ha, "TAI_klxh");
    for (x, y) in ra.iter().zip(&rb) {
        assert!(
            (x.1[k] - y.1[k]).abs() < 1e-6 * x.1[k].max(1.0),
            "{x:?} {y:?}"
        );
    }
}

#[test]
fn map_png_size_and_colour_ends() {
    let d = tmpdir();
    let m = write(d.path(), "e.mtx", &matrix(&hand_rows(), 1));
    let h = write(d.path(), "h.txt", &hours_text());
    let pts = write(
        d.path(),
        "s.pts",
        "0 0 0.8 0 0 1\n0.5 0 0.8 0 0 1\n1 0 0.8 0 0 1\n",
    );
    let png = d.path().join("tai.png");
    let json = d.path().join("m.json");
    let text = stdout_ok(ours("rmetrics").args([
        "--hours",
        &h,
        "--pts",
        &pts,
        "--map",
        "TAI_klxh",
        "--range",
        "1,9",
        "--png",
        png.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        &m,
    ]));
    assert!(text.contains("sensor\tx\ty\tz\tTAI_klxh"));
    let img = image::open(&png).unwrap().to_rgb8();
    // A report-page figure; the colour bar runs palette(0) at the bottom to palette(1) at
    // the top (viridis, the default), on the --range 1,9 given here.
    use rdaylight::metrics::map::{BAR_BOTTOM, BAR_TOP, BAR_W, BAR_X, PLAN};
    use rdaylight::metrics::plot::Palette;
    assert_eq!((img.width(), img.height()), (1200, 900));
    let bx = (BAR_X + BAR_W / 2) as u32;
    assert_eq!(
        img.get_pixel(bx, BAR_BOTTOM as u32 - 1).0,
        Palette::Viridis.colour(0.0)
    );
    // (Row BAR_TOP is the bar's black frame; the next row is t = 1 - 1.5/600.)
    let top = img.get_pixel(bx, BAR_TOP as u32 + 1).0;
    let want = Palette::Viridis.colour(1.0);
    assert!(
        top.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 2),
        "{top:?}"
    );
    let mid = (BAR_TOP + BAR_BOTTOM) as u32 / 2;
    let c = img.get_pixel(bx, mid).0;
    let want = Palette::Viridis.colour(0.5);
    assert!(
        c.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 3),
        "{c:?} {want:?}"
    );
    // Sensor 1 (x = 0, TAI 8.65) is near the top of the scale, sensor 3 (x = 1, TAI 1.15)
    // near the bottom: each colour fills its cell, sensor 1's left of sensor 3's.
    let find = |rgb: [u8; 3]| {
        let mut xs = Vec::new();
        for y in PLAN.1 as u32..PLAN.3 as u32 {
            for x in PLAN.0 as u32..PLAN.2 as u32 {
                if img.get_pixel(x, y).0 == rgb {
                    xs.push(x);
                }
            }
        }
        xs
    };
    let hi = find(Palette::Viridis.colour((8.65 - 1.0) / 8.0));
    let lo = find(Palette::Viridis.colour((1.15 - 1.0) / 8.0));
    assert!(
        hi.len() > 1000 && lo.len() > 1000,
        "{} {}",
        hi.len(),
        lo.len()
    );
    assert!(hi.iter().max() < lo.iter().min());
    // JSON carries the same numbers.
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(j["sensors"][0]["TAI_klxh"], 8.65);
    assert_eq!(j["sensors"][2]["position"][0], 1.0);
    assert!((j["room"]["sDA"].as_f64().unwrap() - 100.0 / 3.0).abs() < 1e-9);
    assert!(
        j["ase_not_computed"]
            .as_str()
            .unwrap()
            .starts_with("ASE needs")
    );
}

#[test]
fn compare_tables_and_matrices_appendix_a() {
    let d = tmpdir();
    let a = write(
        d.path(),
        "a.tsv",
        "# bench\nsensor\tTAI_klxh\tDA\n1\t1\t40\n2\t3\t60\nroom\t2\t50\n",
    );
    let b = write(
        d.path(),
        "b.tsv",
        "sensor\tx\ty\tz\tTAI_klxh\tDA\n1\t0\t0\t0\t2\t50\n2\t1\t0\t0\t4\t70\nroom\t-\t-\t-\t3\t60\n",
    );
    let text = stdout_ok(ours("rmetrics").args(["compare", &a, &b]));
    let (head, rows) = tsv(&text);
    assert_eq!(head, ["metric", "benchmark", "PE_%", "MAPE_%", "RMSE"]);
    assert_eq!(rows[0].0, "TAI_klxh");
    assert_eq!(rows[0].1, [2.0, 50.0, 50.0, 1.0]);
    assert_eq!(rows[1].0, "DA");
    assert_eq!(rows[1].1, [50.0, 20.0, 20.0, 10.0]);
    // Matrices: the variant is the benchmark x 1.1 -> PE of TAI 10 %; RMSE of lux by hand.
    let h = write(d.path(), "h.txt", &hours_text());
    let base = hand_rows();
    let var: Vec<Vec<f64>> = base
        .iter()
        .map(|r| r.iter().map(|v| v * 1.1).collect())
        .collect();
    let mb = write(d.path(), "b.mtx", &matrix(&base, 1));
    let mv = write(d.path(), "v.mtx", &matrix(&var, 1));
    let text = stdout_ok(ours("rmetrics").args(["compare", "--hours", &h, &mb, &mv]));
    let (_, rows) = tsv(&text);
    assert_eq!(rows[0].0, "TAI_klxh");
    assert!((rows[0].1[1] - 10.0).abs() < 1e-6, "{rows:?}");
    let mut sq = 0.0;
    for r in &base {
        for v in &r[2..] {
            sq += (0.1 * v) * (0.1 * v);
        }
    }
    let want = (sq / 24.0f64).sqrt();
    assert_eq!(rows[1].0, "E_lux");
    assert!(
        (rows[1].1[3] - want).abs() < 1e-4 * want,
        "{} vs {want}",
        rows[1].1[3]
    );
    // Different sensor counts are refused.
    let c = write(d.path(), "c.tsv", "sensor\tDA\n1\t5\n");
    let out = run(ours("rmetrics").args(["compare", &a, &c]), b"");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("has 1 sensors, the benchmark"));
}

#[test]
fn help_documents_options_and_a_pipeline() {
    let text = stdout_ok(ours("rmetrics").arg("--help"));
    for opt in [
        "--weather",
        "--hours",
        "--occupied",
        "--weekdays",
        "--jan1",
        "--schedule",
        "--all-steps",
        "--udi",
        "--da",
        "--sda",
        "--ase",
        "--direct-sun",
        "--pts",
        "--output",
        "--json",
        "--map",
        "--png",
        "compare",
        "dctimestep",
        "rmtxop",
    ] {
        assert!(text.contains(opt), "--help lacks {opt}");
    }
}

/// Straightforward reimplementation over a headered ascii NCOMP=1 matrix.
fn load_ascii(text: &str) -> Vec<Vec<f64>> {
    let body = text.split_once("\n\n").unwrap().1;
    body.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn real_radiance_illuminance_matches_an_independent_computation() {
    if !common::have_radiance("real_radiance_illuminance") {
        return;
    }
    let fx = repo().join("radiance-fixtures");
    let d = tmpdir();
    let dc = common::run_ok(
        common::radiance("dctimestep")
            .current_dir(&fx)
            .args(["dc/office_m1.mtx", "sky/london_4days_m1.smx"]),
        b"",
    );
    let illum = common::run_ok(
        common::radiance("rmtxop").args(["-fa", "-c", "47.4", "119.9", "11.6", "-"]),
        &dc,
    );
    let mpath = d.path().join("illum.mtx");
    std::fs::write(&mpath, &illum).unwrap();
    let wea = fx.join("weather/london_4days.wea");
    let json = d.path().join("m.json");
    let out = run(
        ours("rmetrics").args([
            "-w",
            wea.to_str().unwrap(),
            "--pts",
            fx.join("sensors/office.pts").to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            mpath.to_str().unwrap(),
        ]),
        b"",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();

    // Independent computation: parse the matrix and the .wea by hand.
    let e = load_ascii(&String::from_utf8(illum).unwrap());
    let wtext = std::fs::read_to_string(&wea).unwrap();
    let hours: Vec<f64> = wtext
        .lines()
        .skip(6)
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    assert_eq!(e.len(), 165);
    assert_eq!(hours.len(), 96);
    assert!(e.iter().all(|r| r.len() == 96));
    let occ: Vec<usize> = (0..96)
        .filter(|&k| (8.0..18.0).contains(&hours[k]))
        .collect();
    assert_eq!(occ.len(), 40, "4 days x 10 hours");
    assert_eq!(j["occupied_steps"], 40);
    let sensors = j["sensors"].as_array().unwrap();
    assert_eq!(sensors.len(), 165);
    let mut pass = 0;
    let mut tai_sum = 0.0;
    for (i, row) in e.iter().enumerate() {
        let v: Vec<f64> = occ.iter().map(|&k| row[k]).collect();
        let n = v.len() as f64;
        let pct = |f: &dyn Fn(f64) -> bool| 100.0 * v.iter().filter(|&&x| f(x)).count() as f64 / n;
        let tai = v.iter().sum::<f64>() / 1000.0;
        let da = pct(&|x| x >= 300.0);
        let want = [
            ("TAI_klxh", tai),
            ("UDI_n", pct(&|x| x < 100.0)),
            ("UDI_s", pct(&|x| (100.0..300.0).contains(&x))),
            ("UDI_a", pct(&|x| (300.0..=3000.0).contains(&x))),
            ("UDI_e", pct(&|x| x > 3000.0)),
            ("DA", da),
        ];
        let s = &sensors[i];
        for (name, w) in want {
            let got = s[name].as_f64().unwrap();
            assert!(
                (got - w).abs() <= 1e-9 * w.abs().max(1.0),
                "sensor {} {name}: {got} vs {w}",
                i + 1
            );
        }
        // Consistent outputs: DA at 300 lx counts exactly the hours of UDI_a and UDI_e, and
        // the four UDI bins sum to 100.
        let (ua, ue) = (s["UDI_a"].as_f64().unwrap(), s["UDI_e"].as_f64().unwrap());
        assert!((s["DA"].as_f64().unwrap() - (ua + ue)).abs() < 1e-9);
        let udi: f64 = ["UDI_n", "UDI_s", "UDI_a", "UDI_e"]
            .iter()
            .map(|k| s[*k].as_f64().unwrap())
            .sum();
        assert!((udi - 100.0).abs() < 1e-9);
        assert!(tai > 0.0, "daylight reaches every sensor on these days");
        if da >= 50.0 {
            pass += 1;
        }
        tai_sum += tai;
    }
    // sDA consistent with per-sensor DA; room TAI is Eq. 2.2.
    let sda = j["room"]["sDA"].as_f64().unwrap();
    assert!((sda - 100.0 * pass as f64 / 165.0).abs() < 1e-9);
    let tai_room = j["room"]["TAI_klxh"].as_f64().unwrap();
    assert!((tai_room - tai_sum / 165.0).abs() < 1e-9 * tai_room);
    // Side-lit room: the row of sensors by the (south, y = 0) window gets more light than
    // the row at the back wall.
    let y = |s: &serde_json::Value| s["position"][1].as_f64().unwrap();
    let ymin = sensors.iter().map(y).fold(f64::INFINITY, f64::min);
    let ymax = sensors.iter().map(y).fold(f64::NEG_INFINITY, f64::max);
    let mean_at = |yy: f64| {
        let v: Vec<f64> = sensors
            .iter()
            .filter(|s| (y(s) - yy).abs() < 1e-9)
            .map(|s| s["TAI_klxh"].as_f64().unwrap())
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    assert!(
        mean_at(ymin) > 2.0 * mean_at(ymax),
        "{} vs {}",
        mean_at(ymin),
        mean_at(ymax)
    );

    // The same matrix against a weather file with another step count is refused.
    let out = run(
        ours("rmetrics").args([
            "-w",
            fx.join("weather/london_6hours.wea").to_str().unwrap(),
            mpath.to_str().unwrap(),
        ]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("96 columns (time steps), but"), "{err}");
    assert!(err.contains("gendaymtx without -u"), "{err}");
}

#[test]
fn weekdays_come_from_the_epw_data_periods() {
    // The London IWEC EPW says DATA PERIODS ... Sunday, 1/1: a 365-day year from a Sunday
    // has 260 weekdays (its last day is a Sunday too); from a Monday it has 261.
    let d = tmpdir();
    let epw = repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw");
    let m = write(d.path(), "ones.mtx", &matrix(&[vec![1.0; 8760]], 1));
    let run_with = |extra: &[&str]| {
        let mut c = ours("rmetrics");
        c.args(["-w", epw.to_str().unwrap(), "--weekdays"])
            .args(extra)
            .arg(&m);
        stdout_ok(&mut c)
    };
    let a = run_with(&[]);
    assert!(a.contains("# occupied steps: 2600 (2600 h)"), "{a}");
    assert!(a.contains("Monday to Friday"));
    assert_eq!(tsv(&a).1[0].1[0], 2.6);
    let b = run_with(&["--jan1", "Monday"]);
    assert!(b.contains("# occupied steps: 2610 (2610 h)"), "{b}");
}

#[test]
fn bad_inputs_fail_cleanly() {
    let d = tmpdir();
    let h = write(d.path(), "h.txt", &hours_text());
    let full = matrix(&hand_rows(), 1);
    // Every truncated prefix of the matrix: exit 0 (a prefix that is still whole) or 1 with
    // one `rmetrics:` line, never a panic (101).
    for n in (0..full.len()).step_by(3) {
        let m = write(d.path(), "t.mtx", &full[..n]);
        let out = run(ours("rmetrics").args(["--hours", &h, &m]), b"");
        let code = out.status.code();
        assert!(code == Some(0) || code == Some(1), "prefix {n}: {code:?}");
        if code == Some(1) {
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                err.starts_with("rmetrics: ") && err.lines().count() == 1,
                "{err}"
            );
            assert!(out.stdout.is_empty(), "prefix {n}: partial output");
        }
    }
    // A direct-sun matrix of another shape is refused before any output.
    let m = write(d.path(), "e.mtx", &full);
    let sun = write(d.path(), "sun.mtx", &matrix(&[vec![0.0; 10]], 1));
    let out = run(
        ours("rmetrics").args(["--hours", &h, "--direct-sun", &sun, &m]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("both must come from the same sensors and sky steps"),
        "{err}"
    );
    // A spectral matrix (NCOMP=4) is refused with the fix.
    let spec = write(d.path(), "s.mtx", &matrix(&[vec![1.0; 40]], 4));
    let out = run(ours("rmetrics").args(["--hours", &h, &spec]), b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("NCOMP=4; rmetrics reads illuminance"), "{err}");
    // A bad --hours line names file and line.
    let bad = write(d.path(), "bad.txt", "6 21 6.5\n6 21 x\n");
    let out = run(ours("rmetrics").args(["--hours", &bad, &m]), b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with(&format!("rmetrics: {bad}:2: expected 'month day hour'")),
        "{err}"
    );
}
