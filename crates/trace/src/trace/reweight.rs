//! # Path re-weighting records: coefficients as polynomials in material reflectances
//!
//! The material-uncertainty study of the seed dissertation (chapter 3: 500 Monte Carlo draws
//! of every material's reflectance and transmittance) and rcalib's sensitivities need the
//! daylight coefficients of many variants of one scene that differ only in how much light
//! each material reflects or transmits. Re-tracing each variant costs a full run; instead
//! the path tracer records, per record (sensor or pixel) and column (sky patch or sun), the
//! contribution split by the path's **signature**: the multiset of tracked materials at
//! which it scattered with a coefficient proportional to the material's colour `rho`.
//! Scaling material `m`'s colour by `s_m` turns the coefficient into
//!
//! ```text
//! C(s) = sum over signatures sig of  c_sig x prod_m s_m^(n_m(sig))
//! ```
//!
//! where `c_sig` is the (mean) contribution of the paths with signature `sig` and `n_m` how
//! often they met `m`. `C(1)` is the normal output (up to the order of floating-point
//! additions) and `dC/ds_m` at 1 is `sum n_m c_sig` ([`Reweighting::sensitivity`]).
//!
//! ## What is exact and what is not
//! Each path's Monte Carlo weight is a product over its vertices of `coefficient /
//! probability`. The probabilities (which lobe, which direction, Russian roulette by `-lw`)
//! were chosen with the original colours; reusing them for the scaled scene is importance
//! sampling with the old density, which stays **unbiased** as long as every lobe the scaled
//! scene uses has non-zero probability in the old one (scaling never turns a zero
//! coefficient into a non-zero one). So, for the same set of paths:
//! - **exact** (every path's contribution is exactly what the scaled scene's estimator
//!   would give it with these sampling decisions): diffuse reflection and diffuse
//!   transmission of `plastic`/`metal`/`trans` (`rho rdiff`, `rho tdiff`), the specular
//!   transmission of `trans` (`rho tspec`), the specular reflection of `metal` without the
//!   Fresnel estimate (`rho rspec`), `mirror` (`rho`). The depth rules (`-ab`, `-lr`) are
//!   structural and do not depend on weights. Re-tracing the scaled scene gives a
//!   different *sample* (its roulette and lobe choices depend on the new colours) of the
//!   same expectation, so the two agree within Monte Carlo noise, not bit for bit.
//! - **approximations** (documented, small): a rough lobe folded into the diffuse one
//!   below `-st` (`rho rdiff + scolor`, only when the specularity is at most `-st`, 0.02 by
//!   default) is scaled as a whole; a pure-specular `metal`'s Fresnel-blended specular
//!   colour `F + rho s (1-F)` is scaled as a whole; a path with more than [`MAX_EVENTS`]
//!   tracked events counts only the first [`MAX_EVENTS`] (never with the default
//!   `-lr -10`).
//! - **glass**: a pane's transmission `T(theta)` is not proportional to its transmissivity
//!   (path length through the pane, inter-reflections between its faces), so a crossing is
//!   recorded with its incidence angle bin ([`GLASS_BINS`], [`Entry`]). [`Reweighting::apply`]
//!   gives every bin the material's one factor (`s T(theta)`: a neutral film or a
//!   maintenance factor on the pane); [`Reweighting::apply_entries`] gives each bin
//!   `T'(c_b) / T(c_b)`, a pane re-made with another transmissivity, exact at the bins'
//!   centre cosines (0.03 % in diffuse transmittance from 88 % to 50 % at normal incidence).
//! - not tracked: plastic/trans specular *reflection* (white, `rspec`: a property of the
//!   surface finish, not of its colour), glass reflection, emitters, `void`.
//!
//! Sun coefficients (`--suns`) record the glass/`trans` panes a sun ray crosses (shadow
//! transmission `T`, `rho tspec`), with the same rules.
//!
//! ## Cost
//! Measured on the furnished office fixture (165 sensors, MF 1, `-ab 5 -ad 10000`, all 9
//! materials tracked, 2 threads): +15 % CPU time, peak memory 5 MB -> 12 MB, a 3.8 MB file
//! (about 87 000 terms, 530 per sensor); the coefficient output is byte-identical.
//!
//! ## File format (`rdc --reweight FILE`)
//! One line of JSON, then binary rows, all little-endian:
//!
//! ```text
//! {"format":"rdaylight-reweight","version":2,"nrows":R,"ncols":C,"ncomp":K,
//!  "materials":["wall","glazing",...],"entries":[{"material":0,"cos":null},
//!  {"material":1,"cos":0.03125},...],"max_events":16,"command":"rdc ..."}\n
//! R times:  u32 T (terms in this row), then T terms of
//!           u32 column | 16 x u8 signature | K x f64 mean contribution
//! ```
//!
//! A signature lists the tracked numbers met, 1-based indices into `entries` (version 1
//! files have no `entries`: the numbers index `materials`), in ascending order, padded with
//! zeros (all zeros: the path met no tracked material). The
//! terms of a row are sorted by (column, signature); a (column, signature) pair appears at
//! most once. Row `r` column `c` channel `k` of the coefficient matrix is
//! `sum over the row's terms with column c of value[k] x prod over the signature's
//! numbers i of the factor of entries[i-1]`.
//!
//! ## Example
//! ```
//! use rdaylight_trace::trace::reweight::{Reweighting, Signature};
//! // One record, two columns, one channel; materials "wall" (1) and "floor" (2).
//! let mut rw = Reweighting::new(vec!["wall".into(), "floor".into()], 2, 1);
//! rw.push_row(&[
//!     (0, Signature::from_events(&[]), vec![0.5]),         // seen directly
//!     (0, Signature::from_events(&[1]), vec![0.2]),        // one wall bounce
//!     (1, Signature::from_events(&[1, 1, 2]), vec![0.1]),  // wall twice, floor once
//! ]);
//! let c = rw.apply(&[0.8, 1.0])?;                          // walls at 0.8 x reflectance
//! assert!((c[0] - (0.5 + 0.2 * 0.8)).abs() < 1e-12);
//! assert!((c[1] - 0.1 * 0.64).abs() < 1e-12);
//! let d = rw.sensitivity(0);                               // dC/ds_wall at s = 1
//! assert!((d[1] - 0.2).abs() < 1e-12);
//! # Ok::<(), rdaylight_base::Error>(())
//! ```

