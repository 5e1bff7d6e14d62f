//! # Sender and receiver surfaces: `rdc --flux`, the `rfluxmtx` counterpart
//!
//! The matrices of the three- and five-phase methods (view matrix V: sensors -> window
//! patches; daylight matrix D: window patches -> sky patches) are flux transfer matrices
//! between *senders* and *receivers* (Ward et al. 2011, "Simulating the daylight
//! performance of complex fenestration systems using bidirectional scattering
//! distribution functions within Radiance", LEUKOS 7(4); `rfluxmtx(1)`). This module reads
//! the two ends from scene files whose `#@rfluxmtx` comment lines give each surface group
//! a hemisphere basis, and bins the paths of the tracer by them.
//!
//! ```text
//! rfluxmtx [opts] sender.rad|- receivers.rad scene.rad ...
//! rdc --flux [opts] sender.rad|- receivers.rad scene.rad ...      the same matrices
//! ```
//!
//! ## Directives (`#@rfluxmtx h=... u=... o=...`)
//! - `h=kf|kh|kq` (Klems full/half/quarter, [`KlemsBasis`]), `h=rN` (Reinhart MF N,
//!   [`SkyPatches`] without the ground bin), `h=u` (one bin); a leading `-` (`h=-kf`)
//!   mirrors the azimuth (left-handed frame). `h=scN` and `h=cie` are refused.
//! - `u=[-]X|Y|Z|ux,uy,uz`: the basis's up vector (default `+Z`, or `+Y` when the normal's
//!   `|z| >= 0.7`, as rfluxmtx).
//! - `o=FILE`: that receiver's matrix goes to FILE (replaced once complete); without
//!   `o=` every receiver's columns go to standard output, side by side in file order.
//!
//! As in `rfluxmtx.c`, the lines seen so far apply when a new receiver modifier starts:
//! `h=` carries over to later receivers, `u=` and `o=` do not. Receivers are grouped by
//! modifier (consecutive `polygon`, `ring` and `source` primitives sharing one); each
//! group is one receiver, its normal the area-weighted mean of its elements' normals
//! (a `source`'s "normal" is minus its direction, so rays leaving the scene towards it
//! arrive at its front).
//!
//! ## Binning (`klems_full.cal` `kbin`, `reinhartb.cal` `rbin`)
//! A ray arriving with direction `D` at the front of a receiver is binned by `v = -D` in
//! the receiver's frame (`x = normalize(U x N)`, `y = N x x`, `z = N`, [`KlemsFrame`]):
//! Klems patches by `(s v.x, v.y, v.z)`, Reinhart patches by `(s v.x, -v.y, v.z)` as
//! altitude/azimuth (`s = -1` for `h=-..`); rays from behind (`v.z <= 0`) count nothing
//! (bin -1 in the `.cal` files), as do Reinhart directions below the horizon (the ground
//! is not one of `h=rN`'s bins: rfluxmtx's 145 columns at N = 1). `h=u`: one bin for
//! every ray reaching a source, or the front of a surface.
//!
//! ## Senders
//! From standard input (`-`): sensors or rays exactly as `rdc`'s other modes (`-I`, `-ad`),
//! one row per ray. From a file: polygons and rings (a `source` is refused), one row per
//! basis patch; each row averages `-c N` rays (default 10000) whose origin is uniform
//! over the sender's area (several elements: by projected area towards the ray, as
//! `sample_origin`) and whose direction `d` leaves the *back* of the sender with `-d`
//! cosine-distributed inside the patch ([`KlemsBasis::sample`]; Reinhart: uniform in
//! altitude and azimuth inside the patch, rfluxmtx's `sample_reinhart`). So a receiver
//! file can serve as the next sender and the matrices concatenate. Each ray counts its
//! path throughput into the bin it arrives in: a row of D sums to the share of the patch's
//! rays that reach the sky, i.e. D times a sky of unit radiance is the mean radiance the
//! patch's rays see. Origins start `1e-6` along the ray: Radiance ignores intersections at
//! `t <= FTINY` (1e-6, `fvect.h`), so a sender lying on a scene surface does not shade
//! itself.

use super::config::{Flux, SenderInput};
use super::output;
use super::run::{Run, Tracer};
use super::tracer::{Mode, Quantity, Query, Rng, Stratum};
use crate::error::{Error, Location, Result};
use crate::formats::sensors::{RayReader, SensorRay};
use crate::geometry::klems::{KlemsBasis, KlemsFrame, KlemsKind};
use crate::geometry::vec3::{add, cross, dot, normalized, scale, sub};
use crate::progress::{Progress, Stage};
use crate::radiometry::Channels;
use crate::scene::{Directive, Primitive, Scene};
use crate::sky::SkyPatches;
use rand::Rng as _;
use std::f64::consts::PI;
use std::io::Write;
use std::ops::Range;

/// rfluxmtx's default `-c` with a sender file.
pub const DEFAULT_SENDER_SAMPLES: usize = 10000;
/// Radiance's `FTINY`: sender rays start this far along their direction.
pub const SENDER_OFFSET: f64 = 1e-6;

/// A hemisphere subdivision (`h=`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hemisphere {
    Klems(KlemsKind),
    /// Reinhart MF (1 = Tregenza), the 144 MF^2 + 1 sky patches without a ground bin.
    Reinhart(usize),
    /// One bin.
    Uniform,
}

