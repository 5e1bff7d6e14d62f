//! Reproduce the seed's Table 5.7 (issue 8, "Reproduce the seed"): m-EDI at the eye with
//! measured vs uplifted material spectra in an 18-band daylight simulation of a room.
//!
//! Seed setting (chapter 5, section 5.3.1.5, Table 5.7, Fig. 5.20): a seated head-pose
//! viewpoint in a meeting room, Radiance 6.0 in 18 bands, ground-truth surface spectra
//! from a measured database vs spectra uplifted (Jakob & Hanika 2019) from the RGB of those
//! spectra, four time steps near the summer solstice (June 21st 13:00 and 14:00, June 22nd
//! 9:00 and 11:00), two overcast and two clear; reported differences under 6 %.
//!
//! Here: the example room (`examples/room/room.rad`, 6 x 8 x 3 m, south window) with its
//! grey plastics replaced by measured reflectances ([`materials`]), each material's Radiance
//! RGB computed from its measured spectrum, uplifted with the library's default (learned
//! basis) and with Jakob & Hanika; three `rdc -I -cs 18 -m 1` daylight-coefficient runs with
//! the same seed (so the Monte Carlo paths are the same and the noise largely cancels in
//! the differences) times `rspecsky`'s 18-band Perez sky matrix for four London (bundled
//! EPW) steps with the seed's hours ([`steps`]); m-EDI by CIE S 026 from the spectral
//! irradiance (`rmetrics melanopic`'s [`BandWeights`]).
//!
//! The test writes `docs/seed-table-5-7.md` when `SEED_MEDI_UPDATE=1`, and otherwise fails
//! if the committed page differs from what it computes (everything is seeded, so the page
//! is a function of the code). It asserts the seed's criterion: |m-EDI difference| < 6 %
//! at every step and viewpoint for the default uplifting method.

use crate::common;

use clap::Parser;
use rdaylight::cli::rdc::{Options, radiance_args};
use rdaylight::colour::cie::Observer;
use rdaylight::formats::sensors::SensorRay;
use rdaylight::formats::weather::Weather;
use rdaylight::metrics::melanopic::{BandWeights, RADIANCE_SPAN_NM};
use rdaylight::radiometry::Channels;
use rdaylight::rdc::Tracer;
use rdaylight::sky::SkyPatches;
use rdaylight::sky::matrix::{Colours, MatrixOptions, time_steps};
use rdaylight::sky::perez::TimeStep;
use rdaylight::sky::spectral::spectral_sky_matrix;
use rdaylight::uplift::basis::{colorchecker, munsell};
use rdaylight::uplift::output::write_rad;
use rdaylight::uplift::{Method, N, RgbSpace, Spectrum, Uplifter};
use std::fmt::Write as _;

const NCS: usize = 18;
const SEED: &str = "5";
/// A second seed for variants (a) and (b): the Monte Carlo noise of the absolute values and
/// of the differences.
const SEED2: &str = "6";
const AD: &str = "65536";
const AB: &str = "5";
const DOC: &str = "docs/seed-table-5-7.md";

/// One room material: its measured reflectance, Radiance RGB and the two uplifts.
struct Material {
    /// Modifier name in `examples/room/room.rad` (or the new accent wall's).
    modifier: &'static str,
    what: &'static str,
    source: String,
    measured: Spectrum,
    rgb: [f64; 3],
    basis: Spectrum,
    jakob: Spectrum,
}

