//! Radiance pictures against real Radiance: rpict/rtrace output read and compared with
//! pvalue, re-encoded byte for byte, orientations from pflip/protate, our pictures read by
//! pvalue/getinfo/evalglare, spectral pictures, EXR/PNG round trips, and robustness.

use crate::common;

use rdaylight::formats::picture::{
    Picture, PixelFormat, color, exr, preview,
    resolution::{self, Resolution},
};
use std::io::Cursor;
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    common::repo().join("tests/data/picture")
}

/// Render the fixture scene (tests/data/picture/sky.rad) in `dir` and return the octree.
fn octree(dir: &Path) -> PathBuf {
    let scene = std::fs::read(data_dir().join("sky.rad")).unwrap();
    let oct = common::run_ok(common::radiance("oconv").arg("-"), &scene);
    let path = dir.join("sky.oct");
    std::fs::write(&path, oct).unwrap();
    path
}

fn rpict(dir: &Path, view: &[&str], name: &str) -> PathBuf {
    let oct = octree(dir);
    let out = common::run_ok(
        common::radiance("rpict")
            .args(view)
            .args(["-x", "64", "-y", "64", "-ab", "1", "-ad", "64"])
            .arg(&oct),
        b"",
    );
    let path = dir.join(name);
    std::fs::write(&path, out).unwrap();
    path
}

const FISHEYE: &[&str] = &[
    "-vta", "-vp", "0", "0", "1", "-vd", "0", "1", "0.3", "-vu", "0", "0", "1", "-vh", "180",
    "-vv", "180",
];
const PERSPECTIVE: &[&str] = &[
    "-vtv", "-vp", "0", "-3", "1.5", "-vd", "0.2", "1", "-0.2", "-vu", "0", "0", "1", "-vh", "60",
    "-vv", "45",
];

fn doubles(bytes: &[u8]) -> Vec<f64> {
    bytes
        .chunks_exact(8)
        .map(|c| f64::from_ne_bytes(c.try_into().unwrap()))
        .collect()
}

/// pvalue's view of a picture: `((x, y), values)` in file order, picture coordinates with
/// the origin at the bottom left, values exact (`-dd`), original units (`-o`).
fn pvalue_pixels(path: &Path) -> Vec<((usize, usize), [f64; 3])> {
    let vals = doubles(&common::run_ok(
        common::radiance("pvalue")
            .args(["-h", "-H", "-o", "-dd"])
            .arg(path),
        b"",
    ));
    let text = common::run_ok(
        common::radiance("pvalue")
            .args(["-h", "-H", "-o"])
            .arg(path),
        b"",
    );
    let coords: Vec<(usize, usize)> = String::from_utf8(text)
        .unwrap()
        .lines()
        .map(|l| {
            let w: Vec<usize> = l
                .split_whitespace()
                .take(2)
                .map(|v| v.parse().unwrap())
                .collect();
            (w[0], w[1])
        })
        .collect();
    assert_eq!(coords.len() * 3, vals.len());
    coords
        .into_iter()
        .zip(vals.chunks_exact(3))
        .map(|(c, v)| (c, [v[0], v[1], v[2]]))
        .collect()
}

/// Every pixel of `p` equals what pvalue says (exactly, or within `rel` relative).
fn assert_matches_pvalue(p: &Picture, path: &Path, rel: f64) {
    let pv = pvalue_pixels(path);
    assert_eq!(pv.len(), p.width * p.height, "{}", path.display());
    let vals = p.radiance_values();
    for ((x, y), want) in pv {
        let at = ((p.height - 1 - y) * p.width + x) * 3;
        for c in 0..3 {
            let got = vals[at + c] as f64;
            assert!(
                (got - want[c]).abs() <= rel * want[c].abs(),
                "{} pixel ({x},{y}) channel {c}: ours {got}, pvalue {}",
                path.display(),
                want[c]
            );
        }
    }
}

/// The bytes after the header (resolution string and scanlines).
fn data_part(bytes: &[u8]) -> &[u8] {
    let at = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    &bytes[at..]
}

