//! What the scanner stations could see: free space and occlusion, for telling windows from
//! occlusion shadows (issue 19).
//!
//! A gap in a wall's points has one of three causes: the wall is not there (an opening: the
//! beams went through, and glazing returns almost nothing), something stood between every
//! station and that part of the wall (an occlusion shadow of clutter), or no station looked at
//! it closely enough. Only the first is a window. The scan itself says which: a laser return
//! at range r along a beam means the beam crossed free space up to r, so the stations' lines
//! of sight to a gap tell an opening (some station had a clear, not too oblique view and got
//! no return from the wall) from a shadow (every line of sight ends on observed geometry
//! before the wall). This is the occupancy labelling of Adán & Huber ("3D reconstruction of
//! interior wall surfaces under occlusion and clutter", 3DIMPVT 2011) and Xiong, Adán,
//! Akinci & Huber ("Automatic creation of semantically rich 3D building models from laser
//! scanner data", Automation in Construction 31, 2013): a wall patch is *occupied* (points),
//! *occluded* (the ray from the scanner hits something first) or *empty* (the ray reaches it
//! and returns nothing); openings are empty patches. Previtali, Barazzetti, Brumana & Scaioni
//! ("Towards automatic indoor reconstruction of cluttered building rooms from point clouds",
//! ISPRS Annals II-5, 2014) use the same ray test with the scanner positions.
//!
//! Here:
//! - what blocks a line of sight is (a) the shell's other faces, intersected exactly (an L's
//!   re-entrant walls hide one wing from the other), and (b) *clutter*: the points inside the
//!   shell that lie on no shell face (within `band` of it), in an occupancy grid. A grid cell is occupied when
//!   its 3 x 3 x 3 neighbourhood holds at least [`MIN_POINTS`] clutter points: the dilation
//!   closes the sampling gaps of a surface (a ray cannot slip between two samples), and the
//!   count ignores isolated points (noise, flying pixels), which block no view;
//! - a station *faces* a point of a wall when it is on the room side of the wall, within
//!   [`MAX_RANGE`], sees it at no more than [`MAX_INCIDENCE_DEG`] from the normal (beyond
//!   that, returns thin out until the wall itself looks like a gap), and, when its angular
//!   step is known, would have put its samples there closer together than the detector's gap
//!   size ([`Views::with_steps`]);
//! - the ray is marched in half-cell steps from 0.1 m in front of the station (no clutter
//!   is scanned at the tripod) to the wall.
//!
//! When the input carries no station positions (XYZ, LAS, PLY without `comment station`
//! lines; E57 has its scan poses), `rrecon` takes `--stations`, else it assumes one station
//! where a single-scan survey would stand it: 1.5 m above the floor at the point of the floor
//! farthest from the walls ([`assumed_station`]), and says so.

use super::model::{FaceKind, Frame, Model};
use crate::geometry::Vec3;

/// Neighbourhood count from which a grid cell blocks a view (see the module documentation):
/// a surface sampled at the cell size puts about 9 points into any 3 x 3 x 3 block it
/// crosses, an isolated point 1.
pub const MIN_POINTS: u8 = 3;
/// Beyond this range a station is not counted as looking at a wall, metres (phase-based
/// scanners such as the FARO Focus or Leica RTC360 reach 60-130 m; rooms are far smaller).
pub const MAX_RANGE: f64 = 60.0;
/// Largest angle between a line of sight and the wall normal at which a station is expected
/// to have sampled the wall, degrees. At 75 degrees the spacing of a scan's points on the wall
/// is 1/cos = 3.9 times the spacing at normal incidence: 3.5 cm at 5 m for a 0.1 degree
/// scan, still under the 8 cm gap size of [`super::openings`].
pub const MAX_INCIDENCE_DEG: f64 = 75.0;
/// At most this many grid cells (bytes); the cell grows for very large scenes.
const MAX_CELLS: usize = 1 << 25;

/// Counts of clutter points per cell neighbourhood over the shell's bounding box.
#[derive(Debug, Clone)]
pub struct Occupancy {
    lo: Vec3,
    cell: f64,
    dims: [usize; 3],
    count: Vec<u8>,
}

