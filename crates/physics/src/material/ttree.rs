//! # Tensor-tree BSDFs: lookup (Radiance `src/common/bsdf_t.c`, read to learn it)
//!
//! `bsdf2ttree` and `genBSDF -t3|-t4` store a BSDF as a tree over the unit hypercube of
//! incident x outgoing directions, each hemisphere flattened to the unit square by the
//! Shirley-Chiu concentric map (`disk2square`, Shirley & Chiu 1997, "A low distortion map
//! between disk and square"). Rank 4 (anisotropic): `(disk2square(-in.xy),
//! disk2square(out.xy))`. Rank 3 (isotropic): the outgoing direction is first turned about
//! the normal so the incident one lies at azimuth 180 degrees; coordinates
//! `(0.5 - |in.xy| / 2, disk2square(out'.xy))`. A branch node halves every dimension
//! (child index bit `d` set when coordinate `d` is in the upper half); a leaf is a grid of
//! `2^k` cells per dimension, the last dimension fastest. Values are the BSDF (1/sr), no
//! interpolation.
//!
//! Components and sides follow Radiance: WINDOW's `Transmission Front` is Radiance's back
//! incident transmission, and so on (see [`super::bsdf`]); transmission queries with the
//! vectors on the "wrong" sides use reciprocity (the two vectors swap).
//!
//! What exists: [`TreeBsdf::eval`] (photopic). Not yet: sampling (`SDsampTreCDist`), the
//! Lambertian split, CIE-u/v colour, and the material's use of tree data (a `BSDF`
//! material with tensor-tree data is refused at scene compile time).

use crate::error::{Error, Location, Result};
use rdaylight_formats::bsdf::{BsdfXml, Channel, Direction, ScatteringData, TreeNode};

/// One stored tree and the side it serves.
#[derive(Debug, Clone, PartialEq)]
struct Comp {
    rank: usize,
    root: TreeNode,
}

/// The photopic trees of a file, in Radiance's orientation (front = the surface normal's
/// side = WINDOW's back).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TreeBsdf {
    rf: Option<Comp>,
    rb: Option<Comp>,
    tf: Option<Comp>,
    tb: Option<Comp>,
}

/// Radiance's `disk2square`: a point of the unit disc to the unit square.
pub fn disk2square(x: f64, y: f64) -> [f64; 2] {
    use std::f64::consts::PI;
    let r = (x * x + y * y).sqrt();
    let mut phi = y.atan2(x);
    if phi < -PI / 4.0 {
        phi += 2.0 * PI;
    }
    let (a, b) = if phi < PI / 4.0 {
        (r, phi * r / (PI / 4.0))
    } else if phi < 3.0 * PI / 4.0 {
        (-(phi - PI / 2.0) * r / (PI / 4.0), r)
    } else if phi < 5.0 * PI / 4.0 {
        (-r, (phi - PI) * -r / (PI / 4.0))
    } else {
        (-(phi - 3.0 * PI / 2.0) * -r / (PI / 4.0), -r)
    };
    let k = 0.5 / 0.999_999_999_999_9;
    [a * k + 0.5, b * k + 0.5]
}

/// The value of the tree at `pos` (coordinates in [0, 1)).
fn lookup(node: &TreeNode, rank: usize, pos: &[f64]) -> f64 {
    let mut p = [0.0f64; 4];
    p[..rank].copy_from_slice(&pos[..rank]);
    let mut n = node;
    loop {
        match n {
            TreeNode::Branch(kids) => {
                let mut k = 0;
                for (d, x) in p[..rank].iter_mut().enumerate() {
                    *x *= 2.0;
                    if *x >= 1.0 {
                        k |= 1 << d;
                        *x -= 1.0;
                    }
                }
                match kids.get(k) {
                    Some(c) => n = c,
                    None => return 0.0,
                }
            }
            TreeNode::Leaf { log2, values } => {
                if *log2 == 0 {
                    return values.first().map_or(0.0, |&v| v as f64);
                }
                let cells = 1usize << log2;
                let mut idx = 0usize;
                let mut shift = 0;
                for d in (0..rank).rev() {
                    let c = ((cells as f64 * p[d]) as usize).min(cells - 1);
                    idx += c << shift;
                    shift += *log2 as usize;
                }
                return values.get(idx).map_or(0.0, |&v| v as f64);
            }
        }
    }
}

/// Turn `v` about +Z by `theta` radians (right-handed), Radiance's `spinvector` about z.
fn spin_z(v: [f64; 3], theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [v[0] * c - v[1] * s, v[0] * s + v[1] * c, v[2]]
}