#[test]
fn rpict_pictures_match_pvalue_and_reencode_byte_for_byte() {
    if !common::have_radiance("rpict_pictures") {
        return;
    }
    let dir = common::tmpdir();
    for (view, name) in [(FISHEYE, "fish.hdr"), (PERSPECTIVE, "persp.hdr")] {
        let path = rpict(dir.path(), view, name);
        let original = std::fs::read(&path).unwrap();
        let p = Picture::open(&path).unwrap();
        assert_eq!(p.format, PixelFormat::Rgbe);
        assert!(p.view_strings()[0].starts_with(&format!(" {}", view[0])));
        assert_matches_pvalue(&p, &path, 0.0);
        let mut ours = Vec::new();
        p.write(&mut ours, true).unwrap();
        assert!(
            data_part(&ours) == data_part(&original),
            "{name}: re-encoded scanlines differ from rpict's"
        );
    }
}

/// pflip and protate reorder the scanlines and change the resolution string to match, so
/// the picture itself is unchanged (`src/px/pflip.c`, `protate.c`: `neworder`): read back in
/// standard orientation, each must equal the original, and pvalue must agree pixel by pixel.
#[test]
fn pflip_and_protate_orientations_read_as_standard() {
    if !common::have_radiance("orientations") {
        return;
    }
    let dir = common::tmpdir();
    // Not square, so that a transposition mix-up cannot go unnoticed.
    let persp = rpict(dir.path(), PERSPECTIVE, "persp.hdr");
    let orig = Picture::open(&persp).unwrap();
    assert_ne!(orig.width, orig.height);
    let cases: [(&str, &[&str], &str); 6] = [
        ("pflip", &["-h"], "-Y"),
        ("pflip", &["-v"], "+Y"),
        ("pflip", &["-h", "-v"], "+Y"),
        ("protate", &[], "+X"),
        ("protate", &["-r"], "-X"),
        ("pflip", &["-h"], "+X"), // applied to the protate output below
    ];
    let mut seen = std::collections::HashSet::new();
    for (i, (prog, args, start)) in cases.into_iter().enumerate() {
        let input = if i == 5 {
            dir.path().join("protate.hdr")
        } else {
            persp.clone()
        };
        let out = common::run_ok(common::radiance(prog).args(args).arg(&input), b"");
        let path = dir.path().join(format!("{prog}{}.hdr", args.join("")));
        let path = if i == 5 {
            dir.path().join("protate_pflip.hdr")
        } else {
            path
        };
        std::fs::write(&path, &out).unwrap();
        let res_line = String::from_utf8_lossy(&data_part(&out)[..24]).to_string();
        assert!(res_line.starts_with(start), "{prog} {args:?}: {res_line}");
        seen.insert(res_line);
        let p = Picture::open(&path).unwrap();
        assert_eq!((p.width, p.height), (orig.width, orig.height));
        // Independent oracle: pvalue's coordinates for every pixel.
        assert_matches_pvalue(&p, &path, 0.0);
        assert!(p.data == orig.data, "{prog} {args:?}: picture changed");
    }
    assert_eq!(seen.len(), 6, "six different orientations: {seen:?}");
}

/// A picture we write in every encoding is read by pvalue and getinfo as we meant it.
#[test]
fn radiance_reads_our_pictures() {
    if !common::have_radiance("radiance_reads_ours") {
        return;
    }
    let dir = common::tmpdir();
    // ra_xyze's XYZE fixture carries EXPOSURE=5.5866e-03 (1/179): pvalue -o divides it out
    // in float arithmetic, we in double, hence the 1e-6 relative tolerance.
    let xyze = data_dir().join("fish_xyze.hdr");
    let x = Picture::open(&xyze).unwrap();
    assert_eq!(x.format, PixelFormat::Xyze);
    assert_matches_pvalue(&x, &xyze, 1e-6);
    let mut p = Picture::open(data_dir().join("persp.hdr")).unwrap();
    for format in [PixelFormat::Rgbe, PixelFormat::Xyze] {
        p.format = format;
        for rle in [true, false] {
            for order in [resolution::STANDARD, resolution::YMAJOR, resolution::XDECR] {
                let path = dir
                    .path()
                    .join(format!("ours_{format:?}_{rle}_{order}.hdr"));
                let mut bytes = Vec::new();
                p.write_oriented(&mut bytes, rle, order).unwrap();
                std::fs::write(&path, &bytes).unwrap();
                assert_matches_pvalue(&p, &path, 0.0);
                let info = common::run_ok(common::radiance("getinfo").arg("-d").arg(&path), b"");
                let info = String::from_utf8(info).unwrap();
                let res = Resolution {
                    order,
                    xres: p.width,
                    yres: p.height,
                };
                assert_eq!(info, format!("{}: {}", path.display(), res.to_line()));
            }
        }
    }
}

