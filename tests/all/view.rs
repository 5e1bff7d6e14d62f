//! Views compared with real Radiance: every ray `vwrays` writes, `vwrays -d` resolutions,
//! `setview` error reasons, `VIEW=` from a real `rpict` picture, and view files.

use crate::common;

use rdaylight::formats::header::Header;
use rdaylight::formats::view::{Camera, View};

/// Views covering every type, oblique directions and ups, shifts, lifts and clipping.
const VIEWS: &[&str] = &[
    "",
    "-vtv -vp 1 2 1.5 -vd 1 2 0.3 -vu 0 0 1 -vh 60 -vv 40",
    "-vtv -vd 0 3 -1 -vu 0.2 0 1 -vh 70 -vv 70 -vs 0.3 -vl -0.2 -vo 0.5 -va 20",
    "-vth -vp 0 0 1 -vd 1 -1 0.5 -vu 0 0 1 -vh 180 -vv 180",
    "-vth -vd 0 0 1 -vu 0 1 0 -vh 150 -vv 120 -vs 0.1",
    "-vta -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180",
    "-vta -vd 1 1 0 -vu 0 0 1 -vh 360 -vv 360 -vl 0.1",
    "-vta -vp -3 4 1.2 -vd 2 -1 0.4 -vu 0 0 1 -vh 200 -vv 150 -vo 0.2 -va 9",
    "-vtl -vp 5 5 5 -vd -1 -1 -1 -vu 0 0 1 -vh 10 -vv 6 -vs 0.2 -vo 1 -va 30",
    "-vtc -vd 0 1 0 -vu 0 0 1 -vh 360 -vv 90",
    "-vtc -vp 1 1 1 -vd 1 0.5 0.2 -vu 0 0 1 -vh 270 -vv 60 -vs -0.1 -vl 0.2 -vo 0.3",
    "-vts -vd 0 0 1 -vu 0 1 0 -vh 250 -vv 250",
    "-vts -vd 1 2 3 -vu 0 0 1 -vh 180 -vv 120 -vl 0.3",
    "-vtv -vd 0 2 0 -vo 1 -va 5",
    "-vtv -vd 0 1 0 -vo 1 -va 5",
];

fn words(s: &str) -> Vec<&str> {
    s.split_whitespace().collect()
}

fn camera(opts: &str) -> Camera {
    let mut v = View::default();
    let rest = v.extract_args(words(opts)).unwrap();
    assert!(rest.is_empty(), "{opts}: left {rest:?}");
    v.setup().unwrap()
}

/// `vwrays -d` output `-x X -y Y [-ld+]` as numbers.
fn vwrays_dims(args: &[&str]) -> (usize, usize) {
    let out = common::run_ok(common::radiance("vwrays").arg("-d").args(args), b"");
    let text = String::from_utf8(out).unwrap();
    let w = words(&text);
    assert_eq!((w[0], w[2]), ("-x", "-y"), "{text}");
    (w[1].parse().unwrap(), w[3].parse().unwrap())
}

/// `vwrays -fd` rays as (origin, direction) pairs.
fn vwrays_rays(args: &[&str]) -> Vec<[f64; 6]> {
    let out = common::run_ok(common::radiance("vwrays").arg("-fd").args(args), b"");
    assert_eq!(out.len() % 48, 0);
    out.chunks_exact(48)
        .map(|c| {
            let mut r = [0.0; 6];
            for (k, v) in r.iter_mut().enumerate() {
                *v = f64::from_ne_bytes(c[8 * k..8 * k + 8].try_into().unwrap());
            }
            r
        })
        .collect()
}

