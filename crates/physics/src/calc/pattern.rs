//! Patterns defined by `.cal` files, evaluated per ray: `brightfunc`, `colorfunc`
//! (`src/rt/p_func.c`), `specfunc` and `specdata` (Radiance 6, `p_func.c`, `p_data.c`).
//!
//! | type | string arguments | real arguments | value |
//! |---|---|---|---|
//! | `brightfunc` | `expr file.cal [xf]` | `A1..` | scalar `expr` |
//! | `colorfunc` | `rexpr gexpr bexpr file.cal [xf]` | `A1..` | RGB, taken to the run's channels as Radiance's `setscolor` does |
//! | `specfunc` | `sfunc file.cal [xf]` | `nmA nmB A3..` | `sfunc(nm)` sampled over `nmA..nmB` (clipped to the run's range) in `(nmB - nmA)/24` steps, then band-averaged |
//! | `specdata` | `sfunc data.dat file.cal x1 .. x(N-1) [xf]` | `A1..` | the N-D data file interpolated at the coordinates `x1..` over its first N-1 axes; its last axis is wavelength; `sfunc(value, nm)` per sample, then band-averaged |
//!
//! Where they apply: on distant glows (skies) per escaping ray ([`CalPatterns`] in
//! `rdaylight_trace::trace::SkyPattern`); on surfaces per hit ([`PatternedMaterial`]), or once when
//! no expression they evaluate reads the ray ([`CalPattern::is_constant`]).
//!
//! `file.cal` may be `.` (no file). Coordinates and colour expressions are expressions in
//! the file's context. The band averaging is the one `spectrum` and `specfile` use
//! ([`crate::material::spectrum::Sampled::to_channels`], Radiance's `convertscolorcol`).
//!
//! Deviations, each refused or documented rather than silently different:
//! - transforms (`xf` arguments: [`super::xf`]) apply to what the pattern sees of the ray;
//! - `specfunc` samples at step centres; Radiance jitters each sample within its step with
//!   `frandom()` (noise that averages to the same value);
//! - on distant sources the ray origin is taken as the world origin (`Px Py Pz` = 0;
//!   Radiance uses the origin of the ray that escaped);
//! - `T` and `Ts` are the length of the current ray segment (Radiance adds the distances
//!   of the parent rays of the same kind, `raydist`); they agree for primary rays;
//! - an evaluation error inside a render (a missing real argument, runaway recursion)
//!   leaves the ray's colour unchanged, as Radiance's "compute error" warning does; errors
//!   that every ray would hit are found when the scene is compiled, at a probe ray.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use super::xf::{Xf, is_xf_option};
use super::{Expr, Function, Inputs, Program};
use crate::error::{Error, Result};
use crate::material::Color;
use crate::material::spectrum::Sampled;
use crate::radiometry::{Channels, MAX_SAMPLES};
use crate::scene::specdata::DataArray;
use crate::scene::{OType, Object, Primitive, Scene};

/// What a pattern sees of the ray it modifies (Radiance's `chanvalue`, identity transform).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayVars {
    /// Ray direction (`Dx Dy Dz`).
    pub dir: [f64; 3],
    /// Surface normal (`Nx Ny Nz`), facing the ray's origin side as Radiance flips it.
    pub normal: [f64; 3],
    /// Hit point (`Px Py Pz`).
    pub point: [f64; 3],
    /// Distance travelled (`T`).
    pub dist: f64,
    /// `Rdot`: -(direction . normal), clamped to [-1, 1].
    pub rdot: f64,
}

impl RayVars {
    /// A ray that escaped towards a distant source, as `rayorigin` + `sourcehit` leave it:
    /// normal `-D`, `Rdot` 1, distance `FHUGE` (1e10).
    pub fn escaping(dir: [f64; 3]) -> RayVars {
        RayVars {
            dir,
            normal: [-dir[0], -dir[1], -dir[2]],
            point: [0.0; 3],
            dist: 1e10,
            rdot: 1.0,
        }
    }

    /// `$1..$27` in the order of [`super::RAY_VARIABLES`].
    pub fn channels(&self) -> [f64; 27] {
        let mut c = [0.0; 27];
        c[0..3].copy_from_slice(&self.dir);
        c[3..6].copy_from_slice(&self.normal);
        c[6..9].copy_from_slice(&self.point);
        c[9] = self.dist;
        c[10] = self.rdot.clamp(-1.0, 1.0);
        c[11] = 1.0; // S
        // Tx Ty Tz = 0; I, J, K the world axes.
        c[15] = 1.0;
        c[19] = 1.0;
        c[23] = 1.0;
        c[24] = self.dist; // Ts
        c
    }
}

