//! The Radiance scene description (`.rad`): grammar, inline `!commands`, typed primitives,
//! modifier links, writing, bounding boxes.
//!
//! Sources: radiance-notes.md section 4 (grammar, argument table), `doc/ray.1`,
//! `src/common/readobj.c` (reading, aliases, modifier lookup), `src/ot/bbox.c` (bounds).
//!
//! | module | concept |
//! |---|---|
//! | [`otype`] | type names, classes (surface/material/pattern/...), argument-count rules |
//! | [`primitive`] | [`Primitive`]: typed arguments per type, and back to argument lists |
//! | `parse` | words, comments, `!` lines, objects, aliases, modifier resolution (nom) |
//! | `exec` | running `!commands` (or refusing to) |
//! | [`specdata`] | the 1-D data file of a `specfile` |
//! | `write` | canonical `.rad` output ([`std::fmt::Display`], [`Scene::write_rad`]) |
//! | [`mesh`] | compiled meshes (`obj2mesh` output) for `mesh` primitives |
//! | [`obj`] | Wavefront OBJ for `mesh` primitives naming a `.obj` file (our extension) |
//! | [`octree`] | octrees (`oconv`; frozen ones hold their scene) for `instance` primitives |
//! | `binary` | Radiance's portable binary encoding shared by meshes and octrees |
//! | [`compiled`] | compiled scene files (`rdc --compile`): container, source records, scenes in binary |
//! | `bbox` | [`Scene::bounding_box`] as `getbbox` computes it |
//! | [`CompactScene`] | plain surfaces column-wise ([`SurfaceTable`]), the rest as a [`Scene`]: what the tracer loads |
//! | `wrong_kind` | inputs that are not scene text (octrees, pictures, matrices, weather), named as such |
//!
//! ```no_run
//! use rdaylight_formats::scene::{self, LoadOptions};
//! let scene = scene::load(&["room.rad"], &LoadOptions::default())?;
//! scene.check_supported(&["polygon", "plastic", "glass", "light", "glow", "source"])?;
//! for (i, obj) in scene.surfaces() {
//!     let material = scene.material_of(i).map(|m| &scene.objects[m].id);
//!     println!("{} {} uses {:?}", obj.type_name(), obj.id, material);
//! }
//! # Ok::<(), rdaylight_base::Error>(())
//! ```

mod bbox;
mod binary;
pub mod compiled;
mod exec;
pub mod mesh;
pub mod obj;
pub mod octree;
pub mod otype;
mod parse;
pub mod primitive;
pub mod specdata;
mod table;
mod write;
mod wrong_kind;

use std::path::{Path, PathBuf};

pub use bbox::BBox;
pub use otype::{Class, Count, OType};
pub use primitive::{Primitive, Vec3};
pub use specdata::SpecData;
pub use table::{CompactScene, Surface, SurfaceTable, is_plain_surface};
pub use wrong_kind::{check as check_is_scene, is_octree};

use crate::error::{Error, Location, Result};

/// How scene inputs are read.
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// Run `!command` lines and `!command` inputs. Default: true unless the environment
    /// variable `RDAYLIGHT_NO_EXEC` is set to anything but empty or `0` (binaries map
    /// `--no-exec` to `false`). Refused commands are errors that say how to expand the scene.
    pub allow_exec: bool,
    /// Extra environment for commands (e.g. `PATH` to a Radiance `bin/`, `RAYPATH`).
    pub command_env: Vec<(String, String)>,
}

/// Set by [`refuse_exec`]: `--no-exec` for the rest of the process.
static REFUSE_EXEC: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// `--no-exec` of a tool that loads scenes in many places (rcalib's models, truths and
/// re-simulations; rrecon's scenes): from now on [`LoadOptions::from_env`] (and `default`)
/// refuse inline commands in this process, as `RDAYLIGHT_NO_EXEC=1` does. One switch instead
/// of an option threaded through every loader, which a new loader could miss (issue #19:
/// rcalib and rrecon named `--no-exec` in their refusal but did not accept it); setting the
/// variable itself would need `unsafe` (`std::env::set_var`).
pub fn refuse_exec() {
    REFUSE_EXEC.store(true, std::sync::atomic::Ordering::Relaxed);
}

impl LoadOptions {
    /// Options with `allow_exec` taken from `RDAYLIGHT_NO_EXEC` (and [`refuse_exec`]).
    pub fn from_env() -> Self {
        let refuse = REFUSE_EXEC.load(std::sync::atomic::Ordering::Relaxed)
            || std::env::var_os("RDAYLIGHT_NO_EXEC").is_some_and(|v| !v.is_empty() && v != "0");
        LoadOptions {
            allow_exec: !refuse,
            command_env: Vec::new(),
        }
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions::from_env()
    }
}

/// Material types that make a surface glazing (a window, skylight or glazed door).
pub const GLAZING_TYPES: [&str; 5] = ["glass", "dielectric", "interface", "BSDF", "aBSDF"];

