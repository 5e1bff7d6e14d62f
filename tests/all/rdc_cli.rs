//! `rdc` end to end: the real binary against analytic answers (open sky: every coefficient
//! is its patch's projected solid angle, rows sum to pi; horizontal irradiance of a CIE sky
//! integrated numerically), against real rcontrib's committed oracle, and through real
//! `dctimestep`, `rmtxop`, `getinfo` and `evalglare`.

use crate::common;

use common::{ours, radiance, repo, run, run_ok, tmpdir};
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use rdaylight::sky::SkyPatches;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

fn fixture(p: &str) -> String {
    repo()
        .join("radiance-fixtures")
        .join(p)
        .to_string_lossy()
        .into_owned()
}

fn sensors() -> Vec<u8> {
    std::fs::read(fixture("sensors/open.pts")).unwrap()
}

fn rdc(args: &[&str], stdin: &[u8]) -> Vec<u8> {
    run_ok(ours("rdc").args(args), stdin)
}

fn matrix(bytes: &[u8]) -> Matrix {
    Matrix::from_reader(bytes, "rdc output", &ReadOptions::default()).unwrap()
}

/// Projected solid angle of patch `i` seen by an upward sensor: `(pi/n)(sin^2 a1 - sin^2 a0)`
/// for a row from altitude a0 to a1 with n patches, `pi sin^2(alpha/2)` for the zenith cap
/// (half-angle alpha/2), 0 for the ground.
fn projected_solid_angle(p: &SkyPatches, i: usize) -> f64 {
    let a = p.alpha();
    match p.row_of(i) {
        None => 0.0,
        Some(r) if r >= p.rows() => PI * (a / 2.0).sin().powi(2),
        Some(r) => {
            let s0 = (a * r as f64).sin();
            let s1 = (a * (r + 1) as f64).sin();
            PI * (s1 * s1 - s0 * s0) / p.row_len(r) as f64
        }
    }
}

#[test]
fn open_sky_coefficients_are_projected_solid_angles() {
    let n = 20000.0;
    let out = rdc(&["-I", "-m", "1", "-ad", "20000", "-ff", "-n", "2"], &{
        // float rays in (-ff sets input and output)
        let mut b = Vec::new();
        for line in String::from_utf8(sensors()).unwrap().lines() {
            for w in line.split_whitespace() {
                b.extend_from_slice(&w.parse::<f32>().unwrap().to_ne_bytes());
            }
        }
        b
    });
    let m = matrix(&out);
    assert_eq!((m.nrows, m.ncols, m.ncomp()), (4, 146, 3));
    let p = SkyPatches::new(1);
    for r in 0..4 {
        // Every sample puts pi into exactly one bin, so a row sums to pi with zero Monte
        // Carlo variance: only float rounding of 146 values remains (~146 x 6e-8 x pi).
        let s: f64 = (0..146).map(|c| m.get(r, c)[1]).sum();
        assert!((s - PI).abs() < 2e-5, "row {r} sums to {s}");
        for c in 0..146 {
            let v = m.get(r, c);
            assert!(v[0] == v[1] && v[1] == v[2], "grey coefficients");
        }
    }
    // Upward sensor: each bin count is binomial(N, q), q = psa/pi, so the coefficient
    // pi*k/N has sd pi*sqrt(q(1-q)/N). Chi-square over the 145 sky bins.
    let mut chi2 = 0.0;
    let mut zmax: f64 = 0.0;
    for c in 1..146 {
        let psa = projected_solid_angle(&p, c);
        let q = psa / PI;
        let sd = PI * (q * (1.0 - q) / n).sqrt();
        let z = (m.get(0, c)[0] - psa) / sd;
        chi2 += z * z;
        zmax = zmax.max(z.abs());
    }
    let dof = 145.0;
    // chi2/dof has sd sqrt(2/dof) = 0.117; 4 sd, and no single bin beyond 4.5 sd
    // (P < 1e-3 over 145 bins).
    assert!(
        chi2 / dof < 1.0 + 4.0 * (2.0 / dof).sqrt(),
        "chi2/dof {}",
        chi2 / dof
    );
    assert!(zmax < 4.5, "max |z| {zmax}");
    assert_eq!(m.get(0, 0)[0], 0.0, "an upward sensor sees no ground");
    // Vertical sensor: half its view is ground, q = 1/2.
    let sd = PI * (0.25 / n).sqrt();
    assert!(
        (m.get(1, 0)[0] - PI / 2.0).abs() < 5.0 * sd,
        "{:?}",
        m.get(1, 0)
    );
    // Downward sensor: everything in bin 0.
    assert!((m.get(3, 0)[0] - PI).abs() < 1e-5);
}

