//! Plain surfaces held column-wise: the tracer's way to hold a million polygons.
//!
//! A [`Scene`] keeps every object as an [`Object`] (its id, modifier name and location as
//! owned strings, its arguments in their own `Vec`): about 450 bytes and five allocations
//! per polygon, most of the 960 MB that `rdc` needed for a 1M-triangle scene (issue 18).
//! [`CompactScene`] keeps the surfaces that carry only numbers (polygon, sphere, bubble,
//! cone, cup, cylinder, tube, ring: no string arguments, never a modifier) in one
//! [`SurfaceTable`] of columns (about 30 bytes plus the coordinates each) and every other
//! object (modifiers, sources, `mesh`, `instance`, unknown types) as an ordinary [`Scene`],
//! its `rest`. Both remember each object's position in the whole scene, so the tracer
//! numbers surfaces exactly as it does for the same scene loaded as a [`Scene`].
//!
//! Modifier links of the table's surfaces and of `rest`'s objects are indices into
//! `rest.objects` (modifiers are never table surfaces), so the modifier chains work on
//! `rest` alone.

use super::otype::OType;
use super::{Object, Scene};
use crate::error::{Error, Location, Result};

/// The modifier value of a `void` surface in [`SurfaceTable::modifier`].
pub const VOID: u32 = u32::MAX;

/// Surfaces of plain types, one column per field (see the module documentation).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceTable {
    otype: Vec<OType>,
    /// Index in [`CompactScene::rest`] of the modifier, [`VOID`] for `void`.
    modifier: Vec<u32>,
    /// Position among all objects of the scene.
    index: Vec<u32>,
    /// End of each surface's arguments in `reals`.
    reals_end: Vec<u32>,
    reals: Vec<f64>,
    /// End of each surface's id in `ids`.
    id_end: Vec<u32>,
    ids: String,
    /// Where each surface starts: file (index into `files`), line and column (0: unknown).
    file: Vec<u32>,
    line: Vec<u32>,
    col: Vec<u32>,
    files: Vec<String>,
}

/// One surface of a [`SurfaceTable`], borrowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface<'a> {
    pub otype: OType,
    /// Index in [`CompactScene::rest`] of the modifier, `None` for `void`.
    pub modifier: Option<usize>,
    /// Position among all objects of the scene.
    pub index: usize,
    /// The real arguments as written (no fix-ups).
    pub reals: &'a [f64],
    pub id: &'a str,
    file: &'a str,
    line: u32,
    col: u32,
}

impl Surface<'_> {
    /// Where the surface was defined (`file:line:col`, as an [`Object`]'s `loc`).
    pub fn loc(&self) -> Location {
        Location {
            file: self.file.to_string(),
            line: (self.line > 0).then_some(self.line as usize),
            col: (self.col > 0).then_some(self.col as usize),
        }
    }
}

/// Whether objects of this type go into a [`SurfaceTable`] (surfaces with real arguments
/// only; `source` stays an object: the tracer treats it as a light, not a surface).
pub fn is_plain_surface(t: OType) -> bool {
    matches!(
        t,
        OType::Polygon
            | OType::Sphere
            | OType::Bubble
            | OType::Cone
            | OType::Cup
            | OType::Cylinder
            | OType::Tube
            | OType::Ring
    )
}

/// A `u32` for a table column, or the error saying which bound was reached.
fn narrow(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n)
        .ok()
        .filter(|&v| v != u32::MAX)
        .ok_or_else(|| {
            Error::Usage(format!(
                "scene too large: more than {} {what}; split it into several scenes",
                u32::MAX - 1
            ))
        })
}

impl SurfaceTable {
    pub fn len(&self) -> usize {
        self.otype.len()
    }

    pub fn is_empty(&self) -> bool {
        self.otype.is_empty()
    }