#[test]
fn evalglare_gives_the_same_ev_on_our_copy() {
    if !common::have_radiance("evalglare") {
        return;
    }
    let dir = common::tmpdir();
    let fish = rpict(dir.path(), FISHEYE, "fish.hdr");
    let p = Picture::open(&fish).unwrap();
    let ours = dir.path().join("ours.hdr");
    p.save(&ours, true).unwrap();
    // evalglare warns about the small picture (search radius under 3 pixels) and exits 1
    // though it prints Ev: compare output and status.
    let ev = |path: &Path| {
        let out = common::run(common::radiance("evalglare").arg("-V").arg(path), b"");
        let text = String::from_utf8(out.stdout).unwrap();
        (text.trim().to_string(), out.status.code())
    };
    let (a, b) = (ev(&fish), ev(&ours));
    let value: f64 = a.0.parse().unwrap();
    assert!(value > 100.0, "evalglare -V: {a:?}");
    assert_eq!(a, b);
}

/// `rtrace -ffc -cs 6 -co` picture against the same rays in ascii.
#[test]
fn spectral_picture_matches_rtrace_ascii() {
    if !common::have_radiance("spectral") {
        return;
    }
    let dir = common::tmpdir();
    let oct = octree(dir.path());
    let view = [
        "-x", "8", "-y", "8", "-vta", "-vh", "180", "-vv", "180", "-vp", "0", "0", "1", "-vd", "0",
        "0", "1", "-vu", "0", "1", "0",
    ];
    let rays = common::run_ok(common::radiance("vwrays").arg("-ff").args(view), b"");
    let rt = |fmt: &str, extra: &[&str]| {
        common::run_ok(
            common::radiance("rtrace")
                .args([fmt, "-cs", "6", "-co", "-ab", "0"])
                .args(extra)
                .arg(&oct),
            &rays,
        )
    };
    let hsr = rt("-ffc", &["-x", "8", "-y", "8"]);
    let ascii = rt("-ffa", &["-h"]);
    let p = Picture::read(Cursor::new(&hsr), "spec.hsr").unwrap();
    assert_eq!(
        (p.format, p.ncomp(), p.width, p.height),
        (PixelFormat::Spectra, 6, 8, 8)
    );
    assert_eq!(p.channels.splits, [780.0, 588.0, 480.0, 380.0]);
    let want: Vec<f64> = String::from_utf8(ascii)
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(want.len(), p.data.len());
    let mut nonzero = 0;
    for (px, wpx) in p.data.chunks_exact(6).zip(want.chunks_exact(6)) {
        // One common exponent per pixel: the error is at most one mantissa step of the
        // largest sample, max/128 (truncation, then +0.5 on decoding: half that in fact).
        let max = wpx.iter().cloned().fold(0.0, f64::max);
        for (&g, &w) in px.iter().zip(wpx) {
            assert!(
                (g as f64 - w).abs() <= max / 256.0 + 1e-6 * max + 1e-30,
                "{g} vs {w}"
            );
        }
        nonzero += (max > 0.0) as usize;
    }
    assert!(nonzero > 32, "the picture should see the sky");
    // Our spectral write reads back bit-exact, and reproduces rtrace's bytes.
    let mut ours = Vec::new();
    p.write(&mut ours, true).unwrap();
    assert_eq!(data_part(&ours), data_part(&hsr));
    let q = Picture::read(Cursor::new(&ours), "ours.hsr").unwrap();
    assert_eq!(q.data, p.data);
    // Radiance reads ours: pvalue shows the RGB band averages of scolor2color.
    let path = dir.path().join("ours.hsr");
    std::fs::write(&path, &ours).unwrap();
    let pv = doubles(&common::run_ok(
        common::radiance("pvalue")
            .args(["-h", "-H", "-o", "-dd"])
            .arg(&path),
        b"",
    ));
    for (i, px) in p.data.chunks_exact(6).enumerate() {
        let rgb = rdaylight::formats::picture::spectral::to_rgb(px, p.channels.splits);
        for c in 0..3 {
            let w = pv[i * 3 + c];
            assert!(
                (rgb[c] as f64 - w).abs() <= 1e-6 * w.abs(),
                "{rgb:?} vs {w}"
            );
        }
    }
}

