//! The arrangement of planes inside a box: every plane splits every cell it crosses, so the
//! cells are the convex polyhedra of the full arrangement (PolyFit's hypothesis generation,
//! Nan & Wonka 2017, "PolyFit: polygonal surface reconstruction from point clouds", ICCV,
//! with unbounded planes instead of their bounded supporting polygons).
//!
//! In a full arrangement two cells that touch across plane `k` share exactly the same facet:
//! any plane crossing the facet's interior would cross both cells and split them. So facets
//! are matched by plane and centroid.

use crate::geometry::Vec3;

/// A plane `n · x = d`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pl {
    pub n: Vec3,
    pub d: f64,
}

/// A face of a cell; `verts` counter-clockwise seen from outside the cell.
#[derive(Debug, Clone)]
struct CellFace {
    verts: Vec<Vec3>,
    /// Index of the plane, or `None` for the box.
    plane: Option<usize>,
}

/// One facet of the arrangement between two cells.
#[derive(Debug, Clone)]
pub struct Facet {
    /// Plane index, `None` on the box (then `neg` is the exterior).
    pub plane: Option<usize>,
    /// Polygon, counter-clockwise seen from the `pos` cell (its normal points into `pos`).
    pub polygon: Vec<Vec3>,
    /// Cell on the side the polygon normal points to.
    pub pos: usize,
    /// Cell on the other side (`None`: outside the box).
    pub neg: Option<usize>,
}

/// Cells and facets.
#[derive(Debug, Clone)]
pub struct Arrangement {
    pub cells: usize,
    pub facets: Vec<Facet>,
}

const TOL: f64 = 1e-9;

fn centroid(v: &[Vec3]) -> Vec3 {
    v.iter().fold(Vec3::ZERO, |a, &b| a + b) / v.len().max(1) as f64
}

/// Split one convex cell; `None` if the plane does not cross it.
fn split(
    cell: &[CellFace],
    pl: Pl,
    k: usize,
    scale: f64,
) -> Option<(Vec<CellFace>, Vec<CellFace>)> {
    let tol = TOL * scale;
    let side = |p: Vec3| pl.n.dot(p) - pl.d;
    let (mut any_pos, mut any_neg) = (false, false);
    for f in cell {
        for &v in &f.verts {
            let s = side(v);
            any_pos |= s > tol * 1e3;
            any_neg |= s < -tol * 1e3;
        }
    }
    if !(any_pos && any_neg) {
        return None;
    }
    let (mut pos, mut neg) = (Vec::new(), Vec::new());
    let mut cut: Vec<Vec3> = Vec::new();
    for f in cell {
        let n = f.verts.len();
        let (mut fp, mut fneg) = (Vec::new(), Vec::new());
        for i in 0..n {
            let (a, b) = (f.verts[i], f.verts[(i + 1) % n]);
            let (sa, sb) = (side(a), side(b));
            if sa >= -tol {
                fp.push(a);
            }
            if sa <= tol {
                fneg.push(a);
            }
            if sa.abs() <= tol {
                cut.push(a);
            }
            if (sa > tol && sb < -tol) || (sa < -tol && sb > tol) {
                let t = sa / (sa - sb);
                let x = a + (b - a) * t;
                fp.push(x);
                fneg.push(x);
                cut.push(x);
            }
        }
        if fp.len() >= 3 {
            pos.push(CellFace {
                verts: fp,
                plane: f.plane,
            });
        }
        if fneg.len() >= 3 {
            neg.push(CellFace {
                verts: fneg,
                plane: f.plane,
            });
        }
    }
    // The cap: the cut points in angular order around their centroid.
    let c = centroid(&cut);
    let u = if pl.n.x.abs() < 0.9 {
        Vec3::new(1.0, 0.0, 0.0)
    } else {
        Vec3::new(0.0, 1.0, 0.0)
    };
    let u = pl.n.cross(u).normalize();
    let v = pl.n.cross(u);
    let mut ang: Vec<(f64, Vec3)> = cut
        .iter()
        .map(|&p| ((p - c).dot(v).atan2((p - c).dot(u)), p))
        .collect();
    ang.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut cap: Vec<Vec3> = Vec::new();
    for (_, p) in ang {
        if cap
            .last()
            .is_none_or(|q: &Vec3| (*q - p).length() > tol * 1e3)
        {
            cap.push(p);
        }
    }
    while cap.len() > 1 && (cap[0] - cap[cap.len() - 1]).length() <= tol * 1e3 {
        cap.pop();
    }
    if cap.len() < 3 {
        return None;
    }
    // Counter-clockwise around +n: outward for the negative piece.
    neg.push(CellFace {
        verts: cap.clone(),
        plane: Some(k),
    });
    cap.reverse();
    pos.push(CellFace {
        verts: cap,
        plane: Some(k),
    });
    Some((pos, neg))
}

