//! Radiance matrices against real Radiance: we read what rcontrib, gendaymtx, dctimestep and
//! rmtxop write, they read what we write, and `rmtx` computes what dctimestep/rmtxop compute.
//!
//! Tolerances: float data is compared at 1e-6 relative (float rounding is 6e-8; sums of a few
//! hundred float products stay well inside 1e-6); rcontrib ascii (`%.6e`, 7 significant
//! digits) at 1e-6; gendaymtx ascii (`%.3g`) at 5e-3, its rounding bound; products against
//! dctimestep/rmtxop (float storage, double sums) at the brief's 1e-5.

use crate::common;

use rdaylight::formats::matrix::{DataFormat, Matrix, ReadOptions};
use std::path::Path;
use std::process::Command;

/// rcontrib options of the brief, plus `-u-`: rcontrib's default `-u+` seeds its sampling
/// from the clock (measured: runs in different seconds differ), and the format comparisons
/// below need several runs to produce the same coefficients.
const RC: [&str; 15] = [
    "-u-",
    "-I+",
    "-ab",
    "1",
    "-ad",
    "256",
    "-lw",
    "1e-4",
    "-e",
    "MF:1",
    "-f",
    "reinhart.cal",
    "-b",
    "rbin",
    "-bn",
];

/// A sky glow on a full-sphere source over a grey floor, two sensors (one tilted so it sees
/// the ground too), and a 3-hour WEA.
fn scene(dir: &Path) {
    std::fs::write(
        dir.join("sky.rad"),
        "void glow skyglow 0 0 4 1 1 1 0\nskyglow source skydome 0 0 4 0 0 1 360\n\
         void plastic grey 0 0 5 .5 .5 .5 0 0\n\
         grey polygon floor 0 0 12 -5 -5 0 5 -5 0 5 5 0 -5 5 0\n",
    )
    .unwrap();
    let oct = common::run_ok(
        common::radiance("oconv").current_dir(dir).arg("sky.rad"),
        b"",
    );
    std::fs::write(dir.join("sky.oct"), oct).unwrap();
    std::fs::write(
        dir.join("pts.txt"),
        "0 0 1 0 0 1\n1 1 1 0.5 0 0.8\n0 0 1 0 0.7 0.7\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tiny.wea"),
        "place San_Francisco\nlatitude 37.62\nlongitude 122.40\ntime_zone 120\n\
         site_elevation 3.0\nweather_data_file_units 1\n\
         6 21 8.5 300 80\n6 21 12.5 800 120\n6 21 16.5 400 100\n",
    )
    .unwrap();
}

/// Run rcontrib with extra options, output to a file (so FORMAT is padded as in practice).
fn rcontrib(dir: &Path, extra: &[&str], out: &str) {
    let pts = std::fs::read(dir.join("pts.txt")).unwrap();
    let mut c = common::radiance("rcontrib");
    c.current_dir(dir).args(RC).arg("Nrbins").args(extra);
    c.args(["-m", "skyglow", "sky.oct"]);
    let bytes = common::run_ok(&mut c, &pts);
    std::fs::write(dir.join(out), bytes).unwrap();
}