use super::compile::Renderable;
use crate::error::{Error, Location, Result};
use crate::material::ward::WardKind;
use crate::material::{Material, SampleKind};
use std::collections::HashMap;
use std::io::Write;

/// Tracked events recorded per path (the default `-lr -10` allows at most 10).
pub const MAX_EVENTS: usize = 16;
/// Tracked materials at most (signature entries are bytes, 0 = empty).
pub const MAX_TRACKED: usize = 255;
/// Most coefficients (`nrows x ncols x ncomp`) a re-weighting file may stand for: 2^28,
/// what [`Reweighting::apply`] returns as one dense `f64` matrix (2 GiB). A header is a
/// few bytes, so without a bound it could make `apply` allocate anything (fuzzing found
/// `"ncols":10000000000000`); the largest studies (10,000 sensors, 2306 columns, 3
/// channels: 69 million) stay well below it.
pub const MAX_COEFFICIENTS: usize = 1 << 28;
const FORMAT_NAME: &str = "rdaylight-reweight";

/// The multiset of tracked materials a path met: 1-based material numbers in ascending
/// order, zero padded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Signature(pub [u8; MAX_EVENTS]);

impl Signature {
    /// From the 1-based material numbers met, in any order (zeros ignored, at most
    /// [`MAX_EVENTS`] kept).
    pub fn from_events(events: &[u8]) -> Signature {
        let mut e = Events::default();
        for &x in events {
            e.push(x);
        }
        e.signature()
    }

    /// The 1-based material numbers, ascending.
    pub fn events(&self) -> impl Iterator<Item = u8> + '_ {
        self.0.iter().copied().take_while(|&x| x != 0)
    }

    /// How often 0-based tracked material `m` occurs.
    pub fn count(&self, m: usize) -> u32 {
        self.events().filter(|&x| usize::from(x) == m + 1).count() as u32
    }
}

/// A path's tracked events while it is being walked (unsorted, cheap to copy).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Events {
    ev: [u8; MAX_EVENTS],
    n: u8,
}

impl Events {
    /// Record one event at 1-based tracked material `id` (0: untracked, ignored).
    #[inline]
    pub fn push(&mut self, id: u8) {
        if id != 0 && usize::from(self.n) < MAX_EVENTS {
            self.ev[usize::from(self.n)] = id;
            self.n += 1;
        }
    }

    /// Record every event of `other` too (a shadow ray's panes after its path's events).
    #[inline]
    pub fn extend(&mut self, other: &Events) {
        for &id in &other.ev[..usize::from(other.n)] {
            self.push(id);
        }
    }

    /// The canonical (sorted) signature.
    pub fn signature(&self) -> Signature {
        let mut s = Signature::default();
        let n = usize::from(self.n);
        s.0[..n].copy_from_slice(&self.ev[..n]);
        s.0[..n].sort_unstable();
        s
    }
}