/// Compare our pixel rays with Radiance's, pixel by pixel; returns the largest difference.
fn compare_rays(cam: &Camera, theirs: &[[f64; 6]], xres: usize, yres: usize, what: &str) -> f64 {
    assert_eq!(theirs.len(), xres * yres, "{what}: ray count");
    let mut worst: f64 = 0.0;
    let mut none = 0;
    for py in 0..yres {
        for px in 0..xres {
            let t = theirs[py * xres + px];
            let ours = cam.pixel_ray(px, py, xres, yres);
            if t[3..] == [0.0; 3] {
                assert!(
                    ours.is_none(),
                    "{what}: pixel ({px},{py}) should be outside the view"
                );
                none += 1;
                continue;
            }
            let r = ours
                .unwrap_or_else(|| panic!("{what}: pixel ({px},{py}) missing, Radiance has {t:?}"));
            // vwrays scales the direction to the aft plane when -va is given.
            let s = r.max_dist.unwrap_or(1.0);
            let mine = [
                r.org[0],
                r.org[1],
                r.org[2],
                r.dir[0] * s,
                r.dir[1] * s,
                r.dir[2] * s,
            ];
            for k in 0..6 {
                worst = worst.max((mine[k] - t[k]).abs());
            }
        }
    }
    // A 180-degree hemispherical fisheye is a disc: its corners have no rays. (An angular
    // fisheye's corners do: Radiance maps them past 90 degrees, up to 180.)
    if what.contains("-vth") && what.contains("-vh 180 -vv 180") {
        assert!(
            none > 0,
            "{what}: a 180 hemispherical fisheye must have empty corners"
        );
    }
    worst
}

#[test]
fn rays_match_vwrays_for_every_view_type() {
    if !common::have_radiance("rays_match_vwrays_for_every_view_type") {
        return;
    }
    let mut overall: f64 = 0.0;
    for opts in VIEWS {
        let mut args = vec!["-x", "16", "-y", "12"];
        args.extend(words(opts));
        let cam = camera(opts);
        let (xr, yr) = vwrays_dims(&args);
        let (x, y, pa) = cam.normalize_resolution(16, 12, 1.0);
        assert_eq!((x, y), (xr, yr), "{opts}: normalised resolution");
        assert_eq!(pa, 1.0);
        let worst = compare_rays(&cam, &vwrays_rays(&args), xr, yr, opts);
        assert!(worst < 1e-9, "{opts}: max difference {worst:e}");
        overall = overall.max(worst);
    }
    eprintln!("max |ours - vwrays -fd| over all views: {overall:e}");
}

#[test]
fn ascii_rays_match_vwrays_fa() {
    if !common::have_radiance("ascii_rays_match_vwrays_fa") {
        return;
    }
    // The brief's form: `vwrays -fa` (%.5e, so 6 significant digits).
    let opts = "-vta -vp 0.5 -1 1.2 -vd 1 -2 0.5 -vu 0 0 1 -vh 180 -vv 180";
    let mut args = vec!["-fa", "-x", "16", "-y", "12"];
    args.extend(words(opts));
    let out = common::run_ok(common::radiance("vwrays").args(&args), b"");
    let text = String::from_utf8(out).unwrap();
    let cam = camera(opts);
    let (xr, yr, _) = cam.normalize_resolution(16, 12, 1.0);
    let rays: Vec<[f64; 6]> = text
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect();
    let worst = compare_rays(&cam, &rays, xr, yr, opts);
    assert!(worst < 1e-5, "max difference {worst:e}");
}

#[test]
fn direction_length_does_not_scale_clipping() {
    if !common::have_radiance("direction_length_does_not_scale_clipping") {
        return;
    }
    // Radiance keeps |-vd| as the focal distance only: fore/aft clipping is in world units.
    let a = vwrays_rays(&words("-x 8 -y 8 -vtv -vd 0 2 0 -vo 1 -va 5"));
    let b = vwrays_rays(&words("-x 8 -y 8 -vtv -vd 0 1 0 -vo 1 -va 5"));
    assert_eq!(a, b);
    let c2 = camera("-vtv -vd 0 2 0 -vo 1 -va 5");
    assert_eq!(c2.focal_distance(), 2.0);
    let r = c2.view_ray(0.5, 0.5).unwrap();
    assert!((r.org[1] - 1.0).abs() < 1e-15 && (r.max_dist.unwrap() - 4.0).abs() < 1e-15);
    assert!(c2.view().to_string().contains("-vd 0 2 0"));
}

