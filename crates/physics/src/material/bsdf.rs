//! # BSDF data from WINDOW XML: Klems matrices as Radiance uses them
//!
//! [`rdaylight_formats::bsdf`] reads the file; this module gives its Klems blocks their
//! geometry ([`KlemsBasis`]) and derives what the 3-phase method multiplies:
//! [`transmission_matrix`] is `dctimestep`'s `T` (Radiance `src/util/cmbsdf.c`
//! `cm_loadBTDF`, read to learn the conventions, not copied):
//!
//! `T[out][in] = BTDF(out, in) * lambda_in(in)`
//!
//! with rows the outgoing (room-side) patches, columns the incident (outside) patches, and
//! `lambda` the incident patch's projected solid angle ([`KlemsBasis::lambda`]), so that a
//! column sums to the hemispherical transmittance of light arriving through that patch.
//! The block used is the file's `Transmission Front` (WINDOW's front is the outside; Radiance
//! loads it as its back-incident transmission `tb`). When a file has only
//! `Transmission Back`, `dctimestep` uses reciprocity: `T[r][c] = BTDF_back(c', r') *
//! lambda_out(c')` with `'` the patch at the same polar angle and the opposite azimuth (the
//! incident and outgoing bases mirror each other through the normal).
//!
//! The [`Bsdf`] material (`BSDF`, `aBSDF`) is further down: see its documentation.
//!
//! Values: negatives clamp to 0 (as Radiance's loader). Colour: `Visible` (CIE Y) alone is
//! grey (R = G = B = Y); with `CIE-X` and `CIE-Z` blocks of the same direction the three are
//! converted to Radiance RGB (standard primaries, equal-energy white), as `cm_bsdf`'s
//! `ccy2rgb` does.

use crate::error::{Error, Location, Result};
use crate::geometry::klems::KlemsBasis;
use rdaylight_formats::bsdf::{
    BsdfXml, Channel, Component, Direction, KlemsMatrix, Layer, ScatteringData,
};

/// A dense colour matrix: `rgb[r * ncols + c]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ColorMatrix {
    pub nrows: usize,
    pub ncols: usize,
    pub rgb: Vec<[f64; 3]>,
}

impl ColorMatrix {
    pub fn get(&self, r: usize, c: usize) -> [f64; 3] {
        self.rgb[r * self.ncols + c]
    }
}

/// The [`KlemsBasis`] an XML layer defines under `name`.
pub fn layer_basis(layer: &Layer, name: &str, file: &str, line: usize) -> Result<KlemsBasis> {
    let b = layer
        .bases
        .iter()
        .find(|b| b.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| Error::Parse {
            loc: Location::line(file, line),
            msg: format!("expected an <AngleBasis> named '{name}' in <DataDefinition>"),
        })?;
    let (upper, nphi) = b.upper_and_nphis();
    KlemsBasis::from_rings(&upper, &nphi).map_err(|m| Error::Parse {
        loc: Location::line(file, line),
        msg: format!("angle basis '{name}': {m}"),
    })
}

/// The Klems block of `channel` and `direction` in the first layer that has one.
pub fn klems_block<'a>(
    xml: &'a BsdfXml,
    channel: &Channel,
    direction: Direction,
) -> Option<(&'a Layer, &'a Component, &'a KlemsMatrix)> {
    xml.layers.iter().find_map(|l| {
        l.components.iter().find_map(|c| match &c.data {
            ScatteringData::Klems(k) if &c.channel == channel && c.direction == direction => {
                Some((l, c, k))
            }
            _ => None,
        })
    })
}

/// Per-element colour of a Klems direction: grey from `Visible`, or RGB when CIE-X and
/// CIE-Z blocks of the same shape exist. `None` when there is no `Visible` block.
fn klems_colour(
    xml: &BsdfXml,
    direction: Direction,
) -> Option<(&Layer, &Component, Vec<[f64; 3]>)> {
    let (layer, comp, y) = klems_block(xml, &Channel::Visible, direction)?;
    let x = klems_block(xml, &Channel::CieX, direction).map(|b| b.2);
    let z = klems_block(xml, &Channel::CieZ, direction).map(|b| b.2);
    let same = |m: &KlemsMatrix| m.n_in == y.n_in && m.n_out == y.n_out;
    let rgb = match (x, z) {
        (Some(x), Some(z)) if same(x) && same(z) => {
            let m = crate::colour::bands::xyz_to_std_rgb();
            (0..y.values.len())
                .map(|i| {
                    let v = [
                        x.values[i].max(0.0),
                        y.values[i].max(0.0),
                        z.values[i].max(0.0),
                    ];
                    let mut c = [0.0; 3];
                    for (k, ck) in c.iter_mut().enumerate() {
                        *ck = (m[k][0] * v[0] + m[k][1] * v[1] + m[k][2] * v[2]).max(0.0);
                    }
                    c
                })
                .collect()
        }
        _ => y.values.iter().map(|&v| [v.max(0.0); 3]).collect(),
    };
    Some((layer, comp, rgb))
}