impl Hemisphere {
    /// `h=` values as rfluxmtx reads them (`kf`, `k1`, `k`, `kh`, `k2`, `kq`, `k4`, `rN`,
    /// `tN`, `u`, `1`); `Err` says what was expected.
    pub fn parse(v: &str) -> std::result::Result<Hemisphere, String> {
        let lower = v.to_ascii_lowercase();
        let bad = || {
            format!(
                "h={v}: expected kf, kh, kq, rN (Reinhart MF N) or u (rdc does not offer sc or cie)"
            )
        };
        match lower.as_str() {
            "u" | "1" => return Ok(Hemisphere::Uniform),
            "k" | "kf" | "k1" => return Ok(Hemisphere::Klems(KlemsKind::Full)),
            "kh" | "k2" => return Ok(Hemisphere::Klems(KlemsKind::Half)),
            "kq" | "k4" => return Ok(Hemisphere::Klems(KlemsKind::Quarter)),
            _ => {}
        }
        let digits = lower
            .strip_prefix('r')
            .or_else(|| lower.strip_prefix('t'))
            .ok_or_else(bad)?;
        if digits.is_empty() {
            return Ok(Hemisphere::Reinhart(1));
        }
        let mf: usize = digits.parse().map_err(|_| bad())?;
        if mf == 0 || mf > super::config::MAX_MF {
            return Err(format!(
                "h={v}: expected a Reinhart subdivision from 1 to {}",
                super::config::MAX_MF
            ));
        }
        Ok(Hemisphere::Reinhart(mf))
    }
}

/// The parameters in force (rfluxmtx's `PARAMS`).
#[derive(Debug, Clone, Default)]
struct Params {
    hemisphere: Option<(Hemisphere, bool)>,
    up: Option<[f64; 3]>,
    output: Option<String>,
}

/// One `key=value` of a directive (values may be quoted with `'` or `"`).
fn directive_words(text: &str) -> nom::IResult<&str, Vec<(char, &str)>> {
    use nom::Parser;
    use nom::branch::alt;
    use nom::bytes::complete::{take_till, take_till1};
    use nom::character::complete::{char, multispace0, one_of};
    use nom::combinator::all_consuming;
    use nom::multi::many0;
    use nom::sequence::{delimited, preceded, terminated};
    let value = alt((
        delimited(char('"'), take_till(|c| c == '"'), char('"')),
        delimited(char('\''), take_till(|c| c == '\''), char('\'')),
        take_till1(char::is_whitespace),
    ));
    let pair = (terminated(one_of("huo"), char('=')), value);
    all_consuming(terminated(many0(preceded(multispace0, pair)), multispace0)).parse(text)
}

/// `u=` values: `[+-]X|Y|Z` or `ux,uy,uz` (rfluxmtx's `get_direction`).
fn parse_direction(v: &str) -> Option<[f64; 3]> {
    let (sign, axis) = match v.as_bytes().first() {
        Some(b'-') => (-1.0, &v[1..]),
        Some(b'+') => (1.0, &v[1..]),
        _ => (1.0, v),
    };
    match axis.to_ascii_uppercase().as_str() {
        "X" => return Some([sign, 0.0, 0.0]),
        "Y" => return Some([0.0, sign, 0.0]),
        "Z" => return Some([0.0, 0.0, sign]),
        _ => {}
    }
    let c: Vec<f64> = v
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .ok()?;
    match c.as_slice() {
        [a, b, c] if a.is_finite() && b.is_finite() && c.is_finite() => Some([*a, *b, *c]),
        _ => None,
    }
}

impl Params {
    /// Apply one directive line (later values win, as rfluxmtx's `parse_params`).
    fn apply(&mut self, d: &Directive) -> Result<()> {
        let expected = "expected h=kf|kh|kq|rN|u, u=[-]X|Y|Z|ux,uy,uz or o=FILE";
        let (_, words) = directive_words(&d.text).map_err(|_| {
            Error::parse(
                d.loc.clone(),
                format!("bad #@rfluxmtx parameters '{}': {expected}", d.text),
            )
        })?;
        for (key, v) in words {
            match key {
                'h' => {
                    let (left, h) = match v.as_bytes().first() {
                        Some(b'-') => (true, &v[1..]),
                        Some(b'+') => (false, &v[1..]),
                        _ => (false, v),
                    };
                    let h = Hemisphere::parse(h).map_err(|m| Error::parse(d.loc.clone(), m))?;
                    self.hemisphere = Some((h, left));
                }
                'u' => {
                    let u = parse_direction(v).ok_or_else(|| {
                        Error::parse(
                            d.loc.clone(),
                            format!("u={v}: expected [-]X, [-]Y, [-]Z or ux,uy,uz"),
                        )
                    })?;
                    self.up = Some(u);
                }
                _ => {
                    if v.starts_with('!') || v.contains('%') {
                        return Err(Error::parse(
                            d.loc.clone(),
                            format!(
                                "o={v}: rdc writes plain files (no '!command', no '%' patterns); name one file per receiver"
                            ),
                        ));
                    }
                    self.output = Some(v.to_string());
                }
            }
        }
        Ok(())
    }

    /// Forget what belongs to one receiver (rfluxmtx's `clear_params(p, 1)`: `h=` stays).
    fn next_receiver(&mut self) {
        self.up = None;
        self.output = None;
    }
}

/// A triangle `(a, b, c)` of a polygon with its share of the polygon's area.
type Triangle = ([f64; 3], [f64; 3], [f64; 3], f64);

/// A planar element of a sender or receiver.
#[derive(Debug, Clone)]
enum Shape {
    Polygon {
        tris: Vec<Triangle>,
    },
    Ring {
        center: [f64; 3],
        axes: ([f64; 3], [f64; 3]),
        r0: f64,
        r1: f64,
    },
    Source,
}