/// Angle bins of a glass pane's tracked crossings: the pane's transmission `T(cos)` does
/// not scale with its transmissivity by one factor (the path length through the pane and
/// the inter-reflections between its faces change with the angle), so each crossing is
/// recorded with the bin of its incidence cosine, `floor(16 |cos|)`, and a re-weighting may
/// give each bin its own factor `T'(c_b) / T(c_b)` at the bin's centre `c_b`. With 16 bins a
/// pane redrawn from 88 % to 50 % normal transmittance keeps its diffuse transmittance
/// within 0.03 % (one factor for all angles: 8 %).
pub const GLASS_BINS: usize = 16;

/// What one tracked number stands for: a material, and for a glass pane the incidence
/// cosine at the centre of the crossing's angle bin.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Entry {
    /// Index into the tracked material names.
    pub material: usize,
    pub cos: Option<f64>,
}

/// Which materials of a [`Renderable`] are tracked: per renderable material its first
/// 1-based tracked number (0 = not tracked) and whether its crossings are angle-binned,
/// the tracked names, and what each tracked number stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracking {
    pub(super) id: Vec<u8>,
    pub(super) binned: Vec<bool>,
    pub names: Vec<String>,
    pub entries: Vec<Entry>,
}

impl Tracking {
    /// Tracked number of renderable material `m` (0 = untracked).
    #[inline]
    pub(super) fn of(&self, m: u32) -> u8 {
        self.id.get(m as usize).copied().unwrap_or(0)
    }

    /// Tracked number of a crossing of renderable material `m` at incidence cosine `cos`
    /// (the angle bin's number for glass, [`GLASS_BINS`]).
    #[inline]
    pub(super) fn of_at(&self, m: u32, cos: f64) -> u8 {
        let base = self.of(m);
        if base != 0 && self.binned.get(m as usize).copied().unwrap_or(false) {
            let b = ((cos.abs() * GLASS_BINS as f64) as usize).min(GLASS_BINS - 1);
            base + b as u8
        } else {
            base
        }
    }
}

/// Whether a sampled lobe's coefficient is proportional to the material's colour (see the
/// module documentation for the cases).
pub fn scales_with_colour(m: &Material, kind: SampleKind) -> bool {
    match m {
        Material::Ward(w) => match kind {
            SampleKind::DiffuseReflect
            | SampleKind::DiffuseTransmit
            | SampleKind::SpecularTransmit
            | SampleKind::PureTransmit => true,
            SampleKind::SpecularReflect | SampleKind::PureReflect => w.kind == WardKind::Metal,
        },
        Material::Mirror(_) => true,
        Material::Glass(_) => kind == SampleKind::PureTransmit,
        // BSDF data is measured, not a colour to re-weight.
        Material::Emitter(_) | Material::Void { .. } | Material::Bsdf(_) => false,
    }
}

/// Whether a material has anything a colour scale changes.
fn scalable(m: &Material) -> bool {
    matches!(
        m,
        Material::Ward(_) | Material::Mirror(_) | Material::Glass(_)
    )
}

impl Renderable {
    /// The scene name (`id`) of each renderable material, recorded when the scene was
    /// compiled (materials no surface uses are not renderable; surfaces of flattened
    /// meshes and instances are not objects of the caller's scene).
    pub fn material_names(&self) -> Vec<String> {
        self.material_ids.clone()
    }

    /// Tracking for re-weighting: the named materials (`None`: every plastic, metal, trans,
    /// glass and mirror of the scene, in order of first use). Materials that share a name
    /// share a factor. An unknown name is an error listing the known ones.
    pub fn tracking(&self, names: Option<&[String]>) -> Result<Tracking> {
        let all = self.material_names();
        let mut tracked: Vec<String> = Vec::new();
        match names {
            Some(list) => {
                for n in list {
                    if !all
                        .iter()
                        .zip(&self.materials)
                        .any(|(a, m)| a == n && scalable(m))
                    {
                        let mut known: Vec<&str> = all
                            .iter()
                            .zip(&self.materials)
                            .filter(|(_, m)| scalable(m))
                            .map(|(a, _)| a.as_str())
                            .collect();
                        known.dedup();
                        return Err(Error::Usage(format!(
                            "--reweight-materials: no reflecting or transmitting material named '{n}' on a surface; the scene has: {}",
                            known.join(",")
                        )));
                    }
                    if !tracked.contains(n) {
                        tracked.push(n.clone());
                    }
                }
            }
            None => {
                for (a, m) in all.iter().zip(&self.materials) {
                    if scalable(m) && !tracked.contains(a) {
                        tracked.push(a.clone());
                    }
                }
            }
        }
        let is_glass = |name: &str| {
            all.iter()
                .zip(&self.materials)
                .any(|(a, m)| a == name && matches!(m, Material::Glass(_)))
        };
        let mut entries = Vec::new();
        let mut first = Vec::new();
        for (i, t) in tracked.iter().enumerate() {
            first.push(entries.len() + 1);
            if is_glass(t) {
                entries.extend((0..GLASS_BINS).map(|b| Entry {
                    material: i,
                    cos: Some((b as f64 + 0.5) / GLASS_BINS as f64),
                }));
            } else {
                entries.push(Entry {
                    material: i,
                    cos: None,
                });
            }
        }
        if entries.len() > MAX_TRACKED {
            return Err(Error::Usage(format!(
                "--reweight: {} materials to track ({} numbers, a glass pane takes {GLASS_BINS}), at most {MAX_TRACKED}; name the ones that vary with --reweight-materials",
                tracked.len(),
                entries.len()
            )));
        }
        let mut binned = Vec::new();
        let id = all
            .iter()
            .zip(&self.materials)
            .map(|(a, m)| {
                let pos = if scalable(m) {
                    tracked.iter().position(|t| t == a)
                } else {
                    None
                };
                binned.push(pos.is_some() && matches!(m, Material::Glass(_)));
                pos.map_or(0, |p| first[p] as u8)
            })
            .collect();
        Ok(Tracking {
            id,
            binned,
            names: tracked,
            entries,
        })
    }
}