fn load(dir: &Path, file: &str, opts: &ReadOptions) -> Matrix {
    Matrix::load(dir.join(file).to_str().unwrap(), opts)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

fn parse(bytes: &[u8], name: &str) -> Matrix {
    Matrix::from_reader(bytes, name, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Largest relative difference, with a floor so that zeros compare absolutely.
fn rel(a: &Matrix, b: &Matrix) -> f64 {
    a.max_rel_diff(b, 1e-30).unwrap_or_else(|e| panic!("{e}"))
}

/// Assert `r <= tol` and print the measured value (`cargo test -- --nocapture` lists them).
fn within(what: &str, r: f64, tol: f64) {
    eprintln!("measured {what}: max relative difference {r:.3e} (tolerance {tol:.0e})");
    assert!(r <= tol, "{what}: relative difference {r} > {tol}");
}

fn rmtx(dir: &Path) -> Command {
    let mut c = common::ours("rmtx");
    c.current_dir(dir);
    c
}

fn headerless(format: DataFormat, ncols: Option<usize>) -> ReadOptions {
    ReadOptions {
        format: Some(format),
        ncols,
        ..ReadOptions::default()
    }
}

#[test]
fn reads_rcontrib_in_every_format_with_and_without_header_and_nrows() {
    if !common::have_radiance("rcontrib") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    rcontrib(d, &["-y", "3", "-fad"], "ref.mtx");
    let reference = load(d, "ref.mtx", &ReadOptions::default());
    assert_eq!(reference.shape().to_string(), "3x146x3");
    // Not a trivial matrix: the sky sums to pi for the upward sensor (notes §6.2).
    let up: f64 = reference.row(0).iter().step_by(3).sum();
    assert!((up - std::f64::consts::PI).abs() < 0.05, "{up}");
    for (letter, format, tol) in [
        ("a", DataFormat::Ascii, 1e-6),
        ("f", DataFormat::Float, 1e-6),
        ("d", DataFormat::Double, 0.0),
    ] {
        for with_y in [true, false] {
            for with_h in [false, true] {
                let mut extra = vec![format!("-fa{letter}")];
                if with_y {
                    extra.extend(["-y".into(), "3".into()]);
                }
                if with_h {
                    extra.push("-h".into());
                }
                let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
                let name = format!("dc_{letter}{}{}.mtx", u8::from(with_y), u8::from(with_h));
                rcontrib(d, &extra, &name);
                let opts = if with_h {
                    headerless(format, (format != DataFormat::Ascii).then_some(146))
                } else {
                    ReadOptions::default()
                };
                let m = load(d, &name, &opts);
                let r = rel(&m, &reference);
                within(&name, r, tol);
            }
        }
    }
    // And the values rmtxop prints for the same file.
    let out = common::run_ok(
        common::radiance("rmtxop")
            .current_dir(d)
            .args(["-fa", "dc_f10.mtx"]),
        b"",
    );
    let r = rel(&parse(&out, "rmtxop"), &reference);
    within("rmtxop -fa vs ours", r, 1e-6);
}

#[test]
fn reads_gendaymtx_dctimestep_and_rmtxop_outputs() {
    if !common::have_radiance("gendaymtx") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    let sky = |args: &[&str]| {
        common::run_ok(
            common::radiance("gendaymtx")
                .current_dir(d)
                .args(["-m", "1"])
                .args(args)
                .arg("tiny.wea"),
            b"",
        )
    };
    let sd = parse(&sky(&["-od"]), "sky_d");
    assert_eq!(sd.shape().to_string(), "146x3x3");
    let sf = parse(&sky(&["-of"]), "sky_f");
    let sa = parse(&sky(&[]), "sky_a");
    within("gendaymtx -of vs -od", rel(&sf, &sd), 1e-6);
    // %.3g: at most half a unit in the third digit, 5e-3 relative.
    within("gendaymtx ascii vs -od", rel(&sa, &sd), 5e-3);
    // Headerless float: NCOLS (time steps) given, rows read to the end.
    let h = sky(&["-h", "-of"]);
    let sh = Matrix::from_reader(&h[..], "sky_h", &headerless(DataFormat::Float, Some(3))).unwrap();
    assert_eq!(sh, sf);
    std::fs::write(d.join("sky_f.mtx"), sky(&["-of"])).unwrap();

    rcontrib(d, &["-y", "3", "-faf"], "dc.mtx");
    let dc = load(d, "dc.mtx", &ReadOptions::default());
    let want = dc.multiply(&sf).unwrap();
    assert!(
        want.data.iter().any(|&v| v > 10.0),
        "a lit sky gives real values"
    );
    for (prog, args) in [
        ("dctimestep", vec!["dc.mtx", "sky_f.mtx"]),
        ("dctimestep", vec!["-of", "dc.mtx", "sky_f.mtx"]),
        ("rmtxop", vec!["-fa", "dc.mtx", "sky_f.mtx"]),
        ("rmtxop", vec!["-fd", "dc.mtx", "sky_f.mtx"]),
    ] {
        let out = common::run_ok(common::radiance(prog).current_dir(d).args(&args), b"");
        let r = rel(&parse(&out, prog), &want);
        within(&format!("{prog} {args:?} vs our product"), r, 1e-5);
    }
}

#[test]
fn real_radiance_reads_ours() {
    if !common::have_radiance("rmtxop") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    rcontrib(d, &["-y", "3", "-faf"], "dc.mtx");
    let sky = common::run_ok(
        common::radiance("gendaymtx")
            .current_dir(d)
            .args(["-m", "1", "-of", "tiny.wea"]),
        b"",
    );
    std::fs::write(d.join("sky.mtx"), sky).unwrap();
    let dc = load(d, "dc.mtx", &ReadOptions::default());
    let real_ts = parse(
        &common::run_ok(
            common::radiance("dctimestep")
                .current_dir(d)
                .args(["dc.mtx", "sky.mtx"]),
            b"",
        ),
        "dctimestep",
    );
    for f in ["-ff", "-fd", "-fa"] {
        // Written to a file (padded FORMAT) and through a pipe (unpadded).
        let name = format!("ours{f}.mtx");
        let file = std::fs::File::create(d.join(&name)).unwrap();
        let st = rmtx(d).args([f, "dc.mtx"]).stdout(file).status().unwrap();
        assert!(st.success());
        let piped = common::run_ok(rmtx(d).args([f, "dc.mtx"]), b"");
        let headerless = common::run_ok(rmtx(d).args([f, "-h", "dc.mtx"]), b"");
        // fputformat's rule: a seekable file gets FORMAT padded to the element size, a pipe
        // does not.
        let in_file = std::fs::read(d.join(&name)).unwrap();
        let header_len = in_file.len() - headerless.len();
        let elem = match f {
            "-ff" => 4,
            "-fd" => 8,
            _ => 1,
        };
        assert_eq!(header_len % elem, 0, "{f}: data starts at {header_len}");
        if elem > 1 {
            let name = if elem == 4 { "float" } else { "double" };
            let text = String::from_utf8_lossy(&piped);
            assert!(text.contains(&format!("\nFORMAT={name}\n\n")), "{text}");
        }
        for (how, input) in [
            ("file", std::fs::read(d.join(&name)).unwrap()),
            ("pipe", piped),
        ] {
            let back = common::run_ok(common::radiance("rmtxop").args(["-fa", "-"]), &input);
            let r = rel(&parse(&back, "rmtxop"), &dc);
            within(&format!("rmtxop -fa reading our {f} ({how})"), r, 1e-5);
            // getinfo sees our header and `getinfo -` strips exactly it.
            let info = common::run_ok(&mut common::radiance("getinfo"), &input);
            let info = String::from_utf8_lossy(&info);
            assert!(
                info.contains("NROWS=3") && info.contains("NCOLS=146"),
                "{info}"
            );
            let stripped = common::run_ok(common::radiance("getinfo").arg("-"), &input);
            assert_eq!(
                stripped, headerless,
                "getinfo - strips exactly our header ({f})"
            );
        }
        // dctimestep on our DC times the real sky vs dctimestep on the originals.
        let ts = common::run_ok(
            common::radiance("dctimestep")
                .current_dir(d)
                .args([&name, "sky.mtx"]),
            b"",
        );
        let r = rel(&parse(&ts, "dctimestep"), &real_ts);
        within(&format!("dctimestep on our {f}"), r, 1e-5);
    }
}

#[test]
fn rmtx_products_match_dctimestep_and_rmtxop() {
    if !common::have_radiance("dctimestep") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    rcontrib(d, &["-y", "3", "-faf"], "dc.mtx");
    let sky = common::run_ok(
        common::radiance("gendaymtx")
            .current_dir(d)
            .args(["-m", "1", "-od", "tiny.wea"]),
        b"",
    );
    std::fs::write(d.join("sky.mtx"), sky).unwrap();
    let real = |prog: &str, args: &[&str]| {
        parse(
            &common::run_ok(common::radiance(prog).current_dir(d).args(args), b""),
            prog,
        )
    };
    let ours = |args: &[&str]| parse(&common::run_ok(rmtx(d).args(args), b""), "rmtx");
    let cases: [(&str, &[&str], &[&str]); 5] = [
        ("dctimestep", &["dc.mtx", "sky.mtx"], &["dc.mtx", "sky.mtx"]),
        (
            "rmtxop",
            &["-fa", "dc.mtx", "sky.mtx"],
            &["-fa", "dc.mtx", "sky.mtx"],
        ),
        (
            "rmtxop",
            &["-fa", "dc.mtx", "sky.mtx", "-c", "47.4", "119.9", "11.6"],
            &["-fa", "dc.mtx", "sky.mtx", "-c", "47.4", "119.9", "11.6"],
        ),
        (
            "rmtxop",
            &[
                "-fa", "dc.mtx", "sky.mtx", "-c", "47.4", "119.9", "11.6", "-t",
            ],
            &[
                "-fa", "-t", "-c", "47.4", "119.9", "11.6", "dc.mtx", "sky.mtx",
            ],
        ),
        (
            "rmtxop",
            &["-fa", "-s", "2.5", "dc.mtx", "-t"],
            &["-fa", "-s", "2.5", "-t", "dc.mtx"],
        ),
    ];
    for (prog, theirs, mine) in cases {
        let (a, b) = (real(prog, theirs), ours(mine));
        let r = rel(&b, &a);
        within(&format!("rmtx {mine:?} vs {prog} {theirs:?}"), r, 1e-5);
    }
    // A chain of three, left to right (dc streamed, T and sky in memory), against rmtxop.
    // T is a made-up 146 x 146 RGB "transmission" with distinct channels.
    let mut t = String::from("#?RADIANCE\nNROWS=146\nNCOLS=146\nNCOMP=3\nFORMAT=ascii\n\n");
    for i in 0..146 {
        for j in 0..146 {
            let v = if i == j {
                0.5
            } else {
                ((i * 31 + j * 17) % 13) as f64 * 1e-3
            };
            t.push_str(&format!("{v} {} {}\t", v * 0.8, v * 1.1));
        }
        t.push('\n');
    }
    std::fs::write(d.join("T.mtx"), t).unwrap();
    let a = real("rmtxop", &["-fa", "dc.mtx", "T.mtx", "sky.mtx"]);
    let b = ours(&["-fa", "dc.mtx", "T.mtx", "sky.mtx"]);
    within("rmtx dc T sky vs rmtxop dc T sky", rel(&b, &a), 1e-5);
    // The five-phase shape of a sum: products bind tighter than `+`, a `-s` after a `+`
    // scales its term. Against rmtxop summing the three products it computed separately
    // (rmtxop evaluates strictly left to right, so its `+` is only given single matrices).
    for (name, args) in [
        ("e3.mtx", vec!["-fa", "dc.mtx", "T.mtx", "sky.mtx"]),
        ("e3d.mtx", vec!["-fa", "-s", "0.25", "dc.mtx", "sky.mtx"]),
        ("eds.mtx", vec!["-fa", "dc.mtx", "sky.mtx"]),
    ] {
        let out = common::run_ok(common::radiance("rmtxop").current_dir(d).args(args), b"");
        std::fs::write(d.join(name), out).unwrap();
    }
    let a = real(
        "rmtxop",
        &[
            "-fa", "e3.mtx", "+", "-s", "-1", "e3d.mtx", "+", "eds.mtx", "-c", "Y",
        ],
    );
    let b = ours(&[
        "-fa", "dc.mtx", "T.mtx", "sky.mtx", "+", "-s", "-0.25", "dc.mtx", "sky.mtx", "+",
        "dc.mtx", "sky.mtx", "-c", "Y",
    ]);
    within(
        "rmtx V T D s + -s -f Vd sd + Cds s vs rmtxop sums",
        rel(&b, &a),
        1e-5,
    );
    // Terms of different shapes are refused before anything is written.
    let bad = common::run(rmtx(d).args(["dc.mtx", "sky.mtx", "+", "T.mtx"]), b"");
    assert_eq!(bad.status.code(), Some(1));
    assert!(bad.stdout.is_empty());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("same shape"));
    // The three-phase chain with a BSDF file for T (dctimestep V T.xml D s): V and D are
    // made-up Klems-full matrices (sensors x 145, 145 x 146 sky patches), T the blinds'
    // XML (tests/data/bsdf/blinds45.xml); ours reads the XML itself.
    let klems = |nrows: usize, ncols: usize, seed: usize| {
        let mut m = format!("#?RADIANCE\nNROWS={nrows}\nNCOLS={ncols}\nNCOMP=3\nFORMAT=ascii\n\n");
        for i in 0..nrows {
            for j in 0..ncols {
                let v = ((i * 37 + j * 11 + seed) % 17) as f64 * 1e-3;
                m.push_str(&format!("{v} {} {}\t", v * 0.9, v * 1.2));
            }
            m.push('\n');
        }
        m
    };
    std::fs::write(d.join("V.mtx"), klems(3, 145, 1)).unwrap();
    std::fs::write(d.join("D.mtx"), klems(145, 146, 5)).unwrap();
    let xml = common::repo().join("tests/data/bsdf/blinds45.xml");
    let xml = xml.to_str().unwrap();
    let a = real("dctimestep", &["V.mtx", xml, "D.mtx", "sky.mtx"]);
    let b = ours(&["-fa", "V.mtx", xml, "D.mtx", "sky.mtx"]);
    within("rmtx V T.xml D sky vs dctimestep", rel(&b, &a), 1e-5);
    // Symbolic -c Y: like rmtxop, 179 x row Y of the RGB-to-XYZ matrix of Radiance's
    // standard primaries (47.45394 119.94894 11.59712), computed in float by rmtxop.
    let y = ours(&["-fa", "-c", "Y", "dc.mtx", "sky.mtx"]);
    let sym = real("rmtxop", &["-fa", "dc.mtx", "sky.mtx", "-c", "Y"]);
    within("rmtx -c Y vs rmtxop -c Y", rel(&y, &sym), 1e-5);
    // rcontrib without -y writes no NROWS; from a file we count the rows by its size, so
    // our product announces NROWS and rmtxop (which requires it) can read it.
    rcontrib(d, &["-faf"], "dc_noy.mtx");
    let out = common::run_ok(rmtx(d).args(["-ff", "dc_noy.mtx", "sky.mtx"]), b"");
    assert!(String::from_utf8_lossy(&out).contains("NROWS=3\n"));
    let back = common::run_ok(common::radiance("rmtxop").args(["-fa", "-"]), &out);
    let want = real("dctimestep", &["dc.mtx", "sky.mtx"]);
    let r = rel(&parse(&back, "rmtxop"), &want);
    within("rmtx on rcontrib without -y", r, 1e-5);
    // Default output format follows rmtxop: float x double gives float.
    let out = common::run_ok(rmtx(d).args(["dc.mtx", "sky.mtx"]), b"");
    assert!(String::from_utf8_lossy(&out).contains("FORMAT=float"));
}

#[test]
fn cat_stacks_row_blocks() {
    if !common::have_radiance("rcontrib") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    let pts = std::fs::read_to_string(d.join("pts.txt")).unwrap();
    let lines: Vec<&str> = pts.lines().collect();
    std::fs::write(d.join("pts.txt"), format!("{}\n", lines[0])).unwrap();
    rcontrib(d, &["-y", "1", "-fad"], "part1.mtx");
    std::fs::write(d.join("pts.txt"), format!("{}\n{}\n", lines[1], lines[2])).unwrap();
    rcontrib(d, &["-faa"], "part2.mtx");
    // rcontrib's sampling differs between runs with other sensors, so the oracle is the
    // parts themselves, stacked.
    let p1 = load(d, "part1.mtx", &ReadOptions::default());
    let p2 = load(d, "part2.mtx", &ReadOptions::default());
    let mut all = p1.clone();
    all.data.extend_from_slice(&p2.data);
    all.nrows += p2.nrows;
    assert_eq!(all.shape().to_string(), "3x146x3");
    let out = common::run_ok(
        rmtx(d).args(["--cat", "-fd", "part1.mtx", "part2.mtx"]),
        b"",
    );
    let text = String::from_utf8_lossy(&out);
    assert!(
        !text.contains("NROWS="),
        "part2 has no NROWS, so neither has the stack"
    );
    let cat = parse(&out, "cat");
    assert_eq!(cat, all);
}

#[test]
fn big_endian_and_headerless_inputs() {
    use rdaylight::formats::header::Header;
    use rdaylight::formats::matrix::WriteOptions;
    if !common::have_radiance("rmtxop") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    rcontrib(d, &["-y", "3", "-fad"], "dc.mtx");
    let dc = load(d, "dc.mtx", &ReadOptions::default());
    // Written in the other byte order than this machine's (BigEndian=1 on x86): rmtxop
    // swaps it back, and so do we.
    for format in [DataFormat::Float, DataFormat::Double] {
        let mut o = WriteOptions::new(format);
        o.big_endian = !cfg!(target_endian = "big");
        let bytes = dc.write(Vec::new(), "swapped", Header::new(), o).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(&format!("BigEndian={}", u8::from(o.big_endian))));
        let back = common::run_ok(common::radiance("rmtxop").args(["-fd", "-"]), &bytes);
        // rmtxop 6.0a holds float internally: 1e-7 even for double; ours is exact for double.
        let r = rel(&parse(&back, "rmtxop"), &dc);
        assert!(r <= 1e-7, "rmtxop reading our swapped {format:?}: {r}");
        let tol = if format == DataFormat::Float {
            1e-7
        } else {
            0.0
        };
        let r = rel(&parse(&bytes, "ours"), &dc);
        assert!(r <= tol, "reading our swapped {format:?}: {r}");
    }
    // Headerless rcontrib output through rmtx: -if with --ncols, -ia inferring NCOLS.
    rcontrib(d, &["-h", "-faf", "-y", "3"], "h.f");
    rcontrib(d, &["-h", "-faa"], "h.a");
    for (args, tol) in [
        (vec!["-if", "--ncols", "146", "-fd", "h.f"], 1e-7),
        (vec!["-ia", "-fd", "h.a"], 1e-6),
    ] {
        let out = common::run_ok(rmtx(d).args(&args), b"");
        let r = rel(&parse(&out, "rmtx"), &dc);
        assert!(r <= tol, "{args:?}: {r}");
    }
}

#[test]
fn exposure_is_divided_out_like_rmtxop() {
    if !common::have_radiance("rmtxop") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    std::fs::write(
        d.join("e.mtx"),
        "#?RADIANCE\nEXPOSURE=2\nCOLORCORR= 1 2 4\nNROWS=2\nNCOLS=2\nNCOMP=3\n\
         FORMAT=ascii\n\n1 2 3 4 5 6\n7 8 9 10 11 12\n",
    )
    .unwrap();
    let theirs = parse(
        &common::run_ok(
            common::radiance("rmtxop")
                .current_dir(d)
                .args(["-fa", "e.mtx"]),
            b"",
        ),
        "rmtxop",
    );
    let out = common::run_ok(rmtx(d).args(["-fa", "e.mtx"]), b"");
    let mine = parse(&out, "rmtx");
    assert_eq!(mine.get(0, 0), &[0.5, 0.5, 0.375]); // 1/(2x1), 2/(2x2), 3/(2x4)
    within(
        "rmtx vs rmtxop undoing EXPOSURE/COLORCORR",
        rel(&mine, &theirs),
        1e-7,
    );
    assert!(!String::from_utf8_lossy(&out).contains("EXPOSURE"));
}

/// Run `rmtx` expecting failure: exit status 1, nothing on stdout, one line on stderr.
fn fails(dir: &Path, args: &[&str], stdin: &[u8]) -> String {
    let out = common::run(rmtx(dir).args(args), stdin);
    assert_eq!(out.status.code(), Some(1), "{args:?}");
    assert!(out.stdout.is_empty(), "{args:?} wrote to stdout");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    err.trim_end().to_string()
}

#[test]
fn malformed_inputs_give_one_line_errors() {
    let t = common::tmpdir();
    let d = t.path();
    let float_mtx = |nrows: usize, ncols: usize, ncomp: usize, values: usize| {
        let mut b = format!(
            "#?RADIANCE\nNROWS={nrows}\nNCOLS={ncols}\nNCOMP={ncomp}\nBigEndian=0\nFORMAT=float\n\n"
        )
        .into_bytes();
        for i in 0..values {
            b.extend_from_slice(&(i as f32).to_le_bytes());
        }
        b
    };
    std::fs::write(d.join("dc.mtx"), float_mtx(165, 146, 3, 165 * 146 * 3)).unwrap();
    std::fs::write(d.join("sky.mtx"), float_mtx(145, 8, 3, 145 * 8 * 3)).unwrap();
    std::fs::write(d.join("grey.mtx"), float_mtx(146, 8, 1, 146 * 8)).unwrap();
    std::fs::write(d.join("short.mtx"), float_mtx(146, 8, 3, 41 * 8 * 3 + 5)).unwrap();
    std::fs::write(d.join("wrong.mtx"), float_mtx(4, 3, 3, 4 * 4 * 3)).unwrap();
    std::fs::write(
        d.join("bad.mtx"),
        "#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=1\nFORMAT=ascii\n\n1 2\n3 nan?\n",
    )
    .unwrap();
    std::fs::write(
        d.join("open.mtx"),
        "#?RADIANCE\nNROWS=2\nNCOLS=2\nFORMAT=ascii\n",
    )
    .unwrap();

    assert_eq!(
        fails(d, &["dc.mtx", "sky.mtx"], b""),
        "rmtx: dc.mtx (165x146x3) cannot multiply sky.mtx (145x8x3): 146 columns vs 145 rows"
    );
    assert_eq!(
        fails(d, &["dc.mtx", "grey.mtx"], b""),
        "rmtx: dc.mtx (165x146x3) cannot multiply grey.mtx (146x8x1): 3 components vs 1"
    );
    // A truncated right operand is found before anything is written.
    assert_eq!(
        fails(d, &["dc.mtx", "short.mtx"], b""),
        "rmtx: short.mtx: ends inside row 42 (20 of 96 bytes; NCOLS=8 NCOMP=3): \
         truncated, or wrong NCOLS/NCOMP?"
    );
    assert_eq!(
        fails(d, &["-fa", "wrong.mtx"], b""),
        "rmtx: wrong.mtx: more data after row 4 of 4 (NROWS=4, NCOLS=3, NCOMP=3): \
         wrong NROWS or NCOLS?"
    );
    assert_eq!(
        fails(d, &["-fa", "open.mtx"], b""),
        "rmtx: open.mtx:5: file ends inside the header: expected an empty line to close it"
    );
    // Streamed ascii errors surface mid-stream: rows before them may already be out (as
    // with Radiance's own tools); the message is exact and the status 1.
    let out = common::run(
        rmtx(d).args(["-fa", "-"]),
        b"#?RADIANCE\nNCOLS=2\n\n1 2 3 4 5 6\n7 8 9 10 11\n",
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        "rmtx: <stdin>:5: ends inside row 2 (5 of 6 numbers; NCOLS=2 NCOMP=3): \
         truncated, or wrong NCOLS/NCOMP?\n"
    );
    let out = common::run(rmtx(d).args(["-fa", "bad.mtx"]), b"");
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        "rmtx: bad.mtx:8:3: expected a number, found 'nan?'\n"
    );
    assert_eq!(
        fails(d, &["-c", "1", "2", "dc.mtx"], b""),
        "rmtx: result: -c must have N x 3 coefficients, got 2"
    );
}

