//! Materials: energy and sampling invariants, glass formulas, and agreement with real
//! Radiance (`rtrace`) on single-surface scenes.
//!
//! Radiance's direct calculation is deterministic with `-dj 0 -ds 0 -dt 0 -dc 1` (no source
//! jitter, no subdivision, every source tested) and `-ab 0 -av 0 0 0` removes the ambient
//! term, so `rtrace -ov` equals `eval_direct x L_source` up to float rounding (measured
//! at most 6e-7 relative; the tolerance 1e-5 leaves room for rtrace's 7-digit output).
//! Indirect sampling is compared with `rtrace -ab 1 -aa 0` means over repeated rays, within
//! 3.5 combined standard errors.

use crate::common;

use std::f64::consts::PI;
use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight::material::glass::{
    self, Glass, transmissivity_from_transmittance, transmittance_from_transmissivity,
};
use rdaylight::material::sampling::{dot, normalize, reflect};
use rdaylight::material::{
    Color, Material, SampleKind, ShadingOptions, SpecularWeight, Surface, V3, to_channels,
};
use rdaylight::radiometry::Channels;
use rdaylight::scene::{self, LoadOptions, Primitive};

// ---------------------------------------------------------------- helpers

fn parse_material(text: &str, opts: &ShadingOptions, ch: &Channels) -> Material {
    let sc = scene::parse_str(text, "t.rad", Path::new(""), &LoadOptions::default())
        .expect("test scene parses");
    let obj = sc.objects.last().expect("one object");
    Material::from_object(obj, ch, opts)
        .expect("valid material")
        .expect("is a material")
}

fn ward(text: &str, opts: ShadingOptions) -> Material {
    parse_material(text, &opts, &Channels::rgb())
}

fn consistent() -> ShadingOptions {
    ShadingOptions {
        specular: SpecularWeight::Consistent,
        ..ShadingOptions::rtrace()
    }
}

/// Solid angle of a distant `source` of full apex angle `deg` (Radiance: 2 pi (1 - cos(a/2))).
fn source_omega(deg: f64) -> f64 {
    2.0 * PI * (1.0 - (deg.to_radians() / 2.0).cos())
}

fn random_dir(rng: &mut Pcg64) -> V3 {
    loop {
        let v = [
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ];
        let l = dot(v, v);
        if l > 1e-3 && l < 1.0 {
            return normalize(v);
        }
    }
}

/// A random `wo` with `cos(wo, n)` in [lo, 1].
fn random_wo(rng: &mut Pcg64, n: V3, lo: f64) -> V3 {
    loop {
        let w = random_dir(rng);
        if dot(w, n) >= lo {
            return w;
        }
    }
}

/// Run real `rtrace` on `scene` with `rays` (origin, direction); returns RGB per ray.
fn rtrace(scene: &str, rays: &[(V3, V3)], opts: &[&str]) -> Vec<[f64; 3]> {
    let dir = tempfile::tempdir().unwrap();
    let rad = dir.path().join("s.rad");
    std::fs::write(&rad, scene).unwrap();
    let oct = common::run_ok(
        common::radiance("oconv").arg(&rad).current_dir(dir.path()),
        b"",
    );
    let octp = dir.path().join("s.oct");
    std::fs::write(&octp, oct).unwrap();
    let input: String = rays
        .iter()
        // Exponent form: rtrace splits words longer than its buffer (a 35-character
        // "0.0000000000000000122..." became two numbers and shifted every later ray).
        .map(|(o, d)| {
            format!(
                "{:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}\n",
                o[0], o[1], o[2], d[0], d[1], d[2]
            )
        })
        .collect();
    let out = common::run_ok(
        common::radiance("rtrace")
            .args(["-h", "-ov", "-ab", "0", "-av", "0", "0", "0"])
            .args(["-dj", "0", "-ds", "0", "-dt", "0", "-dc", "1", "-dr", "0"])
            .args(opts)
            .arg(&octp),
        input.as_bytes(),
    );
    let text = String::from_utf8(out).unwrap();
    let v: Vec<[f64; 3]> = text
        .lines()
        .map(|l| {
            let f: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            assert_eq!(f.len(), 3, "rtrace line {l:?}");
            [f[0], f[1], f[2]]
        })
        .collect();
    assert_eq!(v.len(), rays.len(), "one rtrace result per ray");
    v
}

fn assert_close(what: &str, ours: [f64; 3], radiance: [f64; 3], rel: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for c in 0..3 {
        let scale = radiance[c].abs().max(ours[c].abs());
        let err = (ours[c] - radiance[c]).abs();
        let r = if scale > 0.0 { err / scale } else { 0.0 };
        worst = worst.max(r);
        assert!(
            err <= rel * scale + 1e-9,
            "{what}: channel {c}: ours {} vs rtrace {} (rel err {r:.2e})",
            ours[c],
            radiance[c]
        );
    }
    worst
}

fn rgb(c: Color) -> [f64; 3] {
    let s = c.as_slice();
    [s[0] as f64, s[1] as f64, s[2] as f64]
}

// ------------------------------------------------- direct light against rtrace

