//! Objects and the permanent shell of a scene.
//!
//! The seed's levels (section 2.3.1) filter *objects* (a chair, a desk), not primitives. A
//! Radiance scene has no objects, only primitives, so they are recovered by a [`Grouping`]:
//!
//! | grouping | an object is | use when |
//! |---|---|---|
//! | `Prefix(sep)` (default, `.`) | the identifiers' part before the first `sep`: `chair_12.leg_3` -> `chair_12` | parts are named after their object (most exporters) |
//! | `Modifier` | every primitive with the same modifier | one material per object |
//! | `Connectivity(tol)` | primitives sharing a vertex within `tol` (union-find) | unnamed meshes |
//! | `Source` | the file, or the inline `!command`, the primitive came from (the scene keeps it: [`Object::loc`]`.file` is `room.rad` or `room.rad:12: !xform ...`) | one file or `!xform` per object |
//!
//! **The permanent shell is never filtered** (GLoD0). A primitive is in the shell if
//! 1. its material is `glass`, `dielectric`, `interface`, `BSDF` or `aBSDF` (windows and
//!    glazing), or
//! 2. its identifier matches a `permanent` pattern ([`glob`]: `*` and `?`; a pattern without
//!    either matches as a prefix), or
//! 3. it has no inline geometry (`source`, `instance`, `mesh`: their extent is unknown here,
//!    so they are kept rather than guessed), or
//! 4. it is a polygon on an enclosing plane of the room: within `tolerance` of a face of the
//!    room box, the bounding box of all geometry in the room [`Frame`] (coordinate axes, or
//!    the principal axes of all points for rotated rooms). Exterior surfaces that widen that
//!    box (a ground plane, site context) are peeled first: a polygon on a face of the box
//!    that reaches beyond the box of everything else is exterior, permanent, and left out of
//!    the room box, which is then recomputed.
//!
//! Rule 4 needs care with groups: with `Prefix` and `Source` grouping a named group is shell
//! only if *all* its polygons lie on enclosing planes (a cabinet's back panel against a wall
//! stays with its cabinet); with `Modifier` and `Connectivity` grouping the on-plane polygons
//! join the shell first (otherwise a wall sharing a material or a vertex with a shelf would
//! be filtered with it), and the rest is grouped.

use std::collections::{BTreeMap, HashMap};

use rdaylight_base::vec3::{V3, dot};
use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::{Primitive, Scene};
use serde::Serialize;

use crate::level::Thresholds;
use crate::obb::{Obb, min_area_obb};
use crate::points::polygon_normal;
use crate::points::{Sampled, sample};

/// How primitives are grouped into objects (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub enum Grouping {
    Prefix(String),
    Modifier,
    Connectivity(f64),
    Source,
}

/// The axes of the room box used for the shell's enclosing planes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// The coordinate axes (rooms modelled axis-aligned, the usual case).
    Axes,
    /// Rooms rotated in plan: z stays up (Radiance's convention) and x, y turn by the plan
    /// angle of the walls: the azimuth (modulo 90 degrees) of vertical polygons' normals
    /// carrying the most area, in 0.1 degree bins, refined by the area-weighted mean within
    /// the winning bin's neighbours. Furniture at other angles has less area than the walls,
    /// so it cannot tip the frame (an area-weighted mean over all polygons would).
    Walls,
}

/// What [`analyse`] does.
#[derive(Debug, Clone)]
pub struct Options {
    pub grouping: Grouping,
    pub frame: Frame,
    /// Distance (m) within which a polygon lies on an enclosing plane. Default 0.01 m: finer
    /// than any wall a survey resolves, coarser than exporters' rounding.
    pub tolerance: f64,
    /// Identifier patterns that are always permanent ([`glob`]).
    pub permanent: Vec<String>,
    pub thresholds: Thresholds,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            grouping: Grouping::Prefix(".".to_string()),
            frame: Frame::Axes,
            tolerance: 0.01,
            permanent: Vec::new(),
            thresholds: Thresholds::default(),
        }
    }
}

