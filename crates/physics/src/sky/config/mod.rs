//! # Typed configurations of the sky generators, as the `rspecsky` tool runs them
//!
//! What `rspecsky` does with its options, as plain validated values and one `write`
//! function each, so that a library caller gets the same files (and the same one-line
//! errors) as a user of the tool, with no command-line parsing in sight:
//!
//! | config | `rspecsky` mode | Radiance |
//! |---|---|---|
//! | [`SkyMatrixConfig`] | `rspecsky [options] weather` (`--model perez\|atmosphere`) | `gendaymtx`, `gensdaymtx` |
//! | [`PointSkyConfig`] | `rspecsky --at "M D H" ...` | `gendaylit` (plus glow sources) |
//! | [`GensskyConfig`] | `rspecsky genssky M D H ...` | `genssky` |
//!
//! Progress and warnings go through [`Messages`]; [`Quiet`] drops them.

pub mod genssky;
pub mod matrix;
pub mod point;

pub use genssky::GensskyConfig;
pub use matrix::{Bands, SkyMatrixConfig, SkyModel};
pub use point::{PointSkyConfig, PointSkyInput};

use super::matrix::Colours;
use crate::progress::{Progress, QUIET};

/// Where a sky generator reports while it works (the tool: standard error).
pub trait Messages: Sync {
    /// Where the stages go (time steps of a matrix, atmosphere tables being computed).
    fn progress(&self) -> &dyn Progress {
        &QUIET
    }
    /// Progress-level information (what is being computed, where the tables are).
    fn info(&self, _msg: &str) {}
    /// A warning the user should always see.
    fn warn(&self, _msg: &str) {}
}

/// Reports nothing.
pub struct Quiet;

impl Messages for Quiet {}

/// One of gendaymtx's colour options. gendaymtx applies `-d`, `-s`, `-g` and `-c` in
/// command-line order in its option loop, so `-d -g r g b` keeps the given ground while
/// `-g r g b -d` blackens it: a config keeps them as a list in the order given.
#[derive(Debug, Clone, PartialEq)]
pub enum ColourEdit {
    /// `-d`: sun only (sky and ground black).
    SunOnly,
    /// `-s`: sky only (no sun).
    SkyOnly,
    /// `-g r g b`: ground reflectance.
    Ground(Vec<f64>),
    /// `-c r g b`: sky colour.
    Sky(Vec<f64>),
}

impl ColourEdit {
    /// Apply `edits` in order to `c`, as gendaymtx's option loop does.
    pub fn apply_all(edits: &[ColourEdit], mut c: Colours) -> Colours {
        for e in edits {
            match e {
                ColourEdit::SunOnly => {
                    c.sky = vec![0.0; 3];
                    c.ground = vec![0.0; 3];
                }
                ColourEdit::SkyOnly => c.sun = vec![0.0; 3],
                ColourEdit::Ground(g) => c.ground = g.clone(),
                ColourEdit::Sky(s) => c.sky = s.clone(),
            }
        }
        c
    }
}