/// A square at z = 0 (normal +z) made of `mat`, lit by a 0.5 degree sun of radiance 1e5 from
/// `sun`, seen by view rays from `views` (directions from the square's centre toward the
/// eye); compares rtrace's radiance with `eval_direct x 1e5`.
fn direct_case(name: &str, mat: &str, sun: V3, views: &[V3]) -> f64 {
    const L: f64 = 1e5;
    let scene = format!(
        "void light sun 0 0 3 {L} {L} {L}\nsun source s 0 0 4 {} {} {} 0.5\n{mat}\n\
         m polygon sq 0 0 12 -1 -1 0  1 -1 0  1 1 0  -1 1 0\n",
        sun[0], sun[1], sun[2]
    );
    let m = ward(mat, ShadingOptions::rtrace());
    let rays: Vec<(V3, V3)> = views
        .iter()
        .map(|v| {
            let v = normalize(*v);
            // Eye 2 units away, aiming at a point near the centre.
            let target = [0.05, -0.03, 0.0];
            let o = [target[0] + 2.0 * v[0], target[1] + 2.0 * v[1], 2.0 * v[2]];
            (o, [-v[0], -v[1], -v[2]])
        })
        .collect();
    let got = rtrace(&scene, &rays, &[]);
    let wi = normalize(sun);
    let omega = source_omega(0.5);
    let half = 0.25f64.to_radians().cos();
    let surf = Surface::flat([0.0, 0.0, 1.0]);
    let mut worst: f64 = 0.0;
    for (v, r) in views.iter().zip(&got) {
        let wo = normalize(*v);
        let mut c = m.eval_direct(wo, wi, &surf, omega).unwrap().scale(L);
        // Pure specular lobes see the sun itself when they point into its disc.
        if let Material::Ward(w) = &m {
            let l = w.lobes(wo, &surf);
            if l.pure && dot(reflect(wo, l.n), wi) >= half {
                c += l.scolor.scale(L);
            }
            if l.pure && l.tran && dot([-wo[0], -wo[1], -wo[2]], wi) >= half {
                c += l.mcolor.scale(l.tspec * L);
            }
        }
        let w = assert_close(&format!("{name}, view {v:?}"), rgb(c), *r, 1e-5);
        worst = worst.max(w);
    }
    eprintln!("{name}: worst relative difference {worst:.2e}");
    worst
}

const VIEWS_FRONT: [V3; 6] = [
    [0.0, 0.0, 1.0],
    [-0.3, -0.2, 1.0],
    [-0.25, -0.15, 1.0],
    [0.6, 0.1, 0.8],
    [-1.0, 0.3, 0.4],
    [-0.5, -0.4, 0.3],
];

#[test]
fn plastic_and_metal_direct_agree_with_rtrace() {
    if !common::have_radiance("plastic_and_metal_direct_agree_with_rtrace") {
        return;
    }
    let sun = [0.3, 0.2, 1.0];
    for (name, mat) in [
        (
            "plastic rough .1",
            "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.1",
        ),
        (
            "plastic rough .02",
            "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.02",
        ),
        ("plastic rough 0", "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0"),
        ("metal rough .1", "void metal m 0 0 5 0.8 0.6 0.3 0.05 0.1"),
        (
            "metal rough .05 spec .9",
            "void metal m 0 0 5 0.8 0.6 0.3 0.9 0.05",
        ),
        ("metal rough 0", "void metal m 0 0 5 0.8 0.6 0.3 0.05 0"),
    ] {
        direct_case(name, mat, sun, &VIEWS_FRONT);
    }
}

#[test]
fn trans_direct_agrees_with_rtrace_front_and_back() {
    if !common::have_radiance("trans_direct_agrees_with_rtrace_front_and_back") {
        return;
    }
    let sun = [0.3, 0.2, 1.0];
    // Behind: the eye looks at the square from below, the sun is above.
    let behind: Vec<V3> = [
        [0.0, 0.0, -1.0],
        [-0.3, -0.2, -1.0],
        [-0.25, -0.15, -1.0],
        [0.5, 0.2, -0.6],
        [-0.7, -0.6, -0.5],
    ]
    .to_vec();
    for (name, mat) in [
        (
            "trans rough .1",
            "void trans m 0 0 7 0.6 0.5 0.4 0.04 0.1 0.5 0.3",
        ),
        (
            "trans rough .2 tspec .9",
            "void trans m 0 0 7 0.6 0.5 0.4 0.04 0.2 0.7 0.9",
        ),
        (
            "trans rough 0",
            "void trans m 0 0 7 0.6 0.5 0.4 0.04 0 0.5 0.3",
        ),
    ] {
        direct_case(&format!("{name} (behind)"), mat, sun, &behind);
        direct_case(&format!("{name} (front)"), mat, sun, &VIEWS_FRONT);
    }
}

#[test]
fn curved_surfaces_get_no_highlight_widening() {
    if !common::have_radiance("curved_surfaces_get_no_highlight_widening") {
        return;
    }
    // A sphere: Radiance's SP_FLAT is off, so alpha^2 is not widened by omega/(4 pi); with
    // roughness .02 the widening would change the highlight by about 1 %.
    const L: f64 = 1e5;
    let sun = normalize([0.3, 0.2, 1.0]);
    let mat = "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.02";
    let scene = format!(
        "void light sun 0 0 3 {L} {L} {L}\nsun source s 0 0 4 {} {} {} 0.5\n{mat}\n\
         m sphere ball 0 0 4 0 0 0 1\n",
        sun[0], sun[1], sun[2]
    );
    let m = ward(mat, ShadingOptions::rtrace());
    let omega = source_omega(0.5);
    // (point on the sphere = its normal, view direction)
    let cases: Vec<(V3, V3)> = vec![
        (normalize([0.1, 0.05, 1.0]), normalize([-0.1, -0.1, 1.0])),
        (normalize([0.0, 0.0, 1.0]), normalize([-0.3, -0.2, 1.0])),
        (normalize([0.2, 0.1, 1.0]), normalize([0.1, 0.0, 1.0])),
    ];
    let rays: Vec<(V3, V3)> = cases
        .iter()
        .map(|(p, v)| {
            let o = [p[0] + 3.0 * v[0], p[1] + 3.0 * v[1], p[2] + 3.0 * v[2]];
            (o, [-v[0], -v[1], -v[2]])
        })
        .collect();
    let got = rtrace(&scene, &rays, &[]);
    for ((p, v), r) in cases.iter().zip(&got) {
        let curved = m
            .eval_direct(*v, sun, &Surface::curved(*p), omega)
            .unwrap()
            .scale(L);
        let flat = m
            .eval_direct(*v, sun, &Surface::flat(*p), omega)
            .unwrap()
            .scale(L);
        // Normals from rtrace's intersection are accurate to ~1e-7; the highlight is steep.
        assert_close(&format!("sphere at {p:?}"), rgb(curved), *r, 1e-4);
        assert!(
            (flat.mean() - curved.mean()).abs() > 1e-3 * curved.mean(),
            "the case must distinguish flat from curved"
        );
    }
}