impl Occupancy {
    /// The grid over `lo..hi` with cells of at least `cell` metres, from `points`.
    pub fn new(lo: Vec3, hi: Vec3, cell: f64, points: impl Iterator<Item = [f64; 3]>) -> Self {
        let size = hi - lo;
        let mut cell = cell.max(1e-3);
        let dims = loop {
            let d = [size.x, size.y, size.z].map(|s| ((s / cell).ceil() as usize).max(1) + 2);
            if d[0].saturating_mul(d[1]).saturating_mul(d[2]) <= MAX_CELLS {
                break d;
            }
            cell *= 1.25;
        };
        // One cell of border so that dilation never wraps.
        let lo = lo - Vec3::new(cell, cell, cell);
        let mut g = Occupancy {
            lo,
            cell,
            dims,
            count: vec![0; dims[0] * dims[1] * dims[2]],
        };
        for p in points {
            let Some([i, j, k]) = g.index(Vec3::from(p)) else {
                continue;
            };
            for dk in k.saturating_sub(1)..=(k + 1).min(dims[2] - 1) {
                for dj in j.saturating_sub(1)..=(j + 1).min(dims[1] - 1) {
                    for di in i.saturating_sub(1)..=(i + 1).min(dims[0] - 1) {
                        let c = &mut g.count[(dk * dims[1] + dj) * dims[0] + di];
                        *c = c.saturating_add(1);
                    }
                }
            }
        }
        g
    }

    pub fn cell(&self) -> f64 {
        self.cell
    }

    fn index(&self, p: Vec3) -> Option<[usize; 3]> {
        let d = (p - self.lo) / self.cell;
        let ijk = [d.x, d.y, d.z];
        // NaN (a non-finite point) is outside too.
        if !ijk.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return None;
        }
        let ijk = ijk.map(|v| v as usize);
        (0..3).all(|a| ijk[a] < self.dims[a]).then_some(ijk)
    }

    /// Does `p` lie in an occupied cell?
    pub fn occupied(&self, p: Vec3) -> bool {
        self.index(p).is_some_and(|[i, j, k]| {
            self.count[(k * self.dims[1] + j) * self.dims[0] + i] >= MIN_POINTS
        })
    }

    /// The first occupied sample of `from + t dir` for t in `t0..t1` (dir a unit vector).
    pub fn first_hit(&self, from: Vec3, dir: Vec3, t0: f64, t1: f64) -> Option<f64> {
        let step = 0.5 * self.cell;
        let mut t = t0;
        while t < t1 {
            if self.occupied(from + dir * t) {
                return Some(t);
            }
            t += step;
        }
        None
    }
}

/// How stations see one point of a wall.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sight {
    /// Stations facing the point (room side, in range, not too oblique).
    pub facing: usize,
    /// Of those, the stations whose line of sight reaches it unobstructed.
    pub clear: usize,
}

/// The stations, the shell faces and the clutter grid: everything the line-of-sight tests
/// need.
#[derive(Debug, Clone)]
pub struct Views {
    pub stations: Vec<Vec3>,
    /// Angular step of each station, radians, when known ([`Views::with_steps`]).
    steps: Vec<Option<f64>>,
    /// The gap size of the window detector, metres.
    gap: f64,
    faces: Vec<(Frame, Vec<[f64; 2]>)>,
    pub grid: Occupancy,
}

impl Views {
    /// Views of `model`'s shell from `stations`, with clutter from `points` (those more than
    /// `band` from every face); grid cells of `cell` metres.
    pub fn new(
        model: &Model,
        points: &[[f64; 3]],
        stations: &[[f64; 3]],
        band: f64,
        cell: f64,
    ) -> Self {
        let faces: Vec<(Frame, Vec<[f64; 2]>)> = model
            .faces
            .iter()
            .map(|f| {
                let fr = Frame::of_polygon(&f.polygon);
                let q = f.polygon.iter().map(|&v| fr.to_2d(v)).collect();
                (fr, q)
            })
            .collect();
        let (mut lo, mut hi) = (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY));
        for v in model.faces.iter().flat_map(|f| f.polygon.iter()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let on_shell = |p: Vec3| {
            faces.iter().any(|(fr, poly)| {
                fr.height(p).abs() <= band && in_polygon_grown(poly, fr.to_2d(p), band)
            })
        };
        // Inside the shell: an odd number of faces crossed by a ray from the point (in a
        // direction no face or edge of a room is parallel to). Points outside (reveals, the
        // outside seen through windows, other rooms) block no line of sight from inside, and
        // the reveals', dilated, would reach into the room at the openings' edges.
        let dir = Vec3::new(0.0123, 0.0217, 1.0).normalize();
        let inside = |p: Vec3| {
            let boxed = p.x >= lo.x
                && p.y >= lo.y
                && p.z >= lo.z
                && p.x <= hi.x
                && p.y <= hi.y
                && p.z <= hi.z;
            boxed
                && faces
                    .iter()
                    .filter(|(fr, poly)| {
                        let denom = fr.n.dot(dir);
                        let t = -fr.height(p) / denom;
                        denom.abs() > 1e-12
                            && t > 0.0
                            && in_polygon_grown(poly, fr.to_2d(p + dir * t), 0.0)
                    })
                    .count()
                    % 2
                    == 1
        };
        let clutter: Vec<[f64; 3]> = points
            .iter()
            .copied()
            .filter(|&p| inside(Vec3::from(p)) && !on_shell(Vec3::from(p)))
            .collect();
        let grid = Occupancy::new(lo, hi, cell, clutter.into_iter());
        Views {
            stations: stations.iter().map(|&s| Vec3::from(s)).collect(),
            steps: vec![],
            gap: f64::INFINITY,
            faces,
            grid,
        }
    }