/// `dctimestep`'s transmission matrix `T` of a Klems BSDF file (module docs): `nrows` =
/// outgoing patches, `ncols` = incident patches. `file` names the file in errors.
pub fn transmission_matrix(xml: &BsdfXml, file: &str) -> Result<ColorMatrix> {
    if let Some((layer, comp, rgb)) = klems_colour(xml, Direction::TransmissionFront) {
        let ScatteringData::Klems(k) = &comp.data else {
            unreachable!("klems_block returns Klems data")
        };
        let inc = layer_basis(layer, &k.incident_basis, file, comp.line)?;
        let out = layer_basis(layer, &k.outgoing_basis, file, comp.line)?;
        check_sizes(k, &inc, &out, file, comp.line)?;
        let mut m = Vec::with_capacity(rgb.len());
        for r in 0..k.n_out {
            for c in 0..k.n_in {
                let l = inc.lambda(c);
                let v = rgb[r * k.n_in + c];
                m.push([v[0] * l, v[1] * l, v[2] * l]);
            }
        }
        return Ok(ColorMatrix {
            nrows: k.n_out,
            ncols: k.n_in,
            rgb: m,
        });
    }
    if let Some((layer, comp, rgb)) = klems_colour(xml, Direction::TransmissionBack) {
        let ScatteringData::Klems(k) = &comp.data else {
            unreachable!("klems_block returns Klems data")
        };
        let inc = layer_basis(layer, &k.incident_basis, file, comp.line)?;
        let out = layer_basis(layer, &k.outgoing_basis, file, comp.line)?;
        check_sizes(k, &inc, &out, file, comp.line)?;
        // Reciprocity (cm_bsdf_recip): the result's columns are the back block's outgoing
        // patches mirrored, its rows the back block's incident patches mirrored.
        let (nrows, ncols) = (k.n_in, k.n_out);
        let mut m = Vec::with_capacity(nrows * ncols);
        for r in 0..nrows {
            let ri = opposite_azimuth(&inc, r);
            for c in 0..ncols {
                let ro = opposite_azimuth(&out, c);
                let l = out.lambda(ro);
                let v = rgb[ro * k.n_in + ri];
                m.push([v[0] * l, v[1] * l, v[2] * l]);
            }
        }
        return Ok(ColorMatrix {
            nrows,
            ncols,
            rgb: m,
        });
    }
    Err(Error::Parse {
        loc: Location::file(file),
        msg: "expected a Klems 'Transmission Front' or 'Transmission Back' block with Visible data (a matrix BSDF with transmission)".into(),
    })
}

fn check_sizes(
    k: &KlemsMatrix,
    inc: &KlemsBasis,
    out: &KlemsBasis,
    file: &str,
    line: usize,
) -> Result<()> {
    if inc.len() != k.n_in || out.len() != k.n_out {
        return Err(Error::Parse {
            loc: Location::line(file, line),
            msg: format!(
                "expected a {} x {} matrix for bases '{}' and '{}', found {} x {}",
                out.len(),
                inc.len(),
                k.outgoing_basis,
                k.incident_basis,
                k.n_out,
                k.n_in
            ),
        });
    }
    Ok(())
}

/// The patch at the same polar angle as patch `i`'s centre and the opposite azimuth.
pub fn opposite_azimuth(b: &KlemsBasis, i: usize) -> usize {
    let c = b.centre(i);
    b.bin_of([-c[0], -c[1], c[2]]).unwrap_or(i)
}

// ---------------------------------------------------------------------------------------
// The BSDF material
// ---------------------------------------------------------------------------------------

/// Which way a Klems basis is laid on the local frame (`bsdf_m.c`'s `fo/bo/fi/bi`): the
/// local `z` is the surface normal (Radiance's front). Outgoing front directions index the
/// basis as they are; back ones mirror `z`; incident ones also turn the azimuth by 180
/// degrees (a Klems incident patch is named by where the light goes, not where it comes
/// from).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lay {
    FrontOut,
    BackOut,
    FrontIn,
    BackIn,
}

impl Lay {
    fn to_basis(self, v: [f64; 3]) -> [f64; 3] {
        match self {
            Lay::FrontOut => v,
            Lay::BackOut => [v[0], v[1], -v[2]],
            Lay::FrontIn => [-v[0], -v[1], v[2]],
            Lay::BackIn => [-v[0], -v[1], -v[2]],
        }
    }
    fn front(self) -> bool {
        matches!(self, Lay::FrontOut | Lay::FrontIn)
    }
    /// Patch of local direction `v`; `None` on the wrong side.
    fn index(self, b: &KlemsBasis, v: [f64; 3]) -> Option<usize> {
        if (v[2] > 0.0) != self.front() && v[2] != 0.0 {
            return None;
        }
        b.bin_of(self.to_basis(v))
    }
    /// A direction in patch `i` (cosine-weighted within it), local.
    fn sample(self, b: &KlemsBasis, i: usize, u: f64, v: f64) -> [f64; 3] {
        // The maps are their own inverses.
        self.to_basis(b.sample(i, u, v))
    }
}

/// One Klems component as Radiance holds it after loading (`SDMat`): the view direction
/// plays the incident one (reverse tracing relies on reciprocity, as `m_bsdf.c` does).
#[derive(Debug, Clone, PartialEq)]
struct KlemsComp {
    inc: KlemsBasis,
    out: KlemsBasis,
    inc_lay: Lay,
    out_lay: Lay,
    /// RGB per element, outgoing-major, the Lambertian minimum removed.
    rgb: Vec<[f32; 3]>,
    /// Photopic value per element (what sampling follows).
    y: Vec<f32>,
    /// Per incident patch: cumulative `y * lambda_out` over outgoing patches (len n_out + 1).
    cdf: Vec<Vec<f64>>,
    /// Per outgoing patch: cumulative `y * lambda_in` over incident patches (reciprocity).
    cdf_rev: Vec<Vec<f64>>,
    /// The largest hemispherical total of any incident patch (`maxHemi`).
    max_hemi: f64,
}

