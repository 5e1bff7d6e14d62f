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
//! What exists: [`TreeBsdf::eval`] (photopic), the hemispherical totals and sampling of an
//! outgoing direction ([`TreeBsdf::sample`]), which the `BSDF` material uses
//! ([`super::bsdf`]). Sampling (our own take on `SDsampTreCDist`): for the incident
//! direction, the tree is tabulated on a grid over the outgoing square as fine as its
//! finest leaf (at most [`MAX_LOG2`] halvings), a cumulative distribution is built over the
//! cells, a cell is picked and a point uniform in it mapped back to the hemisphere by
//! `square2disk`. The Shirley-Chiu map preserves area, and the disc is the hemisphere's
//! projection, so every cell has the same projected solid angle `pi / n^2`: the cell
//! weights are the values themselves and the hemispherical total is `pi / n^2 x sum`.
//! Tables are cached per incident cell (rank 3: its one polar coordinate; rank 4: its
//! square cell), so they are exact wherever the tree is no finer than the grid.
//! Like Radiance (`extract_diffuse`), each tree's smallest value leaves it as a Lambertian
//! part ([`TreeBsdf::lamb`]; the material samples it as diffuse), so [`TreeBsdf::eval`] and
//! the totals cover the directional remainder only. Not yet: CIE-u/v colour.

use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};

use crate::error::{Error, Location, Result};
use rdaylight_formats::bsdf::{BsdfXml, Channel, Direction, ScatteringData, TreeNode};

/// The finest sampling grid: `2^MAX_LOG2` cells per dimension of the outgoing square
/// (`bsdf2ttree -g 5|6` files fit; finer trees are sampled at this resolution with the
/// weight corrected by the true value, so still unbiased where the table is non-zero).
pub const MAX_LOG2: u32 = 6;

/// One stored tree and the side it serves, with its lazily built sampling tables.
#[derive(Debug, Clone, PartialEq)]
struct Comp {
    rank: usize,
    root: TreeNode,
    /// log2 of the sampling grid's cells per dimension.
    log2: u32,
    /// One table per incident cell (rank 3: `n`, rank 4: `n * n`), built on first use.
    cache: Vec<OnceLock<Arc<Table>>>,
}

/// The smallest value of a tree (`SDgetTreMin`).
fn tree_min(node: &TreeNode) -> f64 {
    match node {
        TreeNode::Branch(kids) => kids.iter().map(tree_min).fold(f64::INFINITY, f64::min),
        TreeNode::Leaf { values, .. } => values
            .iter()
            .map(|&v| v as f64)
            .fold(f64::INFINITY, f64::min),
    }
}

/// Subtracts `v` from every value of a tree (`SDsubtractTreVal`).
fn tree_subtract(node: &mut TreeNode, v: f64) {
    match node {
        TreeNode::Branch(kids) => kids.iter_mut().for_each(|k| tree_subtract(k, v)),
        TreeNode::Leaf { values, .. } => values.iter_mut().for_each(|x| *x -= v as f32),
    }
}

/// `subtract_min_Y`: the smallest value over the part of the tree queries reach (rank 3
/// uses only the lower half of its first coordinate) leaves the tree and becomes a
/// Lambertian part, when worth it (between 0.01/pi and 1.5/pi). Returns that part's
/// hemispherical value (`pi x min`), 0 when nothing was taken.
fn subtract_min(rank: usize, root: &mut TreeNode) -> f64 {
    let vmin = match root {
        TreeNode::Branch(kids) if rank == 3 => kids
            .iter()
            .step_by(2)
            .map(tree_min)
            .fold(f64::INFINITY, f64::min),
        TreeNode::Leaf { log2, values } if rank == 3 && *log2 > 0 => values[..values.len() / 2]
            .iter()
            .map(|&v| v as f64)
            .fold(f64::INFINITY, f64::min),
        _ => tree_min(root),
    };
    if !(vmin > 0.01 / PI && vmin < 1.5 / PI) {
        return 0.0;
    }
    tree_subtract(root, vmin);
    PI * vmin
}

/// Halvings to the tree's finest cell along a dimension (branches halve every dimension).
fn depth(node: &TreeNode) -> u32 {
    match node {
        TreeNode::Branch(kids) => 1 + kids.iter().map(depth).max().unwrap_or(0),
        TreeNode::Leaf { log2, .. } => *log2,
    }
}

