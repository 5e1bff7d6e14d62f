//! Hostile and clumsy input (issue #19): every case runs the real binary and asserts exit
//! status 1, exactly one line on stderr, and a message that names the option or the
//! file:line and the limit. One regression test per reported failure.

use crate::common;

use common::{ours, repo, run, run_ok, tmpdir};
use std::path::Path;

/// Run `tool args` with `stdin`; assert status 1, nothing on stdout and one stderr line,
/// which is returned.
fn one_line_error(tool: &str, args: &[&str], stdin: &[u8]) -> String {
    let out = run(ours(tool).args(args), stdin);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{tool} {args:?}: {err}");
    assert_eq!(
        err.lines().count(),
        1,
        "{tool} {args:?}: one line, got: {err}"
    );
    assert!(err.starts_with(&format!("{tool}: ")), "{err}");
    assert!(
        out.stdout.is_empty(),
        "{tool} {args:?}: nothing on stdout after an error"
    );
    err
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

const MATERIAL: &str = "void plastic m 0 0 5 .5 .5 .5 0 0\n";

/// `rdc -I -m 1 -ad 1 big.rad` panicked inside the BVH builder (obvhs index out of bounds)
/// for a sphere of radius 1e39 and polygons at 1e39 or 1e308.
#[test]
fn huge_coordinates_are_a_file_line_error() {
    let d = tmpdir();
    let cases = [
        "m sphere s 0 0 4 0 0 0 1e39\n",
        "m polygon p 0 0 9 0 0 0 1e39 0 0 0 1e39 0\n",
        "m polygon p 0 0 9 0 0 0 1e308 0 0 0 1e308 0\n",
        "m ring r 0 0 8 0 0 0 0 0 1 0 2e9\n",
    ];
    for (i, geometry) in cases.iter().enumerate() {
        let scene = write(
            d.path(),
            &format!("big{i}.rad"),
            &format!("{MATERIAL}{geometry}"),
        );
        let e = one_line_error(
            "rdc",
            &["-I", "-m", "1", "-ad", "1", &scene],
            b"1 1 1 0 0 1\n",
        );
        assert!(e.contains(&format!("big{i}.rad:2:")), "{e}");
        assert!(e.contains("out of range") && e.contains("1e9 m"), "{e}");
    }
    // The same limit for the scan simulator's own BVH.
    let scene = write(d.path(), "scan.rad", &format!("{MATERIAL}{}", cases[1]));
    let e = one_line_error("rrecon", &["simulate", &scene, "--stations", "0,0,1"], b"");
    assert!(
        e.contains("scan.rad:2:") && e.contains("out of range"),
        "{e}"
    );
}

/// Counts and sizes without a bound ran for ever (`-ad 1e18`, `--eye-ad 1e15`), aborted on
/// allocation (`-x 1e8 -y 1e8`, `--samples 1e12`) or started 100,000 threads (`-n`).
#[test]
fn unbounded_counts_are_refused_with_the_limit() {
    let d = tmpdir();
    let scene = write(d.path(), "room.rad", MATERIAL);
    let rdc = |args: &[&str]| {
        let mut a: Vec<&str> = args.to_vec();
        a.push(&scene);
        one_line_error("rdc", &a, b"1 1 1 0 0 1\n")
    };
    let e = rdc(&["-I", "-m", "1", "-ad", "1000000000000000000"]);
    assert!(
        e.contains("-ad 1000000000000000000: at most 16777216 ("),
        "{e}"
    );
    let e = rdc(&["-I", "-m", "1", "-ab", "100000"]);
    assert!(e.contains("-ab 100000: at most 1000 ("), "{e}");
    let e = rdc(&["-I", "-m", "1", "-lr", "-2147483648"]);
    assert!(e.contains("-lr 2147483648: at most 1000 ("), "{e}");
    let e = rdc(&["-I", "-m", "1", "-n", "100000"]);
    assert!(e.contains("-n 100000: at most 1024"), "{e}");
    let e = rdc(&[
        "-I",
        "-m",
        "1",
        "--target-se",
        "0.1",
        "--max-samples",
        "99999999999",
    ]);
    assert!(
        e.contains("--max-samples 99999999999: at most 16777216"),
        "{e}"
    );
    let view = [
        "-vtv", "-vp", "0", "0", "0", "-vd", "0", "1", "0", "-vh", "45", "-vv", "45",
    ];
    let mut a = view.to_vec();
    a.extend(["-x", "100000000", "-y", "100000000"]);
    let e = rdc(&a);
    assert!(
        e.contains("-x 100000000 -y 100000000: a picture of") && e.contains("2 GiB"),
        "{e}"
    );

    let annual = |extra: [&str; 2]| {
        let mut a = vec!["annual", "-w", "x.wea", "-vta", "-vh", "180", "-vv", "180"];
        a.extend(extra);
        a.push(&scene);
        one_line_error("rglare", &a, b"")
    };
    let e = annual(["--eye-ad", "1e15"]);
    assert!(
        e.contains("--eye-ad 1000000000000000: at most 16777216"),
        "{e}"
    );
    let e = annual(["--rays", "100000"]);
    assert!(e.contains("--rays 100000: at most 1024"), "{e}");
    let e = annual(["--rays", "2.5"]);
    assert!(e.contains("--rays: '2.5' is not a whole number"), "{e}");

    let e = one_line_error(
        "rrecon",
        &["eval", &scene, &scene, "--samples", "1000000000000"],
        b"",
    );
    assert!(
        e.contains("--samples 1000000000000: at most 10000000"),
        "{e}"
    );
    // The smaller counts: each names its limit.
    for (tool, args, limit) in [
        (
            "ruplift",
            &["rgb", "--table-res", "1000", "0.5", "0.5", "0.5"][..],
            "128",
        ),
        ("rcalib", &["synth", "--steps", "100000"][..], "8784"),
        (
            "rrecon",
            &["--target-points", "1000000000", "x.ply"][..],
            "100000000",
        ),
        ("rmtx", &["--ncomp", "5000", "x.mtx"][..], "1024"),
        ("rmtx", &["--ncols", "99999999999", "x.mtx"][..], "10000000"),
    ] {
        let e = one_line_error(tool, args, b"");
        assert!(e.contains(&format!("the limit {limit}")), "{tool}: {e}");
    }
}

/// `!yes` in a scene made rinfo run out of memory: an inline command's output is capped
/// (1 GiB) and the command stopped.
#[test]
fn endless_inline_command_output_is_capped() {
    let d = tmpdir();
    let scene = write(d.path(), "yes.rad", &format!("{MATERIAL}!yes\n"));
    let e = one_line_error("rinfo", &[&scene], b"");
    assert!(
        e.contains("yes.rad:2: command '!yes' printed more than 1073741824 bytes"),
        "{e}"
    );
}

/// Every tool: a bad option is one line and status 1 (clap alone prints a block and exits
/// 2); `--help` and `--version` print on stdout and exit 0, tools and subcommands alike.
#[test]
fn usage_errors_are_one_line_and_help_exits_zero() {
    let tools = [
        "rdc", "rmtx", "rinfo", "rmetrics", "rspecsky", "rglare", "ruplift", "rcalib", "rrecon",
        "rglod", "rmcop",
    ];
    for tool in tools {
        let e = one_line_error(tool, &["--no-such-option"], b"");
        assert!(e.contains("--no-such-option"), "{e}");
        for flag in ["--help", "--version"] {
            let out = run(ours(tool).arg(flag), b"");
            assert_eq!(out.status.code(), Some(0), "{tool} {flag}");
            assert!(!out.stdout.is_empty(), "{tool} {flag} prints on stdout");
        }
    }
    let subcommands: [&[&str]; 10] = [
        &["rmcop", "study"],
        &["rmcop", "validate"],
        &["rglare", "annual"],
        &["rspecsky", "genssky"],
        &["rmetrics", "compare"],
        &["ruplift", "proxy"],
        &["rcalib", "compare"],
        &["rrecon", "eval"],
        &["rglod", "study"],
        &["rmetrics", "melanopic"],
    ];
    for sub in subcommands {
        let out = run(ours(sub[0]).args([sub[1], "--help"]), b"");
        assert_eq!(out.status.code(), Some(0), "{sub:?} --help");
        assert!(!out.stdout.is_empty(), "{sub:?} --help prints on stdout");
        let e = one_line_error(sub[0], &[sub[1], "--no-such-option"], b"");
        assert!(
            e.contains("--no-such-option") || e.contains("rdc options"),
            "{e}"
        );
    }
}

/// `rmtx -c nan` and `-s inf` were accepted, as was any `nan`/`inf` a clap option took as
/// a real number.
#[test]
fn non_finite_option_values_are_errors() {
    let d = tmpdir();
    let m = write(
        d.path(),
        "m.mtx",
        "#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n1 2 3\n",
    );
    let e = one_line_error("rmtx", &["-c", "nan", &m], b"");
    assert!(e.contains("-c nan: expected finite numbers"), "{e}");
    let e = one_line_error("rmtx", &["-s", "inf", &m], b"");
    assert!(e.contains("-s inf: expected finite numbers"), "{e}");
    let e = one_line_error("rdc", &["-lw", "nan", "x.rad"], b"");
    assert!(
        e.contains("'nan'") && e.contains("--lw") && e.contains("finite"),
        "{e}"
    );
    let e = one_line_error("rdc", &["-cs", "5", "-cw", "380", "inf", "x.rad"], b"");
    assert!(e.contains("'inf'") && e.contains("--cw"), "{e}");
    let e = one_line_error("ruplift", &["rgb", "0.5", "NaN", "0.5"], b"");
    assert!(e.contains("'NaN'") && e.contains("finite"), "{e}");
    let e = one_line_error("rmetrics", &["--da", "1e999", &m], b"");
    assert!(e.contains("--da") && e.contains("finite"), "{e}");
}

/// `rmetrics` on a matrix holding nan or inf printed `TAI nan`: now an error naming the
/// file, row and column; negative illuminance is a counted note on stderr.
#[test]
fn non_finite_matrix_values_name_row_and_column() {
    let d = tmpdir();
    let hours = write(d.path(), "h.txt", "6 21 10.5\n6 21 11.5\n6 21 12.5\n");
    let head = "#?RADIANCE\nNROWS=2\nNCOLS=3\nNCOMP=1\nFORMAT=ascii\n\n";
    // (`-inf` is already refused by the ascii reader, with file:line.)
    for bad in ["nan", "inf"] {
        let m = write(
            d.path(),
            "m.mtx",
            &format!("{head}100 200 300\n100 200 {bad}\n"),
        );
        let e = one_line_error("rmetrics", &["--hours", &hours, &m], b"");
        assert!(e.contains(&format!("{m}: row 2, column 3: value")), "{e}");
        assert!(e.contains("not a finite number"), "{e}");
    }
    let m = write(
        d.path(),
        "neg.mtx",
        &format!("{head}100 -2 300\n-1 200 300\n"),
    );
    let out = run(ours("rmetrics").args(["--hours", &hours, &m]), b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("2 negative illuminance values"), "{err}");
}

const FLOOR: &str = "m polygon floor 0 0 9 0 0 0 1 0 0 0 1 0\n";

/// A zero sensor direction gave an all-zero row (rcalib: a -100 % error) and an empty
/// sensor file an NROWS=0 matrix with exit 0. rdc's ray stream keeps rtrace's flush
/// convention; sensor files read for coefficients or metrics refuse it with file:line.
#[test]
fn zero_directions_and_empty_sensor_files_are_errors() {
    let d = tmpdir();
    let scene = write(d.path(), "room.rad", &format!("{MATERIAL}{FLOOR}"));
    let rdc = ["-I", "-m", "1", "-ad", "1", "-h", scene.as_str()];
    let e = one_line_error("rdc", &rdc, b"");
    assert!(e.contains("no sensors in <stdin>"), "{e}");
    // rtrace's flush request in a ray stream: still an empty record, one per input ray.
    let out = run_ok(ours("rdc").args(rdc), b"0.5 0.5 1 0 0 0\n");
    let text = String::from_utf8(out).unwrap();
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(text.split_whitespace().all(|v| v.parse::<f64>() == Ok(0.0)));

    let zero = write(d.path(), "zero.pts", "1 1 1 0 0 1\n\n2 2 1 0 0 0\n");
    let empty = write(d.path(), "empty.pts", "");
    let weather = repo().join("tests/data/weather/tiny.wea");
    let weather = weather.to_str().unwrap();
    for (pts, want) in [
        (&zero, format!("{zero}:3: sensor direction is 0 0 0")),
        (&empty, format!("no sensors in {empty}")),
    ] {
        let apply = [
            "apply",
            &scene,
            "--sensors",
            pts,
            "--effect",
            "transmittance:0.9",
        ];
        let e = one_line_error("rcalib", &apply, b"");
        assert!(e.contains(&want), "{e}");
        let study = ["study", "-w", weather, "--pts", pts, "--ad", "1", &scene];
        let e = one_line_error("rglod", &study, b"");
        assert!(e.contains(&want), "{e}");
        let out = d.path().join("mcop").display().to_string();
        let mut mcop = study.to_vec();
        mcop.extend(["-o", &out]);
        let e = one_line_error("rmcop", &mcop, b"");
        assert!(e.contains(&want), "{e}");
    }
    let csv = write(d.path(), "s.csv", "id,x,y,z,dx,dy,dz\nA,1,1,1,0,0,0\n");
    let e = one_line_error(
        "rcalib",
        &["apply", &scene, "--sensors", &csv, "--effect", "walls:1"],
        b"",
    );
    assert!(
        e.contains(&format!("{csv}:2: sensor direction is 0 0 0")),
        "{e}"
    );
}

/// rinfo called empty .mtx/.hdr/.epw files, headerless binary matrices, headerless .wea
/// bodies, .pts files and PNG pictures scenes of "0 objects".
#[test]
fn rinfo_says_what_a_file_is() {
    let d = tmpdir();
    for name in ["a.mtx", "a.hdr", "a.epw"] {
        let p = write(d.path(), name, "");
        let e = one_line_error("rinfo", &[&p], b"");
        assert!(e.contains(&format!("{p}: empty file (0 bytes)")), "{e}");
    }
    let bin = d.path().join("dc.dat");
    std::fs::write(&bin, 0.25f32.to_ne_bytes().repeat(18)).unwrap();
    let e = one_line_error("rinfo", &[bin.to_str().unwrap()], b"");
    assert!(e.contains("binary data without a Radiance header"), "{e}");
    let body = write(d.path(), "body.wea", "1 1 0.5 0 0\n1 1 1.5 0 0\n");
    let e = one_line_error("rinfo", &[&body], b"");
    assert!(e.contains("without a header: a .wea file needs"), "{e}");
    let pts = write(d.path(), "c.pts", "# my sensors\n1 1 1 0 0 1\n");
    let e = one_line_error("rinfo", &[&pts], b"");
    assert!(e.contains(&format!("{pts}:1: expected a number")), "{e}");
    let mtx = write(d.path(), "h.mtx", "1 2 3\n4 5 6\n");
    let e = one_line_error("rinfo", &[&mtx], b"");
    assert!(e.contains("no Radiance header"), "{e}");
    let png = d.path().join("p.png");
    image::RgbImage::new(3, 2).save(&png).unwrap();
    let out = run_ok(ours("rinfo").arg(&png), b"");
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("PNG picture, 3 x 2 pixels"), "{text}");
    // An empty scene is still a scene.
    let rad = write(d.path(), "empty.rad", "");
    let out = run_ok(ours("rinfo").arg(&rad), b"");
    assert!(String::from_utf8_lossy(&out).contains("0 objects"));
}

