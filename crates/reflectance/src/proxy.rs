//! The illuminance-proxy method (Mardaljevic, Brembilla and Drosou 2015; Mardaljevic et al.
//! 2021; extended to three channels in the seed dissertation, section 5.3.1.2): reflectance
//! maps from a calibrated HDR picture and a few points of known reflectance.
//!
//! For a diffuse (Lambertian) surface of reflectance `rho` under illuminance `E`, the
//! luminance is `L = rho E / pi`. So:
//!
//! 1. At each known point `i` (pixel `x_i`, reflectance `rho_i`): `E_i = pi L(x_i) / rho_i`,
//!    with `L` the mean over a small window of pixels of the same material (`window`; a
//!    calibrated picture is still noisy per pixel).
//! 2. Illuminance map `E*(x)` by ordinary kriging of the `E_i` ([`super::kriging`]; fitted
//!    spherical or exponential variogram), in pixel coordinates, separately for each
//!    illumination zone (a second mask of planar surfaces: illuminance is smooth on a plane
//!    but jumps at its edges); pixels of a zone without enough points use all points.
//! 3. Reflectance map `rho(x) = pi L(x) / E*(x)`.
//! 4. Per material (mask region): the mean of `rho(x)`, optionally after dropping the values
//!    below the 5th and above the 95th percentile of the region (the seed's outlier removal).
//!
//! Units: one channel = luminance (cd/m²) and illuminance (lx); three channels = Radiance
//! RGB radiance (W/sr/m² per channel) and irradiance per channel: the 179 lm/W factor
//! cancels in `rho = pi L / E`. Three channels are used when the picture is RGB and every
//! point gives three reflectances; otherwise luminance and photopic reflectance (a point
//! given in RGB counts with its photopic value).
//!
//! Assumptions (seed section 5.5): planar, diffuse surfaces and smoothly varying
//! illuminance; specular surfaces and sharp shadows break them.
//!
//! Points file (CSV or white space; `#` comments; an optional header line):
//! `x, y, rho` or `x, y, r, g, b`, pixel `x` from the left and `y` from the top (0-based).

use nom::{
    Parser,
    branch::alt,
    bytes::complete::take_while1,
    character::complete::{char, space0},
    combinator::{all_consuming, value},
    multi::separated_list1,
    number::complete::double,
    sequence::delimited,
};

use crate::error::{Error, Location, Result};
use crate::formats::picture::{Picture, PixelFormat};
use crate::radiometry::{Channels, RGB_PHOTOPIC};

use rayon::prelude::*;

use super::kriging::{Family, Kriging};
use super::mask::LabelMap;
use rdaylight_base::stats::percentile;

/// A point of known reflectance.
#[derive(Debug, Clone, PartialEq)]
pub struct KnownPoint {
    pub x: usize,
    pub y: usize,
    /// 1 (grey / photopic) or 3 (Radiance RGB) values.
    pub rho: Vec<f64>,
    /// Line in the points file (for messages).
    pub line: usize,
}

/// Parse a points file; `file` names it in errors.
pub fn parse_points(text: &str, file: &str) -> Result<Vec<KnownPoint>> {
    let mut out = Vec::new();
    let mut first = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let loc = || Location::line(file, i + 1);
        let sep = alt((
            value((), delimited(space0, char(','), space0)),
            value((), take_while1(|c: char| c == ' ' || c == '\t')),
        ));
        let r: nom::IResult<&str, Vec<f64>> =
            all_consuming(separated_list1(sep, double)).parse(line);
        let v = match r {
            Ok((_, v)) => v,
            Err(_) if first => {
                // A header line such as `x,y,rho`.
                first = false;
                continue;
            }
            Err(_) => {
                return Err(Error::parse(
                    loc(),
                    format!("expected 'x, y, rho' or 'x, y, r, g, b' (numbers), found '{line}'"),
                ));
            }
        };
        first = false;
        if v.len() != 3 && v.len() != 5 {
            return Err(Error::parse(
                loc(),
                format!(
                    "expected 3 values (x, y, rho) or 5 (x, y, r, g, b), found {}",
                    v.len()
                ),
            ));
        }
        let coord = |c: f64, what: &str| -> Result<usize> {
            if c >= 0.0 && c.fract() == 0.0 && c < 1e9 {
                Ok(c as usize)
            } else {
                Err(Error::parse(
                    loc(),
                    format!("{what} must be a pixel index (0, 1, 2, ...), found {c}"),
                ))
            }
        };
        let rho = v[2..].to_vec();
        if rho.iter().any(|r| !(*r > 0.0 && *r <= 1.0)) {
            return Err(Error::parse(
                loc(),
                format!("reflectance must be in (0, 1], found {rho:?}"),
            ));
        }
        out.push(KnownPoint {
            x: coord(v[0], "x")?,
            y: coord(v[1], "y")?,
            rho,
            line: i + 1,
        });
    }
    Ok(out)
}

