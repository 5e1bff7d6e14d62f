//! Compiled scenes (`rdc --compile scene.rdb room.rad sky.rad`), oconv's octree for `rdc`:
//! the scene's geometry stored as the tracer built it, so that later runs skip parsing and
//! the BVH build and trace the very same primitives (the same bytes out).
//!
//! What is stored is what does not depend on a run's channels or shading options
//! ([`Renderable::compile_parts`]): the BVH (with the shared BVHs of `mesh` and `instance`
//! files), the surfaces (material slot, flat flag, position in the scene), the material
//! slots (material, patterns between, first surface for error messages) and the scene's
//! modifiers and `source`s. Materials and sources are built again for each run
//! ([`Renderable::from_compiled`]), their `.cal`, BSDF and picture files read then, as
//! for a `.rad` scene.
//!
//! The file records the files the scene was read from (scene inputs, `specfile` data, mesh
//! and octree files, an octree's scene files) with their size, time and hash; a run refuses
//! a file whose sources changed since (one line naming the file and the change). Inline
//! `!commands` are recorded but not re-run: their output was compiled in, and editing the
//! command is a change to its scene file; what a command reads is not checked.
//!
//! Layout: `docs/scene-binary-formats.md`, "Compiled scenes"; container and scene encoding:
//! [`crate::scene::compiled`].

use std::path::Path;

use super::compile::{Renderable, Slot, SurfaceInfo, SurfaceName};
use super::sources::Sources;
use crate::error::{Error, Result};
use crate::geometry::Bvh;
use crate::material::ShadingOptions;
use crate::radiometry::Channels;
use crate::scene::compiled::{self as file, Decoder, Encoder, Provenance, SourceRecord};
use crate::scene::{Class, CompactScene, OType, Primitive, Scene};

/// The geometry revision: change it whenever the same scene would give other primitives
/// or another BVH (triangulation, fix-ups, recentring, padding, build parameters), so that
/// files written before are refused instead of traced differently from their sources.
pub const GEOMETRY_REVISION: &str =
    "2026-11-28: ear clipping, recentred f64 triangles, obvhs 0.4 fast_build CWBVH, glass panes";

/// A compiled scene as read: what [`Renderable::from_compiled`] builds a run's renderable
/// from.
pub struct CompiledScene {
    pub provenance: Provenance,
    /// The modifiers and sources (renumbered; links within), with each one's position in
    /// the scene it was compiled from.
    scene: Scene,
    index: Vec<u32>,
    slots: Vec<Slot>,
    surfaces: Vec<SurfaceInfo>,
    bvh: Bvh,
    /// The top-level glass polygons (portal candidates, found again per run).
    panes: Vec<Vec<[f64; 3]>>,
}

impl std::fmt::Debug for CompiledScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledScene")
            .field("objects", &self.scene.objects.len())
            .field("slots", &self.slots.len())
            .field("surfaces", &self.surfaces.len())
            .finish()
    }
}

/// What a scene was read from, for a compiled scene to be written at `rdb`: the scene
/// inputs (files and `!command`s), and `read`, the other files the load and the expansion
/// of meshes and instances read.
pub fn sources(
    inputs: &[String],
    read: &[std::path::PathBuf],
    rdb: &Path,
) -> Result<Vec<SourceRecord>> {
    let mut out = Vec::new();
    for input in inputs {
        if input == "-" {
            return Err(Error::Usage(
                "--compile: standard input cannot be checked for changes later; give the scene as files"
                    .into(),
            ));
        }
        match input.strip_prefix('!') {
            Some(cmd) => out.push(SourceRecord::command(cmd)),
            None => out.push(SourceRecord::file(Path::new(input), rdb)?),
        }
    }
    for p in read {
        let r = SourceRecord::file(p, rdb)?;
        if !out.contains(&r) {
            out.push(r);
        }
    }
    Ok(out)
}

