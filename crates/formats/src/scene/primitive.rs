//! Typed primitives: a Radiance object's type plus its validated arguments.
//!
//! The argument layouts are those of `doc/ray.1` (radiance-notes.md section 4.2). Types the
//! tracer models get named fields; every other type keeps its arguments verbatim in
//! [`Primitive::Other`] after its counts were checked, so nothing is dropped and the writer
//! reproduces it exactly. [`Primitive::from_args`] and [`Primitive::to_args`] are inverses.

use super::otype::OType;
use super::specdata::SpecData;

/// A point or direction.
pub type Vec3 = [f64; 3];

/// One primitive's type and arguments.
///
/// Colours are `Vec<f64>` of the length Radiance fixes for the type (3 today), so that code
/// which reads them does not hard-code 3 channels.
#[derive(Debug, Clone, PartialEq)]
pub enum Primitive {
    /// `source`: distant source in `direction`, full apex `angle` in degrees.
    Source { direction: Vec3, angle: f64 },
    /// `sphere`, or `bubble` when `inward` (normal pointing in).
    Sphere {
        center: Vec3,
        radius: f64,
        inward: bool,
    },
    /// `polygon`: at least 3 vertices, counter-clockwise seen from the front.
    Polygon { vertices: Vec<Vec3> },
    /// `cone`, or `cup` when `inward`.
    Cone {
        p0: Vec3,
        p1: Vec3,
        r0: f64,
        r1: f64,
        inward: bool,
    },
    /// `cylinder`, or `tube` when `inward`.
    Cylinder {
        p0: Vec3,
        p1: Vec3,
        radius: f64,
        inward: bool,
    },
    /// `ring`: disc or annulus of radii `r0`..`r1` around `center`, facing `normal`.
    Ring {
        center: Vec3,
        normal: Vec3,
        r0: f64,
        r1: f64,
    },
    /// `instance`: an octree with an optional transform (`xform` arguments).
    Instance {
        octree: String,
        transform: Vec<String>,
    },
    /// `mesh`: a Radiance mesh file with an optional transform.
    Mesh {
        file: String,
        transform: Vec<String>,
    },
    /// `light`: emitted radiance (W/sr/m^2 per channel).
    Light { color: Vec<f64> },
    /// `illum`: secondary source; `alternate` is the material seen directly (if any).
    Illum {
        alternate: Option<String>,
        color: Vec<f64>,
    },
    /// `glow`: radiance and the maximum radius of its influence (0 = never a direct source).
    Glow { color: Vec<f64>, max_radius: f64 },
    /// `spotlight`: radiance, full cone angle (degrees) and aim direction.
    Spotlight {
        color: Vec<f64>,
        angle: f64,
        direction: Vec3,
    },
    /// `mirror`: reflectance and optional alternate material.
    Mirror {
        alternate: Option<String>,
        color: Vec<f64>,
    },
    /// `plastic`: diffuse colour, specularity, roughness.
    Plastic {
        color: Vec<f64>,
        spec: f64,
        rough: f64,
    },
    /// `metal`: colour (also tints the specular part), specularity, roughness.
    Metal {
        color: Vec<f64>,
        spec: f64,
        rough: f64,
    },
    /// `trans`: plastic plus transmitted fraction `trans` and its specular part `tspec`.
    Trans {
        color: Vec<f64>,
        spec: f64,
        rough: f64,
        trans: f64,
        tspec: f64,
    },
    /// `glass`: transmissivity per channel and optional refractive index (1.52 if absent).
    Glass {
        transmissivity: Vec<f64>,
        index: Option<f64>,
    },
    /// `brightfunc`: scalar pattern `function` from `file` (e.g. `skyfunc` with `skybright.cal`).
    BrightFunc {
        function: String,
        file: String,
        transform: Vec<String>,
        args: Vec<f64>,
    },
    /// `colorfunc`: three channel functions (red, green, blue) from `file`.
    ColorFunc {
        functions: Vec<String>,
        file: String,
        transform: Vec<String>,
        args: Vec<f64>,
    },
    /// `spectrum` (6.0): `values` evenly spaced from `nm_a` to `nm_b` (nm).
    Spectrum {
        nm_a: f64,
        nm_b: f64,
        values: Vec<f64>,
    },
    /// `specfile` (6.0): spectrum from a Radiance data file; `data` holds it when found.
    SpecFile {
        file: String,
        data: Option<SpecData>,
    },
    /// Any other type: counts checked, arguments kept verbatim.
    Other {
        otype: OType,
        strings: Vec<String>,
        reals: Vec<f64>,
    },
}

fn v3(r: &[f64]) -> Vec3 {
    [r[0], r[1], r[2]]
}