/// Options of the method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub family: Family,
    /// Half width of the averaging window at the known points (0 = the pixel itself).
    pub window: usize,
    /// Drop values below the 5th and above the 95th percentile before each region's mean.
    pub trim: bool,
    /// Use luminance even for RGB pictures with RGB points.
    pub mono: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            family: Family::Spherical,
            window: 1,
            trim: false,
            mono: false,
        }
    }
}

/// The mean reflectance of one mask region.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionMean {
    pub name: String,
    /// Radiance RGB reflectance (one-channel results repeat the value).
    pub rgb: [f64; 3],
    /// Pixels in the mean (after trimming: of the first channel).
    pub pixels: usize,
    /// Known points inside the region.
    pub points: usize,
}

/// Everything the method produces.
#[derive(Debug, Clone)]
pub struct ProxyResult {
    /// Channels used: 1 (luminance) or 3 (RGB).
    pub nchan: usize,
    /// Illuminance (or per-channel irradiance) at each known point, input order.
    pub point_illuminance: Vec<Vec<f64>>,
    /// Pixel-wise reflectance, an RGB picture (one-channel results as grey).
    pub reflectance: Picture,
    /// Kriged illuminance map (lx, or W/m² per channel), same layout.
    pub illuminance: Picture,
    /// Per-material means (empty without a mask).
    pub regions: Vec<RegionMean>,
    /// Per zone: (name, points, fitted variogram of the first channel, if any).
    pub zones: Vec<(String, usize, Option<super::kriging::Variogram>)>,
}

/// Values per pixel: luminance (1) or RGB radiance (3), exposure divided out.
fn pixel_values(p: &Picture, three: bool) -> Vec<f64> {
    let rad: Vec<f64> = p.radiance_values().iter().map(|&v| v as f64).collect();
    if three {
        return rad;
    }
    match p.format {
        // Radiance's luminance(): 179 lm/W times the photopic weights of its primaries.
        PixelFormat::Rgbe => rad
            .chunks_exact(3)
            .map(|c| crate::radiometry::luminance([c[0], c[1], c[2]]))
            .collect(),
        // Y is stored in cd/m2.
        PixelFormat::Xyze => rad.chunks_exact(3).map(|c| c[1]).collect(),
        PixelFormat::Spectra => {
            let mut v = Vec::with_capacity(p.width * p.height);
            for y in 0..p.height {
                for x in 0..p.width {
                    v.push(p.luminance(x, y));
                }
            }
            v
        }
    }
}