/// One record's terms while it is being sampled: sums per (column, signature).
#[derive(Debug, Clone, Default)]
pub struct TermTally {
    index: HashMap<(u32, Signature), usize>,
    keys: Vec<(u32, Signature)>,
    sums: Vec<f64>,
}

impl TermTally {
    pub fn clear(&mut self) {
        self.index.clear();
        self.keys.clear();
        self.sums.clear();
    }

    /// Add `value` (one per channel) to (column, signature).
    pub fn add(&mut self, col: u32, sig: Signature, value: &[f64]) {
        let k = value.len();
        let i = *self.index.entry((col, sig)).or_insert_with(|| {
            self.keys.push((col, sig));
            self.sums.extend(std::iter::repeat_n(0.0, k));
            self.keys.len() - 1
        });
        for (s, v) in self.sums[i * k..(i + 1) * k].iter_mut().zip(value) {
            *s += v;
        }
    }

    /// Add another tally's sums (keys new to this one are appended in `other`'s order).
    pub fn merge(&mut self, other: &TermTally) {
        if other.keys.is_empty() {
            return;
        }
        let k = other.sums.len() / other.keys.len();
        for (i, &(col, sig)) in other.keys.iter().enumerate() {
            self.add(col, sig, &other.sums[i * k..(i + 1) * k]);
        }
    }

    /// The record's terms, sorted, each sum divided by `samples`.
    pub fn terms(&self, ncomp: usize, samples: u64) -> Vec<(u32, Signature, Vec<f64>)> {
        let n = samples.max(1) as f64;
        let mut out: Vec<(u32, Signature, Vec<f64>)> = self
            .keys
            .iter()
            .enumerate()
            .map(|(i, &(c, s))| {
                let v = self.sums[i * ncomp..(i + 1) * ncomp]
                    .iter()
                    .map(|x| x / n)
                    .collect();
                (c, s, v)
            })
            .collect();
        out.sort_by_key(|a| (a.0, a.1));
        out
    }
}

/// Re-weighting records of a whole run (see the module documentation): read one with
/// [`Reweighting::read`], evaluate variants with [`Reweighting::apply`].
#[derive(Debug, Clone, PartialEq)]
pub struct Reweighting {
    /// Tracked material names; factor `i` of [`Reweighting::apply`] scales `materials[i]`.
    pub materials: Vec<String>,
    /// What the signatures' numbers stand for (number `e` is `entries[e - 1]`): one entry
    /// per material, or [`GLASS_BINS`] per glass pane ([`Entry::cos`]).
    pub entries: Vec<Entry>,
    pub ncols: usize,
    pub ncomp: usize,
    /// Distinct signatures of the run.
    sigs: Vec<Signature>,
    /// Per row, the range of its terms in `cols`/`sig_of`.
    row_start: Vec<usize>,
    cols: Vec<u32>,
    sig_of: Vec<u32>,
    values: Vec<f64>,
    sig_index: HashMap<Signature, u32>,
}

impl Reweighting {
    /// Empty records for `ncols` columns of `ncomp` channels.
    pub fn new(materials: Vec<String>, ncols: usize, ncomp: usize) -> Reweighting {
        let entries = (0..materials.len())
            .map(|material| Entry {
                material,
                cos: None,
            })
            .collect();
        Reweighting {
            materials,
            entries,
            ncols,
            ncomp,
            sigs: Vec::new(),
            row_start: vec![0],
            cols: Vec::new(),
            sig_of: Vec::new(),
            values: Vec::new(),
            sig_index: HashMap::new(),
        }
    }

