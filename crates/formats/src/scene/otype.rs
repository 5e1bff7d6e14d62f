//! Radiance's primitive type names, their classes and their argument-count rules.
//!
//! Names and classes follow `src/common/otypes.h` (`INIT_OTYPE`, the `T_S`/`T_M`/`T_P`/`T_T`/
//! `T_X` flags); the counts follow the argument table in `doc/ray.1` (summarised in
//! radiance-notes.md section 4.2) and the checks in the `src/rt/m_*.c`/`p_*.c` routines.
//! Where Radiance leaves a count open (function arguments, transforms) the rule says so.

use std::fmt;

/// What an object does in Radiance's type system (`otypes.h` flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Class {
    /// Geometry (`T_S`); its id is never looked up as a modifier.
    Surface,
    /// Materials, including light sources (`T_M`).
    Material,
    /// Patterns that modify colour (`T_P`), including the 6.0 spectral ones.
    Pattern,
    /// Textures that perturb the normal (`T_T`).
    Texture,
    /// Mixtures of two modifiers (`T_X`).
    Mixture,
}

/// How many arguments of one kind (string or real) a type accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Count {
    Exactly(usize),
    AtLeast(usize),
    /// One of a short list (e.g. `glass` 3 or 4 reals; `mist` 0, 3, 6 or 7).
    OneOf(&'static [usize]),
    /// A multiple of `k`, at least `min` (polygon vertices: multiple of 3, at least 9).
    MultipleOf {
        k: usize,
        min: usize,
    },
}

impl Count {
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Count::Exactly(e) => n == e,
            Count::AtLeast(m) => n >= m,
            Count::OneOf(list) => list.contains(&n),
            Count::MultipleOf { k, min } => n >= min && n % k == 0,
        }
    }

    /// `expects {phrase} real arguments{suffix}`: the phrase before the noun and what follows it.
    fn phrase(self) -> (String, String) {
        match self {
            Count::Exactly(e) => (e.to_string(), String::new()),
            Count::AtLeast(m) => (format!("at least {m}"), String::new()),
            Count::OneOf(list) => {
                let words: Vec<String> = list.iter().map(|n| n.to_string()).collect();
                let text = match words.split_last() {
                    Some((last, rest)) if !rest.is_empty() => {
                        format!("{} or {last}", rest.join(", "))
                    }
                    _ => words.join(""),
                };
                (text, String::new())
            }
            Count::MultipleOf { k, min } => {
                (format!("a multiple of {k}"), format!(" (at least {min})"))
            }
        }
    }

    /// The message for a count that does not fit, e.g.
    /// `polygon 'win_s' expects a multiple of 3 real arguments (at least 9), found 11`.
    pub fn mismatch(self, otype: OType, id: &str, noun: &str, found: usize) -> String {
        let (phrase, suffix) = self.phrase();
        let plural = if matches!(self, Count::Exactly(1)) {
            ""
        } else {
            "s"
        };
        format!(
            "{} '{id}' expects {phrase} {noun} argument{plural}{suffix}, found {found}",
            otype.name()
        )
    }
}

macro_rules! otypes {
    ($( $var:ident = $name:literal, $class:ident, $s:expr, $r:expr; )*) => {
        /// Every primitive type Radiance 6 knows (`otypes.h`), except `alias`, which the parser
        /// resolves into a copy of the aliased object.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum OType { $( $var ),* }

        impl OType {
            /// All types, in `otypes.h` order.
            pub const ALL: &'static [OType] = &[ $( OType::$var ),* ];

            /// The name used in scene files.
            pub fn name(self) -> &'static str {
                match self { $( OType::$var => $name ),* }
            }

            pub fn class(self) -> Class {
                match self { $( OType::$var => Class::$class ),* }
            }

            /// Accepted string-argument counts.
            pub fn string_count(self) -> Count {
                match self { $( OType::$var => $s ),* }
            }

            /// Accepted real-argument counts.
            pub fn real_count(self) -> Count {
                match self { $( OType::$var => $r ),* }
            }

            /// Look a type up by its scene-file name (case sensitive, like `otype()`).
            pub fn from_name(name: &str) -> Option<OType> {
                match name { $( $name => Some(OType::$var), )* _ => None }
            }
        }
    };
}

use Count::{AtLeast, Exactly, MultipleOf, OneOf};

