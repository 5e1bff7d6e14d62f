//! Radiance's compiled triangle meshes (`obj2mesh` output, the file a `mesh` primitive names).
//!
//! Sources (read to understand, not copied): `src/common/mesh.h` (layout, vertex and
//! triangle ids), `src/common/readmesh.c` (reading order and limits), `src/common/mesh.c`
//! (`getmeshtrivid`, `getmeshvert`: decoding), `src/common/dircode.c` (normals),
//! `src/ot/cvmesh.c` and `src/ot/obj2mesh.c` (what the writer puts there). Our summary is in
//! `docs/scene-binary-formats.md`.
//!
//! Layout after the text header (`FORMAT=Radiance_tmesh`): format number (2 bytes,
//! `MESHMAGIC = 319` + `sizeof(OBJECT)`), the bounding cube's origin and size as four
//! strings, the `(u,v)` limits as four reals (`u` min, max, `v` min, max), the mesh's octree
//! (skipped: we build our own BVH), the materials as a binary scene ([`super::binary`]), the
//! patch count (4 bytes) and the patches. A patch holds up to 256 vertices, each position as
//! three 4-byte unsigned fractions of the cube (`org + (q + 0.5) / 2^32 * size`), optional
//! 4-byte encoded normals (`0` = none) and `(u,v)` fractions (`0` = none), then triangles:
//! local ones (three 1-byte vertex numbers; a 2-byte material count, then either one
//! material for all or one per triangle), single joiners (one vertex elsewhere: 4-byte id
//! `patch << 8 | vertex`, two local vertices, a material) and double joiners (two vertices
//! elsewhere). Material numbers index the file's own materials; `-1` is `void`.

use std::path::Path;

use super::binary::{self, Reader};
use crate::error::{Error, Location, Result};
use crate::scene::Object;

/// `MESHMAGIC` in `mesh.h`.
const MESHMAGIC: i64 = 319;

/// One mesh triangle in the mesh's own coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshTriangle {
    pub vertices: [[f64; 3]; 3],
    /// Unit vertex normals, when all three vertices have one.
    pub normals: Option<[[f64; 3]; 3]>,
    /// Local `(u,v)` coordinates, when all three vertices have them.
    pub uv: Option<[[f64; 2]; 3]>,
    /// Index into [`MeshFile::materials`]; `None` for `void` (the `mesh` primitive's own
    /// modifier applies, `src/rt/o_mesh.c`).
    pub material: Option<usize>,
}

/// A compiled mesh: its materials (objects with links within the file) and triangles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshFile {
    pub materials: Vec<Object>,
    pub triangles: Vec<MeshTriangle>,
}

/// A decoded vertex: position, normal and `(u,v)` when stored.
type Vertex = ([f64; 3], Option<[f64; 3]>, Option<[f64; 2]>);

/// The flags of a patch's vertex data (`MT_V`, `MT_N`, `MT_UV` in `mesh.h`).
const MT_V: i64 = 1;
const MT_N: i64 = 2;
const MT_UV: i64 = 4;

struct Patch {
    xyz: Vec<[u32; 3]>,
    norm: Option<Vec<i32>>,
    uv: Option<Vec<[u32; 2]>>,
    /// Triangles as vertex ids (`patch << 8 | vertex`) and material number (-1 void).
    tris: Vec<([i64; 3], i64)>,
}

/// A normal from its 4-byte code (`decodedir`, `src/common/dircode.c`): two 13-bit
/// components scaled by `DCSCALE = ((1<<13) - 0.5)·√2`, the third from unit length, bits
/// saying which axis each is and the three signs.
pub fn decode_normal(dc: i32) -> [f64; 3] {
    const DCSCALE: f64 = 11584.5;
    const FMASK: i32 = 0x1fff;
    if dc == 0 {
        return [0.0; 3];
    }
    let d1 = ((dc >> 5) & FMASK) as f64 / DCSCALE;
    let d2 = ((dc >> 18) & FMASK) as f64 / DCSCALE;
    let der = (1.0 - d1 * d1 - d2 * d2).max(0.0).sqrt();
    let f1x = dc & 0o10 != 0;
    let f2z = dc & 0o20 != 0;
    // Which axis receives d1, d2 and the derived component.
    let (a1, a2, a3) = match (f2z, f1x) {
        (false, false) => (1, 0, 2),
        (false, true) => (0, 1, 2),
        (true, false) => (1, 2, 0),
        (true, true) => (0, 2, 1),
    };
    let mut v = [0.0; 3];
    v[a1] = d1;
    v[a2] = d2;
    v[a3] = der;
    for (k, bit) in [0o1, 0o2, 0o4].into_iter().enumerate() {
        if dc & bit != 0 {
            v[k] = -v[k];
        }
    }
    v
}

