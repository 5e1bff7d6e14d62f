//! `mesh` and `instance` primitives read into shared units before compiling.
//!
//! Each `mesh` (a compiled mesh, [`crate::scene::mesh`], or a Wavefront `.obj`,
//! [`crate::scene::obj`], our extension) and each `instance` (an octree,
//! [`crate::scene::octree`]: frozen, or naming its scene files) is read once per distinct
//! file. Its surfaces, in the file's own coordinates, are appended once per (file,
//! material assignment) to a copy of the scene as a [`Unit`]; each primitive naming it is a
//! [`Placement`]: the unit and the primitive's transform (`xform` options:
//! [`Xf::forward_of`]). The compiler gives every unit one BVH, shared by its placements
//! through a two-level BVH (`geometry::bvh::Placed`). The original primitive stays in place
//! (so object indices and modifier links do not move) and is skipped by the compiler.
//!
//! **Materials, as Radiance resolves them.** `src/rt/o_mesh.c`: a mesh whose own modifier is
//! not `void` uses it for every triangle; otherwise each triangle uses its material from the
//! mesh file (obj2mesh's `-a` materials, looked up by `usemtl` name, else group name), and a
//! triangle with none is `void` (transparent). `src/rt/o_instance.c`: an instance whose
//! modifier is not `void` uses it for every surface of the octree; otherwise the octree's own
//! materials. For a `.obj` file read directly the `usemtl` (else group) names are looked up
//! among the scene's modifiers defined before the `mesh` primitive, as `obj2mesh -a` would
//! look them up in its material files.
//!
//! **Transforms.** A placement's rays are taken into the unit (as `o_instance.c` does) and
//! its normals moved back as vectors, so a mirror keeps Radiance's front side. Meshes and
//! instances nested inside an octree are flattened into its unit: points by the composed
//! matrix, radii by its scale, polygon vertex order reversed under a mirror (as `xform`
//! does, [`transformed`]).
//!
//! **What is not modelled.** Mesh vertex normals are not interpolated (Radiance perturbs
//! the shading normal with them: `o_mesh.c`), so smooth-shaded meshes shade flat; patterns
//! on instance materials see world, not instance, coordinates; `source` primitives inside
//! octrees are refused.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::calc::xf::Xf;
use crate::error::{Error, Location, Result};
use crate::scene::find_file;
use crate::scene::mesh::{MeshFile, read_mesh};
use crate::scene::obj::{ObjFile, read_obj};
use crate::scene::octree::{OctreeScene, read_octree};
use crate::scene::{LoadOptions, Object, Primitive, Scene};

/// How deep instances may nest (an octree instancing itself would never end).
const MAX_DEPTH: usize = 8;

/// The scene with every `mesh` and `instance` flattened (borrowed when there are none).
pub fn expand(scene: &Scene) -> Result<Expanded<'_>> {
    if !scene
        .objects
        .iter()
        .any(|o| matches!(o.kind, Primitive::Mesh { .. } | Primitive::Instance { .. }))
    {
        return Ok(Expanded {
            scene: Cow::Borrowed(scene),
            units: Vec::new(),
            placements: Vec::new(),
            files: Vec::new(),
        });
    }
    let mut ex = Expander {
        out: scene.clone(),
        units: Vec::new(),
        placements: Vec::new(),
        unit_of: HashMap::new(),
        current: 0,
        meshes: HashMap::new(),
        objs: HashMap::new(),
        octrees: HashMap::new(),
        mesh_materials: HashMap::new(),
        files: Vec::new(),
    };
    for (i, o) in scene.objects.iter().enumerate() {
        let before = &scene.objects[..i];
        let lookup = |name: &str| {
            before
                .iter()
                .rposition(|b| b.id == name && b.kind.otype().is_modifier())
        };
        ex.current = i;
        ex.object(o, o.modifier, &Xf::default(), &lookup, &o.loc, 0)?;
    }
    Ok(Expanded {
        scene: Cow::Owned(ex.out),
        units: ex.units,
        placements: ex.placements,
        files: ex.files,
    })
}

/// The surfaces of one file (with one material assignment), in its own coordinates: a
/// range of [`Expanded::scene`]'s objects, traced through one shared BVH.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    pub objects: std::ops::Range<usize>,
}