// ------------------------------------------------------------- glass vs rtrace

fn glass_material(args: &str) -> Glass {
    match parse_material(
        &format!("void glass g 0 0 {args}"),
        &ShadingOptions::default(),
        &Channels::rgb(),
    ) {
        Material::Glass(g) => g,
        other => panic!("expected glass, got {other:?}"),
    }
}

/// Unit direction at `deg` from +z in the x-z plane, tilted a little out of it.
fn tilted(deg: f64) -> V3 {
    let t = deg.to_radians();
    normalize([t.sin(), 0.1 * t.sin(), t.cos()])
}

#[test]
fn glass_view_rays_agree_with_rtrace() {
    if !common::have_radiance("glass_view_rays_agree_with_rtrace") {
        return;
    }
    let angles = [0.0, 30.0, 60.0, 75.0, 85.0];
    for args in ["3 0.96 0.8 0.5", "4 0.9 0.6 0.3 1.8"] {
        let g = glass_material(args);
        let pane =
            format!("void glass g 0 0 {args}\ng polygon pane 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n");
        // Transmission: a uniform glow hemisphere behind the pane (below), eye above.
        let below = format!("void glow gl 0 0 4 1 1 1 0\ngl source under 0 0 4 0 0 -1 180\n{pane}");
        // Reflection: the glow hemisphere on the eye's side.
        let above = format!("void glow gl 0 0 4 1 1 1 0\ngl source over 0 0 4 0 0 1 180\n{pane}");
        let rays: Vec<(V3, V3)> = angles
            .iter()
            .map(|&a| {
                let v = tilted(a);
                ([2.0 * v[0], 2.0 * v[1], 2.0 * v[2]], [-v[0], -v[1], -v[2]])
            })
            .collect();
        let t_rad = rtrace(&below, &rays, &[]);
        let r_rad = rtrace(&above, &rays, &[]);
        for ((&a, t), r) in angles.iter().zip(&t_rad).zip(&r_rad) {
            let v = tilted(a);
            let (tc, rc) = g.coefficients(v[2]);
            let wt = assert_close(&format!("glass {args} T at {a} deg"), rgb(tc), *t, 1e-5);
            let wr = assert_close(&format!("glass {args} R at {a} deg"), rgb(rc), *r, 1e-5);
            eprintln!("glass {args} at {a} deg: T {t:?} R {r:?} (rel {wt:.1e}, {wr:.1e})");
            // The sampled continuation has the same expectation.
            let surf = Surface::flat([0.0, 0.0, 1.0]);
            let st = g.sample(v, &surf, 0.0).unwrap();
            let sr = g.sample(v, &surf, 0.999_999).unwrap();
            assert_eq!(st.kind, SampleKind::PureTransmit);
            assert_eq!(sr.kind, SampleKind::PureReflect);
            let p_t = tc.mean() / (tc.mean() + rc.mean());
            let mean_t = rgb(st.weight.scale(p_t));
            let mean_r = rgb(sr.weight.scale(1.0 - p_t));
            assert_close("sampled T", mean_t, *t, 1e-5);
            assert_close("sampled R", mean_r, *r, 1e-5);
        }
    }
}

#[test]
fn sunlight_through_glass_agrees_with_rtrace_irradiance() {
    if !common::have_radiance("sunlight_through_glass_agrees_with_rtrace_irradiance") {
        return;
    }
    const L: f64 = 1e5;
    let g = glass_material("3 0.96 0.8 0.5");
    let omega = source_omega(0.5);
    for a in [0.0, 30.0, 60.0, 75.0] {
        let sun = tilted(a);
        let scene = format!(
            "void light sun 0 0 3 {L} {L} {L}\nsun source s 0 0 4 {} {} {} 0.5\n\
             void glass g 0 0 3 0.96 0.8 0.5\n\
             g polygon pane 0 0 12 -99 -99 0 99 -99 0 99 99 0 -99 99 0\n",
            sun[0], sun[1], sun[2]
        );
        let got = rtrace(&scene, &[([0.0, 0.0, -0.5], [0.0, 0.0, 1.0])], &["-I"]);
        // The shadow ray leaves the sensor toward the sun: wo points back down.
        let t = g
            .shadow_transmission([-sun[0], -sun[1], -sun[2]], &Surface::flat([0.0, 0.0, 1.0]))
            .unwrap();
        let expect = t.scale(L * omega * sun[2]);
        let w = assert_close(
            &format!("sun through glass at {a} deg"),
            rgb(expect),
            got[0],
            1e-5,
        );
        eprintln!("sun at {a} deg: rtrace {:?}, rel {w:.1e}", got[0]);
    }
}

