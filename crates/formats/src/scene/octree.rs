//! Radiance octrees (`oconv` output, the file an `instance` primitive names).
//!
//! Sources (read to understand, not copied): `src/common/readoct.c` (reading order),
//! `src/common/octree.h` (`OCTMAGIC`, node codes), `src/common/sceneio.c` (the binary scene
//! of a frozen octree), `src/ot/writeoct.c`. Our summary is in
//! `docs/scene-binary-formats.md`.
//!
//! Layout after the text header (`FORMAT=Radiance_octree`): format number (2 bytes,
//! `OCTMAGIC = 283` + `sizeof(OBJECT)`), the cube's origin and size as four strings, the
//! names of the scene files oconv read (strings closed by an empty one; none for a frozen
//! octree, `oconv -f`), the object count, the octree (skipped: we build our own BVH) and,
//! when frozen, the scene itself as a binary scene ([`super::binary`]).

use std::path::Path;

use super::binary::{self, Reader};
use crate::error::{Error, Result};
use crate::scene::Object;

/// `OCTMAGIC` in `octree.h`.
const OCTMAGIC: i64 = 283;

/// What an octree holds.
#[derive(Debug, Clone, PartialEq)]
pub enum OctreeScene {
    /// A frozen octree (`oconv -f`): the scene's objects, modifier links within the file.
    Frozen(Vec<Object>),
    /// An octree that names its scene files (as oconv was given them) instead.
    Files(Vec<String>),
}

/// Read an octree's scene (frozen) or the names of its scene files.
pub fn read_octree(path: &Path) -> Result<OctreeScene> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
    parse_octree(&data, &name)
}

/// Parse an octree held in memory (`name` labels errors).
pub fn parse_octree(data: &[u8], name: &str) -> Result<OctreeScene> {
    let start = binary::header(data, name, "Radiance_octree", "octree (oconv output)")?;
    let mut r = Reader::new(data, start, name, "octree");
    let objsize = binary::objsize(&mut r, OCTMAGIC)?;
    for what in ["x", "y", "z"] {
        r.number_string(&format!("the octree cube's origin ({what})"))?;
    }
    r.number_string("the octree cube's size")?;
    let mut files = Vec::new();
    loop {
        let s = r.string("a scene file name (or an empty string after the last)")?;
        if s.is_empty() {
            break;
        }
        files.push(s);
    }
    let at = r.pos();
    let n = r.int(objsize, "the number of objects")?;
    if n < 0 {
        return Err(r.error_at(at, format!("object count {n}")));
    }
    if !files.is_empty() {
        return Ok(OctreeScene::Files(files));
    }
    r.skip_tree(objsize)?;
    let objects = r.scene(objsize)?;
    if objects.len() as i64 != n {
        return Err(r.error_at(
            at,
            format!(
                "the octree says {n} objects but holds {} (damaged octree?)",
                objects.len()
            ),
        ));
    }
    Ok(OctreeScene::Frozen(objects))
}