/// The measured spectra standing in for the seed's SpectralDB picks (surface type and
/// colour): a near-white ceiling, warm off-white painted walls, a brown floor covering and
/// one blue-green painted accent wall (the colour where uplifting errors matter most for
/// melanopic light, whose action spectrum peaks at 490 nm).
fn materials() -> Vec<Material> {
    let obs = Observer::new(RgbSpace::Radiance);
    let cc = colorchecker();
    // Walls: the Munsell chip whose Radiance RGB is nearest to a warm off-white paint
    // (0.62, 0.57, 0.48): a measured, smooth, slightly yellow spectrum of reflectance ~0.57.
    let target = [0.62, 0.57, 0.48];
    let (wi, _) = munsell()
        .iter()
        .enumerate()
        .map(|(i, (_, s))| {
            let c = obs.spectrum_rgb(s);
            (i, (0..3).map(|k| (c[k] - target[k]).powi(2)).sum::<f64>())
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let picks: Vec<(&str, &str, String, Spectrum)> = vec![
        (
            "ceiling_mat",
            "ceiling (white paint)",
            format!("ColorChecker `{}` (white 9.5)", cc[18].0),
            cc[18].1,
        ),
        (
            "wall_mat",
            "north, west, south walls (warm off-white paint)",
            format!("Munsell `{}` (nearest to RGB {target:?})", munsell()[wi].0),
            munsell()[wi].1,
        ),
        (
            "accent_mat",
            "east wall (blue-green accent paint)",
            format!("ColorChecker `{}` (bluish green)", cc[5].0),
            cc[5].1,
        ),
        (
            "floor_mat",
            "floor (brown floor covering)",
            format!("ColorChecker `{}` (dark skin)", cc[0].0),
            cc[0].1,
        ),
    ];
    let basis = Uplifter::new(RgbSpace::Radiance, Method::Basis);
    let jakob = Uplifter::new(RgbSpace::Radiance, Method::Jakob);
    picks
        .into_iter()
        .map(|(modifier, what, source, measured)| {
            // The RGB Radiance would be given for this material: the spectrum's colour in
            // Radiance's RGB (equal-energy white, CIE 1931 2 deg).
            let rgb = obs.spectrum_rgb(&measured);
            Material {
                modifier,
                what,
                source,
                measured,
                rgb,
                basis: basis.uplift_rgb(rgb).spectrum,
                jakob: jakob.uplift_rgb(rgb).spectrum,
            }
        })
        .collect()
}

#[derive(Clone, Copy, PartialEq)]
enum Variant {
    Measured,
    Basis,
    Jakob,
}

impl Material {
    fn spectrum(&self, v: Variant) -> &Spectrum {
        match v {
            Variant::Measured => &self.measured,
            Variant::Basis => &self.basis,
            Variant::Jakob => &self.jakob,
        }
    }
}

/// The example room with the materials of variant `v`: its grey plastic definitions are
/// replaced by `spectrum` + `plastic` pairs and the east wall gets the accent material.
fn scene(mats: &[Material], v: Variant) -> String {
    let room = std::fs::read_to_string(common::repo().join("examples/room/room.rad")).unwrap();
    let mut out = String::new();
    for m in mats {
        let mut buf = Vec::new();
        write_rad(&mut buf, m.modifier, m.spectrum(v), 0.0, 0.0).unwrap();
        out.push_str(&String::from_utf8(buf).unwrap());
    }
    let mut replaced = 0;
    for line in room.lines() {
        if ["wall_mat", "floor_mat", "ceiling_mat"]
            .iter()
            .any(|m| line.starts_with(&format!("void plastic {m} ")))
        {
            replaced += 1;
            continue;
        }
        let line = line.replace("wall_mat polygon east_wall", "accent_mat polygon east_wall");
        out.push_str(&line);
        out.push('\n');
    }
    assert_eq!(replaced, 3, "examples/room/room.rad materials changed");
    assert!(out.contains("accent_mat polygon east_wall"));
    out
}

/// Viewpoints: seated eye height 1.2 m, vertical, as the seed's head-pose view (Fig. 5.10),
/// plus one upward work-plane sensor.
fn viewpoints() -> Vec<(&'static str, SensorRay)> {
    vec![
        (
            "eye, mid-room, facing east (accent wall)",
            SensorRay::new([3.0, 4.0, 1.2], [1.0, 0.0, 0.0]),
        ),
        (
            "eye, mid-room, facing north (back wall)",
            SensorRay::new([3.0, 4.0, 1.2], [0.0, 1.0, 0.0]),
        ),
        (
            "eye, back of room, facing the window",
            SensorRay::new([3.0, 6.5, 1.2], [0.0, -1.0, 0.0]),
        ),
        (
            "eye, near window, facing west",
            SensorRay::new([4.5, 2.0, 1.2], [-1.0, 0.0, 0.0]),
        ),
        (
            "work plane, mid-room, up",
            SensorRay::new([3.0, 4.0, 0.8], [0.0, 0.0, 1.0]),
        ),
    ]
}

/// (label, sky, month, day, EPW hour): the seed's hours; London's June 21st/22nd are partly
/// cloudy (6-9 tenths) at all of them, so the closest-to-solstice days that are fully
/// overcast (June 17th, 10/10 cloud, DNI 0-1 W/m2) and clear (June 26th, 0/10 cloud, DNI
/// 833-842 W/m2) carry them. The seed's text and table disagree on which pair was clear;
/// its discussion ("higher errors under clear skies") and the higher values put the sun at
/// 13:00 and 14:00. EPW hour `H` is the interval ending at `H`:00 (sun at `H - 0.5`, as
/// gendaymtx).
/// The seed's Table 5.7 percentage errors for the same hours (9:00, 11:00, 13:00, 14:00).
const SEED_PE: [&str; 4] = ["1.4", "2.3", "4.8", "5.6"];

const STEPS: [(&str, &str, u32, u32, u32); 4] = [
    ("June 17th - 9:00", "overcast", 6, 17, 9),
    ("June 17th - 11:00", "overcast", 6, 17, 11),
    ("June 26th - 13:00", "clear", 6, 26, 13),
    ("June 26th - 14:00", "clear", 6, 26, 14),
];

fn steps(w: &Weather) -> Vec<TimeStep> {
    let all = time_steps(w);
    STEPS
        .iter()
        .map(|&(_, _, m, d, h)| {
            *all.iter()
                .find(|s| {
                    s.month == m && s.day == d && (s.hour - (f64::from(h) - 0.5)).abs() < 1e-6
                })
                .unwrap_or_else(|| panic!("no EPW record {m}/{d} {h}h"))
        })
        .collect()
}

/// Spectral irradiance `[sensor][step][band]` (Radiance band convention) for variant `v`.
fn irradiance(
    mats: &[Material],
    v: Variant,
    seed: &str,
    dir: &std::path::Path,
    sky: &rdaylight::sky::spectral::SpectralSkyMatrix,
) -> Vec<Vec<Vec<f64>>> {
    let name = match v {
        Variant::Measured => "measured.rad",
        Variant::Basis => "basis.rad",
        Variant::Jakob => "jakob.rad",
    };
    let path = dir.join(name);
    std::fs::write(&path, scene(mats, v)).unwrap();
    let cli = [
        "rdc",
        "-I",
        "-cs",
        "18",
        "-cw",
        "380",
        "780",
        "-ab",
        AB,
        "-ad",
        AD,
        "-lw",
        "0",
        "-s",
        seed,
        "-m",
        "1",
        path.to_str().unwrap(),
    ];
    let opts = Options::parse_from(radiance_args(&cli));
    let scene =
        rdaylight::scene::load(&opts.scene, &rdaylight::scene::LoadOptions::from_env()).unwrap();
    let prepared = Tracer::new(&opts.to_config().unwrap(), &scene).unwrap();
    assert_eq!(prepared.ncols(), sky.nrows());
    let rays: Vec<SensorRay> = viewpoints().into_iter().map(|(_, r)| r).collect();
    let rows = prepared.compute(&rays).unwrap();
    let nt = sky.ncols();
    let mut out = vec![vec![vec![0.0; NCS]; nt]; rays.len()];
    let mut skyrow = Vec::new();
    // rmtx: irradiance = sum over patches of coefficient x sky radiance, band by band.
    for p in 0..sky.nrows() {
        sky.row(p, &mut skyrow);
        for (s, r) in rows.iter().enumerate() {
            let dc = &r.values[p * NCS..(p + 1) * NCS];
            for t in 0..nt {
                for b in 0..NCS {
                    out[s][t][b] += dc[b] * skyrow[t * NCS + b];
                }
            }
        }
    }
    out
}

/// Wavelength-wise mean relative bias and root mean squared relative error (%) of `a`
/// against `b` (seed Eq. 5.3, 5.4), over the entries where `b > 0`.
fn mrb_rmsre(a: &[f64], b: &[f64]) -> (f64, f64) {
    let rel: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(_, y)| **y > 0.0)
        .map(|(x, y)| x / y - 1.0)
        .collect();
    let n = rel.len() as f64;
    (
        100.0 * rel.iter().sum::<f64>() / n,
        100.0 * (rel.iter().map(|r| r * r).sum::<f64>() / n).sqrt(),
    )
}

struct Results {
    mats: Vec<Material>,
    /// `[variant][sensor][step][band]`.
    irr: Vec<Vec<Vec<Vec<f64>>>>,
    /// Variants (a) and (b) with [`SEED2`]: `[variant][sensor][step][band]`.
    irr_seed2: Vec<Vec<Vec<Vec<f64>>>>,
}

fn simulate() -> Results {
    let mats = materials();
    let w = Weather::read_path(
        common::repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw"),
    )
    .unwrap();
    let ch = Channels::spectral(NCS, 380.0, 780.0).unwrap();
    let opts = MatrixOptions {
        perez: Default::default(),
        colours: Colours::gendaymtx(),
        skip_night: false,
    };
    let sky = spectral_sky_matrix(
        &SkyPatches::new(1),
        &steps(&w),
        &w.site,
        &opts,
        &ch,
        &|_, _| {},
    );
    assert_eq!(sky.ncols(), 4);
    let dir = common::tmpdir();
    let irr = [Variant::Measured, Variant::Basis, Variant::Jakob]
        .into_iter()
        .map(|v| irradiance(&mats, v, SEED, dir.path(), &sky))
        .collect();
    let irr_seed2 = [Variant::Measured, Variant::Basis]
        .into_iter()
        .map(|v| irradiance(&mats, v, SEED2, dir.path(), &sky))
        .collect();
    Results {
        mats,
        irr,
        irr_seed2,
    }
}

fn report(r: &Results) -> (String, f64, f64, f64) {
    let ch = Channels::spectral(NCS, 380.0, 780.0).unwrap();
    let bw = BandWeights::new(&ch).unwrap();
    let views = viewpoints();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Seed Table 5.7: m-EDI with measured vs uplifted material spectra\n\n\
         Generated by `tests/all/seed_medi.rs` (`SEED_MEDI_UPDATE=1 cargo test --test all seed_medi::`); \
         the test fails when this page differs from what the code computes.\n\n\
         **Setting** (seed chapter 5, section 5.3.1.5, Table 5.7, Fig. 5.20): m-EDI \
         (CIE S 026) at seated eye height in a side-lit room, 18-band daylight simulation, \
         with each surface's measured reflectance spectrum (a) or a spectrum uplifted from \
         that material's RGB, by the library's default learned basis (b) or by Jakob & \
         Hanika 2019 (c, the seed's method). Room: `examples/room/room.rad` (6 x 8 x 3 m, \
         south window 4.8 x 1.6 m, glass transmissivity 0.96) with these materials \
         (specularity 0):\n"
    );
    let _ = writeln!(
        s,
        "| surface | measured spectrum | Radiance RGB | reflectance RMSRE / MRB (%), basis | Jakob |\n|---|---|---|---|---|"
    );
    for m in &r.mats {
        let (jb, jr) = mrb_rmsre(&m.jakob, &m.measured);
        let (bb, br) = mrb_rmsre(&m.basis, &m.measured);
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} {:.3} {:.3} | {br:.1} / {bb:+.1} | {jr:.1} / {jb:+.1} |",
            m.what, m.source, m.rgb[0], m.rgb[1], m.rgb[2]
        );
    }
    let _ = writeln!(
        s,
        "\nThe RGB is the measured spectrum's colour in Radiance's RGB (equal-energy white, \
         CIE 1931 2 deg; `colour::cie`), the input an RGB-only survey would give. \
         Reflectance errors are over the 81 wavelengths 380-780 nm (5 nm). Spectra: \
         `data/spectra/macbeth_colorchecker24.csv` and `data/spectra/munsell1269_5nm.csv`.\n\n\
         **Sky**: `rspecsky`'s 18-band Perez sky matrix (MF 1, CIE daylight spectra by sky \
         condition) from the bundled London Gatwick IWEC EPW, at the seed's hours on the \
         solstice-nearest fully overcast and clear days (London's June 21st/22nd are partly \
         cloudy at those hours; the seed's text and table disagree on which pair was clear, \
         its discussion and higher values put the sun in the afternoon):\n\n\
         | step | sky | EPW DNI / DHI (W/m2) |\n|---|---|---|"
    );
    let w = Weather::read_path(
        common::repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw"),
    )
    .unwrap();
    for (st, ts) in STEPS.iter().zip(steps(&w)) {
        let _ = writeln!(
            s,
            "| {} | {} | {:.0} / {:.0} |",
            st.0, st.1, ts.direct, ts.diffuse
        );
    }
    let _ = writeln!(
        s,
        "\n**Simulation**: `rdc -I -cs 18 -cw 380 780 -ab {AB} -ad {AD} -lw 0 -s {SEED} -m 1` \
         (daylight coefficients, through `rdc::Tracer`), the same seed for the three \
         variants so that every path is the same and only the reflectances differ (`-lw 0`: \
         no Russian roulette, whose survival odds depend on the reflectances and would make \
         the paths diverge), times the \
         sky matrix (what `rmtx` does); m-EDI and Ev from the 18 bands as `rmetrics \
         melanopic`. Sun and sky are in 146 Reinhart MF 1 patches (the sun smeared over its \
         patch, as in any MF 1 daylight-coefficient run).\n"
    );
    // The seed's Table 5.7 layout: per step, the largest |m-EDI difference| over the eye
    // viewpoints, next to the seed's percentage error for the same hour.
    let _ = writeln!(
        s,
        "## Summary in the seed's layout\n\n\
         Largest |m-EDI difference| over the four eye viewpoints per step (%), and the \
         largest |Ev difference| (%), next to the seed's Table 5.7 (one viewpoint, Jakob & \
         Hanika, Delft):\n\n\
         | step | sky | seed PE (%) | basis m-EDI | Jakob m-EDI | basis Ev | Jakob Ev |\n\
         |---|---|---|---|---|---|---|"
    );
    let eyes: Vec<usize> = (0..views.len())
        .filter(|&v| views[v].0.starts_with("eye"))
        .collect();
    let mut worst_ev = 0.0f64;
    for (t, st) in STEPS.iter().enumerate() {
        let worst = |k: usize, ev: bool| {
            eyes.iter()
                .map(|&v| {
                    let (a, x) = (bw.eval(&r.irr[0][v][t]), bw.eval(&r.irr[k][v][t]));
                    if ev {
                        100.0 * (x.ev / a.ev - 1.0).abs()
                    } else {
                        100.0 * (x.medi / a.medi - 1.0).abs()
                    }
                })
                .fold(0.0f64, f64::max)
        };
        worst_ev = worst_ev.max(worst(1, true)).max(worst(2, true));
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
            st.0,
            st.1,
            SEED_PE[t],
            worst(1, false),
            worst(2, false),
            worst(1, true),
            worst(2, true)
        );
    }
    let _ = writeln!(
        s,
        "\nEv differs less than m-EDI: the uplifted spectra reproduce the measured RGB \
         exactly (equal-energy white), so under daylight their photopic reflectance is \
         nearly the same; the melanopic weighting sees the spectral shape.\n"
    );
    let _ = writeln!(s, "## m-EDI (lx)\n");
    let _ = writeln!(
        s,
        "| step | viewpoint | Ev (a) | (a) measured | (b) basis | diff (lx) | diff (%) | (c) Jakob | diff (lx) | diff (%) |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    let (mut worst_b, mut worst_j) = (0.0f64, 0.0f64);
    // Seed-to-seed change of the absolute m-EDI (a) and of the basis difference (pp).
    let (mut noise, mut noise_diff) = (0.0f64, 0.0f64);
    for (t, st) in STEPS.iter().enumerate() {
        for (v, (vname, _)) in views.iter().enumerate() {
            let m: Vec<_> = (0..3).map(|k| bw.eval(&r.irr[k][v][t])).collect();
            let (a, b, c) = (m[0].medi, m[1].medi, m[2].medi);
            let (pb, pc) = (100.0 * (b / a - 1.0), 100.0 * (c / a - 1.0));
            if vname.starts_with("eye") {
                worst_b = worst_b.max(pb.abs());
                worst_j = worst_j.max(pc.abs());
            }
            let a2 = bw.eval(&r.irr_seed2[0][v][t]).medi;
            let b2 = bw.eval(&r.irr_seed2[1][v][t]).medi;
            noise = noise.max((a2 / a - 1.0).abs() * 100.0);
            noise_diff = noise_diff.max((100.0 * (b2 / a2 - 1.0) - pb).abs());
            let _ = writeln!(
                s,
                "| {} ({}) | {vname} | {:.0} | {a:.0} | {b:.0} | {:+.1} | {pb:+.2} | {c:.0} | {:+.1} | {pc:+.2} |",
                st.0,
                st.1,
                m[0].ev,
                b - a,
                c - a
            );
        }
    }
    let _ = writeln!(
        s,
        "\nLargest |m-EDI difference| at the eye: basis {worst_b:.2} %, Jakob & Hanika \
         {worst_j:.2} % (seed: 1.4-5.6 %, criterion < 6 %). Monte Carlo noise of the \
         absolute values: (a) traced with seed {SEED2} instead of {SEED} differs by up to \
         {noise:.2} % in m-EDI (the sun smeared over its MF 1 patch reaches the eye through \
         diffuse bounces; the window panes are sampled as portals, but the eye sees the \
         sunlit floor and walls, one random bounce away: a noisy estimator), but the \
         differences use the same paths for every variant: the basis difference changes by \
         at most {noise_diff:.2} percentage points between the two seeds.\n"
    );
    let _ = writeln!(
        s,
        "## Spectral irradiance across wavelengths (seed Fig. 5.20)\n\n\
         Per step and viewpoint, the 18 band irradiances of (b) and (c) against (a): mean \
         relative bias MRB and root mean squared relative error RMSRE over the bands (%), \
         and the mean bias in W m-2 nm-1 (the unit of the seed's MRB of 0.12).\n\n\
         | step | viewpoint | basis MRB (%) | basis RMSRE (%) | basis bias (W/m2/nm) | Jakob MRB (%) | Jakob RMSRE (%) | Jakob bias (W/m2/nm) |\n|---|---|---|---|---|---|---|---|"
    );
    let mut all = [Vec::new(), Vec::new(), Vec::new()];
    for (t, st) in STEPS.iter().enumerate() {
        for (v, (vname, _)) in views.iter().enumerate() {
            let a = &r.irr[0][v][t];
            all[0].extend_from_slice(a);
            let mut cells = Vec::new();
            for (k, acc) in all.iter_mut().enumerate().skip(1) {
                let x = &r.irr[k][v][t];
                acc.extend_from_slice(x);
                let (mrb, rmsre) = mrb_rmsre(x, a);
                let bias = x.iter().zip(a).map(|(p, q)| p - q).sum::<f64>()
                    / (NCS as f64 * RADIANCE_SPAN_NM);
                cells.push(format!("{mrb:+.2} | {rmsre:.2} | {bias:+.5}"));
            }
            let _ = writeln!(s, "| {} | {vname} | {} |", st.0, cells.join(" | "));
        }
    }
    let (bm, br) = mrb_rmsre(&all[1], &all[0]);
    let (jm, jr) = mrb_rmsre(&all[2], &all[0]);
    let _ = writeln!(
        s,
        "\nOver all steps, viewpoints and bands: basis MRB {bm:+.2} %, RMSRE {br:.2} %; Jakob \
         & Hanika MRB {jm:+.2} %, RMSRE {jr:.2} % (seed: RMSRE 2.95 %, predominant over \
         prediction).\n"
    );
    // Where the differences sit: per band, relative difference of the summed irradiance
    // over every step and eye viewpoint.
    let _ = writeln!(
        s,
        "Per band, summed over the four steps and the eye viewpoints (%):\n\n\
         | band (nm) | basis | Jakob |\n|---|---|---|"
    );
    for b in (0..NCS).rev() {
        let sum = |k: usize| -> f64 {
            views
                .iter()
                .enumerate()
                .filter(|(_, (n, _))| n.starts_with("eye"))
                .map(|(v, _)| (0..STEPS.len()).map(|t| r.irr[k][v][t][b]).sum::<f64>())
                .sum()
        };
        let (hi, lo) = ch.band(b);
        let a = sum(0);
        let _ = writeln!(
            s,
            "| {lo:.0}-{hi:.0} | {:+.1} | {:+.1} |",
            100.0 * (sum(1) / a - 1.0),
            100.0 * (sum(2) / a - 1.0)
        );
    }
    let _ = writeln!(
        s,
        "\nThe band errors are largest at the ends of the range, where the uplifted \
         reflectances (smooth by construction) miss the measured ones' fall below 420 nm \
         and rise above 680 nm, and where the melanopic and photopic weights are small; \
         m-EDI integrates mostly 450-550 nm, where both uplifts reproduce the measured \
         reflectances closely (the ColorChecker white's measured reflectance falls from \
         0.9 to 0.15 below 420 nm, which neither smooth uplift follows: hence its large \
         reflectance RMSRE in the first table).\n\n\
         ## Notes\n\n\
         - The seed's criterion holds with room to spare for both methods: |m-EDI \
         difference| at most {worst_b:.2} % (basis) and {worst_j:.2} % (Jakob & Hanika) \
         against the seed's 1.4-5.6 %. Unlike the seed, the difference hardly depends on the \
         sky: clear and overcast skies differ in spectrum here only through the CIE \
         daylight CCT of sky and sun. The seed's larger, sky-dependent differences may come \
         from its materials (SpectralDB picks not listed), its RGB extraction, or Monte \
         Carlo noise: it compared independent Radiance runs, whose run-to-run spread is a \
         few % (up to {noise:.1} % here between two seeds for the absolute values), while \
         here every variant follows the same paths.\n\
         - The exterior ground keeps its grey RGB plastic (0.2), converted to bands as \
         Radiance does, identical in all variants.\n\
         - Reproduce: `SEED_MEDI_UPDATE=1 cargo test --test all seed_medi::` rewrites this page; \
         `cargo test --test all seed_medi::` checks it and the criteria (|m-EDI difference| < 6 % \
         at every eye viewpoint and step for the default method; |Ev difference| < 0.5 %)."
    );
    (s, worst_b, worst_j, worst_ev)
}