impl KlemsComp {
    fn n_in(&self) -> usize {
        self.inc.len()
    }
    fn value(&self, i: usize, o: usize) -> [f32; 3] {
        self.rgb[o * self.n_in() + i]
    }
    /// BSDF (RGB, 1/sr) for view direction `v` and light direction `l` (`SDgetMtxBSDF`:
    /// reciprocity when neither index fits).
    fn eval(&self, v: [f64; 3], l: [f64; 3]) -> Option<[f32; 3]> {
        let (i, o) = (
            self.inc_lay.index(&self.inc, v),
            self.out_lay.index(&self.out, l),
        );
        match (i, o) {
            (Some(i), Some(o)) => Some(self.value(i, o)),
            (None, None) => {
                let i = self.inc_lay.index(&self.inc, l)?;
                let o = self.out_lay.index(&self.out, v)?;
                Some(self.value(i, o))
            }
            _ => None,
        }
    }
    /// Hemispherical total (photopic) of view direction `v` and the direction sampled from
    /// `u` (then `u2`, `u3` inside the patch); `None` when `v` fits neither basis.
    fn sample(&self, v: [f64; 3], u: f64, u2: f64, u3: f64) -> Option<(f64, [f64; 3], [f32; 3])> {
        let (cdf, basis, lay, fwd, idx) = if let Some(i) = self.inc_lay.index(&self.inc, v) {
            (&self.cdf[i], &self.out, self.out_lay, true, i)
        } else {
            let o = self.out_lay.index(&self.out, v)?;
            (&self.cdf_rev[o], &self.inc, self.inc_lay, false, o)
        };
        let total = *cdf.last()?;
        if total <= 1e-6 {
            return Some((0.0, v, [0.0; 3]));
        }
        let t = u * total;
        let j = cdf
            .partition_point(|&c| c <= t)
            .saturating_sub(1)
            .min(cdf.len() - 2);
        let dir = lay.sample(basis, j, u2, u3);
        let val = if fwd {
            self.value(idx, j)
        } else {
            self.value(j, idx)
        };
        let y = if fwd {
            self.y[j * self.n_in() + idx]
        } else {
            self.y[idx * self.n_in() + j]
        };
        // Weight = BSDF x cos / pdf = total, coloured by the sample's chromaticity.
        let c = if y > 0.0 {
            let k = total as f32 / y;
            [val[0] * k, val[1] * k, val[2] * k]
        } else {
            [total as f32; 3]
        };
        Some((total, dir, c))
    }
}

/// The four components and Lambertian parts of a Klems BSDF in Radiance's orientation
/// (front = the side the surface normal points to = WINDOW's back, the room side).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct KlemsBsdf {
    rf: Option<KlemsComp>,
    rb: Option<KlemsComp>,
    tf: Option<KlemsComp>,
    tb: Option<KlemsComp>,
    /// Hemispherical reflectances/transmittances of the Lambertian minima (RGB).
    r_lamb_front: [f64; 3],
    r_lamb_back: [f64; 3],
    t_lamb_front: [f64; 3],
    t_lamb_back: [f64; 3],
    /// `<Thickness>` in metres, if the file gives it.
    pub thickness: Option<f64>,
    /// Tensor-tree data, when the file holds trees instead of Klems matrices (then the
    /// Klems components are all `None`).
    tree: Option<super::ttree::TreeBsdf>,
}

const FTINY: f64 = 1e-6;

impl KlemsBsdf {
    /// From a parsed file (its Klems blocks; see the module docs for colour). `file` names
    /// it in errors.
    pub fn from_xml(xml: &BsdfXml, file: &str) -> Result<KlemsBsdf> {
        let mut out = KlemsBsdf {
            thickness: xml.layers.first().and_then(|l| l.material.thickness),
            ..Default::default()
        };
        if xml.layers.iter().all(|l| {
            !l.components
                .iter()
                .any(|c| matches!(c.data, ScatteringData::Klems(_)))
        }) {
            // Tensor-tree data (bsdf2ttree, genBSDF -t3/-t4): trees less their minima,
            // which become the Lambertian parts as for Klems (see super::ttree).
            let t = super::ttree::TreeBsdf::from_xml(xml, file)?;
            out.r_lamb_front = [t.lamb[0]; 3];
            out.r_lamb_back = [t.lamb[1]; 3];
            out.t_lamb_front = [t.lamb[2]; 3];
            out.t_lamb_back = [t.lamb[3]; 3];
            out.tree = Some(t);
            return Ok(out);
        }
        // WINDOW's names -> Radiance's components (front and back swap, bsdf_m.c).
        for (dir, inc, outl) in [
            (Direction::TransmissionBack, Lay::FrontIn, Lay::BackOut),
            (Direction::TransmissionFront, Lay::BackIn, Lay::FrontOut),
            (Direction::ReflectionBack, Lay::FrontIn, Lay::FrontOut),
            (Direction::ReflectionFront, Lay::BackIn, Lay::BackOut),
        ] {
            let Some((layer, comp, rgb)) = klems_colour(xml, dir) else {
                continue;
            };
            let ScatteringData::Klems(k) = &comp.data else {
                continue;
            };
            let ib = layer_basis(layer, &k.incident_basis, file, comp.line)?;
            let ob = layer_basis(layer, &k.outgoing_basis, file, comp.line)?;
            check_sizes(k, &ib, &ob, file, comp.line)?;
            let grey = rgb.iter().all(|c| c[0] == c[1] && c[1] == c[2]);
            let mut y: Vec<f64> = rgb
                .iter()
                .map(|&c| crate::radiometry::photopic(c))
                .collect();
            let mut rgbv: Vec<[f64; 3]> = rgb;
            // The Lambertian part (`subtract_min`): the smallest value, when worth it
            // (> 0.01/pi), leaves every element and becomes a diffuse component. Grey data
            // only; colour data keeps everything in the matrix.
            let ymin = y.iter().copied().fold(f64::INFINITY, f64::min);
            let mut lamb = 0.0;
            if grey && ymin > 0.01 / PI_ {
                for (v, c) in y.iter_mut().zip(rgbv.iter_mut()) {
                    *v -= ymin;
                    *c = [*v; 3];
                }
                lamb = PI_ * ymin;
            }
            let n_in = ib.len();
            let n_out = ob.len();
            let mut cdf = Vec::with_capacity(n_in);
            let mut max_hemi: f64 = 0.0;
            for i in 0..n_in {
                let mut c = Vec::with_capacity(n_out + 1);
                let mut acc = 0.0;
                c.push(0.0);
                for o in 0..n_out {
                    acc += y[o * n_in + i] * ob.lambda(o);
                    c.push(acc);
                }
                max_hemi = max_hemi.max(acc);
                cdf.push(c);
            }
            let mut cdf_rev = Vec::with_capacity(n_out);
            for o in 0..n_out {
                let mut c = Vec::with_capacity(n_in + 1);
                let mut acc = 0.0;
                c.push(0.0);
                for i in 0..n_in {
                    acc += y[o * n_in + i] * ib.lambda(i);
                    c.push(acc);
                }
                cdf_rev.push(c);
            }
            // SDloadFile drops components whose largest hemispherical total is <= 0.001.
            let kc = (max_hemi > 0.001).then(|| KlemsComp {
                inc: ib,
                out: ob,
                inc_lay: inc,
                out_lay: outl,
                rgb: rgbv
                    .iter()
                    .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
                    .collect(),
                y: y.iter().map(|&v| v as f32).collect(),
                cdf,
                cdf_rev,
                max_hemi,
            });
            match dir {
                Direction::TransmissionBack => {
                    out.tf = kc;
                    out.t_lamb_front = [lamb; 3];
                }
                Direction::TransmissionFront => {
                    out.tb = kc;
                    out.t_lamb_back = [lamb; 3];
                }
                Direction::ReflectionBack => {
                    out.rf = kc;
                    out.r_lamb_front = [lamb; 3];
                }
                Direction::ReflectionFront => {
                    out.rb = kc;
                    out.r_lamb_back = [lamb; 3];
                }
            }
        }
        // One transmission block serves both sides (SDloadMtx).
        if out.tb.is_none() && out.tf.is_some() {
            out.t_lamb_back = out.t_lamb_front;
        } else if out.tf.is_none() && out.tb.is_some() {
            out.t_lamb_front = out.t_lamb_back;
        }
        Ok(out)
    }