/// Read a compiled mesh file.
pub fn read_mesh(path: &Path) -> Result<MeshFile> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
    parse_mesh(&data, &name)
}

/// Parse a compiled mesh held in memory (`name` labels errors).
pub fn parse_mesh(data: &[u8], name: &str) -> Result<MeshFile> {
    let start = binary::header(data, name, "Radiance_tmesh", "mesh file (obj2mesh output)")?;
    let mut r = Reader::new(data, start, name, "mesh file");
    let objsize = binary::objsize(&mut r, MESHMAGIC)?;
    let mut org = [0.0; 3];
    for (k, o) in org.iter_mut().enumerate() {
        *o = r.number_string(&format!("the mesh cube's origin ({})", ["x", "y", "z"][k]))?;
    }
    let size = r.number_string("the mesh cube's size")?;
    let mut uvlim = [[0.0; 2]; 2]; // [min, max][u, v]
    for axis in 0..2 {
        // Written per axis: minimum, then maximum.
        for bound in uvlim.iter_mut() {
            bound[axis] = r.real("a (u,v) limit")?;
        }
    }
    r.skip_tree(objsize)?;
    let materials = r.scene(objsize)?;
    let at = r.pos();
    let npatches = r.int(4, "the number of patches")?;
    // Each patch takes at least 12 bytes: a bound from the data, not from the count.
    if npatches < 0 || npatches as usize > data.len() / 12 + 1 {
        return Err(r.error_at(
            at,
            format!(
                "{npatches} patches cannot fit in the file's {} bytes",
                data.len()
            ),
        ));
    }
    let mut patches = Vec::with_capacity(npatches as usize);
    for p in 0..npatches {
        patches.push(patch(&mut r, p, materials.len())?);
    }
    let vres = size / 4294967296.0;
    let vertex = |vid: i64, which: usize| -> Result<Vertex> {
        let pn = (vid >> 8) as usize;
        let local = (vid & 0xff) as usize;
        let p = patches
            .get(pn)
            .filter(|p| local < p.xyz.len())
            .ok_or_else(|| {
                Error::parse(
                    Location::file(name),
                    format!("triangle vertex {which} refers to vertex {local} of patch {pn}, which the mesh file does not have (damaged mesh file?)"),
                )
            })?;
        let q = p.xyz[local];
        let v = std::array::from_fn(|i| org[i] + (q[i] as f64 + 0.5) * vres);
        let n = p
            .norm
            .as_ref()
            .map(|n| n[local])
            .filter(|&c| c != 0)
            .map(decode_normal);
        let uv = p
            .uv
            .as_ref()
            .map(|u| u[local])
            .filter(|u| u[0] != 0)
            .map(|u| {
                std::array::from_fn(|i| {
                    uvlim[0][i] + (uvlim[1][i] - uvlim[0][i]) * (u[i] as f64 + 0.5) / 4294967296.0
                })
            });
        Ok((v, n, uv))
    };
    let mut triangles = Vec::new();
    for p in &patches {
        for (ids, mat) in &p.tris {
            let a = vertex(ids[0], 0)?;
            let b = vertex(ids[1], 1)?;
            let c = vertex(ids[2], 2)?;
            let normals = match (a.1, b.1, c.1) {
                (Some(x), Some(y), Some(z)) => Some([x, y, z]),
                _ => None,
            };
            let uv = match (a.2, b.2, c.2) {
                (Some(x), Some(y), Some(z)) => Some([x, y, z]),
                _ => None,
            };
            triangles.push(MeshTriangle {
                vertices: [a.0, b.0, c.0],
                normals,
                uv,
                material: (*mat >= 0).then_some(*mat as usize),
            });
        }
    }
    Ok(MeshFile {
        materials,
        triangles,
    })
}