impl Options {
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(Error::Usage(format!(
                "--tolerance {}: give a distance >= 0 in metres (default 0.01)",
                self.tolerance
            )));
        }
        match &self.grouping {
            Grouping::Prefix(s) if s.is_empty() => {
                return Err(Error::Usage(
                    "--separator: give a non-empty separator (default '.')".into(),
                ));
            }
            Grouping::Connectivity(t) if !(t.is_finite() && *t >= 0.0) => {
                return Err(Error::Usage(format!(
                    "--by connectivity: tolerance {t} must be a distance >= 0 in metres"
                )));
            }
            _ => {}
        }
        self.thresholds.validate()
    }
}

/// One non-permanent object: its primitives (indices into [`Scene::objects`]), box and level.
#[derive(Debug, Clone, Serialize)]
pub struct GlodObject {
    pub id: String,
    pub members: Vec<usize>,
    pub obb: Obb,
    pub area: f64,
    /// The lowest GLoD (1..=4) containing the object.
    pub level: u8,
}

/// The shell and the objects of a scene.
#[derive(Debug, Clone, Serialize)]
pub struct Analysis {
    /// Surfaces that every level keeps (indices into [`Scene::objects`]).
    pub shell: Vec<usize>,
    pub objects: Vec<GlodObject>,
}

impl Analysis {
    /// Assign every object's level again under other thresholds (e.g. [`crate::percentiles`]
    /// of this scene's own areas).
    pub fn relevel(&mut self, t: &Thresholds) -> Result<()> {
        t.validate()?;
        for o in &mut self.objects {
            o.level = t.level(o.area);
        }
        Ok(())
    }
}