otypes! {
    Polygon = "polygon", Surface, Exactly(0), MultipleOf { k: 3, min: 9 };
    Cone = "cone", Surface, Exactly(0), Exactly(8);
    Sphere = "sphere", Surface, Exactly(0), Exactly(4);
    TexFunc = "texfunc", Texture, AtLeast(4), AtLeast(0);
    Ring = "ring", Surface, Exactly(0), Exactly(8);
    Cylinder = "cylinder", Surface, Exactly(0), Exactly(7);
    Instance = "instance", Surface, AtLeast(1), Exactly(0);
    Cup = "cup", Surface, Exactly(0), Exactly(8);
    Bubble = "bubble", Surface, Exactly(0), Exactly(4);
    Tube = "tube", Surface, Exactly(0), Exactly(7);
    Mesh = "mesh", Surface, AtLeast(1), Exactly(0);
    Plastic = "plastic", Material, Exactly(0), Exactly(5);
    Metal = "metal", Material, Exactly(0), Exactly(5);
    Glass = "glass", Material, Exactly(0), OneOf(&[3, 4]);
    Trans = "trans", Material, Exactly(0), Exactly(7);
    Dielectric = "dielectric", Material, Exactly(0), Exactly(5);
    Plastic2 = "plastic2", Material, AtLeast(4), Exactly(6);
    Metal2 = "metal2", Material, AtLeast(4), Exactly(6);
    Trans2 = "trans2", Material, AtLeast(4), Exactly(8);
    Interface = "interface", Material, Exactly(0), Exactly(8);
    PlasFunc = "plasfunc", Material, AtLeast(2), AtLeast(4);
    MetFunc = "metfunc", Material, AtLeast(2), AtLeast(4);
    BrightFunc = "brightfunc", Pattern, AtLeast(2), AtLeast(0);
    BrightData = "brightdata", Pattern, AtLeast(3), AtLeast(0);
    BrightText = "brighttext", Pattern, AtLeast(2), AtLeast(11);
    ColorPict = "colorpict", Pattern, AtLeast(7), AtLeast(0);
    Glow = "glow", Material, Exactly(0), Exactly(4);
    Source = "source", Surface, Exactly(0), Exactly(4);
    Light = "light", Material, Exactly(0), Exactly(3);
    Illum = "illum", Material, OneOf(&[0, 1]), Exactly(3);
    Spotlight = "spotlight", Material, Exactly(0), Exactly(7);
    Mist = "mist", Material, AtLeast(0), OneOf(&[0, 3, 6, 7]);
    Mirror = "mirror", Material, OneOf(&[0, 1]), Exactly(3);
    TransFunc = "transfunc", Material, AtLeast(2), AtLeast(6);
    BrtdFunc = "BRTDfunc", Material, AtLeast(10), AtLeast(9);
    Bsdf = "BSDF", Material, AtLeast(6), OneOf(&[0, 3, 6, 9]);
    ABsdf = "aBSDF", Material, AtLeast(5), OneOf(&[0, 3, 6, 9]);
    WgmdFunc = "WGMDfunc", Material, AtLeast(13), AtLeast(9);
    PlasData = "plasdata", Material, AtLeast(3), AtLeast(4);
    MetData = "metdata", Material, AtLeast(3), AtLeast(4);
    TransData = "transdata", Material, AtLeast(3), AtLeast(6);
    ColorFunc = "colorfunc", Pattern, AtLeast(4), AtLeast(0);
    Antimatter = "antimatter", Material, AtLeast(0), Exactly(0);
    ColorData = "colordata", Pattern, AtLeast(7), AtLeast(0);
    ColorText = "colortext", Pattern, AtLeast(2), AtLeast(15);
    TexData = "texdata", Texture, AtLeast(8), AtLeast(0);
    MixFunc = "mixfunc", Mixture, AtLeast(4), AtLeast(0);
    MixData = "mixdata", Mixture, AtLeast(5), AtLeast(0);
    MixText = "mixtext", Mixture, AtLeast(4), AtLeast(9);
    MixPict = "mixpict", Mixture, AtLeast(7), AtLeast(0);
    Prism1 = "prism1", Material, AtLeast(5), AtLeast(0);
    Prism2 = "prism2", Material, AtLeast(9), AtLeast(0);
    Ashik2 = "ashik2", Material, AtLeast(4), Exactly(8);
    Spectrum = "spectrum", Pattern, Exactly(0), AtLeast(5);
    SpecFile = "specfile", Pattern, Exactly(1), Exactly(0);
    SpecFunc = "specfunc", Pattern, AtLeast(2), AtLeast(2);
    SpecData = "specdata", Pattern, AtLeast(3), AtLeast(0);
    SpecPict = "specpict", Pattern, AtLeast(5), AtLeast(0);
}

impl OType {
    /// True for types whose ids name modifiers (everything but surfaces; `ismodifier`).
    pub fn is_modifier(self) -> bool {
        self.class() != Class::Surface
    }
}

impl fmt::Display for OType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_unique() {
        assert_eq!(OType::ALL.len(), 58, "59 otypes.h entries minus alias");
        for t in OType::ALL {
            assert_eq!(OType::from_name(t.name()), Some(*t));
        }
        assert_eq!(OType::from_name("alias"), None);
        assert_eq!(OType::from_name("Plastic"), None);
    }

    #[test]
    fn mismatch_messages() {
        let c = OType::Polygon.real_count();
        assert_eq!(
            c.mismatch(OType::Polygon, "win_s", "real", 11),
            "polygon 'win_s' expects a multiple of 3 real arguments (at least 9), found 11"
        );
        assert_eq!(
            OType::Mist
                .real_count()
                .mismatch(OType::Mist, "m", "real", 2),
            "mist 'm' expects 0, 3, 6 or 7 real arguments, found 2"
        );
        assert_eq!(
            OType::SpecFile
                .string_count()
                .mismatch(OType::SpecFile, "s", "string", 2),
            "specfile 's' expects 1 string argument, found 2"
        );
        assert!(!c.accepts(6) && c.accepts(9) && !c.accepts(10) && c.accepts(12));
    }
}