/// One patch (`getpatch` in `readmesh.c`, with its limits).
fn patch(r: &mut Reader, pn: i64, nmats: usize) -> Result<Patch> {
    let at = r.pos();
    let flags = r.int(1, "a patch's vertex flags")?;
    if flags & MT_V == 0 || flags & !(MT_V | MT_N | MT_UV) != 0 {
        return Err(r.error_at(
            at,
            format!("patch {pn} has vertex flags {flags}; expected 1, 3, 5 or 7"),
        ));
    }
    let at = r.pos();
    let nverts = r.int(2, "a patch's vertex count")?;
    if !(1..=256).contains(&nverts) {
        return Err(r.error_at(
            at,
            format!("patch {pn} has {nverts} vertices; expected 1 to 256"),
        ));
    }
    let nv = nverts as usize;
    let mut xyz = Vec::with_capacity(nv);
    for _ in 0..nv {
        let mut q = [0u32; 3];
        for c in q.iter_mut() {
            *c = r.int(4, "a vertex coordinate")? as u32;
        }
        xyz.push(q);
    }
    let norm = if flags & MT_N != 0 {
        let mut n = Vec::with_capacity(nv);
        for _ in 0..nv {
            n.push(r.int(4, "a vertex normal")? as i32);
        }
        Some(n)
    } else {
        None
    };
    let uv = if flags & MT_UV != 0 {
        let mut u = Vec::with_capacity(nv);
        for _ in 0..nv {
            u.push([
                r.int(4, "a vertex (u,v) coordinate")? as u32,
                r.int(4, "a vertex (u,v) coordinate")? as u32,
            ]);
        }
        Some(u)
    } else {
        None
    };
    let local_vertex = |r: &mut Reader| -> Result<i64> {
        let at = r.pos();
        let v = r.int(1, "a local vertex number")? & 0xff;
        if v as usize >= nv {
            return Err(r.error_at(at, format!("patch {pn}: vertex {v} of {nv}")));
        }
        Ok(pn << 8 | v)
    };
    let check_mat = |r: &Reader, at: usize, m: i64| -> Result<i64> {
        if m == -1 || (0..nmats as i64).contains(&m) {
            Ok(m)
        } else {
            Err(r.error_at(
                at,
                format!(
                    "patch {pn}: material number {m}; the file has {nmats} materials (-1 is void)"
                ),
            ))
        }
    };
    let at = r.pos();
    let ntris = r.int(2, "a patch's triangle count")?;
    if !(0..=512).contains(&ntris) {
        return Err(r.error_at(
            at,
            format!("patch {pn} has {ntris} local triangles; expected 0 to 512"),
        ));
    }
    let mut tris = Vec::new();
    for _ in 0..ntris {
        let v = [local_vertex(r)?, local_vertex(r)?, local_vertex(r)?];
        tris.push((v, -1));
    }
    let nmat = r.int(2, "a patch's material count")?;
    if nmat > 1 {
        for t in tris.iter_mut() {
            let at = r.pos();
            let m = r.int(2, "a triangle's material number")?;
            t.1 = check_mat(r, at, m)?;
        }
    } else {
        let at = r.pos();
        let m = r.int(2, "the patch's material number")?;
        let m = check_mat(r, at, m)?;
        for t in tris.iter_mut() {
            t.1 = m;
        }
    }
    let at = r.pos();
    let nj1 = r.int(2, "a patch's joiner-triangle count")?;
    if !(0..=256).contains(&nj1) {
        return Err(r.error_at(
            at,
            format!("patch {pn} has {nj1} joiner triangles; expected 0 to 256"),
        ));
    }
    for _ in 0..nj1 {
        let v1 = r.int(4, "a joiner triangle's vertex id")?;
        let v2 = local_vertex(r)?;
        let v3 = local_vertex(r)?;
        let at = r.pos();
        let m = r.int(2, "a joiner triangle's material number")?;
        tris.push(([v1, v2, v3], check_mat(r, at, m)?));
    }
    let at = r.pos();
    let nj2 = r.int(2, "a patch's double-joiner count")?;
    if !(0..=256).contains(&nj2) {
        return Err(r.error_at(
            at,
            format!("patch {pn} has {nj2} double joiner triangles; expected 0 to 256"),
        ));
    }
    for _ in 0..nj2 {
        let v1 = r.int(4, "a double joiner's vertex id")?;
        let v2 = r.int(4, "a double joiner's vertex id")?;
        let v3 = local_vertex(r)?;
        let at = r.pos();
        let m = r.int(2, "a double joiner's material number")?;
        tris.push(([v1, v2, v3], check_mat(r, at, m)?));
    }
    Ok(Patch {
        xyz,
        norm,
        uv,
        tris,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_decode_to_unit_vectors_on_every_axis() {
        assert_eq!(decode_normal(0), [0.0; 3]);
        // Only flag bits set: both stored components 0, the derived one is the axis.
        assert_eq!(decode_normal(0o4), [0.0, 0.0, -1.0]);
        assert_eq!(decode_normal(0o20), [1.0, 0.0, 0.0]);
        // F1X|F2Z: d1 on x, d2 on z, derived on y.
        let y = decode_normal(0o10 | 0o20);
        assert!((y[1] - 1.0).abs() < 1e-12, "{y:?}");
    }

    #[test]
    fn not_a_mesh_is_named() {
        let e = parse_mesh(b"#?RADIANCE\nFORMAT=Radiance_octree\n\n", "a.rtm")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.rtm: not a Radiance mesh file"), "{e}");
    }
}