/// Simple glob: `*` any run, `?` one character; a pattern without wildcards is a prefix
/// (`wall` matches `wall_3`). Chosen over a regex dependency: identifiers are short and the
/// patterns people write for them are globs.
pub fn glob(pattern: &str, text: &str) -> bool {
    if !pattern.contains(['*', '?']) {
        return text.starts_with(pattern);
    }
    let (p, t): (Vec<char>, Vec<char>) = (pattern.chars().collect(), text.chars().collect());
    // Iterative matcher with one backtrack point (linear in practice, never recursive).
    let (mut i, mut j, mut star, mut mark) = (0, 0, None, 0);
    while j < t.len() {
        if i < p.len() && (p[i] == '?' || p[i] == t[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

struct Surface {
    index: usize,
    sampled: Sampled,
}

fn to_frame(p: V3, axes: &[V3; 3]) -> V3 {
    [dot(p, axes[0]), dot(p, axes[1]), dot(p, axes[2])]
}

fn bbox<'a>(points: impl Iterator<Item = &'a V3>) -> Option<(V3, V3)> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut any = false;
    for p in points {
        any = true;
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    any.then_some((lo, hi))
}

/// Which of `surfaces` (frame coordinates) are polygons on the room box's faces, after
/// peeling exterior polygons (module documentation, rule 4). Returns (on-plane, exterior).
fn enclosing(
    scene: &Scene,
    pts: &[Vec<V3>],
    surfaces: &[Surface],
    tol: f64,
) -> (Vec<bool>, Vec<bool>) {
    let n = surfaces.len();
    let is_polygon: Vec<bool> = surfaces
        .iter()
        .map(|s| matches!(scene.objects[s.index].kind, Primitive::Polygon { .. }))
        .collect();
    let boxes: Vec<Option<(V3, V3)>> = pts.iter().map(|p| bbox(p.iter())).collect();
    let merge = |skip: &[bool], except: Option<usize>| {
        let mut acc: Option<(V3, V3)> = None;
        for i in 0..n {
            if skip[i] || Some(i) == except {
                continue;
            }
            if let Some((l, h)) = boxes[i] {
                acc = Some(match acc {
                    None => (l, h),
                    Some((al, ah)) => (
                        std::array::from_fn(|k| al[k].min(l[k])),
                        std::array::from_fn(|k| ah[k].max(h[k])),
                    ),
                });
            }
        }
        acc
    };
    // The axis of the room-box face polygon `i` lies on, if any.
    let on_face = |i: usize, room: (V3, V3)| -> Option<usize> {
        let (l, h) = boxes[i]?;
        if !is_polygon[i] {
            return None;
        }
        (0..3).find(|&k| {
            (h[k] - room.0[k]).abs() <= tol && (l[k] - room.0[k]).abs() <= tol
                || (h[k] - room.1[k]).abs() <= tol && (l[k] - room.1[k]).abs() <= tol
        })
    };
    let mut exterior = vec![false; n];
    // A few rounds: each peels the outermost layer of site context.
    for _ in 0..8 {
        let Some(room) = merge(&exterior, None) else {
            break;
        };
        let mut peeled = false;
        for i in 0..n {
            let Some(axis) = on_face(i, room).filter(|_| !exterior[i]) else {
                continue;
            };
            let Some((l, h)) = boxes[i] else { continue };
            // Reaching beyond everything else *within its plane* (along the face's own
            // axis every floor is beyond the rest).
            if let Some((ol, oh)) = merge(&exterior, Some(i)) {
                if (0..3).any(|k| k != axis && (l[k] < ol[k] - tol || h[k] > oh[k] + tol)) {
                    exterior[i] = true;
                    peeled = true;
                }
            }
        }
        if !peeled {
            break;
        }
    }
    let on = match merge(&exterior, None) {
        Some(room) => (0..n)
            .map(|i| !exterior[i] && on_face(i, room).is_some())
            .collect(),
        None => vec![false; n],
    };
    (on, exterior)
}

/// The room frame of [`Frame::Walls`].
fn wall_frame(scene: &Scene, surfaces: &[Surface]) -> [V3; 3] {
    const BINS: usize = 900; // 0.1 degree over 90 degrees
    let mut hist = vec![0.0; BINS];
    let mut walls: Vec<(f64, f64)> = Vec::new(); // (azimuth mod 90 in degrees, area)
    for s in surfaces {
        let Primitive::Polygon { vertices } = &scene.objects[s.index].kind else {
            continue;
        };
        let n = crate::points::newell_normal(vertices);
        let area = 0.5 * dot(n, n).sqrt();
        let Some(u) = polygon_normal(vertices) else {
            continue;
        };
        if u[2].abs() > 0.01 {
            continue; // not vertical
        }
        let az = u[1].atan2(u[0]).to_degrees().rem_euclid(90.0);
        hist[((az * 10.0) as usize).min(BINS - 1)] += area;
        walls.push((az, area));
    }
    let Some(best) = (0..BINS).max_by(|&a, &b| hist[a].total_cmp(&hist[b])) else {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    };
    if hist[best] == 0.0 {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    let centre = (best as f64 + 0.5) / 10.0;
    // Circular (mod 90) difference, so 89.95 and 0.05 degrees are neighbours.
    let diff = |a: f64| (a - centre + 45.0).rem_euclid(90.0) - 45.0;
    let (mut sum, mut w) = (0.0, 0.0);
    for &(az, area) in &walls {
        let d = diff(az);
        if d.abs() <= 0.15 {
            sum += d * area;
            w += area;
        }
    }
    let theta = (centre + sum / w).to_radians();
    let (c, s) = (theta.cos(), theta.sin());
    [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
}

struct UnionFind(Vec<usize>);
impl UnionFind {
    fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] != x {
            self.0[x] = self.0[self.0[x]];
            x = self.0[x];
        }
        x
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb)] = ra.min(rb);
        }
    }
}

/// Groups of `items` (indices into `surfaces`) sharing a point within `tol`: points are
/// hashed to cells of size `tol` and compared with the 27 neighbouring cells.
fn connected(surfaces: &[Surface], items: &[usize], tol: f64) -> Vec<Vec<usize>> {
    let cell = tol.max(1e-9);
    let key = |p: V3| -> [i64; 3] { std::array::from_fn(|k| (p[k] / cell).floor() as i64) };
    let mut grid: HashMap<[i64; 3], Vec<(usize, V3)>> = HashMap::new();
    let mut uf = UnionFind((0..items.len()).collect());
    for (slot, &s) in items.iter().enumerate() {
        for &p in &surfaces[s].sampled.points {
            let c = key(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(v) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                            for &(other, q) in v {
                                let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                                if other != slot && dot(d, d) <= tol * tol {
                                    uf.union(slot, other);
                                }
                            }
                        }
                    }
                }
            }
        }
        for &p in &surfaces[s].sampled.points {
            grid.entry(key(p)).or_default().push((slot, p));
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (slot, &item) in items.iter().enumerate() {
        let r = uf.find(slot);
        groups.entry(r).or_default().push(item);
    }
    groups.into_values().collect()
}