#[test]
fn exr_round_trips_float_exact() {
    for name in ["persp.hdr", "fish_xyze.hdr", "spec.hsr"] {
        let p = Picture::open(data_dir().join(name)).unwrap();
        let mut buf = Cursor::new(Vec::new());
        exr::write_exr_to(&p, &mut buf).unwrap();
        let q = exr::read_exr_from(Cursor::new(buf.into_inner()), "t.exr").unwrap();
        assert_eq!(
            (q.width, q.height, q.format),
            (p.width, p.height, p.format),
            "{name}"
        );
        assert_eq!(q.channels.ncomp, p.channels.ncomp);
        assert_eq!(q.channels.splits, p.channels.splits, "{name}");
        assert_eq!(q.data, p.radiance_values(), "{name}");
    }
    let e = exr::read_exr_from(Cursor::new(b"not exr".to_vec()), "bad.exr").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("bad.exr: not a readable OpenEXR file"),
        "{e}"
    );
    // Every truncated prefix of an EXR we wrote is an error, never a panic.
    let p = Picture::open(data_dir().join("small.hdr")).unwrap();
    let mut buf = Cursor::new(Vec::new());
    exr::write_exr_to(&p, &mut buf).unwrap();
    let bytes = buf.into_inner();
    for n in (0..bytes.len()).step_by(7) {
        assert!(exr::read_exr_from(Cursor::new(bytes[..n].to_vec()), "t.exr").is_err());
    }
}

#[test]
fn png_preview_dimensions_and_monotonic_tone_mapping() {
    let p = Picture::open(data_dir().join("persp.hdr")).unwrap();
    let dir = common::tmpdir();
    let png = dir.path().join("p.png");
    preview::write_preview(&p, &png, preview::Exposure::Auto).unwrap();
    let back = preview::read_photo(&png).unwrap();
    assert_eq!((back.width, back.height), (p.width, p.height));
    let jpg = dir.path().join("p.jpg");
    preview::write_preview(&p, &jpg, preview::Exposure::Stops(0.0)).unwrap();
    let back = preview::read_photo(&jpg).unwrap();
    assert_eq!((back.width, back.height), (p.width, p.height));
    let e = preview::read_photo_bytes(b"\x89PNG garbage", "x.png").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("x.png: not a PNG or JPEG picture"),
        "{e}"
    );
    // A grey ramp must give a non-decreasing, not constant, preview.
    let mut ramp = Picture::new(64, 1, Default::default(), PixelFormat::Rgbe);
    for (i, v) in ramp.data.iter_mut().enumerate() {
        *v = (i / 3) as f32 * 0.05;
    }
    for exposure in [preview::Exposure::Auto, preview::Exposure::Stops(-2.0)] {
        let img = preview::tone_map(&ramp, exposure).unwrap();
        let g: Vec<u8> = img.pixels().map(|p| p.0[1]).collect();
        assert!(g.windows(2).all(|w| w[0] <= w[1]), "{g:?}");
        assert!(g[63] > g[1]);
    }
    // Reading an 8-bit PNG undoes sRGB: mid grey 128 is 0.2158605 linear.
    let mut img = image::RgbImage::new(2, 1);
    img.put_pixel(0, 0, image::Rgb([128, 128, 128]));
    img.put_pixel(1, 0, image::Rgb([255, 0, 10]));
    let mut bytes = Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    let lin = preview::read_photo_bytes(bytes.get_ref(), "g.png").unwrap();
    assert!((lin.data[0] - 0.2158605).abs() < 1e-6, "{}", lin.data[0]);
    assert_eq!(lin.data[3], 1.0);
    assert_eq!(lin.data[4], 0.0);
}

/// Radiance's `checkheader` accepts a picture without FORMAT (pvalue reads it as RGBE); so
/// do we. A wrong FORMAT is an error naming the line.
#[test]
fn missing_format_reads_as_rgbe_wrong_format_is_an_error() {
    let bytes = std::fs::read(data_dir().join("small.hdr")).unwrap();
    let orig = Picture::read(Cursor::new(&bytes), "small.hdr").unwrap();
    let text_end = bytes.windows(2).position(|w| w == b"\n\n").unwrap();
    let header = String::from_utf8(bytes[..text_end].to_vec()).unwrap();
    let fmt_line = header
        .lines()
        .position(|l| l.starts_with("FORMAT="))
        .unwrap()
        + 1;
    let without: Vec<u8> = header
        .lines()
        .filter(|l| !l.starts_with("FORMAT="))
        .flat_map(|l| format!("{l}\n").into_bytes())
        .chain(bytes[text_end + 1..].iter().copied())
        .collect();
    let p = Picture::read(Cursor::new(&without), "nofmt.hdr").unwrap();
    assert_eq!((p.format, &p.data), (PixelFormat::Rgbe, &orig.data));
    let wrong = String::from_utf8_lossy(&bytes).replace("FORMAT=32-bit_rle_rgbe", "FORMAT=float");
    let e = Picture::read(Cursor::new(wrong.as_bytes()), "bad.hdr").unwrap_err();
    assert!(
        e.to_string().starts_with(&format!(
            "bad.hdr:{fmt_line}: FORMAT=float: expected a picture"
        )),
        "{e}"
    );
}