impl Primitive {
    /// Build a typed primitive from already count-checked arguments (see
    /// [`OType::string_count`], [`OType::real_count`]). Returns `None` if the counts do not fit,
    /// so callers that skipped the check cannot panic.
    pub fn from_args(otype: OType, strings: Vec<String>, reals: Vec<f64>) -> Option<Primitive> {
        if !otype.string_count().accepts(strings.len()) || !otype.real_count().accepts(reals.len())
        {
            return None;
        }
        let r = &reals;
        let color = |n: usize| r[..n].to_vec();
        use OType as T;
        let p = match otype {
            T::Source => Primitive::Source {
                direction: v3(r),
                angle: r[3],
            },
            T::Sphere | T::Bubble => Primitive::Sphere {
                center: v3(r),
                radius: r[3],
                inward: otype == T::Bubble,
            },
            T::Polygon => Primitive::Polygon {
                vertices: r.chunks_exact(3).map(v3).collect(),
            },
            T::Cone | T::Cup => Primitive::Cone {
                p0: v3(r),
                p1: v3(&r[3..]),
                r0: r[6],
                r1: r[7],
                inward: otype == T::Cup,
            },
            T::Cylinder | T::Tube => Primitive::Cylinder {
                p0: v3(r),
                p1: v3(&r[3..]),
                radius: r[6],
                inward: otype == T::Tube,
            },
            T::Ring => Primitive::Ring {
                center: v3(r),
                normal: v3(&r[3..]),
                r0: r[6],
                r1: r[7],
            },
            T::Instance | T::Mesh => {
                let mut s = strings.into_iter();
                let file = s.next()?;
                let transform = s.collect();
                if otype == T::Instance {
                    Primitive::Instance {
                        octree: file,
                        transform,
                    }
                } else {
                    Primitive::Mesh { file, transform }
                }
            }
            T::Light => Primitive::Light { color: color(3) },
            T::Illum => Primitive::Illum {
                alternate: strings.into_iter().next(),
                color: color(3),
            },
            T::Glow => Primitive::Glow {
                color: color(3),
                max_radius: r[3],
            },
            T::Spotlight => Primitive::Spotlight {
                color: color(3),
                angle: r[3],
                direction: v3(&r[4..]),
            },
            T::Mirror => Primitive::Mirror {
                alternate: strings.into_iter().next(),
                color: color(3),
            },
            T::Plastic => Primitive::Plastic {
                color: color(3),
                spec: r[3],
                rough: r[4],
            },
            T::Metal => Primitive::Metal {
                color: color(3),
                spec: r[3],
                rough: r[4],
            },
            T::Trans => Primitive::Trans {
                color: color(3),
                spec: r[3],
                rough: r[4],
                trans: r[5],
                tspec: r[6],
            },
            T::Glass => Primitive::Glass {
                transmissivity: color(3),
                index: r.get(3).copied(),
            },
            T::BrightFunc => {
                let mut s = strings.into_iter();
                let function = s.next()?;
                let file = s.next()?;
                Primitive::BrightFunc {
                    function,
                    file,
                    transform: s.collect(),
                    args: reals,
                }
            }
            T::ColorFunc => {
                let mut s = strings.into_iter();
                let functions: Vec<String> = s.by_ref().take(3).collect();
                let file = s.next()?;
                Primitive::ColorFunc {
                    functions,
                    file,
                    transform: s.collect(),
                    args: reals,
                }
            }
            T::Spectrum => Primitive::Spectrum {
                nm_a: r[0],
                nm_b: r[1],
                values: r[2..].to_vec(),
            },
            T::SpecFile => Primitive::SpecFile {
                file: strings.into_iter().next()?,
                data: None,
            },
            _ => Primitive::Other {
                otype,
                strings,
                reals,
            },
        };
        Some(p)
    }

    /// The Radiance type of this primitive.
    pub fn otype(&self) -> OType {
        use Primitive as P;
        match self {
            P::Source { .. } => OType::Source,
            P::Sphere { inward: false, .. } => OType::Sphere,
            P::Sphere { inward: true, .. } => OType::Bubble,
            P::Polygon { .. } => OType::Polygon,
            P::Cone { inward: false, .. } => OType::Cone,
            P::Cone { inward: true, .. } => OType::Cup,
            P::Cylinder { inward: false, .. } => OType::Cylinder,
            P::Cylinder { inward: true, .. } => OType::Tube,
            P::Ring { .. } => OType::Ring,
            P::Instance { .. } => OType::Instance,
            P::Mesh { .. } => OType::Mesh,
            P::Light { .. } => OType::Light,
            P::Illum { .. } => OType::Illum,
            P::Glow { .. } => OType::Glow,
            P::Spotlight { .. } => OType::Spotlight,
            P::Mirror { .. } => OType::Mirror,
            P::Plastic { .. } => OType::Plastic,
            P::Metal { .. } => OType::Metal,
            P::Trans { .. } => OType::Trans,
            P::Glass { .. } => OType::Glass,
            P::BrightFunc { .. } => OType::BrightFunc,
            P::ColorFunc { .. } => OType::ColorFunc,
            P::Spectrum { .. } => OType::Spectrum,
            P::SpecFile { .. } => OType::SpecFile,
            P::Other { otype, .. } => *otype,
        }
    }