#[test]
fn open_sky_coefficients_agree_with_rcontrib_oracle() {
    let n = 20000.0;
    let out = rdc(
        &[
            "-I",
            "-m",
            "1",
            "-ad",
            "20000",
            "-faf",
            &fixture("scenes/sky_glow360.rad"),
        ],
        &sensors(),
    );
    let ours = matrix(&out);
    let runs: Vec<Matrix> = (1..=3)
        .map(|k| {
            Matrix::load(
                &fixture(&format!("oracles/open_sensor_dc_run{k}.mtx")),
                &ReadOptions::default(),
            )
            .unwrap()
            .0
        })
        .collect();
    // rcontrib -ad 10000, 3 runs: its stratified samples vary less than a binomial count,
    // so pi^2 q(1-q)/30000 bounds the variance of the 3-run mean from above.
    let n_oracle = 30000.0;
    let (mut chi2, mut k, mut zmax) = (0.0, 0.0, 0.0f64);
    for r in 0..4 {
        for c in 0..146 {
            let o = runs.iter().map(|m| m.get(r, c)[1]).sum::<f64>() / 3.0;
            let v = ours.get(r, c)[1];
            let q = ((o + v) / (2.0 * PI)).clamp(0.0, 1.0);
            if q == 0.0 {
                continue;
            }
            let sd = PI * (q * (1.0 - q) * (1.0 / n + 1.0 / n_oracle)).sqrt();
            if sd == 0.0 {
                assert!((o - v).abs() < 1e-4, "sensor {r} bin {c}: {v} vs {o}");
                continue;
            }
            let z = (v - o) / sd;
            chi2 += z * z;
            k += 1.0;
            zmax = zmax.max(z.abs());
        }
    }
    assert!(k > 300.0, "bins compared: {k}");
    assert!(
        chi2 / k < 1.0 + 4.0 * (2.0 / k).sqrt(),
        "chi2/k {}",
        chi2 / k
    );
    assert!(zmax < 5.0, "max |z| {zmax}");
}

#[test]
fn same_seed_same_bytes_whatever_the_threads() {
    let args = |n: &'static str, s: &'static str| {
        vec![
            "-I", "-m", "1", "-ad", "300", "-h", "-faf", "-n", n, "-s", s,
        ]
    };
    let pts = sensors().repeat(50); // 200 sensors, several blocks of work per thread
    let a = rdc(&args("1", "7"), &pts);
    let b = rdc(&args("2", "7"), &pts);
    let c = rdc(&args("2", "8"), &pts);
    assert_eq!(a.len(), 200 * 146 * 3 * 4);
    assert!(a == b, "-n 1 and -n 2 differ");
    assert!(a != c, "seeds 7 and 8 gave the same output");
    // Without surfaces, direct-only coefficients are the full ones (same samples), and
    // -ab 0 hides the glow sky from -I sensors (Radiance: glow on a source needs a bounce).
    let mut d = args("2", "7");
    d.push("--direct");
    assert!(rdc(&d, &pts) == a, "--direct differs on an open sky");
    // rcontrib's ambient-cache and direct-culling options, which rcontrib overrides and
    // rfluxmtx scripts pass (honeybee: -aa 0.0), are accepted and change nothing.
    let mut hb = args("2", "7");
    hb.extend([
        "-aa", "0.0", "-ar", "256", "-as", "128", "-dt", "0.5", "-dc", "1.0",
    ]);
    assert!(
        rdc(&hb, &pts) == a,
        "-aa/-ar/-as/-dt/-dc changed the output"
    );
    let mut z = args("2", "7");
    z.extend(["-ab", "0"]);
    assert!(
        rdc(&z, &pts).chunks_exact(4).all(|b| b == [0u8; 4]),
        "-ab 0 not zero"
    );
}