    /// Full BSDF (RGB, 1/sr, Lambertian parts included) for local view `v` and light `l`
    /// directions (`SDevalBSDF`).
    pub fn eval(&self, v: [f64; 3], l: [f64; 3]) -> [f64; 3] {
        let (vf, lf) = (v[2] > 0.0, l[2] > 0.0);
        let (lamb, comp) = match (vf, lf) {
            (true, true) => (self.r_lamb_front, self.rf.as_ref()),
            (false, false) => (self.r_lamb_back, self.rb.as_ref()),
            (true, false) => (self.t_lamb_front, self.tf.as_ref().or(self.tb.as_ref())),
            (false, true) => (self.t_lamb_back, self.tb.as_ref().or(self.tf.as_ref())),
        };
        let mut out = [lamb[0] / PI_, lamb[1] / PI_, lamb[2] / PI_];
        if let Some(t) = &self.tree {
            // The view direction plays the incident one (reciprocity, as for Klems).
            let y = t.eval(v, l);
            for o in &mut out {
                *o += y;
            }
        }
        if let Some(c) = comp.and_then(|c| c.eval(v, l)) {
            for k in 0..3 {
                out[k] += c[k] as f64;
            }
        }
        out
    }

    /// Hemispherical reflectance and transmittance (photopic) for light arriving along
    /// local `v` (pointing away from the surface): the Lambertian parts plus the row total.
    pub fn hemispherical(&self, v: [f64; 3]) -> (f64, f64) {
        let front = v[2] > 0.0;
        let (rl, tl) = if front {
            (self.r_lamb_front, self.t_lamb_front)
        } else {
            (self.r_lamb_back, self.t_lamb_back)
        };
        let (tr, tt) = self.lobe_totals(v);
        (
            crate::radiometry::photopic(rl) + tr,
            crate::radiometry::photopic(tl) + tt,
        )
    }

    /// Hemispherical totals (photopic) of the directional parts (Klems matrices less their
    /// Lambertian minima, or the tensor trees) for view `v`: reflection, transmission.
    fn lobe_totals(&self, v: [f64; 3]) -> (f64, f64) {
        if let Some(t) = &self.tree {
            return t.hemispherical(v);
        }
        let (rc, tc) = self.klems_lobes(v);
        let tot = |c: Option<&KlemsComp>| {
            c.and_then(|c| c.sample(v, 0.5, 0.5, 0.5))
                .map_or(0.0, |s| s.0)
        };
        (tot(rc), tot(tc))
    }

    /// The Klems components serving reflection and transmission for view `v`.
    fn klems_lobes(&self, v: [f64; 3]) -> (Option<&KlemsComp>, Option<&KlemsComp>) {
        if v[2] > 0.0 {
            (self.rf.as_ref(), self.tf.as_ref().or(self.tb.as_ref()))
        } else {
            (self.rb.as_ref(), self.tb.as_ref().or(self.tf.as_ref()))
        }
    }

    /// A direction of the directional part of a lobe for view `v` (local), with its weight
    /// `BSDF x cos / pdf` (RGB): the Klems matrix or the tensor tree.
    fn sample_lobe(
        &self,
        v: [f64; 3],
        transmit: bool,
        u: f64,
        u2: f64,
        u3: f64,
    ) -> Option<([f64; 3], [f64; 3])> {
        if let Some(t) = &self.tree {
            let (w, d) = t.sample(v, transmit, u, u2, u3)?;
            return Some((d, [w; 3]));
        }
        let (rc, tc) = self.klems_lobes(v);
        let c = if transmit { tc? } else { rc? };
        let (_, l, rgb) = c.sample(v, u, u2, u3)?;
        Some((l, [rgb[0] as f64, rgb[1] as f64, rgb[2] as f64]))
    }
}

const PI_: f64 = std::f64::consts::PI;