/// One `mesh` or `instance` primitive: a unit moved into the scene by `xf`.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    pub unit: usize,
    /// Forward transform (file coordinates to the scene's).
    pub xf: Xf,
    /// The primitive's index in the scene.
    pub scene_index: usize,
}

/// A scene with its `mesh` and `instance` primitives read: the scene (their surfaces
/// appended, in file coordinates), the units and where each is placed.
#[derive(Debug)]
pub struct Expanded<'a> {
    pub scene: Cow<'a, Scene>,
    pub units: Vec<Unit>,
    pub placements: Vec<Placement>,
    /// The files read (meshes, `.obj` files, octrees and the scene files they name), each
    /// once, in the order read.
    pub files: Vec<PathBuf>,
}

struct Expander {
    out: Scene,
    units: Vec<Unit>,
    placements: Vec<Placement>,
    /// (file, modifier, position for `.obj` name lookups) -> unit.
    unit_of: HashMap<(PathBuf, Option<usize>, Option<usize>), usize>,
    /// The scene index of the top-level object being expanded.
    current: usize,
    meshes: HashMap<PathBuf, Arc<MeshFile>>,
    objs: HashMap<PathBuf, Arc<ObjFile>>,
    octrees: HashMap<PathBuf, Arc<Vec<Object>>>,
    /// Where a mesh file's materials were appended (offset into `out.objects`).
    mesh_materials: HashMap<PathBuf, usize>,
    files: Vec<PathBuf>,
}

fn locate(file: &str, loc: &Location, what: &str, id: &str) -> Result<PathBuf> {
    find_file(file, &loc.file).ok_or_else(|| {
        Error::parse(
            loc.clone(),
            format!(
                "{what} '{id}': file '{file}' not found (looked beside the scene file, in the working folder and on RAYPATH)"
            ),
        )
    })
}

/// `p` with its vertices moved by `xf` (reversed when it mirrors).
fn polygon(vertices: impl Iterator<Item = [f64; 3]>, xf: &Xf) -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = vertices.map(|p| xf.point(p)).collect();
    if xf.mirrors() {
        v.reverse();
    }
    v
}