/// Compile `scene`, read from `inputs` (files and `!command`s, as rdc was given them),
/// write it to `path` (atomically, `command` in its header) and return it as a run reads
/// it. Everything the tracer would refuse is refused now, with its `file:line`.
pub fn compile(
    path: &Path,
    command: &str,
    inputs: &[String],
    scene: &CompactScene,
) -> Result<CompiledScene> {
    // RGB and rcontrib's shading: the materials are checked now (errors at compile time,
    // with their lines), built again for each run.
    let mut kept: Option<(Scene, Vec<u32>, Vec<Slot>)> = None;
    let mut read: Vec<std::path::PathBuf> = scene.files.clone();
    let rest_len = scene.rest.objects.len();
    let (renderable, _) = Renderable::compile_parts(
        scene,
        &Channels::rgb(),
        &ShadingOptions::rcontrib(),
        |expanded, slots, files| {
            kept = Some(shading_scene(expanded, slots, scene, rest_len));
            read.extend_from_slice(files);
        },
    )?;
    let (modifiers, index, slots) = kept.unwrap_or_default();
    let mut all_inputs = inputs.to_vec();
    all_inputs.extend(scene.commands.iter().map(|c| format!("!{c}")));
    let provenance = Provenance {
        tool: format!("rdaylight {}", env!("CARGO_PKG_VERSION")),
        geometry: GEOMETRY_REVISION.into(),
        sources: sources(&all_inputs, &read, path)?,
    };
    let mut body = Encoder::default();
    provenance.encode(&mut body);
    file::encode_scene(&modifiers, &index, &mut body);
    body.len(slots.len());
    for s in &slots {
        body.u32(s.material as u32);
        body.len(s.between.len());
        for &b in &s.between {
            body.u32(b as u32);
        }
        body.str(s.first.otype.name());
        body.str(&s.first.id);
        body.location(&s.first.loc);
    }
    body.len(renderable.surfaces.len());
    body.buf.reserve(9 * renderable.surfaces.len());
    for s in &renderable.surfaces {
        body.u32(s.material);
        body.u8(u8::from(s.flat));
        body.u32(s.scene_index);
    }
    renderable.bvh.encode(&mut body);
    body.len(renderable.pane_polygons.len());
    for p in &renderable.pane_polygons {
        body.len(p.len());
        body.f64s(p.as_flattened());
    }
    file::write(path, command, &body.buf)?;
    Ok(CompiledScene {
        provenance,
        scene: modifiers,
        index,
        slots,
        surfaces: renderable.surfaces,
        bvh: renderable.bvh,
        panes: renderable.pane_polygons,
    })
}

/// True when `path` is a file that starts like a compiled scene.
pub fn is_compiled_file(path: &Path) -> bool {
    use std::io::Read;
    let mut head = vec![0u8; 4096];
    let Ok(mut f) = std::fs::File::open(path) else {
        return false;
    };
    let mut n = 0;
    while n < head.len() {
        match f.read(&mut head[n..]) {
            Ok(0) | Err(_) => break,
            Ok(k) => n += k,
        }
    }
    file::is_compiled(&head[..n])
}

/// The key of `--scene-cache` for scene `inputs`: [`wide64`] of the inputs' names, the
/// working folder, each input's bytes, the format and the geometry revision. `None` when
/// the inputs cannot be checked later (standard input, a `!command`).
pub fn cache_key(inputs: &[String]) -> Result<Option<u64>> {
    use rdaylight_base::hash::wide64;
    if inputs.iter().any(|i| i == "-" || i.starts_with('!')) {
        return Ok(None);
    }
    let mut e = Encoder::default();
    e.str(GEOMETRY_REVISION);
    e.u32(file::VERSION);
    let cwd = std::env::current_dir().unwrap_or_default();
    e.str(&cwd.display().to_string());
    for i in inputs {
        e.str(i);
        let bytes = std::fs::read(i).map_err(|err| Error::io(i.as_str(), err))?;
        e.u64(bytes.len() as u64);
        e.u64(wide64(&bytes));
    }
    Ok(Some(wide64(&e.buf)))
}

/// The objects a run needs to build materials and sources again: every modifier and
/// `source` of the expanded scene, renumbered (links, alias targets and the slots follow),
/// with their positions in the whole scene.
fn shading_scene(
    expanded: &Scene,
    slots: &[Slot],
    scene: &CompactScene,
    rest_len: usize,
) -> (Scene, Vec<u32>, Vec<Slot>) {
    let total = scene.len();
    let mut new_index = vec![usize::MAX; expanded.objects.len()];
    let mut out = Scene::default();
    let mut index = Vec::new();
    for (k, o) in expanded.objects.iter().enumerate() {
        let keep = o.kind.otype().is_modifier() || matches!(o.kind, Primitive::Source { .. });
        if !keep {
            continue;
        }
        let mut o = o.clone();
        o.modifier = o
            .modifier
            .and_then(|m| new_index.get(m).copied())
            .filter(|&m| m != usize::MAX);
        if let Some(a) = &mut o.alias {
            a.target = new_index.get(a.target).copied().unwrap_or(usize::MAX);
            if a.target == usize::MAX {
                o.alias = None;
            }
        }
        new_index[k] = out.objects.len();
        out.objects.push(o);
        index.push(match scene.rest_index.get(k) {
            Some(&i) => i,
            None => (total + (k - rest_len)) as u32,
        });
    }
    let slots = slots
        .iter()
        .map(|s| Slot {
            material: new_index[s.material],
            between: s.between.iter().map(|&b| new_index[b]).collect(),
            first: s.first.clone(),
        })
        .collect();
    (out, index, slots)
}