#[derive(Debug)]
enum Kind {
    Bright(Expr),
    Color([Expr; 3]),
    SpecFunc {
        f: Function,
        lo: f64,
        hi: f64,
    },
    SpecData {
        f: Function,
        data: Arc<DataArray>,
        coords: Vec<Expr>,
    },
}

/// One function-file pattern, ready to evaluate from any thread.
#[derive(Debug)]
pub struct CalPattern {
    /// The pattern's id and type (for messages).
    pub id: String,
    program: Arc<Program>,
    args: Vec<f64>,
    kind: Kind,
    /// The inverse of the pattern's transform, if it has one.
    xf: Option<Xf>,
    ray_dependent: bool,
}

/// Loads each `.cal` and data file once per scene.
#[derive(Debug, Default)]
pub struct Loader {
    programs: HashMap<PathBuf, Arc<Program>>,
    data: HashMap<PathBuf, Arc<DataArray>>,
}

fn find(file: &str, o: &Object, what: &str) -> Result<PathBuf> {
    crate::scene::find_file(file, &o.loc.file).ok_or_else(|| {
        Error::parse(
            o.loc.clone(),
            format!(
                "{} '{}': {what} '{file}' not found (looked beside the scene file, in the working folder and on RAYPATH)",
                o.type_name(),
                o.id
            ),
        )
    })
}

impl Loader {
    fn program(&mut self, file: &str, o: &Object) -> Result<Arc<Program>> {
        if file == "." {
            return Ok(Arc::new(Program::default()));
        }
        let path = find(file, o, "function file")?;
        if let Some(p) = self.programs.get(&path) {
            return Ok(p.clone());
        }
        let p = Arc::new(Program::load(&path)?);
        self.programs.insert(path, p.clone());
        Ok(p)
    }

    fn data(&mut self, file: &str, o: &Object) -> Result<Arc<DataArray>> {
        let path = find(file, o, "data file")?;
        if let Some(d) = self.data.get(&path) {
            return Ok(d.clone());
        }
        let bytes = std::fs::read(&path).map_err(|e| Error::io(path.display().to_string(), e))?;
        let d = Arc::new(DataArray::parse(
            &String::from_utf8_lossy(&bytes),
            &path.display().to_string(),
        )?);
        self.data.insert(path, d.clone());
        Ok(d)
    }
}

/// Whether `o` is a pattern this module evaluates.
pub fn is_cal_pattern(o: &Object) -> bool {
    matches!(
        o.kind,
        Primitive::BrightFunc { .. }
            | Primitive::ColorFunc { .. }
            | Primitive::Other {
                otype: OType::SpecData | OType::SpecFunc,
                ..
            }
    )
}