/// Radiance's `square2disk` (Shirley & Chiu 1997), the inverse of [`disk2square`]: a point
/// of the unit square to the unit disc, area-preserving.
pub fn square2disk(sx: f64, sy: f64) -> [f64; 2] {
    let (a, b) = (2.0 * sx - 1.0, 2.0 * sy - 1.0);
    let q = PI / 4.0;
    let (r, phi) = if a > -b {
        if a > b {
            (a, q * (b / a))
        } else {
            (b, q * (2.0 - a / b))
        }
    } else if a < b {
        (-a, q * (4.0 + b / a))
    } else if b != 0.0 {
        (-b, q * (6.0 - a / b))
    } else {
        (0.0, 0.0)
    };
    [r * phi.cos(), r * phi.sin()]
}

/// Values of one incident direction's BSDF over an `n x n` grid of the outgoing square
/// (index `i * n + j`, `i` along the square's first coordinate) and their running sum.
#[derive(Debug, Clone, PartialEq)]
struct Table {
    n: usize,
    vals: Vec<f64>,
    /// `cdf[k]` = sum of `vals[..k]` (len `n * n + 1`).
    cdf: Vec<f64>,
}

impl Table {
    /// Tabulates `f(sx, sy)` at the cells' centres.
    fn build(n: usize, f: impl Fn(f64, f64) -> f64) -> Table {
        let mut vals = Vec::with_capacity(n * n);
        let mut cdf = Vec::with_capacity(n * n + 1);
        let mut acc = 0.0;
        cdf.push(0.0);
        for i in 0..n {
            for j in 0..n {
                let v = f((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64).max(0.0);
                vals.push(v);
                acc += v;
                cdf.push(acc);
            }
        }
        Table { n, vals, cdf }
    }

    /// Hemispherical total: every cell's projected solid angle is `pi / n^2`.
    fn total(&self) -> f64 {
        self.cdf.last().copied().unwrap_or(0.0) * PI / (self.n * self.n) as f64
    }

    /// A point of the square: a cell in proportion to its value (`u`), uniform inside it
    /// (`u2`, `u3`); with the cell's value.
    fn pick(&self, u: f64, u2: f64, u3: f64) -> Option<(f64, f64, f64)> {
        let sum = *self.cdf.last()?;
        if sum <= 0.0 {
            return None;
        }
        let t = u * sum;
        let k = self
            .cdf
            .partition_point(|&c| c <= t)
            .saturating_sub(1)
            .min(self.vals.len() - 1);
        // A zero cell can only be hit at a boundary: step to the next non-zero one.
        let k = (k..self.vals.len())
            .chain(0..k)
            .find(|&c| self.vals[c] > 0.0)?;
        let n = self.n as f64;
        let (i, j) = ((k / self.n) as f64, (k % self.n) as f64);
        let e = 1e-9;
        Some((
            ((i + u2) / n).clamp(e, 1.0 - e),
            ((j + u3) / n).clamp(e, 1.0 - e),
            self.vals[k],
        ))
    }
}

/// The direction pointing away from the surface on the side of `zsign` whose disc point
/// is `square2disk(sx, sy)` turned by `angle` about `z`.
fn square_dir(sx: f64, sy: f64, zsign: f64, angle: f64) -> [f64; 3] {
    let [x, y] = square2disk(sx, sy);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    spin_z([x, y, zsign * z], angle)
}

/// The photopic trees of a file, in Radiance's orientation (front = the surface normal's
/// side = WINDOW's back).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TreeBsdf {
    rf: Option<Comp>,
    rb: Option<Comp>,
    tf: Option<Comp>,
    tb: Option<Comp>,
    /// Hemispherical values of the Lambertian parts taken out of the trees (`extract_diffuse`):
    /// reflection front, back, transmission front, back.
    pub lamb: [f64; 4],
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
    fn new(rank: usize, root: TreeNode) -> Comp {
        let log2 = depth(&root).min(MAX_LOG2);
        let n = 1usize << log2;
        let cells = if rank == 3 { n } else { n * n };
        Comp {
            rank,
            root,
            log2,
            cache: (0..cells).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The sampling table of incident direction `inc` (its cell's centre) and the angle
    /// that turns the table's square back to the local frame (rank 3 stores the outgoing
    /// direction turned so the incident one lies at azimuth 180 degrees).
    fn table(&self, inc: [f64; 3]) -> (Arc<Table>, f64) {
        let n = 1usize << self.log2;
        let cell = |x: f64| ((x.clamp(0.0, 1.0 - 1e-12) * n as f64) as usize).min(n - 1);
        let centre = |c: usize| (c as f64 + 0.5) / n as f64;
        if self.rank == 3 {
            let g0 = (0.5 - 1e-6) - 0.5 * (inc[0] * inc[0] + inc[1] * inc[1]).sqrt();
            let c = cell(g0);
            let t = self.cache[c].get_or_init(|| {
                Arc::new(Table::build(n, |sx, sy| {
                    lookup(&self.root, 3, &[centre(c), sx, sy])
                }))
            });
            (t.clone(), (-inc[1]).atan2(-inc[0]))
        } else {
            let a = disk2square(-inc[0], -inc[1]);
            let (c0, c1) = (cell(a[0]), cell(a[1]));
            let t = self.cache[c0 * n + c1].get_or_init(|| {
                Arc::new(Table::build(n, |sx, sy| {
                    lookup(&self.root, 4, &[centre(c0), centre(c1), sx, sy])
                }))
            });
            (t.clone(), 0.0)
        }
    }

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
                let mut root = tree.root.clone();
                let lamb = subtract_min(tree.rank, &mut root);
                let comp = Some(Comp::new(tree.rank, root));
                let k = match c.direction {
                    Direction::TransmissionFront => {
                        t.tb = comp;
                        3
                    }
                    Direction::TransmissionBack => {
                        t.tf = comp;
                        2
                    }
                    Direction::ReflectionFront => {
                        t.rb = comp;
                        1
                    }
                    Direction::ReflectionBack => {
                        t.rf = comp;
                        0
                    }
                };
                t.lamb[k] = lamb;
            }
        }
        // One transmission tree serves both sides (SDloadTre).
        if t.tb.is_none() {
            t.lamb[3] = t.lamb[2];
        } else if t.tf.is_none() {
            t.lamb[2] = t.lamb[3];
        }
        if t.rf.is_none() && t.rb.is_none() && t.tf.is_none() && t.tb.is_none() {
            return Err(Error::Parse {
                loc: Location::file(file),
                msg: "expected tensor-tree blocks with Visible data".into(),
            });
        }
        Ok(t)
    }