/// Read a compiled scene, refusing a damaged one, one of another format or geometry
/// revision, and one whose sources changed (each one error line naming the file).
pub fn read(path: &Path) -> Result<CompiledScene> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path.display().to_string(), e))?;
    decode(&bytes, path)
}

/// [`read`] for the bytes of the compiled scene at `path` (its sources are found from
/// there).
pub fn decode(bytes: &[u8], path: &Path) -> Result<CompiledScene> {
    let shown = path.display().to_string();
    let body = file::check(bytes, &shown)?;
    let mut d = Decoder::new(&bytes[body..], body, &shown);
    let provenance = Provenance::decode(&mut d)?;
    if provenance.geometry != GEOMETRY_REVISION {
        return Err(Error::Usage(format!(
            "{shown} was compiled by {} with another geometry (\"{}\"; this rdc: \"{GEOMETRY_REVISION}\"); recompile it with rdc --compile",
            provenance.tool, provenance.geometry
        )));
    }
    provenance.check_fresh(path)?;
    let (scene, index) = file::decode_scene(&mut d)?;
    let n = scene.objects.len();
    let nslots = d.count(4 + 8 + 8 * 3 + 8, "material slot count")?;
    let mut slots = Vec::with_capacity(nslots);
    for _ in 0..nslots {
        let material = d.required_index(n, "slot material")?;
        if scene.objects[material].class() != Class::Material {
            return Err(d.corrupted("a slot whose material is not one"));
        }
        let nb = d.count(4, "slot pattern count")?;
        let between = (0..nb)
            .map(|_| d.required_index(n, "slot pattern"))
            .collect::<Result<Vec<_>>>()?;
        let tname = d.str("surface type")?;
        let otype = OType::from_name(&tname)
            .ok_or_else(|| d.corrupted(format!("unknown type '{tname}'")))?;
        let id = d.str("surface name")?;
        let loc = d.location("surface")?;
        slots.push(Slot {
            material,
            between,
            first: SurfaceName { otype, id, loc },
        });
    }
    let ns = d.count(9, "surface count")?;
    let raw = d.bytes(9 * ns, "surfaces")?;
    let mut surfaces = Vec::with_capacity(ns);
    for b in raw.chunks_exact(9) {
        let material = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        if material as usize >= nslots || b[4] > 1 {
            return Err(d.corrupted("a surface with a bad material slot or flag"));
        }
        surfaces.push(SurfaceInfo {
            material,
            flat: b[4] == 1,
            scene_index: u32::from_le_bytes([b[5], b[6], b[7], b[8]]),
        });
    }
    let bvh = Bvh::decode(&mut d, ns)?;
    let np = d.count(8, "glass pane count")?;
    let mut panes = Vec::with_capacity(np);
    for _ in 0..np {
        let nv = d.count(24, "glass pane vertex count")?;
        let v = d.f64s(3 * nv, "glass pane vertices")?;
        panes.push(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    d.finish()?;
    Ok(CompiledScene {
        provenance,
        scene,
        index,
        slots,
        surfaces,
        bvh,
        panes,
    })
}

impl Renderable {
    /// The renderable of a compiled scene for channels `ch` and shading options `opts`:
    /// the stored geometry as it is, materials and sources built for this run.
    pub fn from_compiled(
        c: CompiledScene,
        ch: &Channels,
        opts: &ShadingOptions,
    ) -> Result<Renderable> {
        let mut shading = super::compile::Shading::new(&c.scene, ch, opts);
        for s in &c.slots {
            shading.add(s.material, &s.between, &s.first)?;
        }
        let mut sources = Sources::default();
        for (k, &i) in c.index.iter().enumerate() {
            shading.source(k, i as usize, &mut sources)?;
        }
        // The same panes as from the sources, so the same portals and the same bytes.
        Ok(Renderable::assemble(
            c.bvh, c.surfaces, shading, sources, ch, c.panes,
        ))
    }
}