#[test]
fn shadow_rays_through_trans_agree_with_rtrace() {
    if !common::have_radiance("shadow_rays_through_trans_agree_with_rtrace") {
        return;
    }
    // Pure specular trans passes sunlight with rho * tspec; a rough trans blocks it (only its
    // own dirnorm transmission reaches the far side), as do plastic and metal.
    const L: f64 = 1e5;
    let omega = source_omega(0.5);
    for mat in [
        "void trans m 0 0 7 0.6 0.5 0.4 0.04 0 0.5 0.3",
        "void trans m 0 0 7 0.6 0.5 0.4 0.0 0 0.9 1",
        "void trans m 0 0 7 0.6 0.5 0.4 0.04 0.1 0.5 0.3",
        "void plastic m 0 0 5 0.6 0.5 0.4 0.04 0",
    ] {
        let m = ward(mat, ShadingOptions::rtrace());
        for a in [0.0, 40.0, 70.0] {
            let sun = tilted(a);
            let scene = format!(
                "void light sun 0 0 3 {L} {L} {L}\nsun source s 0 0 4 {} {} {} 0.5\n{mat}\n\
                 m polygon pane 0 0 12 -99 -99 0 99 -99 0 99 99 0 -99 99 0\n",
                sun[0], sun[1], sun[2]
            );
            let got = rtrace(&scene, &[([0.0, 0.0, -0.5], [0.0, 0.0, 1.0])], &["-I"]);
            let t =
                m.shadow_transmission([-sun[0], -sun[1], -sun[2]], &Surface::flat([0.0, 0.0, 1.0]));
            let expect = t.map_or([0.0; 3], |t| rgb(t.scale(L * omega * sun[2])));
            assert_close(&format!("{mat} sun at {a} deg"), expect, got[0], 1e-5);
        }
    }
}

#[test]
fn mirror_and_light_agree_with_rtrace() {
    if !common::have_radiance("mirror_and_light_agree_with_rtrace") {
        return;
    }
    let ch = Channels::rgb();
    let o = ShadingOptions::default();
    let mirror = parse_material("void mirror m 0 0 3 0.9 0.7 0.5", &o, &ch);
    let light = parse_material("void light m 0 0 3 10 20 30", &o, &ch);
    let glow_sky = "void glow gl 0 0 4 1 2 3 0\ngl source over 0 0 4 0 0 1 180\n";
    let surf = Surface::flat([0.0, 0.0, 1.0]);
    let views = [tilted(0.0), tilted(45.0), tilted(80.0), neg3(tilted(30.0))];
    let rays: Vec<(V3, V3)> = views
        .iter()
        .map(|v| ([2.0 * v[0], 2.0 * v[1], 2.0 * v[2]], neg3(*v)))
        .collect();
    let quad = "m polygon q 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n";
    let mir = rtrace(
        &format!("{glow_sky}void mirror m 0 0 3 0.9 0.7 0.5\n{quad}"),
        &rays,
        &[],
    );
    let lit = rtrace(&format!("void light m 0 0 3 10 20 30\n{quad}"), &rays, &[]);
    for ((v, rm), rl) in views.iter().zip(&mir).zip(&lit) {
        // The reflected ray sees the glow (1 2 3) above, or nothing from the back.
        let ours_m = match mirror.sample(*v, &surf, 0.5, 0.5, 0.5) {
            Some(s) => {
                assert_eq!(s.kind, SampleKind::PureReflect);
                assert!(s.wi[2] > 0.0);
                rgb(s.weight.mul_rgb([1.0, 2.0, 3.0]))
            }
            None => [0.0; 3],
        };
        assert_close(&format!("mirror seen from {v:?}"), ours_m, *rm, 1e-5);
        let ours_l = rgb(light.emission(*v, &surf).unwrap());
        assert_close(&format!("light seen from {v:?}"), ours_l, *rl, 1e-5);
    }
}

#[test]
fn spectral_channels_follow_radiance_setscolor() {
    if !common::have_radiance("spectral_channels_follow_radiance_setscolor") {
        return;
    }
    // Glass transmission of a white glow, 7 bands over 380-780 nm: every band gets the R, G
    // or B transmissivity by its centre wavelength, exactly as rtrace -cs 7 -co.
    let ch = Channels::spectral(7, 380.0, 780.0).unwrap();
    let g = match parse_material(
        "void glass g 0 0 3 0.9 0.6 0.3",
        &ShadingOptions::default(),
        &ch,
    ) {
        Material::Glass(g) => g,
        _ => unreachable!(),
    };
    let scene = "void glow gl 0 0 4 1 1 1 0\ngl source under 0 0 4 0 0 -1 180\n\
                 void glass g 0 0 3 0.9 0.6 0.3\n\
                 g polygon pane 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n";
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.rad"), scene).unwrap();
    let oct = common::run_ok(common::radiance("oconv").arg(dir.path().join("s.rad")), b"");
    std::fs::write(dir.path().join("s.oct"), oct).unwrap();
    let v = tilted(40.0);
    let out = common::run_ok(
        common::radiance("rtrace")
            .args(["-h", "-ov", "-ab", "0", "-cs", "7", "-co+"])
            .arg(dir.path().join("s.oct")),
        format!(
            "{} {} {} {} {} {}\n",
            2.0 * v[0],
            2.0 * v[1],
            2.0 * v[2],
            -v[0],
            -v[1],
            -v[2]
        )
        .as_bytes(),
    );
    let got: Vec<f64> = String::from_utf8(out)
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let (t, _) = g.coefficients(v[2]);
    assert_eq!(t.ncomp(), 7);
    assert_eq!(got.len(), 7, "rtrace -cs 7 -co gives 7 values: {got:?}");
    for (i, (&a, &b)) in t.as_slice().iter().zip(&got).enumerate() {
        assert!(
            ((a as f64) - b).abs() <= 1e-5 * b.abs().max(1e-3),
            "band {i}: ours {a} vs rtrace {b}"
        );
    }
    // Band centres 751, 694, 637, 580, 523, 466, 409 nm against the 588/480 splits.
    let c = to_channels([0.9, 0.6, 0.3], &ch);
    assert_eq!(c.as_slice(), &[0.9f32, 0.9, 0.9, 0.6, 0.6, 0.3, 0.3][..]);
}