/// Find the shell and the objects of `scene`, with each object's OBB and level.
pub fn analyse(scene: &Scene, opts: &Options) -> Result<Analysis> {
    opts.validate()?;
    let mut shell = Vec::new();
    let mut surfaces: Vec<Surface> = Vec::new();
    for (i, o) in scene.surfaces() {
        let glazing = scene.is_glazing(i);
        let pinned = opts.permanent.iter().any(|p| glob(p, &o.id));
        match sample(&o.kind) {
            Some(sampled) if !glazing && !pinned => surfaces.push(Surface { index: i, sampled }),
            _ => shell.push(i),
        }
    }
    let axes = match opts.frame {
        Frame::Axes => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        Frame::Walls => wall_frame(scene, &surfaces),
    };
    let framed: Vec<Vec<V3>> = surfaces
        .iter()
        .map(|s| {
            s.sampled
                .points
                .iter()
                .map(|&p| to_frame(p, &axes))
                .collect()
        })
        .collect();
    let (on_plane, exterior) = enclosing(scene, &framed, &surfaces, opts.tolerance);

    // Groups of surface slots.
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    let named = |key: &dyn Fn(usize) -> String| {
        let mut m: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        let mut order: Vec<String> = Vec::new();
        for (slot, s) in surfaces.iter().enumerate() {
            if exterior[slot] {
                continue;
            }
            let k = key(s.index);
            if !m.contains_key(&k) {
                order.push(k.clone());
            }
            m.entry(k).or_default().push(slot);
        }
        order
            .into_iter()
            .map(|k| {
                let v = m.remove(&k).unwrap_or_default();
                (k, v)
            })
            .collect::<Vec<_>>()
    };
    match &opts.grouping {
        Grouping::Prefix(sep) => {
            groups = named(&|i| {
                let id = &scene.objects[i].id;
                id.split_once(sep.as_str())
                    .map_or(id.clone(), |(a, _)| a.to_string())
            });
        }
        Grouping::Source => groups = named(&|i| scene.objects[i].loc.file.clone()),
        Grouping::Modifier | Grouping::Connectivity(_) => {
            let free: Vec<usize> = (0..surfaces.len())
                .filter(|&s| !exterior[s] && !on_plane[s])
                .collect();
            if let Grouping::Connectivity(tol) = opts.grouping {
                for g in connected(&surfaces, &free, tol) {
                    let id = scene.objects[surfaces[g[0]].index].id.clone();
                    groups.push((id, g));
                }
            } else {
                let mut m: BTreeMap<String, Vec<usize>> = BTreeMap::new();
                let mut order = Vec::new();
                for s in free {
                    let k = scene.objects[surfaces[s].index].modifier_name.clone();
                    if !m.contains_key(&k) {
                        order.push(k.clone());
                    }
                    m.entry(k).or_default().push(s);
                }
                for k in order {
                    let v = m.remove(&k).unwrap_or_default();
                    groups.push((k, v));
                }
            }
            shell.extend(
                (0..surfaces.len())
                    .filter(|&s| on_plane[s])
                    .map(|s| surfaces[s].index),
            );
        }
    }
    shell.extend(
        (0..surfaces.len())
            .filter(|&s| exterior[s])
            .map(|s| surfaces[s].index),
    );

    let mut objects = Vec::new();
    for (id, slots) in groups {
        if slots.is_empty() {
            continue;
        }
        if slots.iter().all(|&s| on_plane[s]) {
            shell.extend(slots.iter().map(|&s| surfaces[s].index));
            continue;
        }
        let points: Vec<V3> = slots
            .iter()
            .flat_map(|&s| surfaces[s].sampled.points.iter().copied())
            .collect();
        let hints: Vec<V3> = slots
            .iter()
            .flat_map(|&s| surfaces[s].sampled.normals.iter().copied())
            .collect();
        let obb = min_area_obb(&points, &hints);
        let area = obb.area();
        let mut members: Vec<usize> = slots.iter().map(|&s| surfaces[s].index).collect();
        members.sort_unstable();
        objects.push(GlodObject {
            id,
            members,
            level: opts.thresholds.level(area),
            obb,
            area,
        });
    }
    shell.sort_unstable();
    shell.dedup();
    Ok(Analysis { shell, objects })
}