/// Run the illuminance-proxy method.
pub fn run(
    picture: &Picture,
    points: &[KnownPoint],
    mask: Option<&LabelMap>,
    zones: Option<&LabelMap>,
    points_file: &str,
    opts: &Options,
) -> Result<ProxyResult> {
    let (w, h) = (picture.width, picture.height);
    if let Some(m) = mask {
        m.check_size(w, h, "the picture")?;
    }
    if let Some(z) = zones {
        z.check_size(w, h, "the picture")?;
    }
    if points.is_empty() {
        return Err(Error::Usage(format!("{points_file}: no known points")));
    }
    for p in points {
        if p.x >= w || p.y >= h {
            return Err(Error::parse(
                Location::line(points_file, p.line),
                format!(
                    "point ({}, {}) is outside the {w} x {h} picture (x from the left, y from \
                     the top, 0-based)",
                    p.x, p.y
                ),
            ));
        }
    }
    let three = !opts.mono
        && picture.format == PixelFormat::Rgbe
        && points.iter().all(|p| p.rho.len() == 3);
    let nc = if three { 3 } else { 1 };
    let vals = pixel_values(picture, three);
    let label = |m: Option<&LabelMap>, x: usize, y: usize| m.and_then(|m| m.get(x, y));

    // 1. Illuminance at the known points.
    let mut e_pts: Vec<Vec<f64>> = Vec::with_capacity(points.len());
    for p in points {
        let own = label(mask, p.x, p.y);
        let r = opts.window;
        let mut sum = vec![0.0; nc];
        let mut n = 0usize;
        for y in p.y.saturating_sub(r)..=(p.y + r).min(h - 1) {
            for x in p.x.saturating_sub(r)..=(p.x + r).min(w - 1) {
                if mask.is_some() && label(mask, x, y) != own {
                    continue;
                }
                for c in 0..nc {
                    sum[c] += vals[(y * w + x) * nc + c];
                }
                n += 1;
            }
        }
        let rho: Vec<f64> = if three {
            p.rho.clone()
        } else if p.rho.len() == 3 {
            vec![(0..3).map(|c| RGB_PHOTOPIC[c] * p.rho[c]).sum()]
        } else {
            p.rho.clone()
        };
        let e: Vec<f64> = (0..nc)
            .map(|c| std::f64::consts::PI * sum[c] / n.max(1) as f64 / rho[c])
            .collect();
        if e.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(Error::parse(
                Location::line(points_file, p.line),
                format!(
                    "point ({}, {}) is black in the picture: no illuminance can be estimated \
                     there",
                    p.x, p.y
                ),
            ));
        }
        e_pts.push(e);
    }

    // 2. Kriging per zone and channel.
    let nzones = zones.map_or(1, |z| z.legend.entries.len());
    let zone_of = |x: usize, y: usize| -> Option<usize> {
        match zones {
            Some(z) => z.get(x, y),
            None => Some(0),
        }
    };
    let coords: Vec<[f64; 2]> = points.iter().map(|p| [p.x as f64, p.y as f64]).collect();
    let krige = |idx: &[usize]| -> Result<Vec<Kriging>> {
        let pts: Vec<[f64; 2]> = idx.iter().map(|&i| coords[i]).collect();
        (0..nc)
            .map(|c| {
                let z: Vec<f64> = idx.iter().map(|&i| e_pts[i][c]).collect();
                Kriging::new(&pts, &z, opts.family)
            })
            .collect()
    };
    let all: Vec<usize> = (0..points.len()).collect();
    let global = krige(&all)?;
    let mut models: Vec<Option<Vec<Kriging>>> = Vec::with_capacity(nzones);
    let mut zone_info = Vec::new();
    for z in 0..nzones {
        let idx: Vec<usize> = all
            .iter()
            .copied()
            .filter(|&i| zone_of(points[i].x, points[i].y) == Some(z))
            .collect();
        let name = zones.map_or("all".to_string(), |m| m.legend.entries[z].name.clone());
        if idx.len() >= super::kriging::MIN_POINTS {
            let k = krige(&idx)?;
            zone_info.push((name, idx.len(), k[0].variogram()));
            models.push(Some(k));
        } else {
            zone_info.push((name, idx.len(), global[0].variogram()));
            models.push(None);
        }
    }

    // 3. Illuminance and reflectance maps (rows in parallel; each pixel is independent).
    let mut refl = Picture::new(w, h, Channels::rgb(), PixelFormat::Rgbe);
    let mut illum = Picture::new(w, h, Channels::rgb(), PixelFormat::Rgbe);
    let rows: Vec<(Vec<f64>, Vec<f64>)> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut rho_row = vec![0.0; w * nc];
            let mut e_row = vec![0.0; w * nc];
            for x in 0..w {
                let k = match zone_of(x, y).and_then(|z| models[z].as_ref()) {
                    Some(k) => k,
                    None => &global,
                };
                for c in 0..nc {
                    let e = k[c].predict([x as f64, y as f64]);
                    let l = vals[(y * w + x) * nc + c];
                    rho_row[x * nc + c] = if e > 0.0 {
                        std::f64::consts::PI * l / e
                    } else {
                        0.0
                    };
                    e_row[x * nc + c] = e.max(0.0);
                }
            }
            (rho_row, e_row)
        })
        .collect();
    let mut rho_vals = Vec::with_capacity(w * h * nc);
    for (y, (rho_row, e_row)) in rows.iter().enumerate() {
        for x in 0..w {
            let at = y * w + x;
            for o in 0..3 {
                // One channel is written as grey.
                let c = if nc == 3 { o } else { 0 };
                refl.data[at * 3 + o] = rho_row[x * nc + c] as f32;
                illum.data[at * 3 + o] = e_row[x * nc + c] as f32;
            }
        }
        rho_vals.extend_from_slice(rho_row);
    }
    let src = points_file.to_string();
    refl.header.push(format!(
        "illuminance-proxy reflectance map ({} channel{}), known points {src}",
        nc,
        if nc == 3 { "s" } else { "" }
    ));
    illum.header.push(format!(
        "illuminance-proxy kriged illuminance ({})",
        if nc == 3 {
            "W/m2 per RGB channel"
        } else {
            "lx, grey"
        }
    ));

    // 4. Per-material means.
    let mut regions = Vec::new();
    if let Some(m) = mask {
        for (li, pix) in m.regions().iter().enumerate() {
            if pix.is_empty() {
                continue;
            }
            let mut mean = [0.0; 3];
            let mut count = 0;
            for c in 0..nc {
                let mut v: Vec<f64> = pix.iter().map(|&i| rho_vals[i * nc + c]).collect();
                if opts.trim {
                    let (lo, hi) = (percentile(&v, 5.0), percentile(&v, 95.0));
                    v.retain(|x| *x >= lo && *x <= hi);
                }
                let mu = v.iter().sum::<f64>() / v.len().max(1) as f64;
                if c == 0 {
                    count = v.len();
                }
                if nc == 3 {
                    mean[c] = mu;
                } else {
                    mean = [mu; 3];
                }
            }
            let npts = points
                .iter()
                .filter(|p| m.get(p.x, p.y) == Some(li))
                .count();
            regions.push(RegionMean {
                name: m.legend.entries[li].name.clone(),
                rgb: mean,
                pixels: count,
                points: npts,
            });
        }
    }
    Ok(ProxyResult {
        nchan: nc,
        point_illuminance: e_pts,
        reflectance: refl,
        illuminance: illum,
        regions,
        zones: zone_info,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mask::Legend;

    /// A 64 x 48 wall of reflectance A with a patch of B (x 24..40, y 16..32) under a
    /// smooth RGB illuminance field; radiance = rho E / pi.
    fn scene(a: [f64; 3], b: [f64; 3]) -> (Picture, LabelMap) {
        let (w, h) = (64, 48);
        let mut p = Picture::new(w, h, Channels::rgb(), PixelFormat::Rgbe);
        let mut img = image::RgbImage::new(w as u32, h as u32);
        for y in 0..h {
            for x in 0..w {
                let e = 500.0 + 6.0 * x as f64 + 3.0 * y as f64;
                let tint = [1.0, 0.9, 0.7];
                let inside = (24..40).contains(&x) && (16..32).contains(&y);
                let rho = if inside { b } else { a };
                for c in 0..3 {
                    p.data[3 * (y * w + x) + c] =
                        (rho[c] * e * tint[c] / std::f64::consts::PI / 179.0) as f32;
                }
                img.put_pixel(
                    x as u32,
                    y as u32,
                    image::Rgb(if inside { [0, 0, 255] } else { [255, 0, 0] }),
                );
            }
        }
        let legend = Legend::parse("ff0000, a\n0000ff, b\n", "l.csv").unwrap();
        (
            p,
            LabelMap::from_image(&img, Some(legend), "m.png").unwrap(),
        )
    }

    #[test]
    fn points_parse() {
        let p = parse_points("x,y,rho\n3, 4, 0.5\n# c\n5 6 0.2 0.3 0.4\n", "p.csv").unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].x, p[0].y, p[0].rho.clone()), (3, 4, vec![0.5]));
        assert_eq!(p[1].rho, vec![0.2, 0.3, 0.4]);
        assert_eq!(p[1].line, 4);
        let e = |t: &str| parse_points(t, "p.csv").unwrap_err().to_string();
        assert!(e("1,2,0.5\n1,2\n").starts_with("p.csv:2: expected 3 values"));
        assert!(e("1,2,0.5\n1,x,0.3\n").starts_with("p.csv:2: expected 'x, y, rho'"));
        assert!(e("1.5,2,0.5\n").starts_with("p.csv:1: x must be a pixel index"));
        assert!(e("1,2,1.5\n").starts_with("p.csv:1: reflectance must be in (0, 1]"));
        let text = "x,y,r,g,b\n1,2,0.1,0.2,0.3\n4 5 0.5\n";
        for cut in 0..text.len() {
            let _ = parse_points(&text[..cut], "cut");
        }
    }

    fn points_on_a(rho: &[f64]) -> Vec<KnownPoint> {
        let mut v = Vec::new();
        let around = [
            (3, 3),
            (30, 5),
            (60, 4),
            (5, 22),
            (18, 25),
            (46, 21),
            (58, 26),
            (4, 43),
            (31, 40),
            (59, 44),
        ];
        for (i, (x, y)) in around.into_iter().enumerate() {
            v.push(KnownPoint {
                x,
                y,
                rho: rho.to_vec(),
                line: i + 1,
            });
        }
        v
    }

    #[test]
    fn recovers_the_unknown_half() {
        let (a, b) = ([0.6, 0.5, 0.4], [0.2, 0.35, 0.6]);
        let (p, m) = scene(a, b);
        // Three channels: the known points on A give B to the kriging accuracy (the
        // illuminance field is linear, so extrapolation to B is close).
        let r = run(
            &p,
            &points_on_a(&a),
            Some(&m),
            None,
            "p.csv",
            &Options::default(),
        )
        .unwrap();
        assert_eq!(r.nchan, 3);
        let rb = &r.regions[1];
        assert_eq!((rb.name.as_str(), rb.points), ("b", 0));
        for c in 0..3 {
            assert!(
                (r.regions[0].rgb[c] - a[c]).abs() < 0.01,
                "{:?}",
                r.regions[0]
            );
            assert!((rb.rgb[c] - b[c]).abs() < 0.03 * b[c] + 0.005, "{rb:?}");
        }
        // E at a point = pi L / rho: the field's value there (179 lm/W cancels per channel).
        let e0 = &r.point_illuminance[0];
        let want = (500.0 + 6.0 * 3.0 + 3.0 * 3.0) / 179.0;
        assert!((e0[0] / want - 1.0).abs() < 0.02, "{e0:?} vs {want}");
        // One channel: photopic reflectance of each half.
        let grey = |v: [f64; 3]| (0..3).map(|c| RGB_PHOTOPIC[c] * v[c]).sum::<f64>();
        let mono = Options {
            mono: true,
            trim: true,
            ..Options::default()
        };
        let r = run(&p, &points_on_a(&a), Some(&m), None, "p.csv", &mono).unwrap();
        assert_eq!(r.nchan, 1);
        // The tint changes the luminance-weighted "reflectance" a little: the photopic
        // value under tinted light is not the photopic value under white light.
        let tinted = |v: [f64; 3]| {
            let t = [1.0, 0.9, 0.7];
            (0..3).map(|c| RGB_PHOTOPIC[c] * v[c] * t[c]).sum::<f64>()
                / (0..3).map(|c| RGB_PHOTOPIC[c] * t[c]).sum::<f64>()
        };
        let want_b = tinted(b) / tinted(a) * grey(a);
        assert!(
            (r.regions[1].rgb[0] - want_b).abs() < 0.02,
            "{:?} vs {want_b}",
            r.regions[1]
        );
        // Out-of-picture points and black points are errors with the file's line.
        let mut bad = points_on_a(&a);
        bad[2].x = 64;
        let e = run(&p, &bad, Some(&m), None, "p.csv", &Options::default())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("p.csv:3: point (64, 4) is outside"), "{e}");
    }

    #[test]
    fn zones_keep_illuminance_jumps_apart() {
        // Double the light on the right half: without zones the kriged field blurs the jump,
        // with a zone per half each half is exact.
        let (a, b) = ([0.5; 3], [0.5; 3]);
        let (mut p, m) = scene(a, b);
        let mut img = image::RgbImage::new(64, 48);
        for y in 0..48 {
            for x in 0..64 {
                if x >= 32 {
                    for c in 0..3 {
                        p.data[3 * (y * 64 + x) + c] *= 2.0;
                    }
                }
                img.put_pixel(
                    x as u32,
                    y as u32,
                    image::Rgb([0, if x < 32 { 50 } else { 100 }, 0]),
                );
            }
        }
        let zones = LabelMap::from_image(&img, None, "z.png").unwrap();
        let pts: Vec<KnownPoint> = points_on_a(&[0.5])
            .into_iter()
            .filter(|q| !(30..34).contains(&q.x))
            .collect();
        let trimmed = Options {
            trim: true,
            ..Options::default()
        };
        let with = run(&p, &pts, Some(&m), Some(&zones), "p.csv", &trimmed).unwrap();
        for r in &with.regions {
            assert!((r.rgb[0] - 0.5).abs() < 0.01, "{r:?}");
        }
        assert_eq!(with.zones.len(), 2);
        assert_eq!((with.zones[0].1, with.zones[1].1), (4, 4));
        let without = run(&p, &pts, Some(&m), None, "p.csv", &trimmed).unwrap();
        let worst = without
            .regions
            .iter()
            .map(|r| (r.rgb[0] - 0.5).abs())
            .fold(0.0, f64::max);
        assert!(worst > 0.02, "{:?}", without.regions);
    }
}