fn neg3(v: V3) -> V3 {
    [-v[0], -v[1], -v[2]]
}

trait MulRgb {
    fn mul_rgb(self, rgb: [f64; 3]) -> Color;
}

impl MulRgb for Color {
    fn mul_rgb(self, rgb: [f64; 3]) -> Color {
        self * Color::from_slice(&[rgb[0] as f32, rgb[1] as f32, rgb[2] as f32])
    }
}

// ------------------------------------------------------------------ invariants

/// `integral of eval_direct/omega over the sphere`, by the midpoint rule in (theta, phi)
/// about the normal on both sides (the eval is smooth for roughness >= .15 at this grid).
fn integrate_eval(m: &Material, wo: V3, s: &Surface) -> [f64; 3] {
    const K: usize = 600;
    const OMEGA: f64 = 1e-12;
    let n = s.normal;
    let (u, v) = rdaylight::material::sampling::frame(n);
    let mut sum = [0.0; 3];
    for side in [1.0, -1.0] {
        for i in 0..K {
            let th = (i as f64 + 0.5) / K as f64 * PI / 2.0;
            let (st, ct) = th.sin_cos();
            let dw = st * (PI / 2.0 / K as f64) * (2.0 * PI / (2 * K) as f64);
            for j in 0..2 * K {
                let ph = (j as f64 + 0.5) / (2 * K) as f64 * 2.0 * PI;
                let (sp, cp) = ph.sin_cos();
                let wi = [
                    side * ct * n[0] + st * (cp * u[0] + sp * v[0]),
                    side * ct * n[1] + st * (cp * u[1] + sp * v[1]),
                    side * ct * n[2] + st * (cp * u[2] + sp * v[2]),
                ];
                let c = m.eval_direct(wo, wi, s, OMEGA).unwrap();
                for (k, x) in c.as_slice().iter().enumerate() {
                    sum[k] += *x as f64 / OMEGA * dw;
                }
            }
        }
    }
    sum
}

/// Mean and standard error per channel of the sampled weights (misses count as zero).
fn mc_albedo(m: &Material, wo: V3, s: &Surface, n: usize, rng: &mut Pcg64) -> ([f64; 3], [f64; 3]) {
    let (mut s1, mut s2) = ([0.0; 3], [0.0; 3]);
    for _ in 0..n {
        if let Some(smp) = m.sample(wo, s, rng.random(), rng.random(), rng.random()) {
            assert!(
                smp.weight
                    .as_slice()
                    .iter()
                    .all(|x| x.is_finite() && *x >= 0.0)
            );
            assert!((dot(smp.wi, smp.wi) - 1.0).abs() < 1e-9);
            for (k, x) in smp.weight.as_slice().iter().enumerate() {
                s1[k] += *x as f64;
                s2[k] += (*x as f64).powi(2);
            }
        }
    }
    let nf = n as f64;
    let mean = s1.map(|x| x / nf);
    let se = [0, 1, 2].map(|k| ((s2[k] / nf - mean[k] * mean[k]).max(0.0) / nf).sqrt());
    (mean, se)
}

const PHYSICAL: [&str; 9] = [
    "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.15",
    "void plastic m 0 0 5 0.9 0.9 0.9 0.1 0.3",
    "void metal m 0 0 5 0.8 0.6 0.3 0.9 0.15",
    "void trans m 0 0 7 0.6 0.5 0.4 0.04 0.15 0.5 0.3",
    "void trans m 0 0 7 0.9 0.9 0.9 0 0.2 0.8 0.9",
    "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0",
    "void metal m 0 0 5 0.8 0.6 0.3 0.9 0",
    "void trans m 0 0 7 0.6 0.5 0.4 0.04 0 0.5 0.3",
    "void trans m 0 0 7 1 1 1 0 0 1 1",
];

#[test]
fn sampling_is_unbiased_for_eval_and_never_gains_energy() {
    // SpecularWeight::Consistent: the sampled estimate of the directional albedo equals the
    // integral of the direct-light BRDF (plus the pure specular coefficients).
    let mut rng = Pcg64::seed_from_u64(7);
    for mat in PHYSICAL {
        let m = ward(mat, consistent());
        for k in 0..2 {
            let n = random_dir(&mut rng);
            let wo = random_wo(&mut rng, n, if k == 0 { 0.6 } else { 0.15 });
            let s = Surface::curved(n);
            let mut expect = integrate_eval(&m, wo, &s);
            if let Material::Ward(w) = &m {
                let l = w.lobes(wo, &s);
                for (c, e) in expect.iter_mut().enumerate() {
                    if l.pure && l.refl {
                        *e += l.scolor.as_slice()[c] as f64;
                    }
                    if l.pure && l.tran {
                        *e += (l.mcolor.as_slice()[c] as f64) * l.tspec;
                    }
                }
            }
            let (mean, se) = mc_albedo(&m, wo, &s, 200_000, &mut rng);
            for c in 0..3 {
                // 3 standard errors of the Monte Carlo estimate plus 2e-3 for the quadrature.
                let tol = 3.0 * se[c] + 2e-3 * expect[c];
                assert!(
                    (mean[c] - expect[c]).abs() <= tol,
                    "{mat} cos(wo) {:.3}: channel {c}: sampled {} +- {} vs integral {}",
                    dot(wo, n),
                    mean[c],
                    se[c],
                    expect[c]
                );
                assert!(
                    mean[c] <= 1.0 + 3.0 * se[c],
                    "{mat}: albedo {} > 1",
                    mean[c]
                );
                assert!(expect[c] <= 1.0 + 2e-3, "{mat}: integral {} > 1", expect[c]);
            }
        }
    }
}