/// A `BSDF` or `aBSDF` material (Radiance `src/rt/m_bsdf.c`, read to learn the behaviour):
///
/// `mod BSDF thick file ux uy uz funcfile [transform] / 0 / 0|3|6|9 rdf gdf bdf rdb gdb bdb
/// rdt gdt bdt`; `aBSDF` has no `thick`. `thick` and `ux uy uz` are numbers or expressions
/// of the function file (`.`: none) that do not read the ray (those are refused); the
/// transform turns the up vector and scales the thickness, as `m_bsdf.c` does.
///
/// - Local frame: `z` = the surface normal (front), `x = normalize(up x N)`, `y = N x x`
///   ([`crate::geometry::klems::KlemsFrame`]); an up vector parallel to the normal makes the
///   surface black (Radiance: "Illegal orientation vector").
/// - Front/back by the side the ray arrives from; the XML's WINDOW front (outside) is
///   Radiance's back: the normal should face the room.
/// - The view direction plays the incident one for both evaluation and sampling (reverse
///   tracing and reciprocity, as Radiance).
/// - Scattering = the Klems matrix (piecewise constant over patches) or the tensor trees
///   ([`super::ttree`], sampled from a per-incident-cell table over the outgoing square)
///   plus Lambertian parts (the matrix or tree minimum, and the extra diffuse arguments,
///   which add). Sampling picks
///   reflection or transmission in proportion to their hemispherical totals, then an
///   outgoing patch in proportion to `BSDF x lambda` and a cosine-weighted direction in it.
///   Lambertian parts are diffuse (ambient) samples that count toward `-ab`; matrix samples
///   are specular ones, unless their total is at most `-st` (then, like Radiance's
///   `specthresh`, the matrix part is folded into the diffuse lobe).
/// - Thickness (`BSDF` only, non-zero): the surface is a proxy. View rays (not ambient or
///   specular samples), shadow rays and rays arriving on the hidden side (the back for a
///   positive thickness) pass straight through; transmitted samples start `thick` behind
///   the surface (opposite the normal).
/// - Shadow rays: blocked by `BSDF` without thickness; `aBSDF` passes them with the "peak"
///   transmission (the matrix value of the straight-through patch above the mean of its
///   ring, times the patch's lambda; a simplification of `compute_through`), and its direct
///   evaluation of a source inside the straight-through cone uses that surround instead
///   of the peak (`direct_specular_OK`), so the sun is not counted twice. With tensor-tree
///   data there is no peak yet: `aBSDF` blocks shadow rays (the sun reaches through
///   samples only). View rays are
///   not split into a through ray and samples as Radiance does (they sample the BSDF).
/// - Patterns modifying the material (Radiance's `r->pcol`, [`Bsdf::pattern`]) multiply
///   everything except the non-diffuse reflection, as `m_bsdf.c` does: the Lambertian
///   reflection and transmission (the data's own and the extra arguments), the
///   non-diffuse transmission (evaluated, sampled or folded below `-st`) and `aBSDF`'s
///   through peak; non-diffuse reflection, and reflection folded below `-st`, keep the
///   data's colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Bsdf {
    pub data: std::sync::Arc<KlemsBsdf>,
    pub up: [f64; 3],
    pub thick: f64,
    pub absdf: bool,
    /// Extra diffuse reflectance front/back and transmittance (RGB), from the real arguments.
    pub rdiff_front: [f64; 3],
    pub rdiff_back: [f64; 3],
    pub tdiff: [f64; 3],
    /// Specular threshold `-st`.
    pub st: f64,
    /// The run's channels.
    pub ch: crate::radiometry::Channels,
    /// Colour of the patterns modifying the material at this hit (`r->pcol`), in the run's
    /// channels; `None` = white.
    pub pattern: Option<super::Color>,
}

impl Bsdf {
    fn colour(&self, rgb: [f64; 3]) -> super::Color {
        super::to_channels(rgb, &self.ch)
    }

    /// `colour(rgb)` times the pattern colour (the parts `m_bsdf.c` multiplies by pcol).
    fn patterned(&self, rgb: [f64; 3]) -> super::Color {
        let c = self.colour(rgb);
        match self.pattern {
            Some(p) if p.ncomp() == c.ncomp() => c * p,
            _ => c,
        }
    }

    /// The same material under a pattern colour (see [`Bsdf::pattern`]); the data stay
    /// shared.
    pub fn with_pattern(&self, pattern: Option<super::Color>) -> Bsdf {
        Bsdf {
            pattern,
            ..self.clone()
        }
    }

    fn frame(&self, normal: [f64; 3]) -> Option<crate::geometry::klems::KlemsFrame> {
        crate::geometry::klems::KlemsFrame::new(normal, self.up)
    }

    /// Whether a ray passes this surface untouched: thickness proxies let view rays
    /// (`primary`), shadow rays and rays from the hidden side through.
    pub fn passes(&self, wo: [f64; 3], s: &super::Surface, primary: bool) -> bool {
        if self.thick == 0.0 {
            return false;
        }
        let hitfront = super::sampling::dot(wo, s.normal) > 0.0;
        primary || ((self.thick > 0.0) ^ hitfront)
    }

    /// Offset of a transmitted ray's origin (`-thick` along the normal), when non-zero.
    pub fn transmit_offset(&self, s: &super::Surface) -> Option<[f64; 3]> {
        (self.thick != 0.0).then(|| super::sampling::scale(s.normal, -self.thick))
    }

    /// Direct coefficient of a source of solid angle `omega` along `wi` (`dir_bsdf`):
    /// `(BSDF(view, light) + extra diffuse / pi) |cos| omega`.
    pub fn eval_direct(
        &self,
        wo: [f64; 3],
        wi: [f64; 3],
        s: &super::Surface,
        omega: f64,
    ) -> super::Color {
        let black = super::Color::black(self.ch.ncomp.max(1));
        let Some(f) = self.frame(s.normal) else {
            return black;
        };
        let (v, l) = (f.to_local(wo), f.to_local(wi));
        if l[2].abs() <= FTINY {
            return black;
        }
        let hitfront = v[2] > 0.0;
        let same_side = (l[2] > 0.0) == hitfront;
        // aBSDF: a source seen straight through is the shadow rays' (they pass the peak);
        // here it gets only the surround, as m_bsdf.c's direct_specular_OK does.
        let through = if self.absdf && !same_side && self.in_through_cone(v, l, omega) {
            self.peak_and_surround(v)
        } else {
            None
        };
        let mut b = match through {
            Some((p, s)) if p.iter().any(|&x| x > 0.0) => s,
            _ => self.data.eval(v, l),
        };
        let extra = if same_side {
            if hitfront {
                self.rdiff_front
            } else {
                self.rdiff_back
            }
        } else {
            self.tdiff
        };
        for k in 0..3 {
            b[k] += extra[k] / PI_;
        }
        let k = l[2].abs() * omega;
        if !same_side {
            // dir_btdf: diffuse and non-diffuse transmission both take the pattern.
            return self.patterned([b[0] * k, b[1] * k, b[2] * k]);
        }
        // dir_brdf: the pattern multiplies the Lambertian reflection (the data's own and
        // the extra argument) but not the non-diffuse part.
        let d = &*self.data;
        let lamb = if hitfront {
            d.r_lamb_front
        } else {
            d.r_lamb_back
        };
        let diffuse: [f64; 3] = std::array::from_fn(|c| (lamb[c] + extra[c]) / PI_ * k);
        let rest: [f64; 3] = std::array::from_fn(|c| b[c] * k - diffuse[c]);
        self.colour(rest) + self.patterned(diffuse)
    }

