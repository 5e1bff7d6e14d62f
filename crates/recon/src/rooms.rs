//! Known test rooms for the scan simulator and the evaluation: rectangular, L-shaped,
//! non-orthogonal with a sloped ceiling, arched window, and cluttered with furniture; and
//! two surveys as real rooms often are (issue 19): glazing flush with the wall (no reveals),
//! a sloped ceiling over a non-rectangular plan, a rectangular and an arched window, and
//! clutter standing clear of the floor in front of a wall (a screen on feet, a desk top),
//! whose occlusion shadows on the wall look like windows: `flush` (a pentagon, three
//! stations) and `flushl` (an L, four stations).
//!
//! A [`RoomSpec`] is a floor outline (counter-clockwise from above, z = 0), a ceiling plane
//! `z = h0 + gx x + gy y`, windows given on outline edges, a reveal depth (wall thickness to
//! the glass), furniture boxes and scanner stations. [`RoomSpec::model`] gives the ground
//! truth [`Model`] (the GLoD0 shell with windows, as the seed's manual models are), and
//! [`RoomSpec::scene`] the scene to scan (the model plus the furniture).

use super::model::{Face, FaceKind, Frame, Model, Opening};
use super::radout;
use crate::error::Result;
use crate::geometry::Vec3;
use crate::scene::{Primitive, Scene};

/// A window on outline edge `edge` (from vertex `edge` to `edge + 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct WindowSpec {
    pub edge: usize,
    /// Distance of the window's left side (seen from inside) from the edge's start.
    pub offset: f64,
    pub width: f64,
    pub sill: f64,
    /// Height of the rectangular part.
    pub height: f64,
    /// A semicircular head of radius `width / 2` on top of the rectangle.
    pub arched: bool,
}

/// A furniture box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxSpec {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

#[derive(Debug, Clone, PartialEq)]
pub struct RoomSpec {
    pub name: String,
    pub outline: Vec<[f64; 2]>,
    /// Ceiling plane `z = c[0] + c[1] x + c[2] y`.
    pub ceiling: [f64; 3],
    pub windows: Vec<WindowSpec>,
    pub reveal_depth: f64,
    pub furniture: Vec<BoxSpec>,
    pub stations: Vec<[f64; 3]>,
}

/// Names of the built-in rooms.
pub const ROOMS: [&str; 7] = [
    "rect",
    "lshape",
    "slanted",
    "arched",
    "cluttered",
    "flush",
    "flushl",
];

fn bx(lo: [f64; 3], hi: [f64; 3]) -> BoxSpec {
    BoxSpec { lo, hi }
}