#[test]
fn radiance_weighting_matches_its_coefficients_and_differs_from_the_brdf_integral() {
    // SpecularWeight::Radiance (rtrace/rcontrib -ss 1): every lobe carries its coefficient,
    // so the sampled albedo is the sum of normal.c's coefficients; this is not the integral
    // of dirnorm's BRDF (measured below), which is why Consistent exists.
    let mut rng = Pcg64::seed_from_u64(11);
    let mut max_gap: f64 = 0.0;
    for mat in PHYSICAL {
        let m = ward(mat, ShadingOptions::rcontrib());
        let mc = ward(mat, consistent());
        let n = random_dir(&mut rng);
        for cos in [0.9, 0.3] {
            let wo = random_wo(&mut rng, n, cos);
            let s = Surface::curved(n);
            let Material::Ward(w) = &m else {
                unreachable!()
            };
            let l = w.lobes(wo, &s);
            let mut expect = [0.0; 3];
            for (c, e) in expect.iter_mut().enumerate() {
                let mcol = l.mcolor.as_slice()[c] as f64;
                let scol = l.scolor.as_slice()[c] as f64;
                if l.refl {
                    *e += scol;
                }
                if l.tran && !l.tblt {
                    *e += mcol * l.tspec;
                }
                if l.rdiff > 1e-6 {
                    *e += mcol * l.rdiff;
                }
                if l.tdiff > 1e-6 {
                    *e += mcol * if l.tblt { l.trans } else { l.tdiff };
                }
            }
            let (mean, se) = mc_albedo(&m, wo, &s, 100_000, &mut rng);
            let (mean_c, _) = mc_albedo(&mc, wo, &s, 100_000, &mut rng);
            for c in 0..3 {
                assert!(
                    (mean[c] - expect[c]).abs() <= 3.0 * se[c] + 1e-6,
                    "{mat}: channel {c}: sampled {} +- {} vs coefficients {}",
                    mean[c],
                    se[c],
                    expect[c]
                );
                assert!(mean[c] <= 1.0 + 1e-6, "{mat}: albedo {} > 1", mean[c]);
                max_gap = max_gap.max((mean[c] - mean_c[c]).abs());
            }
        }
    }
    eprintln!("largest albedo gap Radiance -ss 1 vs BRDF-consistent: {max_gap:.4}");
    assert!(
        max_gap > 0.01,
        "the two weightings should differ measurably here"
    );
}

#[test]
fn ward_reflection_is_reciprocal() {
    let mut rng = Pcg64::seed_from_u64(3);
    for mat in [
        "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.15",
        "void metal m 0 0 5 0.8 0.6 0.3 0.9 0.05",
        "void plastic m 0 0 5 0.5 0.4 0.3 0.2 0.4",
    ] {
        let m = ward(mat, ShadingOptions::rtrace());
        for _ in 0..2000 {
            let n = random_dir(&mut rng);
            let a = random_wo(&mut rng, n, 0.01);
            let b = random_wo(&mut rng, n, 0.01);
            let omega = 6e-5;
            for s in [Surface::flat(n), Surface::curved(n)] {
                let fab = m
                    .eval_direct(a, b, &s, omega)
                    .unwrap()
                    .scale(1.0 / dot(b, n));
                let fba = m
                    .eval_direct(b, a, &s, omega)
                    .unwrap()
                    .scale(1.0 / dot(a, n));
                for (x, y) in fab.as_slice().iter().zip(fba.as_slice()) {
                    assert!(
                        (x - y).abs() <= 1e-4 * x.abs().max(y.abs()) + 1e-9,
                        "{mat}: f(a,b) {x} != f(b,a) {y}"
                    );
                }
            }
        }
    }
}