    /// With the stations' angular steps (radians, [`super::preprocess::angular_steps`]) and
    /// the window detector's gap size: a station then faces a wall point only where its own
    /// samples lie closer than `gap / √2` (range × step / cos(incidence)), the spacing of a
    /// square grid whose triangles' empty circles reach the gap size. Farther apart, that
    /// station alone leaves gaps there, and its clear view proves nothing (a coarse scan's
    /// sparse far walls).
    pub fn with_steps(mut self, steps: Vec<Option<f64>>, gap: f64) -> Self {
        self.steps = steps;
        self.gap = gap;
        self
    }

    /// Is the line of sight from `station` to `target` free of the shell's faces other than
    /// `face` and of clutter? `target` lies on face `face` or beyond it (a return through an
    /// opening); the test ends where the line meets that face's plane.
    pub fn clear(&self, station: Vec3, target: Vec3, face: usize) -> bool {
        let (fr, _) = &self.faces[face];
        let (hs, ht) = (fr.height(station), fr.height(target));
        if hs <= 0.0 || ht >= hs {
            return false;
        }
        let d = target - station;
        let len = d.length();
        if len <= 1e-9 {
            return false;
        }
        let dir = d / len;
        // Where the line crosses the face's plane.
        let end = len * hs / (hs - ht);
        for (k, (g, poly)) in self.faces.iter().enumerate() {
            if k == face {
                continue;
            }
            let denom = g.n.dot(dir);
            if denom.abs() < 1e-12 {
                continue;
            }
            let t = -g.height(station) / denom;
            // Crossings within a few millimetres of the end are the corner the face shares
            // with the wall, not an obstruction.
            if t > 1e-6
                && t < end - 5e-3
                && in_polygon_grown(poly, g.to_2d(station + dir * t), -1e-3)
            {
                return false;
            }
        }
        self.grid.first_hit(station, dir, 0.1, end).is_none()
    }

    /// How the stations see `target`, a point of face `face`.
    pub fn sight(&self, target: Vec3, face: usize) -> Sight {
        let (fr, _) = &self.faces[face];
        let cos_max = MAX_INCIDENCE_DEG.to_radians().cos();
        let mut s = Sight::default();
        for (i, &st) in self.stations.iter().enumerate() {
            let h = fr.height(st);
            let r = (st - target).length();
            if h <= 0.05 || r > MAX_RANGE || h < cos_max * r {
                continue;
            }
            if let Some(Some(step)) = self.steps.get(i)
                && r * step * (r / h) > self.gap * std::f64::consts::FRAC_1_SQRT_2
            {
                continue;
            }
            s.facing += 1;
            if self.clear(st, target, face) {
                s.clear += 1;
            }
        }
        s
    }
}

/// Point in polygon, the polygon grown (or shrunk, `grow` < 0) by `grow` metres: inside, or
/// within `grow` of an edge.
fn in_polygon_grown(poly: &[[f64; 2]], q: [f64; 2], grow: f64) -> bool {
    let inside = super::openings::in_polygon(poly, q);
    let n = poly.len();
    let near = (0..n)
        .map(|i| segment_distance(poly[i], poly[(i + 1) % n], q))
        .fold(f64::INFINITY, f64::min);
    if grow >= 0.0 {
        inside || near <= grow
    } else {
        inside && near > -grow
    }
}