#[test]
fn other_resolutions_and_pixel_aspects_match_vwrays_d() {
    if !common::have_radiance("other_resolutions_and_pixel_aspects_match_vwrays_d") {
        return;
    }
    for (opts, x, y, pa) in [
        ("-vtv -vh 60 -vv 40", 512, 512, "1"),
        ("-vtv -vh 30 -vv 80", 100, 300, "1"),
        ("-vta -vh 180 -vv 180", 640, 480, "1"),
        ("-vtc -vh 360 -vv 100", 1000, 1000, "1"),
        ("-vtl -vh 3 -vv 2", 301, 301, "0.5"),
        ("-vth -vh 120 -vv 160", 77, 33, "2"),
        ("-vts -vh 200 -vv 100", 200, 50, "1.3"),
    ] {
        let xs = x.to_string();
        let ys = y.to_string();
        let mut args = vec!["-x", xs.as_str(), "-y", ys.as_str(), "-pa", pa];
        args.extend(words(opts));
        let theirs = vwrays_dims(&args);
        let (ox, oy, _) = camera(opts).normalize_resolution(x, y, pa.parse().unwrap());
        assert_eq!((ox, oy), theirs, "{opts} -x {x} -y {y} -pa {pa}");
    }
}

#[test]
fn setup_errors_give_radiance_reasons() {
    if !common::have_radiance("setup_errors_give_radiance_reasons") {
        return;
    }
    for opts in [
        "-vd 0 0 0",
        "-vu 0 1 0",
        "-vu 0 0 0",
        "-vtv -vh 180",
        "-vth -vv 181",
        "-vta -vh 361",
        "-vts -vv 360",
        "-vtc -vv 180",
        "-vo 3 -va 2",
        "-vh 0",
    ] {
        let out = common::run(common::radiance("vwrays").arg("-d").args(words(opts)), b"");
        assert!(!out.status.success(), "{opts}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let reason = stderr
            .trim()
            .strip_prefix("vwrays: ")
            .unwrap_or(&stderr)
            .to_string();
        let mut v = View::default();
        v.extract_args(words(opts)).unwrap();
        let ours = v.setup().unwrap_err().to_string();
        assert_eq!(ours, format!("bad view: {reason} ({v})"), "{opts}");
    }
    // The two spelled out.
    let mut v = View::default();
    v.apply_str("-vd 0 0 0", "t").unwrap();
    assert_eq!(
        v.setup().unwrap_err().to_string(),
        "bad view: zero view direction (-vtv -vp 0 0 0 -vd 0 0 0 -vu 0 0 1 -vh 45 -vv 45 -vo 0 -va 0 -vs 0 -vl 0)"
    );
    let mut v = View::default();
    v.apply_str("-vd 0 0 -2 -vu 0 0 1", "t").unwrap();
    assert_eq!(
        v.setup().unwrap_err().to_string(),
        "bad view: view up parallel to view direction (-vtv -vp 0 0 0 -vd 0 0 -2 -vu 0 0 1 -vh 45 -vv 45 -vo 0 -va 0 -vs 0 -vl 0)"
    );
}

#[test]
fn command_line_errors_are_one_line() {
    let err = |s: &str| {
        let mut v = View::default();
        v.extract_args(words(s)).unwrap_err().to_string()
    };
    assert_eq!(
        err("-x 4 -vtq"),
        "command line: unknown view type '-vtq'; expected -vtv, -vtl, -vta, -vth, -vts or -vtc"
    );
    assert_eq!(
        err("-vp 1 2"),
        "command line: -vp expects 3 numbers (view point x y z); found only 2"
    );
    assert_eq!(
        err("-vh abc"),
        "command line: -vh expects a number (horizontal view size); found 'abc'"
    );
    assert!(err("-vf /nonexistent/dir/v.vf").starts_with("/nonexistent/dir/v.vf: "));
}

/// A tiny scene: gensky sky seen through a glow source and a grey ground ring.
fn render_picture(dir: &std::path::Path, view: &str) -> std::path::PathBuf {
    let sky = common::run_ok(
        common::radiance("gensky").args(["3", "21", "12", "-a", "40", "-o", "105", "-m", "105"]),
        b"",
    );
    let mut scene = String::from_utf8(sky).unwrap();
    scene.push_str(
        "\nskyfunc glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void plastic grey 0 0 5 .2 .2 .2 0 0\ngrey ring ground 0 0 8 0 0 0 0 0 1 0 10\n",
    );
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    let oct = common::run_ok(common::radiance("oconv").arg(dir.join("scene.rad")), b"");
    std::fs::write(dir.join("scene.oct"), oct).unwrap();
    let pic = common::run_ok(
        common::radiance("rpict")
            .args(words(view))
            .args(["-x", "8", "-y", "8", "-ab", "0"])
            .arg(dir.join("scene.oct")),
        b"",
    );
    let path = dir.join("pic.hdr");
    std::fs::write(&path, pic).unwrap();
    path
}

#[test]
fn rpict_view_header_round_trips() {
    if !common::have_radiance("rpict_view_header_round_trips") {
        return;
    }
    let tmp = common::tmpdir();
    let opts = "-vta -vp 0 0 1.5 -vd 1 1 0.2 -vu 0 0 2 -vh 180 -vv 180";
    let pic = render_picture(tmp.path(), opts);
    let name = pic.to_str().unwrap();
    let mut r = std::io::BufReader::new(std::fs::File::open(&pic).unwrap());
    let header = Header::read(&mut r, name).unwrap();
    let theirs = header.get("VIEW").expect("rpict writes VIEW=");
    let mut v = View::default();
    assert!(v.apply_header(&header, name).unwrap() >= 1);
    let cam = v.setup().unwrap();
    // rpict writes the view after setview: our text of the same view must be identical.
    assert_eq!(cam.view().to_string(), theirs.trim());
    assert!(
        header.lines.contains(&cam.view().header_line()),
        "{:?}",
        header.lines
    );
    assert_eq!(cam.view(), camera(opts).view());
    // Formatting and parsing again gives the same view and the same text.
    let mut w = View::default();
    w.apply_str(&cam.view().to_string(), "again").unwrap();
    assert_eq!(&w, cam.view());
    assert_eq!(w.to_string(), theirs.trim());
    // The picture as a view file, for us and for vwrays (which also takes its resolution).
    let from_pic = View::from_file(name).unwrap();
    assert_eq!(from_pic.setup().unwrap().view(), cam.view());
    let theirs_rays = vwrays_rays(&[name]);
    let worst = compare_rays(&cam, &theirs_rays, 8, 8, opts);
    assert!(worst < 1e-9, "max difference {worst:e}");
}

#[test]
fn view_files_match_vwrays_vf() {
    if !common::have_radiance("view_files_match_vwrays_vf") {
        return;
    }
    let dir = common::repo().join("tests/data/view");
    for (file, extra) in [
        ("office.vf", ""),
        ("office.vf", "-vh 50 -vs 0.1"),
        ("fisheye.vf", ""),
    ] {
        let path = dir.join(file);
        let p = path.to_str().unwrap();
        let mut args = vec!["-x", "16", "-y", "12", "-vf", p];
        args.extend(words(extra));
        let cam = camera(&args[4..].join(" "));
        let (xr, yr) = vwrays_dims(&args);
        assert_eq!(cam.normalize_resolution(16, 12, 1.0).0, xr);
        let worst = compare_rays(&cam, &vwrays_rays(&args), xr, yr, file);
        assert!(worst < 1e-9, "{file}: max difference {worst:e}");
    }
    // A file of bare options: Radiance finds no view there, and neither do we.
    let bare = dir.join("bare_options.vf");
    let out = common::run(
        common::radiance("vwrays").arg("-d").arg("-vf").arg(&bare),
        b"",
    );
    assert!(!out.status.success());
    let e = View::from_file(bare.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.ends_with(": no view in file: expected a line starting with VIEW=, rpict, rvu or rview"),
        "{e}"
    );
}

#[test]
fn view_loc_inverts_view_ray() {
    for opts in VIEWS {
        let cam = camera(opts);
        for i in 1..10 {
            for j in 1..10 {
                let (x, y) = (i as f64 / 10.0, j as f64 / 10.0);
                let Some(r) = cam.view_ray(x, y) else {
                    continue;
                };
                let p = [
                    r.org[0] + 3.0 * r.dir[0],
                    r.org[1] + 3.0 * r.dir[1],
                    r.org[2] + 3.0 * r.dir[2],
                ];
                let l = cam.view_loc(p).unwrap();
                // 360-degree views meet themselves at the rim: the same direction has two
                // image points there.
                let d = cam.dir();
                let back = r.dir[0] * d[0] + r.dir[1] * d[1] + r.dir[2] * d[2] < -0.95;
                if opts.contains("-vh 360") && back {
                    continue;
                }
                assert!(
                    (l.x - x).abs() < 1e-9 && (l.y - y).abs() < 1e-9,
                    "{opts} ({x},{y}) -> ({},{})",
                    l.x,
                    l.y
                );
            }
        }
    }
}