#[test]
fn glass_conserves_energy_and_matches_published_transmittance() {
    for args in [
        "3 0.96 0.96 0.96",
        "3 1 1 1",
        "3 0.5 0.2 0.01",
        "4 0.9 0.8 0.7 1.8",
        "4 1 1 1 2.4",
    ] {
        let g = glass_material(args);
        for i in 0..=1000 {
            let pdot = (i as f64 / 1000.0).max(1e-6);
            let (t, r) = g.coefficients(pdot);
            for (x, y) in t.as_slice().iter().zip(r.as_slice()) {
                assert!(*x >= 0.0 && *y >= 0.0, "{args} at cos {pdot}: T {x} R {y}");
                assert!(x + y <= 1.0 + 1e-6, "{args} at cos {pdot}: T+R = {}", x + y);
            }
        }
    }
    // Lossless glass transmits everything it does not reflect.
    let (t, r) = glass_material("3 1 1 1").coefficients(0.7);
    assert!(((t.as_slice()[0] + r.as_slice()[0]) as f64 - 1.0).abs() < 1e-6);
    // "The transmissivity of standard 88% transmittance glass is 0.96" (glass.c).
    let (t0, _) = glass_material("3 0.96 0.96 0.96").coefficients(1.0);
    assert!(
        (t0.as_slice()[0] as f64 - 0.88).abs() < 0.002,
        "T(0) = {:?}",
        t0
    );
    for i in 1..=100 {
        let tn_total = i as f64 / 100.0 * 0.918; // at most (1-r)/(1+r) = 0.9183
        let tn = transmissivity_from_transmittance(tn_total);
        assert!((0.0..=1.0 + 1e-9).contains(&tn), "{tn_total} -> {tn}");
        let back = transmittance_from_transmissivity(tn, glass::DEFAULT_INDEX);
        // The published constants are rounded to 10 digits: ~3e-8/Tn absolute.
        assert!(
            (back - tn_total).abs() < 2e-6,
            "{tn_total} -> {tn} -> {back}"
        );
        let exact = glass::transmissivity_for_index(tn_total, glass::DEFAULT_INDEX);
        assert!((exact - tn).abs() < 3e-6, "published {tn} vs exact {exact}");
        let back = transmittance_from_transmissivity(exact, glass::DEFAULT_INDEX);
        assert!(
            (back - tn_total).abs() < 1e-12,
            "{tn_total} -> {exact} -> {back}"
        );
        let exact18 = glass::transmissivity_for_index(tn_total, 1.8);
        let back18 = transmittance_from_transmissivity(exact18, 1.8);
        assert!((back18 - tn_total).abs() < 1e-12);
        let (t, _) = glass_material(&format!("3 {tn} {tn} {tn}")).coefficients(1.0);
        assert!((t.as_slice()[0] as f64 - tn_total).abs() < 1e-5);
    }
}

#[test]
fn material_errors_name_the_object_and_what_was_expected() {
    let sc = scene::parse_str(
        "void plastic ok 0 0 5 .5 .5 .5 0 0\n\nvoid plastic bad 0 0 5 .5 -.5 .5 0 0\n\
         void trans t2 0 0 7 .5 .5 .5 0 0 1.5 0\nvoid glass g 0 0 4 .9 .9 .9 -1\n\
         void dielectric d 0 0 5 1 1 1 1.5 0\nok polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n\
         void spotlight sp 0 0 7 1 1 1 30 0 0 -1\n",
        "room.rad",
        Path::new(""),
        &LoadOptions::default(),
    )
    .unwrap();
    let ch = Channels::rgb();
    let o = ShadingOptions::default();
    let err = |i: usize| match Material::from_object(&sc.objects[i], &ch, &o) {
        Err(e) => e.to_string(),
        Ok(m) => panic!("object {i}: expected an error, got {m:?}"),
    };
    assert!(matches!(
        Material::from_object(&sc.objects[0], &ch, &o),
        Ok(Some(Material::Ward(_)))
    ));
    assert_eq!(
        err(1),
        "room.rad:3:1: plastic 'bad' has colour [0.5, -0.5, 0.5]; expected three finite values >= 0"
    );
    assert_eq!(
        err(2),
        "room.rad:4:1: trans 't2' has transmissivity 1.5; expected a value in [0, 1]"
    );
    assert_eq!(
        err(3),
        "room.rad:5:1: glass 'g' has refractive index -1; expected a finite value > 0"
    );
    assert_eq!(
        err(4),
        "room.rad:6:1: unsupported material type dielectric ('d')"
    );
    // Surfaces are not materials.
    assert!(matches!(
        Material::from_object(&sc.objects[5], &ch, &o),
        Ok(None)
    ));
    assert_eq!(
        err(6),
        "room.rad:8:1: unsupported material type spotlight ('sp'); use light"
    );
    // from_primitive works without a scene.
    let p = Primitive::Light {
        color: vec![1.0, 2.0, 3.0],
    };
    let m = Material::from_primitive(&p, &Channels::spectral(9, 380.0, 780.0).unwrap())
        .unwrap()
        .unwrap();
    assert_eq!(
        m.emission([0.0, 0.0, 1.0], &Surface::flat([0.0, 0.0, 1.0]))
            .unwrap()
            .ncomp(),
        9
    );
}

#[test]
fn emitter_source_rules_follow_radiance() {
    use rdaylight::material::Emitter;
    let ch = Channels::rgb();
    let o = ShadingOptions::default();
    let em = |t: &str| match parse_material(t, &o, &ch) {
        Material::Emitter(e) => e,
        m => panic!("{m:?}"),
    };
    let e: Emitter = em("void light l 0 0 3 1 1 1");
    assert!(e.is_direct_source(false) && e.is_direct_source(true));
    assert!(!e.counts_for_indirect(1e30));
    assert!(!em("void light l 0 0 3 0 0 0").is_direct_source(false));
    let g0 = em("void glow g 0 0 4 1 1 1 0");
    assert!(!g0.is_direct_source(false) && g0.counts_for_indirect(0.5));
    let g5 = em("void glow g 0 0 4 1 1 1 5");
    assert!(g5.is_direct_source(false) && !g5.is_direct_source(true));
    assert!(g5.counts_for_indirect(6.0) && !g5.counts_for_indirect(4.0));
    let gneg = em("void glow g 0 0 4 1 1 1 -1");
    assert!(!gneg.is_direct_source(false) && !gneg.counts_for_indirect(1e30));
    let il = em("void illum i 1 alt 0 3 1 1 1");
    assert!(il.is_direct_source(false) && il.alternate() == Some("alt"));
    // One-sided.
    let s = Surface::flat([0.0, 0.0, 1.0]);
    assert!(e.emission([0.0, 0.0, -1.0], &s).is_black());
    assert!(!e.emission([0.0, 0.6, 0.8], &s).is_black());
}