    /// Surface `k` (panics when out of range, like slice indexing).
    pub fn get(&self, k: usize) -> Surface<'_> {
        let r0 = if k == 0 { 0 } else { self.reals_end[k - 1] } as usize;
        let i0 = if k == 0 { 0 } else { self.id_end[k - 1] } as usize;
        Surface {
            otype: self.otype[k],
            modifier: (self.modifier[k] != VOID).then_some(self.modifier[k] as usize),
            index: self.index[k] as usize,
            reals: &self.reals[r0..self.reals_end[k] as usize],
            id: &self.ids[i0..self.id_end[k] as usize],
            file: self
                .files
                .get(self.file[k] as usize)
                .map_or("", String::as_str),
            line: self.line[k],
            col: self.col[k],
        }
    }

    /// Position among all objects of surface `k` (cheaper than [`SurfaceTable::get`]).
    pub fn index(&self, k: usize) -> usize {
        self.index[k] as usize
    }

    /// The direct modifier of surface `k` (index into `rest`; `None` for `void`).
    pub fn modifier(&self, k: usize) -> Option<usize> {
        (self.modifier[k] != VOID).then_some(self.modifier[k] as usize)
    }

    /// The real arguments of surface `k`.
    pub fn reals(&self, k: usize) -> &[f64] {
        let r0 = if k == 0 { 0 } else { self.reals_end[k - 1] } as usize;
        &self.reals[r0..self.reals_end[k] as usize]
    }

    /// The type of surface `k`.
    pub fn otype(&self, k: usize) -> OType {
        self.otype[k]
    }

    /// Number a file name for [`SurfaceTable::push`] (the last one is reused).
    pub fn file_number(&mut self, name: &str) -> Result<u32> {
        if self.files.last().is_some_and(|f| f == name) {
            return Ok((self.files.len() - 1) as u32);
        }
        self.files.push(name.to_string());
        narrow(self.files.len() - 1, "scene files")
    }

    /// Append a surface: `modifier` an index into `rest` (`None`: `void`), `index` its
    /// position among all objects, `file` from [`SurfaceTable::file_number`], `line` and
    /// `col` 1-based (0: unknown).
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        otype: OType,
        modifier: Option<usize>,
        index: usize,
        reals: &[f64],
        id: &str,
        file: u32,
        line: usize,
        col: usize,
    ) -> Result<()> {
        let modifier = match modifier {
            None => VOID,
            Some(m) => narrow(m, "modifiers")?,
        };
        let index = narrow(index, "objects")?;
        self.reals.extend_from_slice(reals);
        let reals_end = narrow(self.reals.len(), "surface coordinates")?;
        self.ids.push_str(id);
        let id_end = narrow(self.ids.len(), "bytes of surface names")?;
        self.otype.push(otype);
        self.modifier.push(modifier);
        self.index.push(index);
        self.reals_end.push(reals_end);
        self.id_end.push(id_end);
        self.file.push(file);
        self.line.push(u32::try_from(line).unwrap_or(0));
        self.col.push(u32::try_from(col).unwrap_or(0));
        Ok(())
    }

    /// Append the surfaces of `other` (read ahead by the parser on another thread): its
    /// modifier `k` becomes `modifiers[k]`, its positions count from `index`, its lines
    /// from `first_line` (its line 1), its file is `file`. The same columns as pushing
    /// each surface in turn; `false`, with nothing appended, where a push would fail.
    pub(crate) fn append(
        &mut self,
        other: &SurfaceTable,
        modifiers: &[usize],
        index: usize,
        first_line: usize,
        file: u32,
    ) -> bool {
        let n = other.len();
        let modifier: Option<Vec<u32>> = modifiers
            .iter()
            .map(|&m| narrow(m, "modifiers").ok())
            .collect();
        let fits = |v: usize| narrow(v, "").is_ok();
        let (Some(modifier), true, true, true) = (
            modifier,
            n == 0 || fits(index + n - 1),
            fits(self.reals.len() + other.reals.len()),
            fits(self.ids.len() + other.ids.len()),
        ) else {
            return false;
        };
        let (r0, i0) = (self.reals.len() as u32, self.ids.len() as u32);
        self.otype.extend_from_slice(&other.otype);
        self.modifier
            .extend(other.modifier.iter().map(|&m| match m {
                VOID => VOID,
                m => modifier[m as usize],
            }));
        self.index.extend((index..index + n).map(|i| i as u32));
        self.reals_end
            .extend(other.reals_end.iter().map(|&e| r0 + e));
        self.reals.extend_from_slice(&other.reals);
        self.id_end.extend(other.id_end.iter().map(|&e| i0 + e));
        self.ids.push_str(&other.ids);
        self.file.extend(std::iter::repeat_n(file, n));
        self.line.extend(other.line.iter().map(|&l| match l {
            0 => 0,
            l => u32::try_from(first_line + l as usize - 1).unwrap_or(0),
        }));
        self.col.extend_from_slice(&other.col);
        true
    }
}

/// A scene split into plain surfaces (a [`SurfaceTable`]) and every other object (`rest`);
/// see the module documentation. [`super::load_compact`] reads one from files;
/// [`CompactScene::from_scene`] splits a [`Scene`] built in memory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CompactScene {
    /// The objects that are not plain surfaces, in input order; their modifier links (and
    /// aliases' targets, and directives' `before`) are indices into `rest.objects`.
    pub rest: Scene,
    /// Position among all objects of each of `rest`'s objects.
    pub rest_index: Vec<u32>,
    pub surfaces: SurfaceTable,
    /// Files the load read besides its inputs (`specfile` data), in the order read.
    pub files: Vec<std::path::PathBuf>,
    /// The inline `!commands` whose output the load read (their text), in order.
    pub commands: Vec<String>,
}