/// `rrecon eval` scored an empty or sphere-only truth as a perfect match (Chamfer 0).
#[test]
fn rrecon_eval_needs_surfaces_to_sample() {
    let d = tmpdir();
    let room = write(d.path(), "room.rad", &format!("{MATERIAL}{FLOOR}"));
    let empty = write(d.path(), "empty.rad", "");
    let ball = write(
        d.path(),
        "ball.rad",
        &format!("{MATERIAL}m sphere s 0 0 4 0 0 0 1\n"),
    );
    for truth in [&empty, &ball] {
        let e = one_line_error("rrecon", &["eval", truth, &room, "--samples", "100"], b"");
        assert!(
            e.contains(&format!("{truth}: no polygons to sample as the truth")),
            "{e}"
        );
    }
    let e = one_line_error("rrecon", &["eval", &room, &empty, "--samples", "100"], b"");
    assert!(e.contains("as the reconstruction"), "{e}");
}

/// `rcalib apply --effect walls:1e300` wrote 0.95 under a comment saying x1e300.
#[test]
fn rcalib_apply_bounds_scales_and_says_what_it_wrote() {
    let d = tmpdir();
    let ex = repo().join("examples/calib");
    let model = ex.join("model.rad").display().to_string();
    let sensors = ex.join("sensors.csv").display().to_string();
    let apply = |effect: &str| {
        let mut c = ours("rcalib");
        c.args(["apply", &model, "--sensors", &sensors, "--effect", effect]);
        c
    };
    let e = one_line_error(
        "rcalib",
        &[
            "apply",
            &model,
            "--sensors",
            &sensors,
            "--effect",
            "walls:1e300",
        ],
        b"",
    );
    assert!(e.contains("scale 1e300 is above 10"), "{e}");
    let out = String::from_utf8(run_ok(&mut apply("walls:2.5"), b"")).unwrap();
    let notes: Vec<&str> = out.lines().take_while(|l| l.starts_with('#')).collect();
    assert!(notes.iter().any(|l| l.contains("walls:2.500")), "{notes:?}");
    assert!(
        notes
            .iter()
            .any(|l| l.contains("written as 0.95 (the cap)")),
        "{notes:?}"
    );
    let _ = d;
}