#[test]
fn indirect_sampling_agrees_with_rtrace_ab1() {
    if !common::have_radiance("indirect_sampling_agrees_with_rtrace_ab1") {
        return;
    }
    // A glow cone of half-angle 60 degrees around the zenith (never a direct source, so all
    // of it arrives through ambient and specular samples). rtrace -ab 1 -aa 0 traces the
    // same ray many times; its mean and standard error are compared with the expectation of
    // our `sample` (SpecularWeight::Radiance, rtrace's -st .15 -ss 1): weight x L(wi).
    const RAYS: usize = 1500;
    let cos_cone = 60f64.to_radians().cos();
    let glow = "void glow gl 0 0 4 1 1 1 0\ngl source cone 0 0 4 0 0 1 120\n";
    let quad = "m polygon q 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n";
    let mut rng = Pcg64::seed_from_u64(5);
    let mut report = Vec::new();
    for (mat, views) in [
        // spec .05 < -st: the specular is folded into the ambient coefficient
        (
            "void plastic m 0 0 5 0.5 0.4 0.3 0.05 0.1",
            &[0.0, 50.0][..],
        ),
        ("void plastic m 0 0 5 0.5 0.4 0.3 0.2 0.1", &[0.0, 50.0][..]),
        ("void metal m 0 0 5 0.8 0.6 0.3 0.9 0.15", &[20.0, 70.0][..]),
        // seen from below: diffuse and Gaussian transmission toward the cone
        (
            "void trans m 0 0 7 0.6 0.5 0.4 0.04 0.15 0.6 0.5",
            &[180.0, 140.0][..],
        ),
    ] {
        let m = ward(mat, ShadingOptions::rtrace());
        let scene = format!("{glow}{mat}\n{quad}");
        for &a in views {
            let v = tilted(a);
            let rays: Vec<(V3, V3)> = (0..RAYS)
                .map(|_| ([0.1 + 2.0 * v[0], 2.0 * v[1], 2.0 * v[2]], neg3(v)))
                .collect();
            let got = rtrace(
                &scene,
                &rays,
                &[
                    "-ab", "1", "-aa", "0", "-ad", "256", "-as", "0", "-lw", "1e-6",
                ],
            );
            let surf = Surface::flat([0.0, 0.0, 1.0]);
            let n_ours = 2_000_000;
            let mut ours = [0.0; 3];
            let mut ours2 = [0.0; 3];
            for _ in 0..n_ours {
                if let Some(smp) = m.sample(v, &surf, rng.random(), rng.random(), rng.random()) {
                    if smp.wi[2] >= cos_cone {
                        for (c, x) in smp.weight.as_slice().iter().enumerate() {
                            ours[c] += *x as f64;
                            ours2[c] += (*x as f64).powi(2);
                        }
                    }
                }
            }
            for c in 0..3 {
                let mean = ours[c] / n_ours as f64;
                let se_ours = ((ours2[c] / n_ours as f64 - mean * mean) / n_ours as f64).sqrt();
                let vals: Vec<f64> = got.iter().map(|r| r[c]).collect();
                let rm = vals.iter().sum::<f64>() / RAYS as f64;
                let rv = vals.iter().map(|x| (x - rm).powi(2)).sum::<f64>() / (RAYS - 1) as f64;
                let se_rad = (rv / RAYS as f64).sqrt();
                let se = (se_ours * se_ours + se_rad * se_rad).sqrt();
                report.push(format!(
                    "{mat} view {a}: ch {c}: ours {mean:.5} rtrace {rm:.5} +- {se_rad:.5}"
                ));
                assert!(
                    (mean - rm).abs() <= 3.5 * se + 1e-4,
                    "{mat} view {a} deg, channel {c}: ours {mean} +- {se_ours} vs rtrace {rm} +- {se_rad}"
                );
            }
        }
    }
    eprintln!("{}", report.join("\n"));
}

#[test]
fn illum_is_transparent_to_view_rays_like_rtrace() {
    if !common::have_radiance("illum_is_transparent_to_view_rays_like_rtrace") {
        return;
    }
    // An illum window (void alternate) in front of a glow: view rays see the glow through it,
    // not the illum's radiance; from the back likewise.
    let ch = Channels::rgb();
    let il = parse_material(
        "void illum w 0 0 3 50 50 50",
        &ShadingOptions::default(),
        &ch,
    );
    let scene = "void glow gl 0 0 4 1 2 3 0\ngl source under 0 0 4 0 0 -1 180\n\
                 void illum w 0 0 3 50 50 50\nw polygon q 0 0 12 -9 -9 0 9 -9 0 9 9 0 -9 9 0\n";
    let v = tilted(30.0);
    let got = rtrace(
        scene,
        &[([2.0 * v[0], 2.0 * v[1], 2.0 * v[2]], neg3(v))],
        &[],
    );
    let s = Surface::flat([0.0, 0.0, 1.0]);
    let seen = il.emission(v, &s).unwrap();
    let through = il.sample(v, &s, 0.5, 0.5, 0.5).unwrap();
    assert_eq!(through.kind, SampleKind::PureTransmit);
    assert!(through.wi[2] < 0.0);
    let ours = rgb(seen + through.weight.mul_rgb([1.0, 2.0, 3.0]));
    assert_close("illum seen by a view ray", ours, got[0], 1e-5);
}