#[test]
fn coefficients_feed_real_dctimestep_and_rmtxop() {
    if !common::have_radiance("coefficients_feed_real_dctimestep_and_rmtxop") {
        return;
    }
    let dir = tmpdir();
    for (mf, sky, rows) in [
        (1, "sky/london_4days_m1.smx", 146),
        (4, "sky/london_4days_m4.smx", 2306),
    ] {
        let dc = dir.path().join(format!("dc{mf}.mtx"));
        let out = rdc(
            &["-I", "-m", &mf.to_string(), "-ad", "2000", "-faf"],
            &sensors(),
        );
        std::fs::write(&dc, &out).unwrap();
        let dcm = matrix(&out);
        assert_eq!((dcm.nrows, dcm.ncols), (4, rows));
        let skym = Matrix::load(&fixture(sky), &ReadOptions::default())
            .unwrap()
            .0;
        for prog in ["dctimestep", "rmtxop"] {
            let mut cmd = radiance(prog);
            if prog == "rmtxop" {
                cmd.arg("-fa");
            }
            let res = matrix(&run_ok(cmd.arg(&dc).arg(fixture(sky)), b""));
            assert_eq!(
                (res.nrows, res.ncols, res.ncomp()),
                (4, 96, 3),
                "{prog} MF {mf}"
            );
            // Values: DC x sky per channel, computed here in f64.
            for r in 0..4 {
                for t in 0..96 {
                    for k in 0..3 {
                        let e: f64 = (0..rows)
                            .map(|c| dcm.get(r, c)[k] * skym.get(c, t)[k])
                            .sum();
                        let got = res.get(r, t)[k];
                        assert!(
                            (got - e).abs() <= 1e-4 * e.abs() + 1e-6,
                            "{prog} MF {mf} ({r},{t},{k}): {got} vs {e}"
                        );
                    }
                }
            }
        }
    }
}

/// skybright.cal arguments and sun of the committed gensky fixtures.
const OVERCAST: [f64; 3] = [2.0, 6.343e+01, 9.868e+00];
const CLEAR: [f64; 7] = [
    1.0, 6.460e+00, 1.473e+01, 4.053e-01, -0.073170, -0.855646, 0.512363,
];
const CLEAR_SUN: f64 = 6.203e+06;

/// Irradiance on a surface facing `n` from a skyfunc glowing in every direction (the sky
/// and ground glows of skyglow.rad), by the midpoint rule over (z, phi): dω = dz dφ.
fn sky_irradiance(n: [f64; 3], args: &[f64]) -> f64 {
    let (nz, nphi) = (1000, 1000);
    let mut e = 0.0;
    for i in 0..nz {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / nz as f64;
        let s = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
            let d = [s * phi.sin(), s * phi.cos(), z];
            let c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            if c > 0.0 {
                e += rdaylight::sky::cie::skybright(d, args) * c;
            }
        }
    }
    e * (2.0 / nz as f64) * (2.0 * PI / nphi as f64)
}

fn read_ascii_column(bytes: &[u8]) -> Vec<f64> {
    let m = matrix(bytes);
    (0..m.nrows).map(|r| m.get(r, 0)[0]).collect()
}