/// A table: a top `[x0, y0] .. [x1, y1]` from `z` to `z + 0.04` on four 5 cm legs.
fn table(x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> Vec<BoxSpec> {
    let leg = |x: f64, y: f64| bx([x, y, 0.0], [x + 0.05, y + 0.05, z]);
    vec![
        bx([x0, y0, z], [x1, y1, z + 0.04]),
        leg(x0, y0),
        leg(x1 - 0.05, y0),
        leg(x0, y1 - 0.05),
        leg(x1 - 0.05, y1 - 0.05),
    ]
}

/// A free-standing board (a whiteboard or pin board on a stand) 4 cm thick from `z0` to `z1`,
/// parallel to x from `x0` to `x1` at `y`, on two feet: its shadow on the wall behind starts
/// above the floor, as a window's does.
fn screen_x(x0: f64, x1: f64, y: f64, z0: f64, z1: f64) -> Vec<BoxSpec> {
    let foot = |x: f64| bx([x, y - 0.15, 0.0], [x + 0.04, y + 0.19, z0]);
    vec![
        bx([x0, y, z0], [x1, y + 0.04, z1]),
        foot(x0 + 0.1),
        foot(x1 - 0.14),
    ]
}

fn win(edge: usize, offset: f64, width: f64, sill: f64, height: f64) -> WindowSpec {
    WindowSpec {
        edge,
        offset,
        width,
        sill,
        height,
        arched: false,
    }
}

impl RoomSpec {
    /// A built-in room by name (see [`ROOMS`]).
    pub fn named(name: &str) -> Option<RoomSpec> {
        let base = |outline: Vec<[f64; 2]>, windows, stations| RoomSpec {
            name: name.to_string(),
            outline,
            ceiling: [2.7, 0.0, 0.0],
            windows,
            reveal_depth: 0.25,
            furniture: vec![],
            stations,
        };
        Some(match name {
            // 5 x 4 x 2.7 m office, two windows south, one west.
            "rect" => base(
                vec![[0.0, 0.0], [5.0, 0.0], [5.0, 4.0], [0.0, 4.0]],
                vec![
                    win(0, 0.8, 1.4, 0.9, 1.4),
                    win(0, 2.8, 1.4, 0.9, 1.4),
                    win(3, 1.2, 1.6, 1.0, 1.2),
                ],
                vec![[2.0, 1.8, 1.5], [3.6, 2.6, 1.4]],
            ),
            "lshape" => base(
                vec![
                    [0.0, 0.0],
                    [6.0, 0.0],
                    [6.0, 3.0],
                    [3.0, 3.0],
                    [3.0, 6.0],
                    [0.0, 6.0],
                ],
                vec![
                    win(0, 1.0, 1.8, 0.8, 1.5),
                    win(4, 1.0, 1.2, 0.9, 1.3),
                    win(1, 0.8, 1.4, 0.9, 1.3),
                ],
                vec![[1.5, 1.5, 1.5], [4.5, 1.5, 1.5], [1.5, 4.5, 1.5]],
            ),
            // Non-orthogonal plan, ceiling rising 0.2 m per metre towards +x.
            "slanted" => RoomSpec {
                ceiling: [2.5, 0.2, 0.0],
                ..base(
                    vec![[0.0, 0.0], [6.0, 0.4], [5.4, 4.6], [0.4, 4.0]],
                    vec![win(0, 1.0, 1.5, 0.9, 1.3), win(1, 1.2, 1.2, 1.0, 1.4)],
                    vec![[2.0, 2.0, 1.5], [4.2, 2.4, 1.5]],
                )
            },
            "arched" => base(
                vec![[0.0, 0.0], [6.0, 0.0], [6.0, 4.5], [0.0, 4.5]],
                vec![
                    WindowSpec {
                        arched: true,
                        ..win(0, 1.0, 1.2, 0.8, 1.1)
                    },
                    WindowSpec {
                        arched: true,
                        ..win(0, 3.6, 1.2, 0.8, 1.1)
                    },
                ],
                vec![[3.0, 2.2, 1.5], [1.5, 3.0, 1.5]],
            )
            .with_ceiling(3.2),
            "cluttered" => RoomSpec {
                furniture: vec![
                    // Desks, a tall cabinet against the north wall, a low shelf under a window.
                    BoxSpec {
                        lo: [0.6, 1.6, 0.0],
                        hi: [2.2, 2.4, 0.75],
                    },
                    BoxSpec {
                        lo: [3.0, 1.6, 0.0],
                        hi: [4.6, 2.4, 0.75],
                    },
                    BoxSpec {
                        lo: [1.0, 3.55, 0.0],
                        hi: [2.2, 4.0, 2.0],
                    },
                    BoxSpec {
                        lo: [3.2, 0.0, 0.0],
                        hi: [4.6, 0.4, 0.8],
                    },
                ],
                ..RoomSpec::named("rect")?
            }
            .renamed(name),
            // A pentagon (one corner cut off) under a ceiling rising 0.12 m per metre to the
            // north, both windows flush: a rectangle south, an arch west. A board on a stand
            // 0.55 m in front of the north wall, a desk along the east wall, a low cabinet
            // against the south wall.
            "flush" => RoomSpec {
                ceiling: [2.5, 0.0, 0.12],
                reveal_depth: 0.0,
                furniture: [
                    screen_x(1.2, 2.7, 4.45, 0.65, 1.95),
                    table(5.75, 0.8, 6.45, 2.4, 0.72),
                    vec![bx([4.0, 0.0, 0.0], [5.2, 0.45, 0.8])],
                ]
                .concat(),
                ..base(
                    vec![[0.0, 0.0], [6.5, 0.0], [6.5, 3.4], [4.9, 5.0], [0.0, 5.0]],
                    vec![
                        win(0, 1.2, 1.6, 0.85, 1.3),
                        WindowSpec {
                            arched: true,
                            ..win(4, 1.6, 1.1, 0.9, 1.0)
                        },
                    ],
                    vec![[2.3, 2.0, 1.5], [4.7, 2.6, 1.45], [1.4, 3.2, 1.55]],
                )
            },
            // An L under a ceiling sloping in both directions, four stations; flush windows:
            // an arch south, rectangles north and east. A board on a stand 0.45 m in front of
            // the south wall beside the arch, a desk under the north window.
            "flushl" => RoomSpec {
                ceiling: [2.55, 0.05, 0.04],
                reveal_depth: 0.0,
                furniture: [
                    screen_x(3.4, 5.6, 0.45, 0.6, 1.9),
                    table(0.5, 5.6, 2.6, 6.3, 0.74),
                ]
                .concat(),
                ..base(
                    vec![
                        [0.0, 0.0],
                        [7.0, 0.0],
                        [7.0, 3.2],
                        [3.4, 3.2],
                        [3.4, 6.5],
                        [0.0, 6.5],
                    ],
                    vec![
                        WindowSpec {
                            arched: true,
                            ..win(0, 1.2, 1.2, 0.9, 1.05)
                        },
                        win(4, 1.0, 1.5, 1.0, 1.2),
                        win(1, 0.9, 1.4, 0.9, 1.3),
                    ],
                    vec![
                        [1.6, 1.6, 1.5],
                        [5.3, 1.9, 1.45],
                        [1.7, 4.8, 1.55],
                        [2.4, 2.9, 1.5],
                    ],
                )
            },
            _ => return None,
        })
    }

    fn with_ceiling(mut self, h: f64) -> RoomSpec {
        self.ceiling = [h, 0.0, 0.0];
        self
    }
    fn renamed(mut self, n: &str) -> RoomSpec {
        self.name = n.to_string();
        self
    }

    fn ceiling_at(&self, p: [f64; 2]) -> f64 {
        self.ceiling[0] + self.ceiling[1] * p[0] + self.ceiling[2] * p[1]
    }

    /// The ground-truth shell with its windows.
    pub fn model(&self) -> Model {
        let o = &self.outline;
        let n = o.len();
        let v = |p: [f64; 2], z: f64| Vec3::new(p[0], p[1], z);
        let mut faces = vec![
            Face {
                name: "floor".into(),
                kind: FaceKind::Floor,
                polygon: o.iter().map(|&p| v(p, 0.0)).collect(),
            },
            Face {
                name: "ceiling".into(),
                kind: FaceKind::Ceiling,
                polygon: o.iter().rev().map(|&p| v(p, self.ceiling_at(p))).collect(),
            },
        ];
        for i in 0..n {
            let (a, b) = (o[i], o[(i + 1) % n]);
            faces.push(Face {
                name: format!("wall{i}"),
                kind: FaceKind::Wall,
                polygon: vec![
                    v(b, 0.0),
                    v(a, 0.0),
                    v(a, self.ceiling_at(a)),
                    v(b, self.ceiling_at(b)),
                ],
            });
        }
        let mut openings = Vec::new();
        for (k, w) in self.windows.iter().enumerate() {
            let (a, b) = (o[w.edge], o[(w.edge + 1) % n]);
            let dir = (v(b, 0.0) - v(a, 0.0)).normalize();
            let left = v(a, 0.0) + dir * w.offset;
            let right = left + dir * w.width;
            let up = Vec3::new(0.0, 0.0, 1.0);
            // Counter-clockwise seen from inside (the left of the edge direction).
            let mut outline = vec![left + up * w.sill, left + up * (w.sill + w.height)];
            if w.arched {
                let c = (left + right) * 0.5 + up * (w.sill + w.height);
                let r = w.width * 0.5;
                for s in 1..16 {
                    let t = std::f64::consts::PI * s as f64 / 16.0;
                    outline.push(c - dir * (r * t.cos()) + up * (r * t.sin()));
                }
            }
            outline.push(right + up * (w.sill + w.height));
            outline.push(right + up * w.sill);
            openings.push(Opening {
                face: 2 + w.edge,
                name: format!("window{k}"),
                outline,
                depth: None,
            });
        }
        Model {
            faces,
            openings,
            reveal_depth: self.reveal_depth,
        }
    }

    /// The scene to scan: the model's polygons and the furniture (material `furniture`).
    pub fn scene(&self) -> Result<Scene> {
        let mut polys = self.model().polygons();
        super::model::fix_t_junctions(&mut polys, 1e-6);
        let mut s = radout::to_scene(&polys, None)?;
        if !self.furniture.is_empty() {
            s.push(
                "void",
                "furniture",
                Primitive::Plastic {
                    color: vec![0.3; 3],
                    spec: 0.0,
                    rough: 0.0,
                },
            )?;
        }
        for (k, b) in self.furniture.iter().enumerate() {
            for (j, quad) in box_faces(b).into_iter().enumerate() {
                s.push(
                    "furniture",
                    format!("furniture{k}_{j}"),
                    Primitive::Polygon {
                        vertices: quad.iter().map(|p| p.to_array()).collect(),
                    },
                )?;
            }
        }
        Ok(s)
    }

    /// Into-room frame of wall `edge` (for tests).
    pub fn wall_frame(&self, edge: usize) -> Frame {
        Frame::of_polygon(&self.model().faces[2 + edge].polygon)
    }
}

/// The six outward-facing quads of a box.
fn box_faces(b: &BoxSpec) -> Vec<[Vec3; 4]> {
    let [x0, y0, z0] = b.lo;
    let [x1, y1, z1] = b.hi;
    let p = Vec3::new;
    vec![
        [p(x0, y0, z0), p(x0, y1, z0), p(x1, y1, z0), p(x1, y0, z0)],
        [p(x0, y0, z1), p(x1, y0, z1), p(x1, y1, z1), p(x0, y1, z1)],
        [p(x0, y0, z0), p(x1, y0, z0), p(x1, y0, z1), p(x0, y0, z1)],
        [p(x0, y1, z0), p(x0, y1, z1), p(x1, y1, z1), p(x1, y1, z0)],
        [p(x0, y0, z0), p(x0, y0, z1), p(x0, y1, z1), p(x0, y1, z0)],
        [p(x1, y0, z0), p(x1, y1, z0), p(x1, y1, z1), p(x1, y0, z1)],
    ]
}

#[cfg(test)]
mod tests {
    use super::super::model::{fix_t_junctions, watertight};
    use super::*;
    use crate::geometry::polygon_area;
    use crate::geometry::triangulate::newell_normal;

    #[test]
    fn every_test_room_is_closed_with_windows_facing_in() {
        for name in ROOMS {
            let r = RoomSpec::named(name).unwrap();
            let m = r.model();
            for o in &m.openings {
                let n = newell_normal(&o.outline).normalize();
                let f = Frame::of_polygon(&m.faces[o.face].polygon);
                assert!((n - f.n).length() < 1e-9, "{name} {}", o.name);
            }
            let mut polys = m.polygons();
            fix_t_junctions(&mut polys, 1e-6);
            let w = watertight(&polys, 1e-6);
            assert!(w.is_closed(), "{name}: {w:?}");
            assert!(m.opening_area() > 1.0 && polygon_area(&m.faces[0].polygon) > 15.0);
            r.scene().unwrap();
        }
    }
}