/// True for a polygon with no area (obj2mesh drops such faces with a warning).
fn degenerate(v: &[[f64; 3]]) -> bool {
    let mut n = [0.0; 3];
    for k in 0..v.len() {
        let (a, b) = (v[k], v[(k + 1) % v.len()]);
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let len2 = n.iter().map(|c| c * c).sum::<f64>();
    let size2 = v
        .iter()
        .flat_map(|p| p.iter())
        .map(|c| c * c)
        .fold(0.0, f64::max)
        .max(1e-300);
    !len2.is_finite() || len2 <= 1e-24 * size2 * size2
}

impl Expander {
    /// Handle one object of the scene (or of an octree at `depth` > 0): flatten meshes and
    /// instances; at depth > 0 also append ordinary objects, moved by `xf`.
    fn object(
        &mut self,
        o: &Object,
        modifier: Option<usize>,
        xf: &Xf,
        lookup: &dyn Fn(&str) -> Option<usize>,
        loc: &Location,
        depth: usize,
    ) -> Result<()> {
        match &o.kind {
            Primitive::Mesh { file, transform } => {
                let own = Xf::forward_of(transform, loc, &format!("mesh '{}'", o.id))?;
                let path = locate(file, loc, "mesh", &o.id)?;
                if depth == 0 {
                    return self.place(o, path, modifier, own, lookup, loc);
                }
                self.mesh(o, &path, modifier, &own.then(xf), lookup, loc)
            }
            Primitive::Instance { octree, transform } => {
                if depth >= MAX_DEPTH {
                    return Err(Error::parse(
                        loc.clone(),
                        format!(
                            "instance '{}' nests more than {MAX_DEPTH} octrees deep",
                            o.id
                        ),
                    ));
                }
                let own = Xf::forward_of(transform, loc, &format!("instance '{}'", o.id))?;
                let path = locate(octree, loc, "instance", &o.id)?;
                if depth == 0 {
                    return self.place(o, path, modifier, own, lookup, loc);
                }
                self.instance(&path, modifier, &own.then(xf), loc, depth)
            }
            _ if depth == 0 => Ok(()),
            Primitive::Source { .. } => Err(Error::unsupported(
                loc.clone(),
                format!("source '{}' inside an instanced octree", o.id),
            )),
            kind => {
                let kind = if kind.is_surface() {
                    transformed(kind, xf)
                } else {
                    kind.clone()
                };
                self.out.objects.push(Object {
                    modifier,
                    modifier_name: modifier
                        .map_or("void".into(), |m| self.out.objects[m].id.clone()),
                    id: o.id.clone(),
                    kind,
                    alias: None,
                    loc: loc.clone(),
                });
                Ok(())
            }
        }
    }

    /// A top-level `mesh` or `instance`: its surfaces in the file's own coordinates are
    /// appended once per (file, modifier) as a [`Unit`]; every primitive naming it is a
    /// [`Placement`] of that unit.
    fn place(
        &mut self,
        o: &Object,
        path: PathBuf,
        modifier: Option<usize>,
        xf: Xf,
        lookup: &dyn Fn(&str) -> Option<usize>,
        loc: &Location,
    ) -> Result<()> {
        // `.obj` faces find their materials by name among the modifiers before the
        // primitive, so with a `void` modifier the unit depends on the position too.
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        let position = (is_obj && modifier.is_none()).then_some(self.current);
        let key = (path.clone(), modifier, position);
        let unit = match self.unit_of.get(&key) {
            Some(&u) => u,
            None => {
                let start = self.out.objects.len();
                let identity = Xf::default();
                if matches!(o.kind, Primitive::Mesh { .. }) {
                    self.mesh(o, &path, modifier, &identity, lookup, loc)?;
                } else {
                    self.instance(&path, modifier, &identity, loc, 0)?;
                }
                let u = self.units.len();
                self.units.push(Unit {
                    objects: start..self.out.objects.len(),
                });
                self.unit_of.insert(key, u);
                u
            }
        };
        self.placements.push(Placement {
            unit,
            xf,
            scene_index: self.current,
        });
        Ok(())
    }

    fn push_polygon(&mut self, id: &str, modifier: usize, vertices: Vec<[f64; 3]>, loc: &Location) {
        self.out.objects.push(Object {
            modifier: Some(modifier),
            modifier_name: self.out.objects[modifier].id.clone(),
            id: id.to_string(),
            kind: Primitive::Polygon { vertices },
            alias: None,
            loc: loc.clone(),
        });
    }

    fn mesh(
        &mut self,
        o: &Object,
        path: &Path,
        modifier: Option<usize>,
        xf: &Xf,
        lookup: &dyn Fn(&str) -> Option<usize>,
        loc: &Location,
    ) -> Result<()> {
        let path = path.to_path_buf();
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if is_obj {
            let obj = match self.objs.get(&path) {
                Some(m) => m.clone(),
                None => {
                    let m = Arc::new(read_obj(&path)?);
                    self.files.push(path.clone());
                    self.objs.insert(path.clone(), m.clone());
                    m
                }
            };
            for f in &obj.faces {
                let m = match (modifier, &f.material) {
                    (Some(m), _) => m,
                    (None, None) => continue, // void: transparent
                    (None, Some(name)) => lookup(name).ok_or_else(|| {
                            Error::parse(
                                Location::line(path.display().to_string(), f.line),
                                format!(
                                    "undefined modifier '{name}' (usemtl or group name of a face of mesh '{}'); define it in the scene before the mesh, or give the mesh a modifier",
                                    o.id
                                ),
                            )
                        })?,
                };
                let v = polygon(f.vertices.iter().copied(), xf);
                if !degenerate(&v) {
                    self.push_polygon(&o.id, m, v, loc);
                }
            }
            return Ok(());
        }
        let mesh = match self.meshes.get(&path) {
            Some(m) => m.clone(),
            None => {
                let m = Arc::new(read_mesh(&path)?);
                self.files.push(path.clone());
                self.meshes.insert(path.clone(), m.clone());
                m
            }
        };
        // The mesh's own materials, appended once per file (only when some face uses them).
        let base = if modifier.is_none() && mesh.triangles.iter().any(|t| t.material.is_some()) {
            Some(self.mesh_materials(&path, &mesh.materials))
        } else {
            None
        };
        for t in &mesh.triangles {
            let m = match (modifier, t.material, base) {
                (Some(m), _, _) => m,
                (None, Some(k), Some(b)) => b + k,
                _ => continue, // void: transparent (o_mesh.c)
            };
            let v = polygon(t.vertices.iter().copied(), xf);
            if !degenerate(&v) {
                self.push_polygon(&o.id, m, v, loc);
            }
        }
        Ok(())
    }

    fn mesh_materials(&mut self, path: &Path, materials: &[Object]) -> usize {
        if let Some(&b) = self.mesh_materials.get(path) {
            return b;
        }
        let base = self.out.objects.len();
        for m in materials {
            let mut m = m.clone();
            m.modifier = m.modifier.map(|k| k + base);
            self.out.objects.push(m);
        }
        self.mesh_materials.insert(path.to_path_buf(), base);
        base
    }

    fn instance(
        &mut self,
        path: &Path,
        modifier: Option<usize>,
        xf: &Xf,
        loc: &Location,
        depth: usize,
    ) -> Result<()> {
        let path = path.to_path_buf();
        let objects = match self.octrees.get(&path) {
            Some(s) => s.clone(),
            None => {
                let s = Arc::new(match read_octree(&path)? {
                    OctreeScene::Frozen(objects) => objects,
                    OctreeScene::Files(files) => {
                        // oconv's inputs as it named them: from the working folder, else
                        // beside the octree.
                        let dir = path.parent().unwrap_or(Path::new(""));
                        let inputs: Vec<String> = files
                            .iter()
                            .map(|f| {
                                if Path::new(f).exists() {
                                    f.clone()
                                } else {
                                    dir.join(f).display().to_string()
                                }
                            })
                            .collect();
                        self.files.extend(
                            inputs
                                .iter()
                                .filter(|f| !f.starts_with('!') && *f != "-")
                                .map(PathBuf::from),
                        );
                        crate::scene::load(&inputs, &LoadOptions::from_env())?.objects
                    }
                });
                self.files.push(path.clone());
                self.octrees.insert(path.clone(), s.clone());
                s
            }
        };
        // Index in `out` of each octree modifier that was appended.
        let mut map: Vec<Option<usize>> = Vec::with_capacity(objects.len());
        for (k, obj) in objects.iter().enumerate() {
            let theirs = obj.modifier.filter(|&j| j < k).and_then(|j| map[j]);
            let at = self.out.objects.len();
            if !obj.kind.is_surface() {
                // Their modifiers are needed only when the instance has none (o_instance.c).
                if modifier.is_none() {
                    self.object(obj, theirs, xf, &|_| None, loc, depth + 1)?;
                }
                map.push((self.out.objects.len() > at).then_some(at));
                continue;
            }
            map.push(None);
            let m = modifier.or(theirs);
            let nested = matches!(
                obj.kind,
                Primitive::Mesh { .. } | Primitive::Instance { .. }
            );
            if m.is_none() && !nested {
                continue; // void: transparent
            }
            let earlier = &objects[..k];
            let lookup = |name: &str| {
                earlier
                    .iter()
                    .rposition(|b| b.id == name && b.kind.otype().is_modifier())
                    .and_then(|j| map[j])
            };
            self.object(obj, m, xf, &lookup, loc, depth + 1)?;
        }
        Ok(())
    }
}

/// A surface primitive moved by `xf` (points by the matrix, radii by its scale).
pub fn transformed(kind: &Primitive, xf: &Xf) -> Primitive {
    match kind {
        Primitive::Polygon { vertices } => Primitive::Polygon {
            vertices: polygon(vertices.iter().copied(), xf),
        },
        Primitive::Sphere {
            center,
            radius,
            inward,
        } => Primitive::Sphere {
            center: xf.point(*center),
            radius: radius * xf.sca,
            inward: *inward,
        },
        Primitive::Cylinder {
            p0,
            p1,
            radius,
            inward,
        } => Primitive::Cylinder {
            p0: xf.point(*p0),
            p1: xf.point(*p1),
            radius: radius * xf.sca,
            inward: *inward,
        },
        Primitive::Cone {
            p0,
            p1,
            r0,
            r1,
            inward,
        } => Primitive::Cone {
            p0: xf.point(*p0),
            p1: xf.point(*p1),
            r0: r0 * xf.sca,
            r1: r1 * xf.sca,
            inward: *inward,
        },
        Primitive::Ring {
            center,
            normal,
            r0,
            r1,
        } => Primitive::Ring {
            center: xf.point(*center),
            normal: xf.vector(*normal),
            r0: r0 * xf.sca,
            r1: r1 * xf.sca,
        },
        other => other.clone(),
    }
}