    /// Sample a continuation (three uniforms in [0, 1)).
    pub fn sample(
        &self,
        wo: [f64; 3],
        s: &super::Surface,
        u1: f64,
        u2: f64,
        u3: f64,
    ) -> Option<super::Sample> {
        use super::{Sample, SampleKind};
        let f = self.frame(s.normal)?;
        let v = f.to_local(wo);
        let hitfront = v[2] > 0.0;
        let d = &*self.data;
        let (rl, tl, rx) = if hitfront {
            (d.r_lamb_front, d.t_lamb_front, self.rdiff_front)
        } else {
            (d.r_lamb_back, d.t_lamb_back, self.rdiff_back)
        };
        let lum = crate::radiometry::photopic;
        // Hemispherical totals of the directional parts for this view direction.
        let (rs, ts) = d.lobe_totals(v);
        // Below -st the matrix part is folded into the diffuse lobe (specthresh).
        let (rs_spec, rs_fold) = if rs <= self.st + FTINY {
            (0.0, rs)
        } else {
            (rs, 0.0)
        };
        let (ts_spec, ts_fold) = if ts <= self.st + FTINY {
            (0.0, ts)
        } else {
            (ts, 0.0)
        };
        let rd = [
            rl[0] + rx[0] + rs_fold,
            rl[1] + rx[1] + rs_fold,
            rl[2] + rx[2] + rs_fold,
        ];
        // The part of `rd` a pattern multiplies (sample_sdf: none on folded reflection).
        let rd_lamb = [rl[0] + rx[0], rl[1] + rx[1], rl[2] + rx[2]];
        let td = [
            tl[0] + self.tdiff[0] + ts_fold,
            tl[1] + self.tdiff[1] + ts_fold,
            tl[2] + self.tdiff[2] + ts_fold,
        ];
        let w = [rs_spec, ts_spec, lum(rd).max(0.0), lum(td).max(0.0)];
        let total: f64 = w.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let mut x = u1 * total;
        let mut lobe = 3;
        for (k, &wk) in w.iter().enumerate() {
            if x < wk {
                lobe = k;
                break;
            }
            x -= wk;
        }
        let p = w[lobe] / total;
        // Reuse the remainder of u1 for the patch choice.
        let u = (x / w[lobe]).clamp(0.0, 1.0 - 1e-12);
        let nside = |front: bool| {
            if front {
                f.z
            } else {
                super::sampling::neg(f.z)
            }
        };
        let inv_p = 1.0 / p;
        let (dir, weight, kind) = match lobe {
            0 | 1 => {
                let (l, rgb) = d.sample_lobe(v, lobe == 1, u, u2, u3)?;
                let w = rgb.map(|x| x * inv_p);
                if lobe == 0 {
                    // sample_sdcomp: no pattern on non-diffuse reflection.
                    (f.to_world(l), self.colour(w), SampleKind::SpecularReflect)
                } else {
                    (
                        f.to_world(l),
                        self.patterned(w),
                        SampleKind::SpecularTransmit,
                    )
                }
            }
            2 => (
                super::sampling::cosine_hemisphere(nside(hitfront), u2, u3),
                self.patterned(rd_lamb.map(|x| x * inv_p)) + self.colour([rs_fold * inv_p; 3]),
                SampleKind::DiffuseReflect,
            ),
            _ => (
                super::sampling::cosine_hemisphere(nside(!hitfront), u2, u3),
                self.patterned(td.map(|x| x * inv_p)),
                SampleKind::DiffuseTransmit,
            ),
        };
        Some(Sample {
            wi: dir,
            weight,
            kind,
        })
    }

    /// What a shadow ray keeps: `aBSDF` its peak transmission, `BSDF` with thickness all of
    /// it, `BSDF` without thickness nothing.
    pub fn shadow_transmission(&self, wo: [f64; 3], s: &super::Surface) -> Option<super::Color> {
        if self.thick != 0.0 {
            return Some(super::Color::splat(self.ch.ncomp.max(1), 1.0));
        }
        if !self.absdf {
            return None;
        }
        let f = self.frame(s.normal)?;
        let v = f.to_local(wo);
        let t = self.peak(v)?;
        // compute_through: the through component takes the pattern.
        (t.iter().any(|&x| x > 0.0)).then(|| self.patterned(t))
    }

    /// The straight-through "peak" of the transmission seen from local `v` (RGB): the
    /// through patch's value above the mean of its ring neighbours, times its lambda.
    fn peak(&self, v: [f64; 3]) -> Option<[f64; 3]> {
        self.peak_and_surround(v).map(|(p, _)| p)
    }

    /// The peak (as [`Bsdf::peak`]) and the surround BTDF (RGB, 1/sr, Lambertian part
    /// included: the ring mean plus the matrix minimum over pi) seen from local `v`; also
    /// the smallest projected solid angle of the outgoing basis (`minProjSA`).
    fn peak_and_surround(&self, v: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
        let d = &*self.data;
        let c = if v[2] > 0.0 {
            d.tf.as_ref().or(d.tb.as_ref())?
        } else {
            d.tb.as_ref().or(d.tf.as_ref())?
        };
        let through = [-v[0], -v[1], -v[2]];
        let i = c.inc_lay.index(&c.inc, v)?;
        let o = c.out_lay.index(&c.out, through)?;
        let val = c.value(i, o);
        let (r, _) = c.out.ring_of(o);
        let n = c.out.ring_len(r);
        let start = (0..c.out.len()).find(|&k| c.out.ring_of(k).0 == r)?;
        let mut sur = [0.0f64; 3];
        let mut m = 0;
        for k in start..start + n {
            if k != o {
                let x = c.value(i, k);
                for ch in 0..3 {
                    sur[ch] += x[ch] as f64;
                }
                m += 1;
            }
        }
        let lam = c.out.lambda(o);
        let lamb = if v[2] > 0.0 {
            d.t_lamb_front
        } else {
            d.t_lamb_back
        };
        let mut out = [0.0; 3];
        let mut surround = [0.0; 3];
        for ch in 0..3 {
            let s = if m > 0 { sur[ch] / m as f64 } else { 0.0 };
            out[ch] = ((val[ch] as f64 - s) * lam).max(0.0);
            surround[ch] = s.max(0.0) + lamb[ch] / PI_;
        }
        Some((out, surround))
    }