/// `rdc` took a view point at 1e300; geometry is bounded at 1e9 m, the view now too.
#[test]
fn far_view_points_are_refused() {
    let d = tmpdir();
    let scene = write(d.path(), "room.rad", &format!("{MATERIAL}{FLOOR}"));
    let e = one_line_error(
        "rdc",
        &[
            "-m", "1", "-vtv", "-vp", "1e300", "0", "0", "-vd", "0", "1", "0", "-x", "4", "-y",
            "4", &scene,
        ],
        b"",
    );
    assert!(
        e.contains("bad view: view point out of range") && e.contains("1e9 m"),
        "{e}"
    );
}

/// rspecsky turned a DNI of 1e308 into a sky of inf/NaN, and a negative DNI was an error
/// in a .wea but a silent dark sky from an EPW: one policy for both formats.
#[test]
fn weather_values_are_bounded_in_both_formats() {
    let d = tmpdir();
    let head = "place X_Y\nlatitude 37.62\nlongitude 122.4\ntime_zone 120\nsite_elevation 3.0\n\
                weather_data_file_units 1\n";
    let wea = write(d.path(), "big.wea", &format!("{head}3 21 12.5 1e308 80\n"));
    let e = one_line_error("rspecsky", &["-m", "1", &wea], b"");
    assert!(
        e.contains(&format!("{wea}:7: direct value 1e308 W/m2 is above 2041.5")),
        "{e}"
    );
    let epw = std::fs::read_to_string(repo().join("tests/data/weather/london_2days.epw")).unwrap();
    let mut lines: Vec<String> = epw.lines().map(String::from).collect();
    let mut fields: Vec<String> = lines[20].split(',').map(String::from).collect();
    fields[14] = "-5".into();
    lines[20] = fields.join(",");
    let bad = write(d.path(), "neg.epw", &(lines.join("\n") + "\n"));
    let e = one_line_error("rspecsky", &["-m", "1", &bad], b"");
    assert!(
        e.contains(&format!("{bad}:21: negative Direct Normal")),
        "{e}"
    );
    // The missing code passes, as Radiance passes it.
    let ok = write(d.path(), "miss.wea", &format!("{head}3 21 12.5 9999 80\n"));
    run_ok(ours("rspecsky").args(["-m", "1", &ok]), b"");
}