    /// The same, with the entries of a run that tracked glass by angle
    /// ([`Tracking::entries`]); an entry naming no material is an error.
    pub fn with_entries(mut self, entries: Vec<Entry>) -> Result<Reweighting> {
        if let Some(e) = entries.iter().find(|e| e.material >= self.materials.len()) {
            return Err(Error::Usage(format!(
                "re-weighting entry for material {} of {}",
                e.material,
                self.materials.len()
            )));
        }
        self.entries = entries;
        Ok(self)
    }

    /// Number of records (rows).
    pub fn nrows(&self) -> usize {
        self.row_start.len() - 1
    }

    /// Number of (row, column, signature) terms and of distinct signatures.
    pub fn size(&self) -> (usize, usize) {
        (self.cols.len(), self.sigs.len())
    }

    /// The distinct signatures of the run; [`Reweighting::row_terms`] refers to them by
    /// index.
    pub fn signatures(&self) -> &[Signature] {
        &self.sigs
    }

    /// Row `r`'s terms: `(column, signature index, ncomp values)`.
    pub fn row_terms(&self, r: usize) -> impl Iterator<Item = (usize, usize, &[f64])> + '_ {
        let k = self.ncomp;
        (self.row_start[r]..self.row_start[r + 1]).map(move |t| {
            (
                self.cols[t] as usize,
                self.sig_of[t] as usize,
                &self.values[t * k..(t + 1) * k],
            )
        })
    }

    /// Append a row of terms `(column, signature, ncomp values)`.
    pub fn push_row(&mut self, terms: &[(u32, Signature, Vec<f64>)]) {
        for (c, s, v) in terms {
            let next = self.sigs.len() as u32;
            let id = *self.sig_index.entry(*s).or_insert(next);
            if id == next {
                self.sigs.push(*s);
            }
            self.cols.push(*c);
            self.sig_of.push(id);
            self.values
                .extend((0..self.ncomp).map(|k| v.get(k).copied().unwrap_or(0.0)));
        }
        self.row_start.push(self.cols.len());
    }

    /// The coefficient matrix (`nrows x ncols x ncomp`, row-major, as rdc writes it) with
    /// tracked material `i`'s colour scaled by `scales[i]` in every channel.
    pub fn apply(&self, scales: &[f64]) -> Result<Vec<f64>> {
        if scales.len() != self.materials.len() {
            return Err(Error::Usage(format!(
                "re-weighting: {} scale factors for {} tracked materials ({})",
                scales.len(),
                self.materials.len(),
                self.materials.join(",")
            )));
        }
        let per_channel: Vec<f64> = scales
            .iter()
            .flat_map(|&s| std::iter::repeat_n(s, self.ncomp))
            .collect();
        self.apply_channels(&per_channel)
    }

    /// As [`Reweighting::apply`] with one factor per material and channel:
    /// `scales[i * ncomp + k]` (spectral or coloured draws).
    pub fn apply_channels(&self, scales: &[f64]) -> Result<Vec<f64>> {
        let k = self.ncomp;
        if scales.len() != self.materials.len() * k {
            return Err(Error::Usage(format!(
                "re-weighting: {} channel factors, expected {} materials x {k} channels",
                scales.len(),
                self.materials.len()
            )));
        }
        // One factor per distinct signature and channel, then a sparse sum.
        let mut factor = vec![1.0; self.sigs.len() * k];
        for (si, s) in self.sigs.iter().enumerate() {
            for e in s.events() {
                let m = self.material_of(e);
                for c in 0..k {
                    factor[si * k + c] *= scales.get(m * k + c).copied().unwrap_or(1.0);
                }
            }
        }
        Ok(self.accumulate(|si, c| factor[si * k + c]))
    }

    /// Derivative of every coefficient with respect to tracked material `m`'s factor at
    /// all factors 1: `sum over terms of n_m(sig) x value` (a first-order sensitivity).
    pub fn sensitivity(&self, m: usize) -> Vec<f64> {
        let counts: Vec<f64> = self
            .sigs
            .iter()
            .map(|s| s.events().filter(|&e| self.material_of(e) == m).count() as f64)
            .collect();
        self.accumulate(|si, _| counts[si])
    }

    /// The material index of 1-based tracked number `e`.
    fn material_of(&self, e: u8) -> usize {
        self.entries
            .get(usize::from(e) - 1)
            .map_or(usize::MAX, |x| x.material)
    }

    /// The coefficient matrix with one grey factor per tracked number (entry): for glass
    /// entries the caller gives `T'(c) / T(c)` at the entry's cosine.
    pub fn apply_entries(&self, factors: &[f64]) -> Result<Vec<f64>> {
        if factors.len() != self.entries.len() {
            return Err(Error::Usage(format!(
                "re-weighting: {} entry factors for {} entries",
                factors.len(),
                self.entries.len()
            )));
        }
        let f: Vec<f64> = self
            .sigs
            .iter()
            .map(|s| s.events().map(|e| factors[usize::from(e) - 1]).product())
            .collect();
        Ok(self.accumulate(|si, _| f[si]))
    }

    fn accumulate(&self, factor: impl Fn(usize, usize) -> f64) -> Vec<f64> {
        let k = self.ncomp;
        let mut out = vec![0.0; self.nrows() * self.ncols * k];
        for r in 0..self.nrows() {
            for t in self.row_start[r]..self.row_start[r + 1] {
                let (c, si) = (self.cols[t] as usize, self.sig_of[t] as usize);
                if c >= self.ncols {
                    continue;
                }
                let base = (r * self.ncols + c) * k;
                for ch in 0..k {
                    out[base + ch] += self.values[t * k + ch] * factor(si, ch);
                }
            }
        }
        out
    }

    /// Write in the file format of the module documentation.
    pub fn write(&self, w: impl Write, command: &str) -> std::io::Result<()> {
        let mut rw = RowWriter::start(
            w,
            &self.materials,
            &self.entries,
            self.nrows(),
            self.ncols,
            self.ncomp,
            command,
        )?;
        for r in 0..self.nrows() {
            let terms: Vec<(u32, Signature, Vec<f64>)> = (self.row_start[r]..self.row_start[r + 1])
                .map(|t| {
                    (
                        self.cols[t],
                        self.sigs[self.sig_of[t] as usize],
                        self.values[t * self.ncomp..(t + 1) * self.ncomp].to_vec(),
                    )
                })
                .collect();
            rw.row(&terms)?;
        }
        Ok(())
    }

    /// Read a file written by `rdc --reweight` (`name` for messages).
    pub fn read(path: &str) -> Result<Reweighting> {
        let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        Self::parse(&data, path)
    }

    /// Parse the bytes of a re-weighting file; errors name `name` and the byte offset.
    pub fn parse(data: &[u8], name: &str) -> Result<Reweighting> {
        use nom::Parser;
        use nom::bytes::complete::{take, take_until};
        use nom::number::complete::{le_f64, le_u32};
        let err = |off: usize, msg: String| {
            Error::parse(Location::file(name), format!("byte {off}: {msg}"))
        };
        let header_res: nom::IResult<&[u8], &[u8]> = take_until(&b"\n"[..]).parse(data);
        let Ok((_, line)) = header_res else {
            return Err(err(
                0,
                "no header line; expected a JSON line then binary rows".into(),
            ));
        };
        let h: Header = serde_json::from_slice(line)
            .map_err(|e| err(0, format!("header is not the expected JSON ({e})")))?;
        if h.format != FORMAT_NAME || !(1..=2).contains(&h.version) {
            return Err(err(
                0,
                format!(
                    "format '{}' version {}; expected '{FORMAT_NAME}' version 1 or 2",
                    h.format, h.version
                ),
            ));
        }
        let max_ncomp = crate::radiometry::MAX_SAMPLES;
        if h.max_events != MAX_EVENTS
            || !(1..=max_ncomp).contains(&h.ncomp)
            || h.materials.len() > MAX_TRACKED
        {
            return Err(err(
                0,
                format!(
                    "max_events {}, ncomp {}, {} materials; expected {MAX_EVENTS}, 1 to {max_ncomp}, at most {MAX_TRACKED}",
                    h.max_events,
                    h.ncomp,
                    h.materials.len()
                ),
            ));
        }
        let coefficients = h
            .nrows
            .checked_mul(h.ncols)
            .and_then(|n| n.checked_mul(h.ncomp));
        if coefficients.is_none_or(|n| n > MAX_COEFFICIENTS) {
            return Err(err(
                0,
                format!(
                    "{} rows x {} columns x {} channels; expected at most {MAX_COEFFICIENTS} coefficients (split the sensors into rdc runs of fewer rows)",
                    h.nrows, h.ncols, h.ncomp
                ),
            ));
        }
        let k = h.ncomp;
        let term_bytes = 4 + MAX_EVENTS + 8 * k;
        let mut rw = Reweighting::new(h.materials, h.ncols, k);
        if !h.entries.is_empty() {
            rw = rw
                .with_entries(h.entries)
                .map_err(|e| err(0, e.to_string()))?;
        }
        if rw.entries.len() > MAX_TRACKED {
            return Err(err(
                0,
                format!("{} entries, at most {MAX_TRACKED}", rw.entries.len()),
            ));
        }
        let mut rest = &data[line.len() + 1..];
        for r in 0..h.nrows {
            let off = data.len() - rest.len();
            let (r2, t) = le_u32::<_, nom::error::Error<&[u8]>>
                .parse(rest)
                .map_err(|_| {
                    err(
                        off,
                        format!("row {r} of {} missing; file truncated", h.nrows),
                    )
                })?;
            let t = t as usize;
            // Validate the count against what is left before allocating.
            if r2.len() / term_bytes < t {
                return Err(err(
                    off,
                    format!(
                        "row {r} announces {t} terms, only {} bytes left; file truncated",
                        r2.len()
                    ),
                ));
            }
            rest = r2;
            let mut terms = Vec::with_capacity(t);
            for _ in 0..t {
                let off = data.len() - rest.len();
                let (r3, (col, sig)) = (le_u32::<_, nom::error::Error<&[u8]>>, take(MAX_EVENTS))
                    .parse(rest)
                    .map_err(|_| err(off, "term truncated".into()))?;
                let mut s = Signature::default();
                s.0.copy_from_slice(sig);
                let valid =
                    s.0.windows(2)
                        .all(|w| w[1] == 0 || (w[0] != 0 && w[0] <= w[1]))
                        && s.events().all(|e| usize::from(e) <= rw.entries.len());
                if !valid || col as usize >= h.ncols {
                    return Err(err(
                        off,
                        format!(
                            "row {r}: column {col} / signature {:?}; expected a column < {} and ascending tracked numbers <= {}",
                            s.events().collect::<Vec<_>>(),
                            h.ncols,
                            rw.entries.len()
                        ),
                    ));
                }
                let (r4, v) = nom::multi::count(le_f64::<_, nom::error::Error<&[u8]>>, k)
                    .parse(r3)
                    .map_err(|_| err(off, "term values truncated".into()))?;
                rest = r4;
                terms.push((col, s, v));
            }
            rw.push_row(&terms);
        }
        if !rest.is_empty() {
            return Err(err(
                data.len() - rest.len(),
                format!(
                    "{} bytes after the {} rows; expected the end of the file",
                    rest.len(),
                    h.nrows
                ),
            ));
        }
        Ok(rw)
    }
}