impl CalPattern {
    /// Build the pattern of object `o` (a type for which [`is_cal_pattern`] holds) and
    /// check it at a probe ray (straight up), so that undefined names and missing
    /// arguments are reported at the object's location before rendering.
    pub fn from_object(o: &Object, ch: &Channels, loader: &mut Loader) -> Result<CalPattern> {
        let bad = |msg: String| Error::parse(o.loc.clone(), msg);
        // Radiance skips words before the first transform option (getfunc).
        let mut xf: Option<Xf> = None;
        let mut set_xf = |args: &[String]| -> Result<()> {
            let start = args
                .iter()
                .position(|a| is_xf_option(a))
                .unwrap_or(args.len());
            if start < args.len() {
                xf = Some(Xf::inverse_of(
                    &args[start..],
                    &o.loc,
                    &format!("{} '{}'", o.type_name(), o.id),
                )?);
            }
            Ok(())
        };
        let expr = |p: &Program, text: &str| -> Result<Expr> {
            p.expr(
                text,
                &format!("{} '{}' argument '{text}'", o.type_name(), o.id),
            )
        };
        let (program, args, kind) = match &o.kind {
            Primitive::BrightFunc {
                function,
                file,
                transform,
                args,
            } => {
                set_xf(transform)?;
                let p = loader.program(file, o)?;
                let e = expr(&p, function)?;
                (p, args.clone(), Kind::Bright(e))
            }
            Primitive::ColorFunc {
                functions,
                file,
                transform,
                args,
            } => {
                set_xf(transform)?;
                let p = loader.program(file, o)?;
                let [r, g, b] = functions.as_slice() else {
                    return Err(bad(format!(
                        "colorfunc '{}' has {} colour expressions; expected 3",
                        o.id,
                        functions.len()
                    )));
                };
                let k = Kind::Color([expr(&p, r)?, expr(&p, g)?, expr(&p, b)?]);
                (p, args.clone(), k)
            }
            Primitive::Other {
                otype: OType::SpecFunc,
                strings,
                reals,
            } => {
                let [sfunc, file, xf @ ..] = strings.as_slice() else {
                    return Err(bad(format!(
                        "specfunc '{}' expects at least 2 string arguments (function, file)",
                        o.id
                    )));
                };
                set_xf(xf)?;
                let (Some(&a), Some(&b)) = (reals.first(), reals.get(1)) else {
                    return Err(bad(format!(
                        "specfunc '{}' expects at least 2 real arguments (nmA nmB)",
                        o.id
                    )));
                };
                let p = loader.program(file, o)?;
                let f = p
                    .function(sfunc)
                    .map_err(|e| bad(format!("specfunc '{}': {e}", o.id)))?;
                let (lo, hi) = (a.min(b), a.max(b));
                (p, reals.clone(), Kind::SpecFunc { f, lo, hi })
            }
            Primitive::Other {
                otype: OType::SpecData,
                strings,
                reals,
            } => {
                let [sfunc, dfile, file, rest @ ..] = strings.as_slice() else {
                    return Err(bad(format!(
                        "specdata '{}' expects at least 3 string arguments (function, data file, function file)",
                        o.id
                    )));
                };
                let data = loader.data(dfile, o)?;
                let nd = data.dims();
                if nd < 2 {
                    return Err(bad(format!(
                        "specdata '{}': data file '{dfile}' has {nd} dimension; expected at least 2 (coordinates, then wavelength last)",
                        o.id
                    )));
                }
                if rest.len() < nd - 1 {
                    return Err(bad(format!(
                        "specdata '{}': data file '{dfile}' has {nd} dimensions, so {} coordinate expressions are expected after the function file; found {}",
                        o.id,
                        nd - 1,
                        rest.len()
                    )));
                }
                let (coords, xf) = rest.split_at(nd - 1);
                set_xf(xf)?;
                let p = loader.program(file, o)?;
                let f = p
                    .function(sfunc)
                    .map_err(|e| bad(format!("specdata '{}': {e}", o.id)))?;
                let coords = coords
                    .iter()
                    .map(|c| expr(&p, c))
                    .collect::<Result<Vec<_>>>()?;
                (p, reals.clone(), Kind::SpecData { f, data, coords })
            }
            _ => {
                return Err(bad(format!(
                    "{} '{}' is not a function-file pattern",
                    o.type_name(),
                    o.id
                )));
            }
        };
        let mut pat = CalPattern {
            id: format!("{} '{}'", o.type_name(), o.id),
            program,
            args,
            kind,
            xf,
            ray_dependent: true,
        };
        pat.ray_dependent = pat.reads_ray();
        pat.try_eval(&RayVars::escaping([0.0, 0.0, 1.0]), ch)
            .map_err(|e| Error::parse(o.loc.clone(), format!("{}: {e}", pat.id)))?;
        Ok(pat)
    }

    /// Whether the value can change from ray to ray: a static check that no expression or
    /// function the pattern evaluates reads a ray variable.
    fn reads_ray(&self) -> bool {
        let p = &self.program;
        match &self.kind {
            Kind::Bright(e) => p.reads_ray(e),
            Kind::Color(es) => es.iter().any(|e| p.reads_ray(e)),
            Kind::SpecFunc { f, .. } => p.function_reads_ray(f),
            Kind::SpecData { f, coords, .. } => {
                p.function_reads_ray(f) || coords.iter().any(|e| p.reads_ray(e))
            }
        }
    }

    /// True when the pattern does not depend on the ray (so a constant colour can stand
    /// for it).
    pub fn is_constant(&self) -> bool {
        !self.ray_dependent
    }