/// An `alias` object's origin: the object it copied.
#[derive(Debug, Clone, PartialEq)]
pub struct Alias {
    /// Index of the aliased object in [`Scene::objects`].
    pub target: usize,
    /// Its id as written (`old_id` in `modifier alias new_id old_id`).
    pub target_id: String,
}

/// One scene object.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Index of the modifier object in [`Scene::objects`], `None` for `void`.
    pub modifier: Option<usize>,
    /// The modifier as written (`void`, `inherit` for aliases, or an id); the writer uses it.
    pub modifier_name: String,
    pub id: String,
    /// Type and arguments. For an alias, a copy of the aliased object's.
    pub kind: Primitive,
    /// Set when the object was written as `modifier alias id old_id`.
    pub alias: Option<Alias>,
    /// Where the object's first word is (for command output: `room.rad:12: !cmd` + line:col).
    pub loc: Location,
}

impl Object {
    /// A new object without a location (for tools that build scenes).
    pub fn new(modifier: Option<(usize, &str)>, id: impl Into<String>, kind: Primitive) -> Self {
        Object {
            modifier: modifier.map(|m| m.0),
            modifier_name: modifier.map_or("void".to_string(), |m| m.1.to_string()),
            id: id.into(),
            kind,
            alias: None,
            loc: Location::default(),
        }
    }

    /// The type name as written in scene files (`polygon`, `BSDF`, ...; an alias reports the
    /// aliased type).
    pub fn type_name(&self) -> &'static str {
        self.kind.type_name()
    }

    pub fn class(&self) -> Class {
        self.kind.otype().class()
    }

    /// True if both objects say the same thing (everything but the location).
    pub fn same_content(&self, other: &Object) -> bool {
        self.modifier == other.modifier
            && self.modifier_name == other.modifier_name
            && self.id == other.id
            && self.kind == other.kind
            && self.alias == other.alias
    }
}

/// A scene: objects in input order. Modifier links point backwards (a modifier must be
/// defined before use), so the list is also a valid order for writing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    pub objects: Vec<Object>,
    /// `#@rfluxmtx` comment lines, in input order ([`Directive`]).
    pub directives: Vec<Directive>,
}

/// A `#@rfluxmtx variable=value ...` comment line (`rfluxmtx(1)`: the hemisphere basis,
/// up vector and output of the sender or receiver surfaces that follow it). Every other
/// comment is dropped; these are kept because they carry meaning for `rdc`'s
/// sender/receiver mode (`rdaylight_trace::rdc::flux`).
#[derive(Debug, Clone, PartialEq)]
pub struct Directive {
    /// Index in [`Scene::objects`] of the first object after the line (the objects it
    /// applies to start there).
    pub before: usize,
    /// The text after `#@rfluxmtx`, trimmed (`h=kf u=+Z o=v.mtx`).
    pub text: String,
    /// Where the line is (`file:line`).
    pub loc: Location,
}

/// The word that starts a kept comment: `#@rfluxmtx` (rfluxmtx.c's `PARAMSTART`).
pub const RFLUXMTX_DIRECTIVE: &str = "#@rfluxmtx";

/// Read scene inputs in order, as `oconv` names them: file paths, `-` for standard input,
/// `!command` for a command's output. Modifiers defined in one input serve the next ones.
pub fn load<S: AsRef<str>>(inputs: &[S], opts: &LoadOptions) -> Result<Scene> {
    Ok(load_parts(inputs, opts)?.0)
}

/// [`load`], also giving the range of [`Scene::objects`] each input made (rdc's
/// sender/receiver mode tells the receiver file's objects from the scene's this way).
pub fn load_parts<S: AsRef<str>>(
    inputs: &[S],
    opts: &LoadOptions,
) -> Result<(Scene, Vec<std::ops::Range<usize>>)> {
    let mut loader = parse::Loader::new(opts);
    let mut parts = Vec::with_capacity(inputs.len());
    for input in inputs {
        let start = loader.len();
        loader.load_input(input.as_ref())?;
        parts.push(start..loader.len());
    }
    Ok((loader.finish(), parts))
}

/// [`load`] into a [`CompactScene`]: plain surfaces (polygons, spheres, cones, cylinders,
/// rings) go into a [`SurfaceTable`] instead of becoming [`Object`]s, so a scene of a
/// million polygons takes about a quarter of the memory and time.
pub fn load_compact<S: AsRef<str>>(inputs: &[S], opts: &LoadOptions) -> Result<CompactScene> {
    let mut loader = parse::Loader::compact(opts);
    for input in inputs {
        loader.load_input(input.as_ref())?;
    }
    Ok(loader.finish_compact())
}

/// Parse scene text named `name` (for locations); `!` commands run, and `specfile` data files
/// are looked up, in `base_dir` (empty = the current directory).
pub fn parse_str(text: &str, name: &str, base_dir: &Path, opts: &LoadOptions) -> Result<Scene> {
    let mut loader = parse::Loader::new(opts);
    loader.parse(text, name.to_string(), base_dir.to_path_buf(), 0)?;
    Ok(loader.finish())
}