/// The arrangement of `planes` inside the box `lo..hi`.
pub fn build(planes: &[Pl], lo: Vec3, hi: Vec3) -> Arrangement {
    let p = |x, y, z| Vec3::new(x, y, z);
    let (a, b) = (lo, hi);
    let scale = (hi - lo).max_abs().max(1.0);
    let cube = vec![
        vec![
            p(a.x, a.y, a.z),
            p(a.x, b.y, a.z),
            p(b.x, b.y, a.z),
            p(b.x, a.y, a.z),
        ],
        vec![
            p(a.x, a.y, b.z),
            p(b.x, a.y, b.z),
            p(b.x, b.y, b.z),
            p(a.x, b.y, b.z),
        ],
        vec![
            p(a.x, a.y, a.z),
            p(b.x, a.y, a.z),
            p(b.x, a.y, b.z),
            p(a.x, a.y, b.z),
        ],
        vec![
            p(a.x, b.y, a.z),
            p(a.x, b.y, b.z),
            p(b.x, b.y, b.z),
            p(b.x, b.y, a.z),
        ],
        vec![
            p(a.x, a.y, a.z),
            p(a.x, a.y, b.z),
            p(a.x, b.y, b.z),
            p(a.x, b.y, a.z),
        ],
        vec![
            p(b.x, a.y, a.z),
            p(b.x, b.y, a.z),
            p(b.x, b.y, b.z),
            p(b.x, a.y, b.z),
        ],
    ];
    let mut cells: Vec<Vec<CellFace>> = vec![
        cube.into_iter()
            .map(|verts| CellFace { verts, plane: None })
            .collect(),
    ];
    for (k, &pl) in planes.iter().enumerate() {
        let mut next = Vec::with_capacity(cells.len() * 2);
        for c in cells {
            match split(&c, pl, k, scale) {
                Some((a, b)) => {
                    next.push(a);
                    next.push(b);
                }
                None => next.push(c),
            }
        }
        cells = next;
    }
    // Match facets: faces on plane k whose outward normal is -n_k belong to the pos cell.
    let mut facets = Vec::new();
    // Per plane: (cell, face centroid, face, cell on the positive side).
    type Half = (usize, Vec3, Vec<Vec3>, bool);
    let mut half: Vec<Vec<Half>> = vec![vec![]; planes.len()];
    for (ci, c) in cells.iter().enumerate() {
        for f in c {
            match f.plane {
                None => {
                    // Box face: outward normal points out of the box; seen from inside.
                    let mut poly = f.verts.clone();
                    poly.reverse();
                    facets.push(Facet {
                        plane: None,
                        polygon: poly,
                        pos: ci,
                        neg: None,
                    });
                }
                Some(k) => {
                    let n = crate::geometry::triangulate::newell_normal(&f.verts);
                    let is_pos = n.dot(planes[k].n) < 0.0;
                    half[k].push((ci, centroid(&f.verts), f.verts.clone(), is_pos));
                }
            }
        }
    }
    for (k, hs) in half.iter().enumerate() {
        for (ci, c, verts, is_pos) in hs.iter().filter(|h| h.3) {
            let _ = is_pos;
            let other = hs
                .iter()
                .filter(|h| !h.3)
                .min_by(|x, y| (x.1 - *c).length().total_cmp(&(y.1 - *c).length()));
            if let Some((nj, nc, _, _)) = other
                && (*nc - *c).length() < 1e-6 * scale
            {
                let mut poly = verts.clone();
                poly.reverse();
                facets.push(Facet {
                    plane: Some(k),
                    polygon: poly,
                    pos: *ci,
                    neg: Some(*nj),
                });
            }
        }
    }
    Arrangement {
        cells: cells.len(),
        facets,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polygon_area;

    #[test]
    fn three_planes_in_a_box_make_eight_cells_with_matched_facets() {
        let planes = [
            Pl {
                n: Vec3::new(1.0, 0.0, 0.0),
                d: 0.5,
            },
            Pl {
                n: Vec3::new(0.0, 1.0, 0.0),
                d: 0.3,
            },
            Pl {
                n: Vec3::new(0.0, 0.6, 0.8),
                d: 0.6,
            },
        ];
        let a = build(&planes, Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0));
        assert_eq!(a.cells, 8);
        // Box facets cover the box surface; inner facets of plane 0 cover its section.
        let box_area: f64 = a
            .facets
            .iter()
            .filter(|f| f.plane.is_none())
            .map(|f| polygon_area(&f.polygon))
            .sum();
        assert!((box_area - 6.0).abs() < 1e-9, "{box_area}");
        let p0: f64 = a
            .facets
            .iter()
            .filter(|f| f.plane == Some(0))
            .map(|f| polygon_area(&f.polygon))
            .sum();
        assert!((p0 - 1.0).abs() < 1e-9, "{p0}");
        for f in &a.facets {
            if let Some(k) = f.plane {
                let n = crate::geometry::triangulate::newell_normal(&f.polygon).normalize();
                assert!((n - planes[k].n).length() < 1e-9);
            }
        }
    }
}