impl Comp {
    /// `SDqueryTre` once the sides are settled: `inc` and `out` point away from the surface.
    fn query(&self, inc: [f64; 3], out: [f64; 3]) -> f64 {
        let mut g = [0.0; 4];
        if self.rank == 3 {
            let r = spin_z(out, -(-inc[1]).atan2(-inc[0]));
            g[0] = (0.5 - 1e-6) - 0.5 * (inc[0] * inc[0] + inc[1] * inc[1]).sqrt();
            let s = disk2square(r[0], r[1]);
            g[1] = s[0];
            g[2] = s[1];
        } else {
            let a = disk2square(-inc[0], -inc[1]);
            let b = disk2square(out[0], out[1]);
            g = [a[0], a[1], b[0], b[1]];
        }
        for x in &mut g {
            *x = x.clamp(0.0, 1.0 - 1e-12);
        }
        lookup(&self.root, self.rank, &g).max(0.0)
    }
}

impl TreeBsdf {
    /// The `Visible` trees of a file; an error when it has none.
    pub fn from_xml(xml: &BsdfXml, file: &str) -> Result<TreeBsdf> {
        let mut t = TreeBsdf::default();
        for l in &xml.layers {
            for c in &l.components {
                let ScatteringData::Tree(tree) = &c.data else {
                    continue;
                };
                if c.channel != Channel::Visible {
                    continue;
                }
                let comp = Some(Comp {
                    rank: tree.rank,
                    root: tree.root.clone(),
                });
                match c.direction {
                    Direction::TransmissionFront => t.tb = comp,
                    Direction::TransmissionBack => t.tf = comp,
                    Direction::ReflectionFront => t.rb = comp,
                    Direction::ReflectionBack => t.rf = comp,
                }
            }
        }
        if t.rf.is_none() && t.rb.is_none() && t.tf.is_none() && t.tb.is_none() {
            return Err(Error::Parse {
                loc: Location::file(file),
                msg: "expected tensor-tree blocks with Visible data".into(),
            });
        }
        Ok(t)
    }

    /// The BSDF (photopic, 1/sr) for local directions `inc` and `out`, both pointing away
    /// from the surface, `z` the front normal (`SDevalBSDF`).
    pub fn eval(&self, inc: [f64; 3], out: [f64; 3]) -> f64 {
        let (fi, fo) = (inc[2] > 0.0, out[2] > 0.0);
        match (fi, fo) {
            (true, true) => self.rf.as_ref().map_or(0.0, |c| c.query(inc, out)),
            (false, false) => self.rb.as_ref().map_or(0.0, |c| c.query(inc, out)),
            (true, false) => match (&self.tf, &self.tb) {
                (Some(c), _) => c.query(inc, out),
                // The back component with reciprocity: its incident side is the back.
                (None, Some(c)) => c.query(out, inc),
                _ => 0.0,
            },
            (false, true) => match (&self.tb, &self.tf) {
                (Some(c), _) => c.query(inc, out),
                (None, Some(c)) => c.query(out, inc),
                _ => 0.0,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disk2square_corners_and_centre() {
        let c = disk2square(0.0, 0.0);
        assert!((c[0] - 0.5).abs() < 1e-12 && (c[1] - 0.5).abs() < 1e-12);
        let e = disk2square(1.0, 0.0);
        assert!((e[0] - 1.0).abs() < 1e-9 && (e[1] - 0.5).abs() < 1e-9);
        let d = std::f64::consts::FRAC_1_SQRT_2;
        let k = disk2square(-d, -d);
        assert!(k[0].abs() < 1e-9 && k[1].abs() < 1e-9, "{k:?}");
    }

    #[test]
    fn lookup_follows_branch_bits_and_leaf_order() {
        // Rank 3: child 0b101 (dims 0 and 2 high) holds a 2x2x2 leaf 0..8.
        let mut kids: Vec<TreeNode> = (0..8)
            .map(|k| TreeNode::Leaf {
                log2: 0,
                values: vec![100.0 + k as f32],
            })
            .collect();
        kids[5] = TreeNode::Leaf {
            log2: 1,
            values: (0..8).map(|v| v as f32).collect(),
        };
        let root = TreeNode::Branch(kids);
        assert_eq!(lookup(&root, 3, &[0.1, 0.9, 0.1]), 102.0);
        // In child 5: local (0.2, 0.6, 0.8) -> cells (0, 1, 1): index 0*4 + 1*2 + 1 = 3.
        assert_eq!(lookup(&root, 3, &[0.6, 0.3, 0.9]), 3.0);
    }
}