impl Scene {
    /// Append an object whose modifier is looked up by name like the parser does (most recent
    /// modifier with that id; `void` for none). Returns its index.
    pub fn push(
        &mut self,
        modifier: &str,
        id: impl Into<String>,
        kind: Primitive,
    ) -> Result<usize> {
        let m = if modifier == "void" {
            None
        } else {
            Some(
                self.find_modifier(modifier)
                    .ok_or_else(|| Error::Usage(format!("undefined modifier '{modifier}'")))?,
            )
        };
        self.objects.push(Object {
            modifier: m,
            modifier_name: modifier.to_string(),
            id: id.into(),
            kind,
            alias: None,
            loc: Location::default(),
        });
        Ok(self.objects.len() - 1)
    }

    /// Index of the most recently defined modifier (non-surface) called `id`.
    pub fn find_modifier(&self, id: &str) -> Option<usize> {
        self.objects
            .iter()
            .rposition(|o| o.id == id && o.kind.otype().is_modifier())
    }

    /// Surfaces with their indices.
    pub fn surfaces(&self) -> impl Iterator<Item = (usize, &Object)> {
        self.objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.kind.is_surface())
    }

    /// The modifier chain of object `index`: its modifier, that one's modifier, ... up to
    /// `void`. Links always point to earlier objects, so the walk ends.
    pub fn modifier_chain(&self, index: usize) -> ModifierChain<'_> {
        ModifierChain {
            scene: self,
            next: self
                .objects
                .get(index)
                .and_then(|o| o.modifier.filter(|&m| m < index)),
        }
    }

    /// The material of a surface: the first material in its modifier chain, as Radiance's
    /// `findmaterial` does. `None` if the chain ends without one (or for modifiers with none).
    pub fn material_of(&self, index: usize) -> Option<usize> {
        self.modifier_chain(index)
            .find(|&m| self.objects[m].class() == Class::Material)
    }

    /// Whether surface `index` is glazing: its material is one of [`GLAZING_TYPES`] (what
    /// rglod keeps in the permanent shell and rmetrics draws as windows on maps).
    pub fn is_glazing(&self, index: usize) -> bool {
        self.material_of(index)
            .is_some_and(|m| GLAZING_TYPES.contains(&self.objects[m].type_name()))
    }

    /// The patterns, textures and mixtures that modify a material, nearest first (the chain
    /// from the material's modifier up to the next material or `void`). Radiance applies them
    /// farthest first (`raytexture` recurses before applying), i.e. in reverse of this list.
    pub fn patterns_of(&self, material: usize) -> Vec<usize> {
        self.modifier_chain(material)
            .take_while(|&m| self.objects[m].class() != Class::Material)
            .collect()
    }

    /// Indices of all objects whose type is not in `supported`.
    pub fn unsupported(&self, supported: &[&str]) -> Vec<usize> {
        (0..self.objects.len())
            .filter(|&i| !supported.contains(&self.objects[i].type_name()))
            .collect()
    }

    /// Error for the first object whose type is not in `supported`:
    /// `file:line:col: unsupported primitive type 'BSDF' ('blind'); supported here: ...`.
    pub fn check_supported(&self, supported: &[&str]) -> Result<()> {
        match self.unsupported(supported).first() {
            None => Ok(()),
            Some(&i) => {
                let o = &self.objects[i];
                Err(Error::unsupported(
                    o.loc.clone(),
                    format!(
                        "primitive type '{}' ('{}'); supported here: {}",
                        o.type_name(),
                        o.id,
                        supported.join(", ")
                    ),
                ))
            }
        }
    }
}

/// Iterator over a modifier chain, see [`Scene::modifier_chain`].
pub struct ModifierChain<'s> {
    scene: &'s Scene,
    next: Option<usize>,
}

impl Iterator for ModifierChain<'_> {
    type Item = usize;
    fn next(&mut self) -> Option<usize> {
        let cur = self.next?;
        // Only follow links that point backwards, so hand-built cycles cannot loop forever.
        self.next = self
            .scene
            .objects
            .get(cur)
            .and_then(|o| o.modifier.filter(|&m| m < cur));
        Some(cur)
    }
}

/// Radiance's search for a file a scene names (patterns' data, pictures, BSDF XML, meshes,
/// octrees): the scene file's folder, the working folder, then
/// the `RAYPATH` folders.
pub fn find_file(file: &str, scene_file: &str) -> Option<PathBuf> {
    let p = Path::new(file);
    if p.is_absolute() {
        return p.is_file().then(|| p.to_path_buf());
    }
    let mut c = Vec::new();
    if let Some(d) = Path::new(scene_file).parent() {
        c.push(d.join(file));
    }
    c.push(p.to_path_buf());
    if let Some(rp) = std::env::var_os("RAYPATH") {
        c.extend(std::env::split_paths(&rp).map(|d| d.join(file)));
    }
    c.into_iter().find(|x| x.is_file())
}