    /// The pattern's colour factor for a ray; errors leave the colour unchanged (factor 1),
    /// as Radiance's "compute error" does.
    pub fn eval(&self, ray: &RayVars, ch: &Channels) -> Color {
        self.try_eval(ray, ch)
            .unwrap_or_else(|_| Color::splat(ch.ncomp.max(1), 1.0))
    }

    /// The pattern's colour factor, or the evaluation error.
    pub fn try_eval(&self, ray: &RayVars, ch: &Channels) -> Result<Color> {
        let mut chan = ray.channels();
        if let Some(x) = &self.xf {
            x.apply(&mut chan);
        }
        let inputs = Inputs {
            chan: &chan,
            args: &self.args,
        };
        let p = &self.program;
        let n = ch.ncomp.max(1);
        match &self.kind {
            Kind::Bright(e) => Ok(Color::splat(n, p.eval(e, inputs)?)),
            Kind::Color([r, g, b]) => Ok(crate::material::to_channels(
                [p.eval(r, inputs)?, p.eval(g, inputs)?, p.eval(b, inputs)?],
                ch,
            )),
            Kind::SpecFunc { f, lo, hi } => {
                // p_specfunc: clip to the run's range, MAXCSAMP steps, no finer than a
                // quarter band.
                let (wmin, wmax) = (
                    ch.splits[3].min(ch.splits[0]),
                    ch.splits[3].max(ch.splits[0]),
                );
                let (lo, hi) = (lo.max(wmin), hi.min(wmax));
                if lo >= hi {
                    return Ok(Color::splat(n, 1.0)); // "incompatible wavelength sampling"
                }
                let step = ((hi - lo) / MAX_SAMPLES as f64).max(0.25 / n as f64 * (wmax - wmin));
                let ns = ((hi - lo) / step + 0.1) as usize;
                // Samples downward from half a step below the top (p_specfunc).
                let vals = (0..ns)
                    .map(|i| p.call(f, &[hi - (ns as f64 - i as f64 - 0.5) * step], inputs))
                    .collect::<Result<Vec<f64>>>()?;
                // convertscolorcol(.., ns, lo, hi): ns intervals covering lo..hi.
                let h = 0.5 * (hi - lo) / ns.max(1) as f64;
                Ok(Sampled::new(lo + h, hi - h, vals).to_channels(ch))
            }
            Kind::SpecData { f, data, coords } => {
                let pt = coords
                    .iter()
                    .map(|c| p.eval(c, inputs))
                    .collect::<Result<Vec<f64>>>()?;
                let v = data.vector(&pt);
                let ax = data
                    .axes
                    .last()
                    .ok_or_else(|| Error::Usage("empty data".into()))?;
                let wl_axis = DataArray {
                    axes: vec![ax.clone()],
                    values: v,
                };
                let step = ax.siz / (ax.n as f64 - 1.0);
                let vals = (0..ax.n)
                    .map(|i| {
                        let wl = ax.org + i as f64 * step;
                        p.call(f, &[wl_axis.value(&[wl]), wl], inputs)
                    })
                    .collect::<Result<Vec<f64>>>()?;
                Ok(Sampled::new(ax.org, ax.org + ax.siz, vals).to_channels(ch))
            }
        }
    }
}

/// The product of several patterns (a modifier chain) in a run's channels, shared by the
/// tracer's threads.
#[derive(Debug, Clone)]
pub struct CalPatterns {
    pub list: Vec<Arc<CalPattern>>,
    pub ch: Channels,
}

impl CalPatterns {
    pub fn eval(&self, ray: &RayVars) -> Color {
        let ch = &self.ch;
        let mut it = self.list.iter();
        let Some(first) = it.next() else {
            return Color::splat(ch.ncomp.max(1), 1.0);
        };
        it.fold(first.eval(ray, ch), |acc, p| acc * p.eval(ray, ch))
    }
}

impl PartialEq for CalPatterns {
    fn eq(&self, o: &Self) -> bool {
        self.ch == o.ch
            && self.list.len() == o.list.len()
            && self
                .list
                .iter()
                .zip(&o.list)
                .all(|(a, b)| Arc::ptr_eq(a, b))
    }
}

/// The function-file patterns of one scene, built when first asked for (Radiance too only
/// loads a pattern's files when a ray first meets it) and shared afterwards.
pub struct ScenePatterns<'s> {
    scene: &'s Scene,
    ch: Channels,
    loader: RefCell<Loader>,
    built: RefCell<HashMap<usize, Arc<CalPattern>>>,
}