#[test]
fn seed_table_5_7_medi_measured_vs_uplifted() {
    let r = simulate();
    assert_eq!(r.mats.len(), 4);
    for m in &r.mats {
        assert_eq!(m.measured.len(), N);
    }
    let (page, worst_b, worst_j, worst_ev) = report(&r);
    eprintln!("{page}");
    // Sanity of the simulation itself: daylight at the eye in the hundreds of lux or more,
    // sunny steps brighter than overcast ones.
    let ch = Channels::spectral(NCS, 380.0, 780.0).unwrap();
    let bw = BandWeights::new(&ch).unwrap();
    for v in 0..viewpoints().len() {
        let e: Vec<f64> = (0..4).map(|t| bw.eval(&r.irr[0][v][t]).ev).collect();
        assert!(e.iter().all(|x| *x > 50.0), "viewpoint {v}: Ev {e:?}");
        assert!(e[2] > e[0] && e[3] > e[1], "viewpoint {v}: Ev {e:?}");
    }
    // Both uplifts reproduce each material's Radiance RGB exactly, so photopic light at
    // the eye hardly changes; a larger change would mean the RGB or the colorimetry chain
    // (spectrum -> RGB -> spectrum -> 18 bands) is inconsistent.
    assert!(worst_ev < 0.5, "Ev difference {worst_ev:.2} % >= 0.5 %");
    // The seed's criterion for the default method.
    assert!(
        worst_b < 6.0,
        "basis m-EDI difference {worst_b:.2} % >= 6 %"
    );
    eprintln!("worst m-EDI difference: basis {worst_b:.2} %, Jakob {worst_j:.2} %");
    let path = common::repo().join(DOC);
    if std::env::var_os("SEED_MEDI_UPDATE").is_some() {
        std::fs::write(&path, &page).unwrap();
    } else {
        let doc = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            doc == page,
            "{DOC} is out of date: regenerate with SEED_MEDI_UPDATE=1 cargo test --test all seed_medi::"
        );
    }
}