#[test]
fn old_rle_picture_reads() {
    // Hand-made old-style run-length picture: 20 pixels in one scanline, A, 3 repeats of
    // A, B, then (1,1,1,15): B 15 more times.
    let a = [200u8, 100, 50, 129];
    let b = [128u8, 128, 128, 130];
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 20\n".to_vec();
    bytes.extend(a);
    bytes.extend([1, 1, 1, 3]);
    bytes.extend(b);
    bytes.extend([1, 1, 1, 15]);
    let p = Picture::read(Cursor::new(&bytes), "old.hdr").unwrap();
    let da = color::decode_rgbe(a);
    let db = color::decode_rgbe(b);
    for x in 0..20 {
        assert_eq!(p.pixel(x, 0), if x < 4 { &da[..] } else { &db[..] }, "{x}");
    }
}

fn fixtures() -> Vec<(String, Vec<u8>)> {
    [
        "fish.hdr",
        "persp.hdr",
        "fish_xyze.hdr",
        "rot.hdr",
        "spec.hsr",
        "small.hdr",
    ]
    .iter()
    .map(|n| (n.to_string(), std::fs::read(data_dir().join(n)).unwrap()))
    .collect()
}

#[test]
fn fixtures_read() {
    for (name, bytes) in fixtures() {
        let p = Picture::read(Cursor::new(&bytes), &name).unwrap();
        assert_eq!(p.data.len(), p.width * p.height * p.ncomp(), "{name}");
    }
    // rot.hdr is `protate fish.hdr`: other scanline order, same picture.
    let fish = Picture::open(data_dir().join("fish.hdr")).unwrap();
    let rot = Picture::open(data_dir().join("rot.hdr")).unwrap();
    assert!(rot.data == fish.data);
    // ra_xyze output: luminance is Y with the exposure divided out, and agrees with the
    // RGB picture's 179 (0.265 R + 0.670 G + 0.065 B) to the precision of the two encodings.
    let xyze = Picture::open(data_dir().join("fish_xyze.hdr")).unwrap();
    for (x, y) in [(0, 0), (32, 32), (10, 50), (63, 40)] {
        let (a, b) = (fish.luminance(x, y), xyze.luminance(x, y));
        assert!((a - b).abs() <= 0.01 * a, "({x},{y}): {a} vs {b}");
    }
}

#[test]
fn every_truncated_prefix_is_an_error_never_a_panic() {
    for (name, bytes) in fixtures() {
        for n in 0..bytes.len() {
            let r = Picture::read(Cursor::new(&bytes[..n]), &name);
            let e = r.expect_err(&format!("{name}: prefix of {n} bytes read as a picture"));
            let text = e.to_string();
            assert!(text.starts_with(&name) && !text.contains('\n'), "{text}");
        }
    }
    // The exact message for a picture cut inside its pixels.
    let bytes = std::fs::read(data_dir().join("fish.hdr")).unwrap();
    let e = Picture::read(Cursor::new(&bytes[..bytes.len() / 2]), "view.hdr").unwrap_err();
    let text = e.to_string();
    assert!(
        text.starts_with("view.hdr: scanline ") && text.ends_with(" of 64 ends early"),
        "{text}"
    );
}

#[test]
fn random_corruption_never_panics() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut errors = 0;
    for (name, bytes) in fixtures() {
        let start = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
        for _ in 0..300 {
            let mut b = bytes.clone();
            for _ in 0..rng.random_range(1..8) {
                let i = rng.random_range(start..b.len());
                b[i] = rng.random();
            }
            errors += Picture::read(Cursor::new(&b), &name).is_err() as usize;
        }
    }
    // Corrupting run-length counts must be caught at least some of the time.
    assert!(errors > 100, "{errors}");
}