impl<'s> ScenePatterns<'s> {
    pub fn new(scene: &'s Scene, ch: &Channels) -> Self {
        ScenePatterns {
            scene,
            ch: *ch,
            loader: RefCell::default(),
            built: RefCell::default(),
        }
    }

    /// The pattern of object `k`, which must satisfy [`is_cal_pattern`].
    pub fn get(&self, k: usize) -> Result<Arc<CalPattern>> {
        if let Some(p) = self.built.borrow().get(&k) {
            return Ok(p.clone());
        }
        let o = self
            .scene
            .objects
            .get(k)
            .ok_or_else(|| Error::Usage(format!("no object {k}")))?;
        let p = Arc::new(CalPattern::from_object(
            o,
            &self.ch,
            &mut self.loader.borrow_mut(),
        )?);
        self.built.borrow_mut().insert(k, p.clone());
        Ok(p)
    }

    /// True for a function-file pattern that gives the same colour for every ray, and for
    /// one that fails to build (so that the caller asks for its colour and reports the
    /// error).
    pub fn is_constant(&self, k: usize) -> bool {
        match self.scene.objects.get(k) {
            Some(o) if is_cal_pattern(o) => self.get(k).map_or(true, |p| p.is_constant()),
            _ => false,
        }
    }

    /// The colour of a constant pattern (see [`ScenePatterns::is_constant`]).
    pub fn constant_color(&self, k: usize) -> Result<Color> {
        let p = self.get(k)?;
        p.try_eval(&RayVars::escaping([0.0, 0.0, 1.0]), &self.ch)
    }

    /// The run's channels.
    pub fn channels(&self) -> Channels {
        self.ch
    }
}

/// A surface material modified by function-file patterns that depend on the ray: rebuilt
/// at each hit with the pattern colour there (Radiance's `r->pcol`, which `raytexture`
/// sets before the material routine runs, with the geometric normal, before any flip).
#[derive(Debug, Clone)]
pub struct PatternedMaterial {
    kind: Primitive,
    loc: crate::error::Location,
    id: String,
    /// Product of the constant patterns of the chain.
    base: Option<Color>,
    pats: CalPatterns,
    opts: crate::material::ShadingOptions,
    /// The material without the varying patterns, used if a hit's colour is unusable.
    fallback: crate::material::Material,
}

impl PatternedMaterial {
    /// `material` is the scene object of the material, `base` the constant pattern colour,
    /// `fallback` the material built with `base` only.
    pub fn new(
        material: &Object,
        base: Option<Color>,
        pats: CalPatterns,
        opts: &crate::material::ShadingOptions,
        fallback: crate::material::Material,
    ) -> Self {
        PatternedMaterial {
            kind: material.kind.clone(),
            loc: material.loc.clone(),
            id: material.id.clone(),
            base,
            pats,
            opts: *opts,
            fallback,
        }
    }

    /// The material at a hit: `dir` the ray direction, `normal` the unflipped geometric
    /// normal, `point` the hit point, `t` the distance travelled.
    pub fn at(
        &self,
        dir: [f64; 3],
        normal: [f64; 3],
        point: [f64; 3],
        t: f64,
    ) -> crate::material::Material {
        let rdot = -(dir[0] * normal[0] + dir[1] * normal[1] + dir[2] * normal[2]);
        let ray = RayVars {
            dir,
            normal,
            point,
            dist: t,
            rdot,
        };
        let mut pcol = self.pats.eval(&ray);
        if let Some(b) = self.base {
            pcol = pcol * b;
        }
        // Colours must be finite and non-negative for the material; Radiance would carry a
        // negative pattern value into the shading, we fall back to the unpatterned material.
        if !pcol.as_slice().iter().all(|v| v.is_finite() && *v >= 0.0) {
            return self.fallback.clone();
        }
        // A BSDF keeps its data (loaded once from its XML file) and takes the colour.
        if let crate::material::Material::Bsdf(b) = &self.fallback {
            return crate::material::Material::Bsdf(Box::new(b.with_pattern(Some(pcol))));
        }
        match crate::material::Material::build_patterned(
            &self.kind,
            &self.pats.ch,
            &self.opts,
            &self.loc,
            &self.id,
            Some(pcol),
        ) {
            Ok(Some(m)) => m,
            _ => self.fallback.clone(),
        }
    }
}