    /// `aBSDF`: whether a source along local `l` lies in the straight-through cone of the
    /// view `v` (`direct_specular_OK`'s over-counting test: shadow rays already carry the
    /// peak), `omega` the source's solid angle. The cone's size follows m_bsdf.c's rule
    /// with the basis's smallest patch as `minProjSA`.
    fn in_through_cone(&self, v: [f64; 3], l: [f64; 3], omega: f64) -> bool {
        let d = &*self.data;
        let Some(c) = (if v[2] > 0.0 {
            d.tf.as_ref().or(d.tb.as_ref())
        } else {
            d.tb.as_ref().or(d.tf.as_ref())
        }) else {
            return false;
        };
        let min_psa = (0..c.out.len())
            .map(|k| c.out.lambda(k))
            .fold(f64::INFINITY, f64::min);
        let tomega = omega * l[2].abs();
        let (dx, dy) = (l[0] + v[0], l[1] + v[1]);
        dx * dx + dy * dy
            <= (2.5 * 4.0 / PI_) * (tomega + min_psa + 2.0 * (tomega * min_psa).sqrt())
    }
}

/// Builds a [`Bsdf`] from a `BSDF`/`aBSDF` primitive's arguments; `scene_file` locates the
/// XML file (beside it, the working folder, `RAYPATH`), `bad` builds located errors.
pub fn build_material(
    absdf: bool,
    strings: &[String],
    reals: &[f64],
    loc: &Location,
    id: &str,
    st: f64,
    ch: &crate::radiometry::Channels,
) -> Result<Bsdf> {
    let tname = if absdf { "aBSDF" } else { "BSDF" };
    let bad = |msg: String| Error::Parse {
        loc: loc.clone(),
        msg: format!("{tname} '{id}' {msg}"),
    };
    let unsupported = |what: String| Error::Unsupported {
        loc: loc.clone(),
        what: format!("{what} on {tname} '{id}'"),
    };
    let scene_file = loc.file.as_str();
    let k = usize::from(!absdf);
    let need = 5 + k;
    if strings.len() < need {
        return Err(bad(format!(
            "has {} string arguments; expected at least {need}",
            strings.len()
        )));
    }
    // m_bsdf.c's getfunc(m, 5, 0x1d, 1): the thickness and the up vector are expressions
    // in the context of the function file (`.`: none), and the transform after it turns
    // the up vector and scales the thickness (`mf->fxp`, the transform as xform applies
    // it). Expressions that read the ray (Nx, Px, ...) would vary per hit: refused.
    let funcfile = &strings[k + 4];
    let program = if funcfile == "." {
        crate::calc::Program::default()
    } else {
        let path = rdaylight_formats::scene::find_file(funcfile, scene_file).ok_or_else(|| {
            bad(format!("function file '{funcfile}' not found (looked beside the scene file, in the working folder and on RAYPATH)"))
        })?;
        crate::calc::Program::load(&path)?
    };
    let num = |s: &str, what: &str| -> Result<f64> {
        if let Some(v) = s.parse::<f64>().ok().filter(|v| v.is_finite()) {
            return Ok(v);
        }
        let e = program
            .expr(s, what)
            .map_err(|e| bad(format!("has {what} '{s}' that does not parse ({e})")))?;
        if program.reads_ray(&e) {
            return Err(unsupported(format!(
                "{what} expression '{s}' that depends on the ray"
            )));
        }
        program
            .eval(&e, crate::calc::Inputs::default())
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(format!("has {what} '{s}' that is not a finite number")))
    };
    let xf = crate::calc::xf::Xf::forward_of(&strings[need..], loc, tname)?;
    let thick = if absdf {
        0.0
    } else {
        num(&strings[0], "thickness")? * xf.sca
    };
    let thick = if thick.abs() <= FTINY { 0.0 } else { thick };
    let file = &strings[k];
    let up = xf.vector([
        num(&strings[k + 1], "up x")?,
        num(&strings[k + 2], "up y")?,
        num(&strings[k + 3], "up z")?,
    ]);
    if reals.len() > 9 || reals.len() % 3 != 0 {
        return Err(bad(format!(
            "has {} real arguments; expected 0, 3, 6 or 9",
            reals.len()
        )));
    }
    let path = rdaylight_formats::scene::find_file(file, scene_file).ok_or_else(|| {
        bad(format!("BSDF file '{file}' not found (looked beside the scene file, in the working folder and on RAYPATH)"))
    })?;
    let name = path.display().to_string();
    let xml = rdaylight_formats::bsdf::load(&path)?;
    let data = KlemsBsdf::from_xml(&xml, &name)?;
    let trip = |i: usize| -> [f64; 3] {
        if reals.len() >= i + 3 {
            [reals[i], reals[i + 1], reals[i + 2]]
        } else {
            [0.0; 3]
        }
    };
    Ok(Bsdf {
        data: std::sync::Arc::new(data),
        up,
        thick,
        absdf,
        rdiff_front: trip(0),
        rdiff_back: trip(3),
        tdiff: trip(6),
        st,
        ch: *ch,
        pattern: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiometry::{STD_PRIMARIES, rgb_to_xyz};

    #[test]
    fn xyz_to_rgb_inverts_rgb_to_xyz() {
        let a = rgb_to_xyz(&STD_PRIMARIES);
        let b = crate::colour::bands::xyz_to_std_rgb();
        // b a = identity, element by element.
        for (r, c) in (0..3).flat_map(|r| (0..3).map(move |c| (r, c))) {
            let v: f64 = (0..3).map(|k| b[r][k] * a[k][c]).sum();
            assert!((v - f64::from(u8::from(r == c))).abs() < 1e-12);
        }
    }

    fn proxy(thick: f64, absdf: bool) -> Bsdf {
        Bsdf {
            data: std::sync::Arc::new(KlemsBsdf::default()),
            up: [0.0, 0.0, 1.0],
            thick,
            absdf,
            rdiff_front: [0.0; 3],
            rdiff_back: [0.0; 3],
            tdiff: [0.2; 3],
            st: 0.15,
            ch: crate::radiometry::Channels::rgb(),
            pattern: None,
        }
    }

    #[test]
    fn thickness_makes_a_proxy_as_m_bsdf_does() {
        let s = super::super::Surface::flat([0.0, 1.0, 0.0]);
        let (front, back) = ([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]);
        // No thickness: nothing passes; shadow rays are blocked.
        let b = proxy(0.0, false);
        assert!(!b.passes(front, &s, true) && !b.passes(back, &s, false));
        assert!(b.shadow_transmission(front, &s).is_none());
        assert!(b.transmit_offset(&s).is_none());
        // Positive thickness: view rays pass, rays from the back pass, samples from the
        // front stay; shadow rays pass; transmitted samples move behind the surface.
        let b = proxy(0.01, false);
        assert!(b.passes(front, &s, true) && b.passes(back, &s, false));
        assert!(!b.passes(front, &s, false));
        assert_eq!(
            b.shadow_transmission(front, &s).unwrap().as_slice(),
            &[1.0f32; 3][..]
        );
        assert_eq!(b.transmit_offset(&s), Some([0.0, -0.01, 0.0]));
        // Negative thickness: the front is the hidden side.
        let b = proxy(-0.01, false);
        assert!(b.passes(front, &s, false) && !b.passes(back, &s, false));
        // Extra diffuse transmission alone: a Lambertian transmitter (rho_t cos omega / pi).
        let b = proxy(0.0, false);
        let c = b.eval_direct(front, back, &s, 0.01).as_slice()[1] as f64;
        assert!((c - 0.2 * 0.01 / std::f64::consts::PI).abs() < 1e-9, "{c}");
        // An up vector along the normal makes the surface black.
        let mut b = proxy(0.0, false);
        b.up = [0.0, 1.0, 0.0];
        assert!(b.sample(front, &s, 0.5, 0.5, 0.5).is_none());
    }

    /// CIE-X/Y/Z blocks become Radiance RGB (standard primaries) in dctimestep's T; a
    /// Visible-only file is grey. A 2-patch basis keeps the numbers readable.
    #[test]
    fn xyz_blocks_give_rgb_and_visible_alone_grey() {
        let block = |ch: &str, v: &str| {
            format!(
                "<WavelengthData><Wavelength>{ch}</Wavelength><WavelengthDataBlock>\
                 <WavelengthDataDirection>Transmission Front</WavelengthDataDirection>\
                 <ColumnAngleBasis>B</ColumnAngleBasis><RowAngleBasis>B</RowAngleBasis>\
                 <ScatteringData>{v}</ScatteringData></WavelengthDataBlock></WavelengthData>"
            )
        };
        let doc = |blocks: String| {
            format!(
                "<WindowElement><Optical><Layer><DataDefinition>\
                 <IncidentDataStructure>Columns</IncidentDataStructure><AngleBasis>\
                 <AngleBasisName>B</AngleBasisName><AngleBasisBlock><nPhis>1</nPhis>\
                 <ThetaBounds><LowerTheta>0</LowerTheta><UpperTheta>45</UpperTheta></ThetaBounds>\
                 </AngleBasisBlock><AngleBasisBlock><nPhis>1</nPhis><ThetaBounds>\
                 <LowerTheta>45</LowerTheta><UpperTheta>90</UpperTheta></ThetaBounds>\
                 </AngleBasisBlock></AngleBasis></DataDefinition>{blocks}</Layer></Optical>\
                 </WindowElement>"
            )
        };
        let grey =
            rdaylight_formats::bsdf::parse(&doc(block("Visible", "1 2 3 4")), "g.xml").unwrap();
        let t = transmission_matrix(&grey, "g.xml").unwrap();
        let lam0 = std::f64::consts::PI * 0.5; // pi (sin^2 45 - 0)
        assert!((t.get(0, 0)[0] - lam0).abs() < 1e-12 && t.get(0, 0)[0] == t.get(0, 0)[2]);
        let xyz = format!(
            "{}{}{}",
            block("CIE-X", "0.5 0 0 0"),
            block("Visible", "1 0 0 0"),
            block("CIE-Z", "0.25 0 0 0")
        );
        let c = rdaylight_formats::bsdf::parse(&doc(xyz), "c.xml").unwrap();
        let t = transmission_matrix(&c, "c.xml").unwrap();
        let m = crate::colour::bands::xyz_to_std_rgb();
        let rgb = t.get(0, 0);
        for k in 0..3 {
            let want = (m[k][0] * 0.5 + m[k][1] + m[k][2] * 0.25).max(0.0) * lam0;
            assert!((rgb[k] - want).abs() < 1e-12, "{k}: {rgb:?}");
        }
        // The photopic value of the colour is the Visible value (Y), as it must be.
        assert!(
            (crate::radiometry::photopic(rgb) - lam0).abs() < 1e-3 * lam0,
            "{rgb:?}"
        );
    }

    #[test]
    fn opposite_azimuth_is_an_involution() {
        let b = KlemsBasis::new(crate::geometry::klems::KlemsKind::Full);
        for i in 0..b.len() {
            let j = opposite_azimuth(&b, i);
            assert_eq!(b.ring_of(i).0, b.ring_of(j).0);
            assert_eq!(opposite_azimuth(&b, j), i);
        }
        assert_eq!(opposite_azimuth(&b, 0), 0);
        assert_eq!(opposite_azimuth(&b, 1), 5);
    }
}