/// Streaming: a 10,000 x 146 x 3 float matrix read row by row. `MatrixReader` holds one
/// row (146 x 3 numbers and its 1,752 bytes) plus the 64 kB read buffer; nothing is sized
/// from NROWS, so memory does not grow with the 10,000 rows (by design; no timing here).
#[test]
fn streams_a_large_matrix_row_by_row() {
    use rdaylight::formats::matrix::MatrixReader;
    let t = common::tmpdir();
    let path = t.path().join("big.mtx");
    let (nrows, ncols) = (10_000usize, 146usize);
    let mut bytes =
        format!("#?RADIANCE\nNROWS={nrows}\nNCOLS={ncols}\nNCOMP=3\nBigEndian=0\nFORMAT=float\n\n")
            .into_bytes();
    for r in 0..nrows {
        for i in 0..ncols * 3 {
            bytes.extend_from_slice(&((r * 7 + i) as f32).to_le_bytes());
        }
    }
    std::fs::write(&path, bytes).unwrap();
    let mut reader = MatrixReader::open(path.to_str().unwrap(), &ReadOptions::default()).unwrap();
    let mut row = vec![0.0; reader.row_len()];
    let mut n = 0;
    while reader.read_row(&mut row).unwrap() {
        assert_eq!(row[5], (n * 7 + 5) as f64);
        n += 1;
    }
    assert_eq!(n, nrows);
}