/// `rmtx -fa truncated.mtx > out` wrote a header promising NROWS=165, then 150 rows;
/// `rmetrics melanopic` printed a header cut off at NCOLS= before its error.
#[test]
fn nothing_is_written_before_the_input_is_known_whole() {
    let d = tmpdir();
    let rows: Vec<String> = (0..150).map(|i| format!("{i} 2 3")).collect();
    let t = write(
        d.path(),
        "t.mtx",
        &format!(
            "#?RADIANCE\nNROWS=165\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n{}\n",
            rows.join("\n")
        ),
    );
    let e = one_line_error("rmtx", &["-fa", &t], b"");
    assert!(e.contains("ends after row 150 of 165"), "{e}");
    let e = one_line_error("rmtx", &["--cat", &t, &t], b"");
    assert!(e.contains("ends after row 150 of 165"), "{e}");
    let rgb = write(
        d.path(),
        "rgb.mtx",
        "#?RADIANCE\nNROWS=1\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n1 2 3 4 5 6\n",
    );
    let e = one_line_error("rmetrics", &["melanopic", &rgb], b"");
    assert!(e.contains("spectral bands"), "{e}");
}

/// `rdc --se-out` replaced the old file with a header-only one on an input error, and a
/// `--reweight` target that could not be replaced left its `.part` file behind.
#[test]
fn rdc_side_outputs_are_atomic() {
    let d = tmpdir();
    let scene = write(d.path(), "room.rad", &format!("{MATERIAL}{FLOOR}"));
    let se = write(d.path(), "se.txt", "OLD\n");
    let e = one_line_error(
        "rdc",
        &[
            "-I",
            "-m",
            "1",
            "-ad",
            "4",
            "--target-se",
            "0.5",
            "--se-out",
            &se,
            &scene,
        ],
        b"1 1 1 0 0 1\n1 2 3\n",
    );
    assert!(e.contains("<stdin>:2:"), "{e}");
    assert_eq!(std::fs::read_to_string(&se).unwrap(), "OLD\n");
    std::fs::create_dir(d.path().join("rw.dat")).unwrap();
    let rw = d.path().join("rw.dat").display().to_string();
    let out = run(
        ours("rdc").args(["-I", "-m", "1", "-ad", "4", "--reweight", &rw, &scene]),
        b"1 1 1 0 0 1\n",
    );
    assert_eq!(out.status.code(), Some(1));
    let sky = write(
        d.path(),
        "sky.rad",
        "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n",
    );
    std::fs::create_dir(d.path().join("pic.hdr")).unwrap();
    let pic = d.path().join("pic.hdr").display().to_string();
    let view = [
        "-vtv", "-vp", "0.5", "0.5", "1", "-vd", "0", "1", "0", "-x", "4", "-y", "4",
    ];
    let out = run(
        ours("rdc")
            .args(view)
            .args(["-ad", "1", "-o", &pic, &scene, &sky]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    let names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!names.iter().any(|n| n.ends_with(".part")), "{names:?}");
}

/// Error lines echoed whole binary lines and 50 KB tokens.
#[test]
fn quoted_input_in_errors_is_cut_to_a_readable_length() {
    let d = tmpdir();
    let token = "x".repeat(50_000);
    let scene = write(
        d.path(),
        "t.rad",
        &format!("{MATERIAL}m polygon p 0 0 {token}\n"),
    );
    let e = one_line_error("rinfo", &[&scene], b"");
    assert!(
        e.len() < 400 && e.contains("..."),
        "{} bytes: {}",
        e.len(),
        &e[..e.len().min(300)]
    );
    let mut junk = b"void plastic m 0 0 5 .5 .5 .5 0 0\nm polygon p 0 0 \x01\x02\x1b[2J".to_vec();
    junk.extend(std::iter::repeat_n(b'\xfe', 20_000));
    let bin = d.path().join("b.rad");
    std::fs::write(&bin, &junk).unwrap();
    let e = one_line_error(
        "rdc",
        &["-I", "-m", "1", bin.to_str().unwrap()],
        b"1 1 1 0 0 1\n",
    );
    assert!(
        e.len() < 1200 && !e.contains('\u{1b}'),
        "{} bytes: {e}",
        e.len()
    );
}

/// `rrecon --auto --seed 3` gave a different model on every run (HashMap order decided
/// plane components and shell loops): two runs now give the same bytes.
#[test]
fn rrecon_is_reproducible_per_seed() {
    let d = tmpdir();
    let room = d.path().join("room.rad");
    std::fs::write(&room, run_ok(ours("rrecon").args(["room", "rect"]), b"")).unwrap();
    let scan = run_ok(
        ours("rrecon").args(["simulate", room.to_str().unwrap(), "--resolution", "0.5"]),
        b"",
    );
    let recon = || {
        run_ok(
            ours("rrecon").args(["--auto", "--seed", "3", "--target-points", "40000", "-"]),
            &scan,
        )
    };
    let first = recon();
    assert!(!first.is_empty());
    for _ in 0..2 {
        assert!(
            recon() == first,
            "two runs of rrecon --auto --seed 3 differ"
        );
    }
    let one_thread = run_ok(
        ours("rrecon").env("RAYON_NUM_THREADS", "1").args([
            "--auto",
            "--seed",
            "3",
            "--target-points",
            "40000",
            "-",
        ]),
        &scan,
    );
    assert!(one_thread == first, "one thread and all cores differ");
}

/// rcalib and rrecon named `--no-exec` in their refusal without accepting it; every tool
/// that reads scenes takes it and says in --help that inline commands run by default.
#[test]
fn every_scene_reader_accepts_no_exec() {
    let tools: [&[&str]; 7] = [
        &["rdc"],
        &["rglare", "annual"],
        &["rcalib", "apply"],
        &["rrecon"],
        &["rglod", "study"],
        &["rmcop", "study"],
        &["rinfo"],
    ];
    for t in tools {
        let out = run(ours(t[0]).args(&t[1..]).arg("--help"), b"");
        let help = String::from_utf8_lossy(&out.stdout).replace(char::is_whitespace, " ");
        let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(help.contains("--no-exec"), "{t:?} --help: {help}");
        assert!(help.contains("By default they run"), "{t:?} --help: {help}");
    }
    let d = tmpdir();
    let scene = write(
        d.path(),
        "cmd.rad",
        &format!("{MATERIAL}!echo m polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n"),
    );
    let e = one_line_error("rrecon", &["eval", "--no-exec", &scene, &scene], b"");
    assert!(e.contains("refused to run inline command '!echo"), "{e}");
    let pts = write(d.path(), "s.pts", "0.5 0.5 1 0 0 1\n");
    let e = one_line_error(
        "rcalib",
        &[
            "apply",
            "--no-exec",
            &scene,
            "--sensors",
            &pts,
            "--effect",
            "transmittance:0.9",
        ],
        b"",
    );
    assert!(e.contains("refused to run inline command '!echo"), "{e}");
}

/// `rdc room.oct` answered "undefined modifier 'oconv'" (issue #21): the octree's header
/// line was read as an object. Every tool that reads scenes names an octree, a picture, a
/// matrix or a weather file given in a scene's place, in one line.
#[test]
fn octrees_and_other_files_given_as_scenes_are_named() {
    let d = tmpdir();
    // The first bytes of a real `oconv room.rad skydome.rad` (Radiance 6).
    let mut oct = b"#?RADIANCE\noconv room.rad skydome.rad\nFORMAT=Radiance_octree\n\n".to_vec();
    oct.extend_from_slice(b"\x01\x1f-20.00001\0-29.00001\0-21.50001\x0046.00002\0room.rad\0");
    let oct_path = d.path().join("room.oct");
    std::fs::write(&oct_path, &oct).unwrap();
    let oct = oct_path.display().to_string();
    let want =
        format!("{oct} is a Radiance octree (oconv output); give the .rad scene files instead");
    let pts = write(d.path(), "s.pts", "0.5 0.5 1 0 0 1\n");
    let oct_bytes = std::fs::read(&oct_path).unwrap();
    let cases: [(&str, Vec<&str>, &[u8]); 6] = [
        (
            "rdc",
            vec!["-I", "-ab", "1", "-ad", "4", &oct],
            b"0 0 1 0 0 1\n",
        ),
        ("rdc", vec!["-I", "-ab", "1", "-ad", "4", "-"], &oct_bytes),
        ("rglod", vec!["objects", &oct], b""),
        ("rrecon", vec!["simulate", &oct], b""),
        (
            "rcalib",
            vec!["apply", &oct, "--sensors", &pts, "--effect", "walls:0.5"],
            b"",
        ),
        ("rinfo", vec!["-d", &oct], b""),
    ];
    for (tool, args, stdin) in cases {
        if tool == "rinfo" {
            // rinfo describes any file: an octree is shown by its header; -d names it.
            let out = run(ours(tool).arg(&oct), stdin);
            assert_eq!(out.status.code(), Some(0), "{tool} {oct}");
            let e = one_line_error(tool, &args, stdin);
            assert!(
                e.contains("is a Radiance octree (oconv output): it has no dimensions"),
                "{e}"
            );
            continue;
        }
        let e = one_line_error(tool, &args, stdin);
        let want = if args.last() == Some(&"-") {
            want.replace(&oct, "<stdin>")
        } else {
            want.clone()
        };
        assert_eq!(e.trim_end(), format!("{tool}: {want}"), "{tool} {args:?}");
    }
    let mtx = write(
        d.path(),
        "dc.mtx",
        "#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n1 2 3\n",
    );
    let e = one_line_error("rdc", &["-I", &mtx], b"0 0 1 0 0 1\n");
    assert!(
        e.contains("is a Radiance matrix (FORMAT=ascii), not a scene"),
        "{e}"
    );
    let epw = repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw");
    let e = one_line_error("rdc", &["-I", &epw.display().to_string()], b"0 0 1 0 0 1\n");
    assert!(e.contains("is a weather file (EPW), not a scene"), "{e}");
}

/// `rglod filter -l 0 room.rad | rinfo -` (rglod's own example) said "-: 0 objects": rinfo
/// read standard input to judge its kind, then loaded "-" again and found it empty.
#[test]
fn rinfo_describes_a_scene_on_standard_input() {
    let scene = format!("{MATERIAL}m polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n");
    let out = run_ok(ours("rinfo").arg("-"), scene.as_bytes());
    let text = String::from_utf8_lossy(&out);
    assert!(
        text.starts_with("-: 2 objects (1 surfaces, 1 modifiers)"),
        "{text}"
    );
}