#[derive(Debug, Clone)]
struct Element {
    shape: Shape,
    /// Unit normal (for a source, minus its direction).
    normal: [f64; 3],
    area: f64,
}

/// Two unit vectors across `n`.
fn axes_across(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() < 0.6 {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = normalized(cross(a, n));
    (u, cross(n, u))
}

/// The element of a `polygon`, `ring` or `source` object (`None` for other types and
/// for elements of zero area, which rfluxmtx skips with a warning).
fn element(kind: &Primitive, loc: &Location, id: &str) -> Result<Option<Element>> {
    use crate::geometry::Vec3;
    use crate::geometry::triangulate::{newell_normal, triangulate};
    match kind {
        Primitive::Polygon { vertices } => {
            let vs: Vec<Vec3> = vertices.iter().map(|&v| Vec3::from(v)).collect();
            let nn = newell_normal(&vs);
            let area = nn.length();
            if area.is_nan() || area <= 0.0 {
                return Ok(None);
            }
            let idx = triangulate(&vs).map_err(|e| e.at(loc.clone()))?;
            let tris = idx
                .iter()
                .map(|&[a, b, c]| {
                    let (a, b, c) = (vertices[a], vertices[b], vertices[c]);
                    let t =
                        0.5 * dot(cross(sub(b, a), sub(c, a)), cross(sub(b, a), sub(c, a))).sqrt();
                    (a, b, c, t / area)
                })
                .collect();
            Ok(Some(Element {
                shape: Shape::Polygon { tris },
                normal: (nn * (1.0 / area)).to_array(),
                area,
            }))
        }
        Primitive::Ring {
            center,
            normal,
            r0,
            r1,
        } => {
            let l = dot(*normal, *normal).sqrt();
            let (r0, r1) = (r0.min(*r1), r0.max(*r1));
            let area = PI * (r1 * r1 - r0 * r0);
            if l.is_nan() || area.is_nan() || l <= 0.0 || area <= 0.0 {
                return Ok(None);
            }
            let n = scale(*normal, 1.0 / l);
            Ok(Some(Element {
                shape: Shape::Ring {
                    center: *center,
                    axes: axes_across(n),
                    r0,
                    r1,
                },
                normal: n,
                area,
            }))
        }
        Primitive::Source { direction, angle } => {
            let l = dot(*direction, *direction).sqrt();
            if l.is_nan() || l <= 0.0 {
                return Err(Error::parse(
                    loc.clone(),
                    format!("source '{id}' has no direction; expected a non-zero vector"),
                ));
            }
            // rfluxmtx's "area" of a source: pi sin^2(angle/2), pi for a hemisphere.
            let s = (angle.to_radians() * 0.5).sin();
            Ok(Some(Element {
                shape: Shape::Source,
                normal: scale(*direction, -1.0 / l),
                area: PI * s * s,
            }))
        }
        _ => Ok(None),
    }
}

/// A hemisphere basis placed on a surface: which bin an arriving ray falls in, which
/// direction a sender's patch sends.
#[derive(Debug, Clone)]
pub struct Basis {
    pub hemisphere: Hemisphere,
    /// `h=-..`: azimuths mirrored.
    pub left_handed: bool,
    pub frame: KlemsFrame,
    klems: Option<KlemsBasis>,
    patches: Option<SkyPatches>,
}

impl Basis {
    /// `normal` (not necessarily unit) and `up` (rfluxmtx's default when `None`).
    fn new(
        (hemisphere, left_handed): (Hemisphere, bool),
        normal: [f64; 3],
        up: Option<[f64; 3]>,
        loc: &Location,
    ) -> Result<Basis> {
        let n = normalized(normal);
        if !n.iter().all(|c| c.is_finite()) || dot(normal, normal) == 0.0 {
            return Err(Error::parse(
                loc.clone(),
                "the surfaces' normals cancel out (undefined normal for hemisphere sampling); \
                 expected surfaces facing one way",
            ));
        }
        let up = up.unwrap_or(if n[2].abs() < 0.7 {
            [0.0, 0.0, 1.0]
        } else {
            [0.0, 1.0, 0.0]
        });
        let frame = KlemsFrame::new(n, up).ok_or_else(|| {
            Error::parse(
                loc.clone(),
                format!(
                    "up vector u={},{},{} is parallel to the surfaces' normal; give another u=",
                    up[0], up[1], up[2]
                ),
            )
        })?;
        Ok(Basis {
            hemisphere,
            left_handed,
            frame,
            klems: match hemisphere {
                Hemisphere::Klems(k) => Some(KlemsBasis::new(k)),
                _ => None,
            },
            patches: match hemisphere {
                Hemisphere::Reinhart(mf) => Some(SkyPatches::new(mf)),
                _ => None,
            },
        })
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        match (&self.klems, &self.patches) {
            (Some(k), _) => k.len(),
            (_, Some(p)) => p.len() - 1,
            _ => 1,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Local coordinates of `v` (pointing away from the surface's front): Klems
    /// `(s v.x, v.y, v.z)`; Reinhart `(s v.x, -v.y, v.z)` so that `SkyPatches`' azimuth
    /// (from local +y towards +x) is `reinhartb.cal`'s.
    fn local(&self, v: [f64; 3]) -> [f64; 3] {
        let s = if self.left_handed { -1.0 } else { 1.0 };
        let l = self.frame.to_local(v);
        match self.hemisphere {
            Hemisphere::Reinhart(_) => [s * l[0], -l[1], l[2]],
            _ => [s * l[0], l[1], l[2]],
        }
    }

    /// World vector from local coordinates ([`Basis::local`]'s inverse).
    fn world(&self, l: [f64; 3]) -> [f64; 3] {
        let s = if self.left_handed { -1.0 } else { 1.0 };
        let l = match self.hemisphere {
            Hemisphere::Reinhart(_) => [s * l[0], -l[1], l[2]],
            _ => [s * l[0], l[1], l[2]],
        };
        self.frame.to_world(l)
    }

    /// The bin of a ray arriving with unit direction `d` (`None`: from behind, or below a
    /// Reinhart basis's horizon). `source`: the receiver is a distant source (`h=u` then
    /// takes every ray).
    pub fn bin_arriving(&self, d: [f64; 3], source: bool) -> Option<usize> {
        let v = [-d[0], -d[1], -d[2]];
        let l = self.local(v);
        match (&self.klems, &self.patches) {
            (Some(k), _) => {
                if l[2] > 0.0 {
                    k.bin_of(l)
                } else {
                    None
                }
            }
            (_, Some(p)) => {
                if l[2] > 0.0 {
                    Some(p.bin_of(l).checked_sub(1)?)
                } else {
                    None
                }
            }
            _ => (source || l[2] > 0.0).then_some(0),
        }
    }

    /// The direction `v` (away from the front, unit) of a sender sample in bin `b` from two
    /// uniforms; the ray then travels along `-v`.
    fn sample_away(&self, b: usize, u: f64, w: f64) -> [f64; 3] {
        let l = match (&self.klems, &self.patches) {
            (Some(k), _) => k.sample(b, u, w),
            (_, Some(p)) => reinhart_sender_local(p, b, u, w),
            _ => {
                // rfluxmtx's sample_uniform: a cosine-weighted hemisphere (square2disk).
                let r = u.sqrt();
                let phi = 2.0 * PI * w;
                [r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt()]
            }
        };
        normalized(self.world(l))
    }
}

/// rfluxmtx's `sample_reinhart` for sky bin `b` (0-based, no ground): altitude uniform in
/// the row (the zenith cap's fraction squared "to avoid crowding"), azimuth uniform in the
/// column; local `(sin azi cos alt, cos azi cos alt, sin alt)`.
fn reinhart_sender_local(p: &SkyPatches, b: usize, u: f64, w: f64) -> [f64; 3] {
    let i = b + 1;
    let (row, col, n) = match p.row_of(i) {
        Some(r) if r < p.rows() => {
            let first = 1 + (0..r).map(|k| p.row_len(k)).sum::<usize>();
            (r, i - first, p.row_len(r))
        }
        _ => (p.rows(), 0, 1),
    };
    let rah = 0.5 * PI / (p.rows() as f64 + 0.5);
    let u = if row >= p.rows() { u * u } else { u };
    let alt = (row as f64 + u) * rah;
    let azi = 2.0 * PI * (col as f64 + w - 0.5) / n as f64;
    [azi.sin() * alt.cos(), azi.cos() * alt.cos(), alt.sin()]
}

/// One receiver: a modifier's group of surfaces (or sources) with a basis.
#[derive(Debug, Clone)]
pub struct Receiver {
    pub modifier: String,
    pub basis: Basis,
    /// `o=FILE`.
    pub output: Option<String>,
    /// Its objects' indices in the scene.
    pub objects: Vec<usize>,
    /// All elements are distant sources.
    pub source: bool,
    /// First column in the record.
    pub offset: usize,
}

/// Every receiver, and which scene object belongs to which.
#[derive(Debug, Clone)]
pub struct Receivers {
    pub list: Vec<Receiver>,
    /// Receiver of each scene object (`u32::MAX`: none).
    owner: Vec<u32>,
    ncols: usize,
}

/// Directives that come before object `i` (in order), not yet taken.
fn take_directives<'a>(ds: &'a [Directive], next: &mut usize, i: usize) -> &'a [Directive] {
    let start = *next;
    while *next < ds.len() && ds[*next].before <= i {
        *next += 1;
    }
    &ds[start..*next]
}

/// The directives of `range` (and those just before its first object).
fn directives_of(scene: &Scene, range: &Range<usize>) -> (Vec<Directive>, Location) {
    let ds: Vec<Directive> = scene
        .directives
        .iter()
        .filter(|d| d.before >= range.start && d.before <= range.end)
        .cloned()
        .collect();
    let loc = scene
        .objects
        .get(range.start)
        .map(|o| Location::file(o.loc.file.clone()))
        .unwrap_or_default();
    (ds, loc)
}

impl Receivers {
    /// The receivers of the objects `range` of `scene` (the receiver file), `name` for
    /// errors.
    pub fn from_scene(scene: &Scene, range: Range<usize>, name: &str) -> Result<Receivers> {
        let (ds, _) = directives_of(scene, &range);
        let mut next = 0;
        let mut params = Params::default();
        let mut list: Vec<Receiver> = Vec::new();
        // The receiver being gathered: modifier, params, summed area-weighted normal,
        // objects, all sources, location of its first object.
        struct Open {
            modifier: String,
            params: Params,
            normal: [f64; 3],
            objects: Vec<usize>,
            source: bool,
            non_hemisphere_source: bool,
            loc: Location,
        }
        let mut open: Option<Open> = None;
        let finish = |o: Open, list: &mut Vec<Receiver>| -> Result<()> {
            let h = o.params.hemisphere.ok_or_else(|| {
                Error::parse(
                    o.loc.clone(),
                    format!(
                        "receiver '{}' has no hemisphere sampling type; add a line '#@rfluxmtx h=kf u=Z' (or h=rN, h=u) before it",
                        o.modifier
                    ),
                )
            })?;
            if h.0 != Hemisphere::Uniform && o.non_hemisphere_source {
                return Err(Error::parse(
                    o.loc.clone(),
                    format!(
                        "receiver '{}': a source with h=kf/kh/kq/rN must be 180 degrees (a hemisphere); use h=u for other sources",
                        o.modifier
                    ),
                ));
            }
            let basis = Basis::new(h, o.normal, o.params.up, &o.loc)?;
            let offset = list.last().map_or(0, |r| r.offset + r.basis.len());
            list.push(Receiver {
                modifier: o.modifier,
                basis,
                output: o.params.output,
                objects: o.objects,
                source: o.source,
                offset,
            });
            Ok(())
        };
        for i in range.clone() {
            let obj = &scene.objects[i];
            let Some(el) = element(&obj.kind, &obj.loc, &obj.id)? else {
                continue;
            };
            let new = open
                .as_ref()
                .is_none_or(|o| o.modifier != obj.modifier_name);
            if new {
                if let Some(o) = open.take() {
                    finish(o, &mut list)?;
                    params.next_receiver();
                }
                for d in take_directives(&ds, &mut next, i) {
                    params.apply(d)?;
                }
                if list.iter().any(|r| r.modifier == obj.modifier_name) {
                    return Err(Error::parse(
                        obj.loc.clone(),
                        format!(
                            "receiver modifier '{}' used again after another receiver; keep each receiver's surfaces together",
                            obj.modifier_name
                        ),
                    ));
                }
                open = Some(Open {
                    modifier: obj.modifier_name.clone(),
                    params: params.clone(),
                    normal: [0.0; 3],
                    objects: Vec::new(),
                    source: true,
                    non_hemisphere_source: false,
                    loc: obj.loc.clone(),
                });
            }
            let o = open.as_mut().expect("opened above");
            o.normal = add(o.normal, scale(el.normal, el.area));
            o.objects.push(i);
            let is_source = matches!(el.shape, Shape::Source);
            o.source &= is_source;
            o.non_hemisphere_source |= is_source && (el.area - PI).abs() > 1e-3;
        }
        match open {
            Some(o) => finish(o, &mut list)?,
            None => {
                return Err(Error::parse(
                    Location::file(name),
                    "no receiver surface (polygon, ring or source); expected at least one after a #@rfluxmtx h=... line",
                ));
            }
        }
        let outputs = list.iter().filter(|r| r.output.is_some()).count();
        if outputs != 0 && outputs != list.len() {
            return Err(Error::parse(
                Location::file(name),
                "some receivers have o=FILE and some not; give every receiver an o= or none (all to standard output)",
            ));
        }
        let mut owner = vec![u32::MAX; scene.objects.len()];
        for (k, r) in list.iter().enumerate() {
            for &i in &r.objects {
                owner[i] = k as u32;
            }
        }
        let ncols = list.iter().map(|r| r.basis.len()).sum();
        Ok(Receivers { list, owner, ncols })
    }

    /// Columns of a record (every receiver's bins, in order).
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// The column a ray arriving along `d` at scene object `object` counts in.
    pub fn column(&self, object: usize, d: [f64; 3]) -> Option<usize> {
        let k = *self.owner.get(object)?;
        let r = self.list.get(k as usize)?;
        r.basis.bin_arriving(d, r.source).map(|b| r.offset + b)
    }
}

/// The sender surface: a basis and the elements rays start from.
#[derive(Debug, Clone)]
pub struct Sender {
    pub basis: Basis,
    elements: Vec<Element>,
}

impl Sender {
    /// The sender of the objects `range` of `scene` (the sender file).
    pub fn from_scene(scene: &Scene, range: Range<usize>, name: &str) -> Result<Sender> {
        let (ds, _) = directives_of(scene, &range);
        let mut params = Params::default();
        let mut next = 0;
        let mut elements = Vec::new();
        let mut normal = [0.0; 3];
        let mut first: Option<Location> = None;
        for i in range.clone() {
            let obj = &scene.objects[i];
            for d in take_directives(&ds, &mut next, i) {
                params.apply(d)?;
            }
            let Some(el) = element(&obj.kind, &obj.loc, &obj.id)? else {
                continue;
            };
            if matches!(el.shape, Shape::Source) {
                return Err(Error::parse(
                    obj.loc.clone(),
                    format!(
                        "source '{}' cannot be a sender; expected polygons or rings",
                        obj.id
                    ),
                ));
            }
            first.get_or_insert(obj.loc.clone());
            normal = add(normal, scale(el.normal, el.area));
            elements.push(el);
        }
        let Some(loc) = first else {
            return Err(Error::parse(
                Location::file(name),
                "no sender surface; expected polygons or rings after a #@rfluxmtx h=kf line",
            ));
        };
        let h = params.hemisphere.ok_or_else(|| {
            Error::parse(
                loc.clone(),
                "sender has no hemisphere sampling type; add '#@rfluxmtx h=kf u=Z' (or h=rN, h=u) before it",
            )
        })?;
        Ok(Sender {
            basis: Basis::new(h, normal, params.up, &loc)?,
            elements,
        })
    }

    /// Rows (the basis's patches).
    pub fn rows(&self) -> usize {
        self.basis.len()
    }

    /// A point of the sender for a ray along `d`: an element chosen by projected area
    /// (`-n.d x area`, rfluxmtx's `sample_origin`), then uniform over it.
    fn origin(&self, d: [f64; 3], rng: &mut Rng) -> Option<[f64; 3]> {
        let weight = |e: &Element| (-dot(e.normal, d) * e.area).max(0.0);
        let el = if self.elements.len() == 1 {
            &self.elements[0]
        } else {
            let total: f64 = self.elements.iter().map(weight).sum();
            if total.is_nan() || total <= 0.0 {
                return None;
            }
            let mut x = rng.random::<f64>() * total;
            let mut pick = &self.elements[self.elements.len() - 1];
            for e in &self.elements {
                let w = weight(e);
                if x < w {
                    pick = e;
                    break;
                }
                x -= w;
            }
            pick
        };
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        Some(match &el.shape {
            Shape::Polygon { tris } => {
                let mut x = rng.random::<f64>();
                let mut t = &tris[tris.len() - 1];
                for tri in tris {
                    if x < tri.3 {
                        t = tri;
                        break;
                    }
                    x -= tri.3;
                }
                // Uniform in a triangle: (1 - sqrt u) a + sqrt u (1 - v) b + sqrt u v c.
                let s = u.sqrt();
                add(
                    add(scale(t.0, 1.0 - s), scale(t.1, s * (1.0 - v))),
                    scale(t.2, s * v),
                )
            }
            Shape::Ring {
                center,
                axes,
                r0,
                r1,
            } => {
                let r = (u * (r1 * r1 - r0 * r0) + r0 * r0).sqrt();
                let phi = 2.0 * PI * v;
                add(
                    *center,
                    add(scale(axes.0, r * phi.cos()), scale(axes.1, r * phi.sin())),
                )
            }
            Shape::Source => return None,
        })
    }

    /// Sample `stratum` of row `b`: a ray leaving the back of the sender with `-d` in
    /// patch `b` (jittered over the patch across the row's samples).
    pub fn query(&self, b: usize, stratum: Stratum, rng: &mut Rng) -> Option<Query> {
        let (u, w) = stratum.unit_square(rng);
        let v = self.basis.sample_away(b, u, w);
        let d = [-v[0], -v[1], -v[2]];
        let o = self.origin(d, rng)?;
        Some(Query {
            org: add(o, scale(d, SENDER_OFFSET)),
            dir: d,
            quantity: Quantity::Radiance,
        })
    }
}

/// What a flux run reads before tracing: the scene to trace (system files, then the
/// receiver file), the receivers and the sender.
pub struct Setup {
    pub scene: Scene,
    pub receivers: Receivers,
    pub sender: Option<Sender>,
}

impl Setup {
    /// Load `scene` files, then the receiver file, then (not traced) the sender file.
    pub fn load(flux: &Flux, scene: &[String], opts: &crate::scene::LoadOptions) -> Result<Setup> {
        let mut inputs: Vec<String> = scene.to_vec();
        inputs.push(flux.receiver.clone());
        if let SenderInput::File(f) = &flux.sender {
            inputs.push(f.clone());
        }
        let (mut all, parts) = crate::scene::load_parts(&inputs, opts)?;
        let recv = parts[scene.len()].clone();
        let receivers = Receivers::from_scene(&all, recv.clone(), &flux.receiver)?;
        let sender = match &flux.sender {
            SenderInput::File(f) => {
                Some(Sender::from_scene(&all, parts[scene.len() + 1].clone(), f)?)
            }
            SenderInput::Stdin => None,
        };
        // The sender is not part of the traced scene (rfluxmtx leaves it out of the octree).
        all.objects.truncate(recv.end);
        all.directives.clear();
        Ok(Setup {
            scene: all,
            receivers,
            sender,
        })
    }
}

/// One output matrix: standard output, or a receiver's `o=` file written beside its
/// target and renamed over it once complete.
struct Output {
    sink: output::Sink<Box<dyn Write + Send>>,
    /// `(path, temporary)` for an `o=` file.
    file: Option<(String, std::path::PathBuf)>,
    /// Columns of the record that go here.
    cols: Range<usize>,
}

/// `rdc --flux`: load the scene, the receivers and the sender, then write one row per
/// sender patch (or per ray of standard input) to standard output or the receivers' `o=`
/// files. Records are seeded as rdc's other modes (record `i` from `(seed, i)`), so the
/// bytes do not depend on `-n`.
pub fn main(run: &Run, flux: &Flux, progress: &dyn Progress) -> Result<()> {
    let stage = Stage::uncounted(progress, "loading the scene");
    let setup = Setup::load(flux, &run.scene, &run.load)?;
    drop(stage);
    let stage = Stage::uncounted(progress, "compiling the scene");
    let compact = crate::scene::CompactScene::from_scene(&setup.scene)?;
    let mut tracer = Tracer::build(
        &run.config,
        super::run::SceneInput::Compact(&compact),
        Some(&run.scene),
        &run.command,
    )?;
    if setup.sender.is_some() {
        // rfluxmtx's sender rays fan out -ad ambient samples at their first diffuse hit
        // (the ground in front of a window, for a daylight matrix): so do ours.
        let ad = run.config.sampling.ad.min(u32::MAX as usize) as u32;
        tracer.estimator.set_first_bounce_split(ad);
    }
    drop(stage);
    let receivers = &setup.receivers;
    let mut job = tracer.job();
    job.mode = Mode::Flux { receivers };
    // Rays from standard input: read them all first (NROWS goes in the header).
    let rays: Vec<SensorRay> = match &setup.sender {
        Some(_) => Vec::new(),
        None => {
            let stdin = std::io::stdin();
            let reader = RayReader::new(stdin.lock(), "<stdin>", run.input);
            let rays = reader.collect::<Result<Vec<_>>>()?;
            if rays.is_empty() {
                return Err(crate::formats::sensors::no_sensors("<stdin>"));
            }
            if let Some(y) = run.y.filter(|&y| y != rays.len()) {
                return Err(Error::parse(
                    Location::file("<stdin>"),
                    format!("{} sensors read, -y announced {y}", rays.len()),
                ));
            }
            rays
        }
    };
    let nrows = match &setup.sender {
        Some(s) => {
            job.ad = flux.samples.unwrap_or(DEFAULT_SENDER_SAMPLES);
            s.rows()
        }
        None => rays.len(),
    };
    // Temporary `o=` files: removed on any failure, renamed over their targets at the end.
    let mut temps = Vec::new();
    let result = trace_rows(
        run, &tracer, &setup, job, &rays, nrows, &mut temps, progress,
    );
    if result.is_err() {
        for t in &temps {
            let _ = std::fs::remove_file(t);
        }
    }
    result
}

/// Trace and write the rows (`temps` collects the temporary files opened).
#[allow(clippy::too_many_arguments)]
fn trace_rows(
    run: &Run,
    tracer: &Tracer,
    setup: &Setup,
    job: super::run::Job,
    rays: &[SensorRay],
    nrows: usize,
    temps: &mut Vec<std::path::PathBuf>,
    progress: &dyn Progress,
) -> Result<()> {
    let channels = tracer.channels;
    let receivers = &setup.receivers;
    let mut outputs = open_outputs(run, receivers, &channels, nrows, temps)?;
    let pool = tracer.pool()?;
    let irradiance = run.config.irradiance;
    let stage = Stage::new(progress, "tracing", Some(nrows as u64), "records");
    let result = pool.install(|| -> Result<()> {
        let block_len = job.block_len();
        let mut done = 0;
        while done < nrows {
            let end = (done + block_len).min(nrows);
            let results = match &setup.sender {
                Some(sender) => {
                    let patches: Vec<usize> = (done..end).collect();
                    let query = |&b: &usize, st: Stratum, rng: &mut Rng| sender.query(b, st, rng);
                    job.block(done as u64, &patches, &query, progress)
                }
                None => {
                    let query = |r: &SensorRay, _: Stratum, _: &mut Rng| {
                        super::run::sensor_query(r, irradiance)
                    };
                    job.block(done as u64, &rays[done..end], &query, progress)
                }
            };
            for r in &results {
                for o in outputs.iter_mut() {
                    let ncomp = channels.ncomp;
                    o.sink
                        .write_row(&r.values[o.cols.start * ncomp..o.cols.end * ncomp])?;
                }
            }
            for o in outputs.iter_mut() {
                o.sink.flush()?;
            }
            done = end;
        }
        Ok(())
    });
    drop(stage);
    result?;
    for o in outputs {
        o.sink.finish()?;
        if let Some((path, tmp)) = o.file {
            crate::io::replace_with(&tmp, &path, Ok(()))?;
        }
    }
    Ok(())
}

/// The matrices a run writes: one per receiver with `o=`, else one on standard output
/// with every receiver's columns (rcontrib's `-fo` interleaving of several `-m`).
fn open_outputs(
    run: &Run,
    receivers: &Receivers,
    channels: &Channels,
    nrows: usize,
    temps: &mut Vec<std::path::PathBuf>,
) -> Result<Vec<Output>> {
    let header =
        |ncols: usize| output::header(&run.command, None, channels, Some(nrows), ncols, run.output);
    if receivers.list.iter().all(|r| r.output.is_none()) {
        let ncols = receivers.ncols();
        let w: Box<dyn Write + Send> = Box::new(std::io::BufWriter::new(std::io::stdout()));
        let sink = output::Sink::matrix(
            w,
            header(ncols),
            nrows,
            ncols,
            *channels,
            run.output,
            run.header,
            crate::io::stdout_is_file(),
        )?;
        return Ok(vec![Output {
            sink,
            file: None,
            cols: 0..ncols,
        }]);
    }
    let mut out: Vec<Output> = Vec::new();
    for r in &receivers.list {
        let path = r.output.clone().unwrap_or_default();
        if out
            .iter()
            .any(|o| o.file.as_ref().is_some_and(|f| f.0 == path))
        {
            return Err(Error::Usage(format!(
                "o={path} names two receivers' output; give each receiver its own file"
            )));
        }
        let tmp = crate::io::temp_beside(std::path::Path::new(&path));
        let f = std::fs::File::create(&tmp).map_err(|e| Error::io(&path, e))?;
        // Pushed before anything can fail, so that a failure removes it.
        temps.push(tmp.clone());
        let w: Box<dyn Write + Send> = Box::new(std::io::BufWriter::new(f));
        let ncols = r.basis.len();
        let sink = output::Sink::matrix(
            w,
            header(ncols),
            nrows,
            ncols,
            *channels,
            run.output,
            run.header,
            true,
        )?;
        out.push(Output {
            sink,
            file: Some((path, tmp)),
            cols: r.offset..r.offset + ncols,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::LoadOptions;

    fn scene(text: &str) -> Scene {
        crate::scene::parse_str(
            text,
            "t.rad",
            std::path::Path::new(""),
            &LoadOptions::default(),
        )
        .unwrap()
    }

    #[test]
    fn hemisphere_letters_as_rfluxmtx() {
        assert_eq!(
            Hemisphere::parse("kf"),
            Ok(Hemisphere::Klems(KlemsKind::Full))
        );
        assert_eq!(
            Hemisphere::parse("k4"),
            Ok(Hemisphere::Klems(KlemsKind::Quarter))
        );
        assert_eq!(Hemisphere::parse("r4"), Ok(Hemisphere::Reinhart(4)));
        assert_eq!(Hemisphere::parse("r"), Ok(Hemisphere::Reinhart(1)));
        assert_eq!(Hemisphere::parse("u"), Ok(Hemisphere::Uniform));
        assert!(Hemisphere::parse("sc6").unwrap_err().contains("h=sc6"));
        assert!(Hemisphere::parse("r31").is_err());
    }

    #[test]
    fn sky_receiver_bins_as_reinhartb() {
        // The usual 3-phase sky: a 180-degree glow source up, u=+Y: 145 columns (no ground).
        let s = scene(
            "#@rfluxmtx h=r1 u=+Y\nvoid glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n",
        );
        let r = Receivers::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap();
        assert_eq!(r.ncols(), 145);
        let p = SkyPatches::new(1);
        for i in 1..p.len() {
            let d = p.centre(i);
            assert_eq!(r.column(1, d), Some(i - 1), "patch {i}");
        }
        assert_eq!(r.column(1, [0.0, 0.3, -0.9]), None);
    }

    #[test]
    fn window_receiver_and_sender_agree_on_klems_patches() {
        // A window in the plane y = 0 facing -Y (into a room at y < 0), u=+Z.
        let text = "#@rfluxmtx h=kf u=+Z\nvoid glow wg 0 0 4 1 1 1 0\nwg polygon w 0 0 12 0 0 1  1 0 1  1 0 2  0 0 2\n";
        let s = scene(text);
        let r = Receivers::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap();
        let snd = Sender::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap();
        assert_eq!(r.ncols(), 145);
        assert_eq!(snd.rows(), 145);
        let mut rng = super::super::tracer::record_rng(1, 2);
        for b in 0..145 {
            for k in 0..20 {
                let q = snd
                    .query(
                        b,
                        Stratum {
                            index: k,
                            count: 20,
                        },
                        &mut rng,
                    )
                    .unwrap();
                // A sender ray leaves through the back (towards +Y, out of the room); the
                // same file as a receiver bins a ray from the room arriving along that
                // direction in the same patch, so V and D concatenate.
                assert!(q.dir[1] > 0.0);
                assert_eq!(r.column(1, q.dir), Some(b));
                assert!(q.org[0] >= 0.0 && q.org[0] <= 1.0 && (q.org[2] - 1.5).abs() <= 0.5);
            }
        }
    }

    #[test]
    fn reinhart_sender_rays_land_in_their_own_sky_patch() {
        // A downward-facing (normal -Z) sender with h=r1 u=+Y sends its rays up, through
        // the frame of the usual sky receiver: every patch's rays bin into that patch.
        let snd = scene(
            "#@rfluxmtx h=r1 u=+Y\nvoid glow g 0 0 4 1 1 1 0\ng polygon p 0 0 12 0 0 0 0 1 0 1 1 0 1 0 0\n",
        );
        let snd = Sender::from_scene(&snd, 0..snd.objects.len(), "s.rad").unwrap();
        let sky = scene(
            "#@rfluxmtx h=r1 u=+Y\nvoid glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n",
        );
        let r = Receivers::from_scene(&sky, 0..sky.objects.len(), "t.rad").unwrap();
        assert_eq!(snd.rows(), 145);
        let mut rng = super::super::tracer::record_rng(3, 4);
        for b in 0..145 {
            for k in 0..16 {
                let q = snd
                    .query(
                        b,
                        Stratum {
                            index: k,
                            count: 16,
                        },
                        &mut rng,
                    )
                    .unwrap();
                assert!(q.dir[2] > 0.0);
                assert_eq!(r.column(1, q.dir), Some(b), "patch {b}");
            }
        }
    }

    #[test]
    fn directive_prefixes_and_junk_never_panic() {
        let texts = [
            "h=-kf u=0.1,0.2,1 o='my file.mtx'",
            "h=r4 u=-Y o=\"a b\"",
            "h= u= o=",
            "x=1 h=kq",
            "h=kf u=1,2 o=!cmd",
            "\u{e9}=\u{e9} h=\u{e9}",
        ];
        for t in texts {
            for end in (0..=t.len()).filter(|&e| t.is_char_boundary(e)) {
                let d = Directive {
                    before: 0,
                    text: t[..end].to_string(),
                    loc: Location::line("t.rad", 1),
                };
                let mut p = Params::default();
                if let Err(e) = p.apply(&d) {
                    let m = e.to_string();
                    assert!(m.starts_with("t.rad:1"), "{m}");
                    assert!(!m.contains('\n'), "{m}");
                }
            }
        }
    }

    #[test]
    fn directives_follow_rfluxmtx_scoping() {
        // h= carries over to the second receiver, o= does not: mixed outputs are refused.
        let s = scene(
            "#@rfluxmtx h=u o=a.mtx\nvoid glow g1 0 0 4 1 1 1 0\ng1 source s1 0 0 4 0 0 1 180\nvoid glow g2 0 0 4 1 1 1 0\ng2 source s2 0 0 4 0 0 -1 180\n",
        );
        let e = Receivers::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap_err();
        assert!(e.to_string().contains("o=FILE"), "{e}");
        let s = scene("#@rfluxmtx h=q\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n");
        let e = Receivers::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap_err();
        assert!(e.to_string().starts_with("t.rad:1"), "{e}");
        let s = scene("void glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n");
        let e = Receivers::from_scene(&s, 0..s.objects.len(), "t.rad").unwrap_err();
        assert!(e.to_string().contains("#@rfluxmtx h=kf"), "{e}");
    }
}