#[derive(serde::Serialize, serde::Deserialize)]
struct Header {
    format: String,
    version: u32,
    nrows: usize,
    ncols: usize,
    ncomp: usize,
    materials: Vec<String>,
    /// Version 2: what each tracked number stands for (absent: one per material).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    entries: Vec<Entry>,
    max_events: usize,
    #[serde(default)]
    command: String,
}

/// Streaming writer of the file format: the header, then one [`RowWriter::row`] per record.
pub struct RowWriter<W: Write> {
    w: W,
    buf: Vec<u8>,
}

impl<W: Write> RowWriter<W> {
    pub fn start(
        mut w: W,
        materials: &[String],
        entries: &[Entry],
        nrows: usize,
        ncols: usize,
        ncomp: usize,
        command: &str,
    ) -> std::io::Result<RowWriter<W>> {
        let h = Header {
            format: FORMAT_NAME.into(),
            version: 2,
            nrows,
            ncols,
            ncomp,
            materials: materials.to_vec(),
            entries: entries.to_vec(),
            max_events: MAX_EVENTS,
            command: command.into(),
        };
        let line = serde_json::to_string(&h).map_err(std::io::Error::other)?;
        w.write_all(line.as_bytes())?;
        w.write_all(b"\n")?;
        Ok(RowWriter { w, buf: Vec::new() })
    }