fn segment_distance(a: [f64; 2], b: [f64; 2], q: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((q[0] - a[0] - t * dx).powi(2) + (q[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// Where a single-scan survey stands its scanner when the input does not say: 1.5 m above the
/// floor (at most 0.3 m under the ceiling's lowest corner) at the floor point farthest from
/// the floor's edges, found on a 40 x 40 grid (the centroid of an L lies outside it).
pub fn assumed_station(model: &Model) -> Option<[f64; 3]> {
    let floor = model.faces.iter().find(|f| f.kind == FaceKind::Floor)?;
    let fr = Frame::of_polygon(&floor.polygon);
    let poly: Vec<[f64; 2]> = floor.polygon.iter().map(|&v| fr.to_2d(v)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in &poly {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let n = 40;
    let mut best: Option<([f64; 2], f64)> = None;
    for i in 0..n {
        for j in 0..n {
            let q = [
                lo[0] + (i as f64 + 0.5) / n as f64 * (hi[0] - lo[0]),
                lo[1] + (j as f64 + 0.5) / n as f64 * (hi[1] - lo[1]),
            ];
            if !in_polygon_grown(&poly, q, 0.0) {
                continue;
            }
            let d = (0..poly.len())
                .map(|k| segment_distance(poly[k], poly[(k + 1) % poly.len()], q))
                .fold(f64::INFINITY, f64::min);
            if best.is_none_or(|b| d > b.1) {
                best = Some((q, d));
            }
        }
    }
    let (q, _) = best?;
    let p = fr.to_3d(q);
    let ceiling = model
        .faces
        .iter()
        .filter(|f| f.kind == FaceKind::Ceiling)
        .flat_map(|f| f.polygon.iter().map(|v| v.z))
        .fold(f64::INFINITY, f64::min);
    let z = (p.z + 1.5).min(ceiling - 0.3).max(p.z + 0.2);
    Some([p.x, p.y, z])
}

#[cfg(test)]
mod tests {
    use super::super::rooms::RoomSpec;
    use super::*;

    /// A 5 x 4 m room, one station; a 1 m box standing 1 m in front of the east wall hides
    /// part of that wall, and nothing hides the west wall.
    #[test]
    fn a_box_hides_the_wall_behind_it_and_nothing_else() {
        let model = RoomSpec::named("rect").unwrap().model();
        let mut clutter = Vec::new();
        // The box's faces sampled every 2 cm: x 3.0..3.04 (a board), y 1.5..2.5, z 0.5..1.5.
        for i in 0..=50 {
            for j in 0..=50 {
                let (y, z) = (1.5 + i as f64 * 0.02, 0.5 + j as f64 * 0.02);
                clutter.push([3.0, y, z]);
                clutter.push([3.04, y, z]);
            }
        }
        let station = [1.0, 2.0, 1.0];
        let v = Views::new(&model, &clutter, &[station], 0.03, 0.03);
        let east = model.faces.iter().position(|f| f.name == "wall1").unwrap();
        let west = model.faces.iter().position(|f| f.name == "wall3").unwrap();
        // Straight behind the board: facing, blocked.
        assert_eq!(
            v.sight(Vec3::new(5.0, 2.0, 1.0), east),
            Sight {
                facing: 1,
                clear: 0
            }
        );
        // Beside the shadow: clear.
        assert_eq!(
            v.sight(Vec3::new(5.0, 0.5, 1.0), east),
            Sight {
                facing: 1,
                clear: 1
            }
        );
        assert_eq!(
            v.sight(Vec3::new(0.0, 2.0, 1.0), west),
            Sight {
                facing: 1,
                clear: 1
            }
        );
        // Grazing (more than 75 degrees from the normal): not facing.
        let north = model.faces.iter().position(|f| f.name == "wall2").unwrap();
        let near_north = Views::new(&model, &[], &[[1.0, 3.8, 1.0]], 0.03, 0.03);
        assert_eq!(near_north.sight(Vec3::new(4.5, 4.0, 1.0), north).facing, 0);
        assert_eq!(near_north.sight(Vec3::new(1.2, 4.0, 1.0), north).facing, 1);
        // Isolated points block nothing.
        let lone = Views::new(&model, &[[3.0, 2.0, 1.0]], &[station], 0.03, 0.03);
        assert_eq!(lone.sight(Vec3::new(5.0, 2.0, 1.0), east).clear, 1);
    }

    #[test]
    fn an_l_hides_one_wing_from_the_other_and_the_assumed_station_is_inside() {
        let model = RoomSpec::named("lshape").unwrap().model();
        // A station in the north wing (x < 3, y > 3): the east wing's end wall (x = 6,
        // y 0..3) lies behind the re-entrant wall x = 3 from there; the south wall does not.
        let v = Views::new(&model, &[], &[[1.5, 4.5, 1.5]], 0.03, 0.05);
        let east = model.faces.iter().position(|f| f.name == "wall1").unwrap();
        let south = model.faces.iter().position(|f| f.name == "wall0").unwrap();
        assert_eq!(
            v.sight(Vec3::new(6.0, 1.5, 1.0), east),
            Sight {
                facing: 1,
                clear: 0
            }
        );
        assert_eq!(
            v.sight(Vec3::new(1.5, 0.0, 1.0), south),
            Sight {
                facing: 1,
                clear: 1
            }
        );
        let s = assumed_station(&model).unwrap();
        assert!(s[0] < 3.0 || s[1] < 3.0, "{s:?} lies in the L");
        assert!((s[2] - 1.5).abs() < 1e-9);
    }
}