    /// The directional BSDF (photopic, 1/sr, Lambertian parts excluded) for local directions `inc` and `out`, both pointing away
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

/// How one lobe (reflection or transmission) of a view direction is served: a component
/// queried forwards (view = its incident direction) or, for transmission when only the
/// other side's component exists, by reciprocity (view = its outgoing direction).
enum Lobe<'a> {
    Forward(&'a Comp),
    Reciprocal(&'a Comp),
}

impl TreeBsdf {
    /// The component serving reflection (`transmit` false) or transmission for light
    /// arriving along local `v` (pointing away from the surface), and the outgoing side.
    fn lobe(&self, v: [f64; 3], transmit: bool) -> Option<(Lobe<'_>, f64)> {
        let front = v[2] > 0.0;
        let side = if front == transmit { -1.0 } else { 1.0 };
        let (own, other) = match (front, transmit) {
            (true, false) => (&self.rf, &None),
            (false, false) => (&self.rb, &None),
            (true, true) => (&self.tf, &self.tb),
            (false, true) => (&self.tb, &self.tf),
        };
        match (own, other) {
            (Some(c), _) => Some((Lobe::Forward(c), side)),
            (None, Some(c)) => Some((Lobe::Reciprocal(c), side)),
            _ => None,
        }
    }

    /// The table of a lobe: cached for forward components; built afresh over the
    /// unturned outgoing square for reciprocal ones (slower; exact for rank 4 only).
    fn lobe_table(&self, lobe: &Lobe<'_>, v: [f64; 3], side: f64) -> (Arc<Table>, f64) {
        match lobe {
            Lobe::Forward(c) => c.table(v),
            Lobe::Reciprocal(c) => {
                let n = 1usize << c.log2;
                let t = Table::build(n, |sx, sy| c.query(square_dir(sx, sy, side, 0.0), v));
                (Arc::new(t), 0.0)
            }
        }
    }

    /// Hemispherical reflectance and transmittance (photopic) for light arriving along
    /// local `v`: `integral BSDF cos` over each outgoing hemisphere.
    pub fn hemispherical(&self, v: [f64; 3]) -> (f64, f64) {
        let tot = |transmit: bool| {
            self.lobe(v, transmit)
                .map_or(0.0, |(l, side)| self.lobe_table(&l, v, side).0.total())
        };
        (tot(false), tot(true))
    }

    /// An outgoing direction (local, pointing away) for view `v`, reflected or transmitted,
    /// from three uniforms; with its weight `BSDF x cos / pdf` (photopic; the lobe's
    /// hemispherical total wherever the tree is no finer than the grid). `None` when the
    /// lobe is empty.
    pub fn sample(
        &self,
        v: [f64; 3],
        transmit: bool,
        u: f64,
        u2: f64,
        u3: f64,
    ) -> Option<(f64, [f64; 3])> {
        let (lobe, side) = self.lobe(v, transmit)?;
        let (t, angle) = self.lobe_table(&lobe, v, side);
        let (sx, sy, tv) = t.pick(u, u2, u3)?;
        let d = square_dir(sx, sy, side, angle);
        let f = match lobe {
            Lobe::Forward(c) => c.query(v, d),
            Lobe::Reciprocal(c) => c.query(d, v),
        };
        // pdf (per projected solid angle) = tv / sum x n^2 / pi, so the weight is
        // f / pdf = total x f / tv.
        Some((t.total() * f / tv, d))
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

    #[test]
    fn square2disk_inverts_disk2square() {
        for k in 0..200 {
            let r = ((k % 10) as f64 + 0.5) / 10.0;
            let phi = (k / 10) as f64 * 0.33 - 3.0;
            let (x, y) = (r * phi.cos(), r * phi.sin());
            let s = disk2square(x, y);
            let d = square2disk(s[0], s[1]);
            assert!(
                (d[0] - x).abs() < 1e-9 && (d[1] - y).abs() < 1e-9,
                "{x} {y}: {d:?}"
            );
        }
    }

    fn lobe_tt() -> TreeBsdf {
        let text = include_str!("../../../../tests/data/bsdf/lobe_tt.xml");
        let xml = rdaylight_formats::bsdf::parse(text, "lobe_tt.xml").unwrap();
        TreeBsdf::from_xml(&xml, "lobe_tt.xml").unwrap()
    }

    /// `integral eval(v, d) cos dw` over the outgoing hemisphere of `side`, by the midpoint
    /// rule on a (cos theta, phi) grid: independent of the Shirley-Chiu map and the tables.
    /// `region` restricts it (a test of the sampled distribution's shape, not just its sum).
    fn integrate(t: &TreeBsdf, v: [f64; 3], side: f64, region: impl Fn([f64; 3]) -> bool) -> f64 {
        let (nm, np) = (300, 600);
        let mut acc = 0.0;
        for i in 0..nm {
            let mu = (i as f64 + 0.5) / nm as f64;
            let s = (1.0 - mu * mu).sqrt();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let d = [s * phi.cos(), s * phi.sin(), side * mu];
                if region(d) {
                    acc += t.eval(v, d) * mu;
                }
            }
        }
        acc * 2.0 * PI / (nm * np) as f64
    }

    /// Sampling against evaluation on the bsdf2ttree fixture (reflection 0.2/pi; transmission
    /// 0.05/pi + 0.5 max(0, -i.o)^20): for each view direction and lobe, (1) the table's
    /// hemispherical total equals the quadrature of `eval x cos`, and (2) the sampled
    /// directions' weights, summed over a sub-region (the outgoing half-space x > 0 and the
    /// cone within 30 degrees of the normal), estimate the same region's quadrature: the
    /// sampler reproduces the distribution, not only its total. Error: 5 standard errors of
    /// the sample mean plus 1 % of the total (the quadrature's error on the steep lobe, whose
    /// cells the polar grid cuts).
    /// A named sub-region of the outgoing directions.
    type Region<'a> = (&'a str, &'a dyn Fn([f64; 3]) -> bool);

    #[test]
    fn sampling_integrates_to_the_evaluated_hemispherical_totals() {
        let t = lobe_tt();
        // extract_diffuse: reflection 0.2/pi leaves whole; transmission keeps its lobe above
        // the 0.05/pi floor (bsdf2ttree's cells hold the exact floor far from the lobe).
        for (k, want) in [(0, 0.2), (1, 0.2), (2, 0.05), (3, 0.05)] {
            assert!((t.lamb[k] - want).abs() < 1e-4, "lamb {k}: {:?}", t.lamb);
        }
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            // xorshift64* (Vigna 2016): enough for a deterministic test.
            seed ^= seed >> 12;
            seed ^= seed << 25;
            seed ^= seed >> 27;
            (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        for v in [
            [0.0f64, 0.0, 1.0],
            [0.3, -0.4, 0.866],
            [-0.6, 0.2, -0.775],
            [0.9, 0.1, 0.42],
        ] {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let v = [v[0] / n, v[1] / n, v[2] / n];
            let (hr, ht) = t.hemispherical(v);
            for (transmit, total) in [(false, hr), (true, ht)] {
                let side = if (v[2] > 0.0) == transmit { -1.0 } else { 1.0 };
                let q = integrate(&t, v, side, |_| true);
                assert!(
                    (total - q).abs() < 0.01 * q + 1e-4,
                    "{v:?} transmit {transmit}: table {total} quadrature {q}"
                );
                if total <= 1e-9 {
                    // Reflection is the constant 0.2/pi: all of it is the Lambertian part.
                    assert!(t.sample(v, transmit, 0.3, 0.5, 0.5).is_none());
                    continue;
                }
                let m = 100_000;
                let regions: [Region; 2] = [
                    ("x>0", &|d: [f64; 3]| d[0] > 0.0),
                    ("cone30", &|d: [f64; 3]| {
                        d[2].abs() > 30f64.to_radians().cos()
                    }),
                ];
                for (name, region) in regions {
                    let (mut s1, mut s2, mut off) = (0.0, 0.0, 0);
                    for _ in 0..m {
                        let (w, d) = t.sample(v, transmit, rnd(), rnd(), rnd()).unwrap();
                        assert!(d[2] * side > 0.0, "sample on the wrong side");
                        // The grid is as fine as the tree: a sample's value is its cell's,
                        // so its weight is the total (importance sampling exact). A sample
                        // landing in the wrong place (axis, turn, side) would not be.
                        if (w / total - 1.0).abs() > 1e-6 {
                            off += 1;
                        }
                        let x = if region(d) { w } else { 0.0 };
                        s1 += x;
                        s2 += x * x;
                    }
                    assert!(
                        off * 1000 < m,
                        "{v:?} transmit {transmit}: {off} of {m} samples off the table"
                    );
                    let mean = s1 / m as f64;
                    let se = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
                    let want = integrate(&t, v, side, region);
                    assert!(
                        (mean - want).abs() < 5.0 * se + 0.01 * total,
                        "{v:?} transmit {transmit} {name}: sampled {mean} (se {se}) quadrature {want}"
                    );
                }
            }
        }
    }

    /// With only the back-incident transmission tree, front transmission is sampled by
    /// reciprocity (a table over the tree's incident coordinate, not aligned with a rank-3
    /// tree's cells): weights then vary, but their mean over a region still equals the
    /// quadrature of `eval x cos` there, which uses the same tree reciprocally.
    #[test]
    fn reciprocal_transmission_sampling_is_unbiased() {
        let mut t = lobe_tt();
        t.tf = None;
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed >> 12;
            seed ^= seed << 25;
            seed ^= seed >> 27;
            (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        for v in [[0.0f64, 0.0, 1.0], [0.3, -0.4, 0.866]] {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let v = [v[0] / n, v[1] / n, v[2] / n];
            let total = t.hemispherical(v).1;
            let q = integrate(&t, v, -1.0, |_| true);
            assert!(
                (total - q).abs() < 0.02 * q,
                "{v:?}: table {total} quadrature {q}"
            );
            let m = 20_000;
            let (mut s1, mut s2) = (0.0, 0.0);
            for _ in 0..m {
                let (w, d) = t.sample(v, true, rnd(), rnd(), rnd()).unwrap();
                assert!(d[2] < 0.0, "transmitted sample on the front");
                let x = if d[0] > 0.0 { w } else { 0.0 };
                s1 += x;
                s2 += x * x;
            }
            let mean = s1 / m as f64;
            let se = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
            let want = integrate(&t, v, -1.0, |d| d[0] > 0.0);
            assert!(
                (mean - want).abs() < 5.0 * se + 0.01 * total,
                "{v:?}: sampled {mean} (se {se}) quadrature {want}"
            );
        }
    }
}