    pub fn row(&mut self, terms: &[(u32, Signature, Vec<f64>)]) -> std::io::Result<()> {
        self.buf.clear();
        self.buf
            .extend_from_slice(&(terms.len() as u32).to_le_bytes());
        for (c, s, v) in terms {
            self.buf.extend_from_slice(&c.to_le_bytes());
            self.buf.extend_from_slice(&s.0);
            for x in v {
                self.buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        self.w.write_all(&self.buf)
    }

    /// The underlying writer (flush it yourself).
    pub fn into_inner(self) -> W {
        self.w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Reweighting {
        let mut rw = Reweighting::new(vec!["a".into(), "b".into()], 3, 2);
        rw.push_row(&[
            (0, Signature::from_events(&[]), vec![1.0, 2.0]),
            (2, Signature::from_events(&[2, 1]), vec![0.5, 0.25]),
        ]);
        rw.push_row(&[]);
        rw.push_row(&[(1, Signature::from_events(&[1, 1]), vec![4.0, 8.0])]);
        rw
    }

    fn bytes(rw: &Reweighting) -> Vec<u8> {
        let mut v = Vec::new();
        rw.write(&mut v, "rdc test").unwrap();
        v
    }

    #[test]
    fn signatures_are_sorted_multisets() {
        let s = Signature::from_events(&[3, 1, 3, 0, 2]);
        assert_eq!(s.events().collect::<Vec<_>>(), [1, 2, 3, 3]);
        assert_eq!((s.count(2), s.count(0), s.count(5)), (2, 1, 0));
        assert_eq!(s, Signature::from_events(&[3, 3, 2, 1]));
        let many = Signature::from_events(&[1; 40]);
        assert_eq!(many.events().count(), MAX_EVENTS);
    }

    #[test]
    fn apply_and_sensitivity_are_the_polynomial() {
        let rw = sample();
        let c = rw.apply(&[0.5, 2.0]).unwrap();
        let mut want = vec![0.0; 3 * 3 * 2];
        want[0] = 1.0;
        want[1] = 2.0;
        want[4] = 0.5 * 0.5 * 2.0;
        want[5] = 0.25 * 0.5 * 2.0;
        want[2 * 6 + 2] = 4.0 * 0.25;
        want[2 * 6 + 3] = 8.0 * 0.25;
        assert_eq!(c, want);
        let one = rw.apply(&[1.0, 1.0]).unwrap();
        assert_eq!(one[4], 0.5);
        let d = rw.sensitivity(0);
        assert_eq!((d[4], d[2 * 6 + 2], d[0]), (0.5, 8.0, 0.0));
        assert!(rw.apply(&[1.0]).is_err());
        let ch = rw.apply_channels(&[0.5, 1.0, 2.0, 1.0]).unwrap();
        assert_eq!((ch[4], ch[5]), (0.5 * 0.5 * 2.0, 0.25));
    }

    #[test]
    fn files_round_trip() {
        let rw = sample();
        let back = Reweighting::parse(&bytes(&rw), "x.rw").unwrap();
        assert_eq!(
            back.apply(&[0.3, 0.7]).unwrap(),
            rw.apply(&[0.3, 0.7]).unwrap()
        );
        assert_eq!((back.nrows(), back.size()), (3, (3, 3)));
    }

    #[test]
    fn every_truncated_prefix_is_an_error() {
        let b = bytes(&sample());
        for n in 0..b.len() {
            let e = Reweighting::parse(&b[..n], "x.rw").unwrap_err().to_string();
            assert!(e.starts_with("x.rw: byte "), "{n}: {e}");
        }
        let mut extra = b.clone();
        extra.push(0);
        assert!(Reweighting::parse(&extra, "x.rw").is_err());
    }

    #[test]
    fn bad_terms_and_huge_counts_are_errors() {
        let b = bytes(&sample());
        let body = b.iter().position(|&x| x == b'\n').unwrap() + 1;
        let mut huge = b.clone();
        huge[body..body + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = Reweighting::parse(&huge, "x.rw").unwrap_err().to_string();
        assert!(e.contains("announces 4294967295 terms"), "{e}");
        let mut badsig = b.clone();
        badsig[body + 8] = 9; // material 9 of 2
        let e = Reweighting::parse(&badsig, "x.rw").unwrap_err().to_string();
        assert!(e.contains("expected a column < 3"), "{e}");
        let e = Reweighting::parse(b"{\"format\":\"x\"}\n", "x.rw")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("x.rw: byte 0: header"), "{e}");
    }

    /// Fuzzing (fuzz/README.md, `reweight` target): a header claiming 10^13 columns read
    /// without complaint and made `apply` allocate 80 TB; one claiming 2^61 channels
    /// overflowed the term size. Both are errors naming the sizes.
    #[test]
    fn huge_header_sizes_are_errors() {
        let file = |nrows: u64, ncols: u64, ncomp: u64| {
            let mut b = format!(
                "{{\"format\":\"rdaylight-reweight\",\"version\":2,\"nrows\":{nrows},\
                 \"ncols\":{ncols},\"ncomp\":{ncomp},\"materials\":[\"a\"],\"entries\":[],\
                 \"max_events\":16,\"command\":\"\"}}\n"
            )
            .into_bytes();
            b.extend(0u32.to_le_bytes());
            Reweighting::parse(&b, "x.rw").map(|rw| rw.size())
        };
        let e = file(1, 10_000_000_000_000, 1).unwrap_err().to_string();
        assert_eq!(
            e,
            "x.rw: byte 0: 1 rows x 10000000000000 columns x 1 channels; expected at most \
             268435456 coefficients (split the sensors into rdc runs of fewer rows)"
        );
        let e = file(1, 3, 1 << 61).unwrap_err().to_string();
        assert!(e.contains("ncomp 2305843009213693952,"), "{e}");
        assert!(e.contains("expected 16, 1 to 24,"), "{e}");
        assert!(file(u64::MAX, u64::MAX, 3).is_err());
        assert_eq!(file(1, 3, 3).unwrap(), (0, 0));
    }
}