impl CompactScene {
    /// Number of objects of the whole scene.
    pub fn len(&self) -> usize {
        self.rest.objects.len() + self.surfaces.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Split `scene` (copies its objects). A plain surface whose modifier link points at
    /// another surface (only a hand-built scene can have one) is treated as `void`, as the
    /// tracer treats a chain that ends without a material.
    pub fn from_scene(scene: &Scene) -> Result<CompactScene> {
        let mut out = CompactScene::default();
        // Index in `rest` of each object kept there.
        let mut new_index: Vec<Option<usize>> = Vec::with_capacity(scene.objects.len());
        let remap = |m: Option<usize>, new_index: &[Option<usize>]| {
            m.and_then(|m| new_index.get(m).copied().flatten())
        };
        for (i, o) in scene.objects.iter().enumerate() {
            let t = o.kind.otype();
            if is_plain_surface(t) && o.alias.is_none() {
                let (_, reals) = o.kind.to_args();
                let file = out.surfaces.file_number(&o.loc.file)?;
                out.surfaces.push(
                    t,
                    remap(o.modifier, &new_index),
                    i,
                    &reals,
                    &o.id,
                    file,
                    o.loc.line.unwrap_or(0),
                    o.loc.col.unwrap_or(0),
                )?;
                new_index.push(None);
                continue;
            }
            let mut o: Object = o.clone();
            o.modifier = remap(o.modifier, &new_index);
            if let Some(a) = &mut o.alias {
                a.target = remap(Some(a.target), &new_index).unwrap_or(usize::MAX);
            }
            new_index.push(Some(out.rest.objects.len()));
            out.rest.objects.push(o);
            out.rest_index.push(narrow(i, "objects")?);
        }
        out.rest.directives = scene
            .directives
            .iter()
            .map(|d| {
                let mut d = d.clone();
                d.before = new_index[..d.before.min(new_index.len())]
                    .iter()
                    .filter(|k| k.is_some())
                    .count();
                d
            })
            .collect();
        Ok(out)
    }

    /// The objects of the whole scene in input order: `Ok(k)` for `rest.objects[k]`,
    /// `Err(k)` for table surface `k`.
    pub fn order(&self) -> impl Iterator<Item = std::result::Result<usize, usize>> + '_ {
        let (mut r, mut t) = (0usize, 0usize);
        std::iter::from_fn(move || {
            let next_rest = self.rest_index.get(r).copied();
            let next_table = (t < self.surfaces.len()).then(|| self.surfaces.index[t]);
            match (next_rest, next_table) {
                (Some(a), Some(b)) if b < a => {
                    t += 1;
                    Some(Err(t - 1))
                }
                (Some(_), _) => {
                    r += 1;
                    Some(Ok(r - 1))
                }
                (None, Some(_)) => {
                    t += 1;
                    Some(Err(t - 1))
                }
                (None, None) => None,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const TEXT: &str = "void plastic red 0 0 5 .5 .1 .1 0 0\n\
        red polygon p1 0 0 9 0 0 0 1 0 0 1 1 0\n\
        void glow sky 0 0 4 1 1 1 0\n\
        sky source s 0 0 4 0 0 1 180\n\
        red sphere ball 0 0 4 1 2 3 .5\n\
        void polygon hole 0 0 9 0 0 0 0 1 0 1 1 0\n";

    #[test]
    fn a_scene_splits_into_rest_and_table_keeping_positions() {
        let scene =
            crate::scene::parse_str(TEXT, "t.rad", Path::new(""), &Default::default()).unwrap();
        let c = CompactScene::from_scene(&scene).unwrap();
        assert_eq!(c.len(), 6);
        let rest: Vec<&str> = c.rest.objects.iter().map(|o| o.id.as_str()).collect();
        assert_eq!(rest, ["red", "sky", "s"]);
        assert_eq!(c.rest_index, [0, 2, 3]);
        assert_eq!(c.rest.objects[2].modifier, Some(1));
        let s = c.surfaces.get(1);
        assert_eq!(
            (s.otype, s.modifier, s.index, s.id),
            (OType::Sphere, Some(0), 4, "ball")
        );
        assert_eq!(s.reals, [1.0, 2.0, 3.0, 0.5]);
        assert_eq!(s.loc().to_string(), "t.rad:5:1");
        assert_eq!(c.surfaces.get(2).modifier, None);
        let order: Vec<_> = c.order().collect();
        assert_eq!(order, [Ok(0), Err(0), Ok(1), Ok(2), Err(1), Err(2)]);
        // Loading straight into the columns gives the same split.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.rad");
        std::fs::write(&p, TEXT).unwrap();
        let name = p.display().to_string();
        let loaded =
            crate::scene::load_compact(std::slice::from_ref(&name), &Default::default()).unwrap();
        assert_eq!(loaded.rest_index, c.rest_index);
        assert_eq!(loaded.surfaces.len(), 3);
        for k in 0..3 {
            let (a, b) = (loaded.surfaces.get(k), c.surfaces.get(k));
            assert_eq!(
                (a.otype, a.modifier, a.index, a.reals, a.id),
                (b.otype, b.modifier, b.index, b.reals, b.id)
            );
            assert_eq!(a.loc().line, b.loc().line);
        }
        assert!(
            loaded
                .rest
                .objects
                .iter()
                .zip(&c.rest.objects)
                .all(|(a, b)| a.same_content(b))
        );
    }
}