/// Picture-coded matrices (`-fc`): RGBE rows for 3 components, Radiance_spectra beyond,
/// in both directions with real rmtxop. RGBE keeps 8-bit mantissas under a shared
/// exponent, so a value is exact to within 1/256 of its element's largest component
/// (tolerance below: 2^-8 of the element maximum, plus the half-step decode offset).
#[test]
fn picture_coded_matrices_both_ways() {
    if !common::have_radiance("rmtxop") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    scene(d);
    rcontrib(d, &["-y", "3", "-fad"], "dc.mtx");
    let dc = load(d, "dc.mtx", &ReadOptions::default());
    // Theirs into ours: rmtxop -fc, read by us, equals rmtxop -fa of the same -fc file.
    let theirs = common::run_ok(
        common::radiance("rmtxop")
            .current_dir(d)
            .args(["-fc", "dc.mtx"]),
        b"",
    );
    std::fs::write(d.join("dc.rgbe"), &theirs).unwrap();
    let ours_read = parse(&theirs, "dc.rgbe");
    let want = parse(
        &common::run_ok(
            common::radiance("rmtxop")
                .current_dir(d)
                .args(["-fa", "dc.rgbe"]),
            b"",
        ),
        "rmtxop -fa",
    );
    within(
        "our read of rmtxop -fc vs rmtxop -fa of it",
        rel(&ours_read, &want),
        1e-6,
    );
    // Ours into theirs: rmtx -fc, read by rmtxop -fa, equals what we read back ourselves,
    // and both are within RGBE quantisation of the original.
    let mine = common::run_ok(rmtx(d).args(["-fc", "dc.mtx"]), b"");
    assert_eq!(
        &mine[mine.len() - 16..],
        &theirs[theirs.len() - 16..],
        "same RGBE bytes as rmtxop for the same values"
    );
    let back = parse(&mine, "rmtx -fc");
    let by_rmtxop = parse(
        &common::run_ok(common::radiance("rmtxop").args(["-fa", "-"]), &mine),
        "rmtxop -fa",
    );
    within(
        "rmtxop reading our -fc vs our reading",
        rel(&back, &by_rmtxop),
        1e-6,
    );
    for r in 0..dc.nrows {
        for c in 0..dc.ncols {
            let e = dc.get(r, c);
            let m = e.iter().cloned().fold(0.0, f64::max);
            for (k, v) in e.iter().enumerate() {
                let got = back.get(r, c)[k];
                assert!(
                    (got - v).abs() <= m / 128.0 + 1e-30,
                    "RGBE round trip at ({r},{c},{k}): {got} vs {v}"
                );
            }
        }
    }
    // Spectral: 6 components through -fc become Radiance_spectra, read back by rmtxop.
    let mut spec = String::from("#?RADIANCE\nNROWS=2\nNCOLS=3\nNCOMP=6\nFORMAT=ascii\n\n");
    for i in 0..2 {
        for j in 0..3 {
            for k in 0..6 {
                spec.push_str(&format!("{} ", 0.1 + (i * 18 + j * 6 + k) as f64 * 0.01));
            }
            spec.push('\t');
        }
        spec.push('\n');
    }
    let mine = common::run_ok(rmtx(d).args(["-fc", "-"]), spec.as_bytes());
    assert!(String::from_utf8_lossy(&mine).contains("FORMAT=Radiance_spectra"));
    let back = parse(&mine, "rmtx -fc spectral");
    let by_rmtxop = parse(
        &common::run_ok(common::radiance("rmtxop").args(["-fa", "-"]), &mine),
        "rmtxop -fa",
    );
    assert_eq!((back.nrows, back.ncols, back.channels.ncomp), (2, 3, 6));
    within(
        "rmtxop reading our spectral -fc",
        rel(&back, &by_rmtxop),
        1e-6,
    );
    let orig = parse(spec.as_bytes(), "spec");
    within("spectral -fc round trip", rel(&back, &orig), 1.0 / 64.0);
}