#[test]
fn point_in_time_irradiance_equals_the_integrated_sky() {
    let dir = tmpdir();
    let normals = [
        [0.0, 0.0, 1.0],
        [0.0, -1.0, 0.0],
        [FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2],
        [0.0, 0.0, -1.0],
    ];
    for (case, args, sun) in [
        ("overcast", &OVERCAST[..], 0.0),
        ("clear", &CLEAR[..], CLEAR_SUN),
    ] {
        let se = dir.path().join(format!("{case}.se"));
        let out = rdc(
            &[
                "-I",
                "-oi",
                "-ad",
                "20000",
                "--se-out",
                se.to_str().unwrap(),
                &fixture(&format!("skies/{case}_gensky.rad")),
                &fixture("skies/skyglow.rad"),
            ],
            &sensors(),
        );
        let lux = read_ascii_column(&out);
        let rel = read_ascii_column(&std::fs::read(&se).unwrap());
        let sund = {
            let d = [CLEAR[4], CLEAR[5], CLEAR[6]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            [d[0] / l, d[1] / l, d[2] / l]
        };
        let omega = 2.0 * PI * (1.0 - (0.25f64).to_radians().cos());
        for (s, n) in normals.iter().enumerate() {
            let c = n[0] * sund[0] + n[1] * sund[1] + n[2] * sund[2];
            let e = sky_irradiance(*n, args) + sun * omega * c.max(0.0);
            // -oi: 179 x (0.265 + 0.670 + 0.065) = 179 for grey light.
            let expect = 179.0 * e;
            // The reported relative SE must be a real error bar: positive (the sky is not
            // uniform) and small at 20000 samples; the value lies within 5 of them.
            assert!(
                rel[s] > 0.0 && rel[s] < 0.02,
                "{case} sensor {s}: rel SE {}",
                rel[s]
            );
            let tol = 5.0 * rel[s] * lux[s] + 1e-6 * expect;
            assert!(
                (lux[s] - expect).abs() < tol,
                "{case} sensor {s}: {} lx vs analytic {expect} (tol {tol})",
                lux[s]
            );
        }
    }
}

#[test]
fn point_in_time_agrees_with_real_rtrace() {
    if !common::have_radiance("point_in_time_agrees_with_real_rtrace") {
        return;
    }
    let dir = tmpdir();
    // gensky (skybright.cal) and gendaylit (perezlum.cal) skies, with and without sun.
    for sky in [
        "overcast_gensky",
        "clear_gensky",
        "clear_gendaylit",
        "intermediate_gendaylit",
    ] {
        let skyf = fixture(&format!("skies/{sky}.rad"));
        let oct = dir.path().join("sky.oct");
        let o = run_ok(
            radiance("oconv")
                .arg(&skyf)
                .arg(fixture("skies/skyglow.rad")),
            b"",
        );
        std::fs::write(&oct, o).unwrap();
        let rt = run_ok(
            radiance("rtrace")
                .args([
                    "-h", "-I", "-ab", "1", "-ad", "4096", "-aa", "0", "-as", "0",
                ])
                .arg(&oct),
            &sensors(),
        );
        let rt = first_column(&rt);
        let se = dir.path().join("se");
        let out = rdc(
            &[
                "-I",
                "-h",
                "-ad",
                "8192",
                "--se-out",
                se.to_str().unwrap(),
                &skyf,
                &fixture("skies/skyglow.rad"),
            ],
            &sensors(),
        );
        let ours = first_column(&out);
        let rel = read_ascii_column(&std::fs::read(&se).unwrap());
        for s in 0..4 {
            // rtrace's 4096 stratified samples vary at most like 4096 plain ones: its SE is
            // at most ours x sqrt(8192/4096). The sun is exact in both (rtrace -dj 0 aims at
            // the disc centre, solid angle 2 pi (1 - cos(angle/2))); 2e-4 covers its float
            // arithmetic.
            let sd = rel[s] * ours[s] * (1.0f64 + 2.0).sqrt();
            assert!(
                (ours[s] - rt[s]).abs() < 5.0 * sd + 2e-4 * rt[s] + 1e-3,
                "{sky} sensor {s}: ours {} rtrace {} (sd {sd})",
                ours[s],
                rt[s]
            );
        }
    }
}

/// First number of each line of headerless ascii output.
fn first_column(bytes: &[u8]) -> Vec<f64> {
    String::from_utf8(bytes.to_vec())
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn spectral_channels_and_streaming_with_y() {
    // -cs 6: NCOMP=6 with WAVELENGTH_SPLITS, the same grey coefficient in every band.
    let out = rdc(
        &["-I", "-m", "1", "-ad", "500", "-cs", "6", "-faf"],
        &sensors(),
    );
    let text = String::from_utf8_lossy(&out[..200]).into_owned();
    assert!(
        text.contains("NCOMP=6\nWAVELENGTH_SPLITS= 780 588 480 380\nNROWS=4\nNCOLS=146\n"),
        "{text}"
    );
    let m = matrix(&out);
    assert_eq!((m.nrows, m.ncols, m.ncomp()), (4, 146, 6));
    assert!((0..146).all(|c| m.get(0, c).iter().all(|&v| v == m.get(0, c)[0])));
    // -y: the input streams; the rows are the same as when the sensors are counted first.
    let a = rdc(&["-I", "-m", "1", "-ad", "50", "-h", "-faf"], &sensors());
    let b = rdc(
        &["-I", "-m", "1", "-ad", "50", "-h", "-faf", "-y", "4"],
        &sensors(),
    );
    assert!(a == b);
    let e = fails(
        &["-I", "-m", "1", "-ad", "5", "-h", "-y", "3"],
        &sensors(),
        true,
    );
    assert!(
        e.contains("more than the 3 sensors announced with -y"),
        "{e}"
    );
}

#[test]
fn target_se_stops_when_reached() {
    let dir = tmpdir();
    let se = dir.path().join("se");
    rdc(
        &[
            "-I",
            "-ad",
            "256",
            "--target-se",
            "0.01",
            "--se-out",
            se.to_str().unwrap(),
            &fixture("skies/overcast_gensky.rad"),
            &fixture("skies/skyglow.rad"),
        ],
        &sensors(),
    );
    let m = matrix(&std::fs::read(&se).unwrap());
    for r in 0..4 {
        let (rel, n) = (m.get(r, 0)[0], m.get(r, 1)[0]);
        assert!(rel <= 0.01, "sensor {r}: rel SE {rel} above target");
        assert!(n >= 256.0 && n % 256.0 == 0.0, "sensor {r}: {n} samples");
        // One sample pi*L of an overcast sky (radiance 1:3 from horizon to zenith) varies by
        // about 20 %, so 256 samples leave an upward sensor near 1.25 %: it needs a second
        // batch.
        if r == 0 {
            assert!(n >= 512.0, "upward sensor stopped after {n} samples");
        }
        assert!(n <= 25600.0, "sensor {r}: more than --max-samples");
    }
}

#[test]
fn sun_coefficients_at_patch_centres_and_weather_positions() {
    let out = rdc(
        &["-I", "--suns", "6", "-faf", "-h", "-y", "1"],
        b"0 0 0 0 0 1\n",
    );
    let v: Vec<f32> = out
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes(b.try_into().unwrap()))
        .collect();
    let p = SkyPatches::new(6);
    assert_eq!(v.len(), p.len() * 3);
    let omega = 2.0 * PI * (1.0 - (0.533f64 / 2.0).to_radians().cos());
    assert_eq!(v[0], 0.0, "ground column");
    for i in 1..p.len() {
        let expect = p.centre(i)[2] * omega;
        assert!(
            ((v[3 * i] as f64) - expect).abs() < 1e-6 * expect + 1e-12,
            "patch {i}"
        );
    }
    // Weather file: one column per hour; 2 Mar 12:30 London, sun 30.8 deg up (gensky).
    let out = rdc(
        &["-I", "--suns", &fixture("weather/london_6hours.wea"), "-fa"],
        b"0 0 0 0 0 1\n",
    );
    let m = matrix(&out);
    assert_eq!((m.nrows, m.ncols), (1, 6));
    let expect = 30.8f64.to_radians().sin() * omega;
    assert!(
        (m.get(0, 2)[0] / expect - 1.0).abs() < 0.01,
        "{:?}",
        m.get(0, 2)
    );
}

/// Horizontal illuminance of the overcast fixture sky (lux).
fn overcast_lux() -> f64 {
    179.0 * sky_irradiance([0.0, 0.0, 1.0], &OVERCAST)
}

#[test]
fn fisheye_picture_has_a_view_radiance_accepts() {
    let dir = tmpdir();
    let hdr = dir.path().join("sky.hdr");
    let view = [
        "-vta", "-vp", "0", "0", "0", "-vd", "0", "0", "1", "-vu", "0", "1", "0", "-vh", "180",
        "-vv", "180",
    ];
    let mut args: Vec<&str> = view.to_vec();
    let (o, g) = (
        fixture("skies/overcast_gensky.rad"),
        fixture("skies/skyglow.rad"),
    );
    args.extend(["-x", "128", "-y", "128", "-ad", "16", &o, &g]);
    std::fs::write(&hdr, rdc(&args, b"")).unwrap();
    let pic = rdaylight::formats::picture::Picture::open(&hdr).unwrap();
    assert_eq!((pic.width, pic.height), (128, 128));
    assert!(pic.view_strings().iter().any(|v| v.contains("-vta")));
    if !common::have_radiance("fisheye_picture_has_a_view_radiance_accepts") {
        return;
    }
    let info = String::from_utf8(run_ok(radiance("getinfo").arg(&hdr), b"")).unwrap();
    assert!(
        info.contains("VIEW= -vta -vp 0 0 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180"),
        "{info}"
    );
    let res = String::from_utf8(run_ok(radiance("getinfo").arg("-d").arg(&hdr), b"")).unwrap();
    let res: Vec<&str> = res.split_whitespace().collect();
    assert!(res.ends_with(&["-Y", "128", "+X", "128"]), "{res:?}");
    // evalglare 3.06 -V exits with status 1 even on rpict's own pictures (checked on
    // radiance-fixtures/pictures/office_overcast_window.hdr), so read its stdout only.
    let ev: f64 = String::from_utf8(run(radiance("evalglare").arg("-V").arg(&hdr), b"").stdout)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let expect = overcast_lux();
    // evalglare integrates pixel solid angles from the VIEW; the error is the fisheye's
    // pixelation at the horizon, where cos(theta) ~ 0 (measured -0.1 % at 64 px).
    assert!(
        (ev / expect - 1.0).abs() < 0.01,
        "evalglare -V {ev} vs {expect}"
    );
}

#[test]
fn per_pixel_coefficients_have_one_row_per_pixel() {
    let out = rdc(
        &[
            "-vta", "-vd", "0", "0", "1", "-vu", "0", "1", "0", "-vh", "180", "-vv", "180", "-x",
            "16", "-y", "16", "-m", "1", "-ad", "1", "-faf",
        ],
        b"",
    );
    let m = matrix(&out);
    assert_eq!((m.nrows, m.ncols), (256, 146));
    // Centre rays only (-ad 1): each pixel's ray lands in exactly one bin. A 180-degree
    // angular fisheye still has rays in its corners (they look backwards, as rpict's do),
    // so inside the circle the ray is above the horizon, outside it below (ground, bin 0).
    for py in 0..16 {
        for px in 0..16 {
            let r = py * 16 + px;
            let s: f64 = (0..146).map(|c| m.get(r, c)[0]).sum();
            assert_eq!(s, 1.0, "pixel {px},{py}");
            let (x, y) = (
                (px as f64 + 0.5) / 16.0 - 0.5,
                (py as f64 + 0.5) / 16.0 - 0.5,
            );
            let d = (x * x + y * y).sqrt();
            if d < 0.5 - 1.0 / 16.0 {
                assert_eq!(m.get(r, 0)[0], 0.0, "pixel {px},{py} inside the circle");
            } else if d > 0.5 + 1.0 / 16.0 {
                assert_eq!(m.get(r, 0)[0], 1.0, "pixel {px},{py} outside the circle");
            }
        }
    }
    if common::have_radiance("per_pixel_coefficients") {
        let dir = tmpdir();
        let f = dir.path().join("pix.mtx");
        std::fs::write(&f, &out).unwrap();
        let r = matrix(&run_ok(
            radiance("rmtxop")
                .arg("-fa")
                .arg(&f)
                .arg(fixture("sky/london_4days_m1.smx")),
            b"",
        ));
        assert_eq!((r.nrows, r.ncols), (256, 96));
    }
}

/// Run rdc expecting failure: exit 1, one line on stderr (returned), and nothing on stdout
/// unless `streamed` (with -y, rows already computed have been written, as rcontrib does).
fn fails(args: &[&str], stdin: &[u8], streamed: bool) -> String {
    let out = run(ours("rdc").args(args), stdin);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(
        streamed || out.stdout.is_empty(),
        "{args:?} wrote to stdout"
    );
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn bad_inputs_give_one_line_errors() {
    let e = fails(&["-I", "-m", "1"], b"0 0 0 0 0 1\n0 0 0 0 0\n", false);
    assert!(e.starts_with("rdc: <stdin>:2: "), "{e}");
    let dir = tmpdir();
    let bad = dir.path().join("bad.rad");
    std::fs::write(
        &bad,
        "void glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 360\nvoid antimatter am 1 void 0 0\n",
    )
    .unwrap();
    let e = fails(
        &["-I", "-m", "1", bad.to_str().unwrap()],
        b"0 0 0 0 0 1\n",
        false,
    );
    assert!(e.starts_with(&format!("rdc: {}:3", bad.display())), "{e}");
    assert!(e.contains("unsupported primitive type 'antimatter'"), "{e}");
    // A polygon with a zero-area outline is refused by the tracer's scene compiler with its
    // location (surfaces are traced now; bad ones are still errors, not silent holes).
    let room = dir.path().join("room.rad");
    std::fs::write(
        &room,
        "void plastic w 0 0 5 .5 .5 .5 0 0\nw polygon floor 0 0 9 0 0 0 1 0 0 2 0 0\n",
    )
    .unwrap();
    let e = fails(
        &["-I", "-m", "1", room.to_str().unwrap()],
        b"0 0 0 0 0 1\n",
        false,
    );
    assert!(e.contains(":2") && e.contains("floor"), "{e}");
    for m in ["0", "x", "31"] {
        let e = fails(&["-I", "-m", m], b"0 0 0 0 0 1\n", false);
        assert!(e.contains("-m") || e.contains("MF"), "{e}");
    }
    let e = fails(&["-I"], b"0 0 0 0 0 1\n", false);
    assert!(e.contains("no scene given"), "{e}");
    let e = fails(&["-I", "-m", "1", "-fx"], b"", false);
    assert!(e.contains("-fx"), "{e}");
}

#[test]
fn every_truncated_sensor_file_gives_rows_or_one_error() {
    // Truncations of a valid ascii sensor file: whole lines give rows, a cut line gives a
    // located error; never a panic.
    let pts = sensors();
    for cut in 0..pts.len() {
        let out = run(
            ours("rdc").args(["-I", "-m", "1", "-ad", "4", "-h"]),
            &pts[..cut],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "cut {cut}: {err}");
        if !out.status.success() {
            // A cut before the first whole line leaves no sensors: an error since issue #19.
            assert!(
                err.starts_with("rdc: <stdin>:") || err.starts_with("rdc: no sensors in <stdin>"),
                "cut {cut}: {err}"
            );
            assert!(out.stdout.is_empty());
        }
    }
}

#[test]
fn random_bytes_never_panic() {
    // Deterministic pseudo-random bytes (xorshift) as ascii and as float/double rays.
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let bytes: Vec<u8> = (0..4800)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    for f in ["-fa", "-ff", "-fd"] {
        for len in [1, 23, 24, 480, 4800] {
            let out = run(
                ours("rdc").args(["-I", "-m", "1", "-ad", "2", "-h", f]),
                &bytes[..len],
            );
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!err.contains("panicked"), "{f} {len}: {err}");
            assert!(
                out.status.code() == Some(0) || err.lines().count() == 1,
                "{f} {len}: {err}"
            );
        }
    }
    let e = fails(
        &["-I", "-m", "1", "--se-out", "/nonexistent/dir/se"],
        &sensors(),
        false,
    );
    assert!(e.contains("/nonexistent/dir/se"), "{e}");
}

#[test]
fn help_documents_every_option_with_radiance_counterparts() {
    let out = run_ok(ours("rdc").arg("--help"), b"");
    let h = String::from_utf8(out).unwrap();
    for opt in [
        "--ab",
        "--ad",
        "--lw",
        "--lr",
        "--dj",
        "--st",
        "--ss",
        "--preset",
        "--irradiance",
        "-m",
        "--direct",
        "--suns",
        "--cs",
        "--cw",
        "-f",
        "-h",
        "-n",
        "-s",
        "-x",
        "-y",
        "--target-se",
        "--se-out",
        "--no-exec",
        "--oi",
        "rcontrib",
        "rtrace -I",
        "rpict",
        "dctimestep",
        "Examples",
    ] {
        assert!(h.contains(opt), "--help lacks {opt}");
    }
    assert!(
        h.contains("-vta") && h.contains("-vf"),
        "--help lacks the view options"
    );
}