    /// The type name as written in scene files (`polygon`, `BSDF`, ...).
    pub fn type_name(&self) -> &'static str {
        self.otype().name()
    }

    /// The string and real arguments in Radiance's order (inverse of [`Primitive::from_args`]).
    pub fn to_args(&self) -> (Vec<String>, Vec<f64>) {
        use Primitive as P;
        let cat = |parts: &[&[f64]]| parts.concat();
        match self {
            P::Source { direction, angle } => (vec![], cat(&[direction, &[*angle]])),
            P::Sphere { center, radius, .. } => (vec![], cat(&[center, &[*radius]])),
            P::Polygon { vertices } => (vec![], vertices.iter().flatten().copied().collect()),
            P::Cone { p0, p1, r0, r1, .. } => (vec![], cat(&[p0, p1, &[*r0, *r1]])),
            P::Cylinder { p0, p1, radius, .. } => (vec![], cat(&[p0, p1, &[*radius]])),
            P::Ring {
                center,
                normal,
                r0,
                r1,
            } => (vec![], cat(&[center, normal, &[*r0, *r1]])),
            P::Instance {
                octree: file,
                transform,
            }
            | P::Mesh { file, transform } => {
                let mut s = vec![file.clone()];
                s.extend(transform.iter().cloned());
                (s, vec![])
            }
            P::Light { color } => (vec![], color.clone()),
            P::Illum { alternate, color } | P::Mirror { alternate, color } => {
                (alternate.iter().cloned().collect(), color.clone())
            }
            P::Glow { color, max_radius } => (vec![], cat(&[color, &[*max_radius]])),
            P::Spotlight {
                color,
                angle,
                direction,
            } => (vec![], cat(&[color, &[*angle], direction])),
            P::Plastic { color, spec, rough } | P::Metal { color, spec, rough } => {
                (vec![], cat(&[color, &[*spec, *rough]]))
            }
            P::Trans {
                color,
                spec,
                rough,
                trans,
                tspec,
            } => (vec![], cat(&[color, &[*spec, *rough, *trans, *tspec]])),
            P::Glass {
                transmissivity,
                index,
            } => {
                let mut r = transmissivity.clone();
                r.extend(index);
                (vec![], r)
            }
            P::BrightFunc {
                function,
                file,
                transform,
                args,
            } => {
                let mut s = vec![function.clone(), file.clone()];
                s.extend(transform.iter().cloned());
                (s, args.clone())
            }
            P::ColorFunc {
                functions,
                file,
                transform,
                args,
            } => {
                let mut s = functions.clone();
                s.push(file.clone());
                s.extend(transform.iter().cloned());
                (s, args.clone())
            }
            P::Spectrum { nm_a, nm_b, values } => (vec![], cat(&[&[*nm_a, *nm_b], values])),
            P::SpecFile { file, .. } => (vec![file.clone()], vec![]),
            P::Other { strings, reals, .. } => (strings.clone(), reals.clone()),
        }
    }

    /// True for geometry (surfaces), false for modifiers.
    pub fn is_surface(&self) -> bool {
        !self.otype().is_modifier()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Argument lists that fit every type's rules, for round trips through the typed form.
    fn sample(t: OType) -> (Vec<String>, Vec<f64>) {
        let ns = match t.string_count() {
            super::super::otype::Count::Exactly(n) | super::super::otype::Count::AtLeast(n) => n,
            super::super::otype::Count::OneOf(l) => l[l.len() - 1],
            super::super::otype::Count::MultipleOf { min, .. } => min,
        };
        let nr = match t.real_count() {
            super::super::otype::Count::Exactly(n) | super::super::otype::Count::AtLeast(n) => n,
            super::super::otype::Count::OneOf(l) => l[l.len() - 1],
            super::super::otype::Count::MultipleOf { min, .. } => min,
        };
        (
            (0..ns).map(|i| format!("s{i}")).collect(),
            (0..nr).map(|i| i as f64 * 0.5 - 1.0).collect(),
        )
    }

    #[test]
    fn from_args_and_to_args_are_inverse_for_every_type() {
        for &t in OType::ALL {
            let (s, r) = sample(t);
            let p = Primitive::from_args(t, s.clone(), r.clone()).expect("sample fits");
            assert_eq!(p.otype(), t);
            assert_eq!(p.to_args(), (s, r), "{t}");
        }
    }

    #[test]
    fn from_args_refuses_bad_counts_without_panicking() {
        for &t in OType::ALL {
            for ns in 0..3 {
                for nr in 0..12 {
                    let s = vec!["x".to_string(); ns];
                    let r = vec![1.0; nr];
                    let ok = t.string_count().accepts(ns) && t.real_count().accepts(nr);
                    assert_eq!(Primitive::from_args(t, s, r).is_some(), ok, "{t} {ns} {nr}");
                }
            }
        }
    }
}
