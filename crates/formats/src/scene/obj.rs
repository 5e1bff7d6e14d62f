//! Wavefront OBJ geometry for `mesh` primitives that name a `.obj` file directly (an
//! rdaylight extension: Radiance's `mesh` needs `obj2mesh` first).
//!
//! What is read follows `obj2mesh`'s reader (`src/ot/wfconv.c`, read to understand): `v`
//! (x y z), `vn`, `vt`, `f` with `v`, `v/vt`, `v//vn` or `v/vt/vn` references (1-based, or
//! negative: counted back from the last one defined), `usemtl NAME` and `g NAME`. A face's
//! material is its `usemtl` name, or else its group name; `void` (or neither) leaves it to
//! the `mesh` primitive's modifier. `o`, `s`, `mtllib`, `usemap`, comments and anything else
//! are skipped, as `obj2mesh` skips them (it only counts them for a warning). Faces keep
//! their vertex order (obj2mesh keeps the winding when it triangulates); they are returned
//! as polygons and triangulated by the tracer.

use std::path::Path;

use nom::Parser;
use nom::bytes::complete::tag;
use nom::character::complete::{i64 as int, space0, space1};
use nom::combinator::{all_consuming, opt};
use nom::multi::many1;
use nom::number::complete::double;
use nom::sequence::preceded;

use crate::error::{Error, Location, Result};

/// One polygonal face.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjFace {
    pub vertices: Vec<[f64; 3]>,
    /// Vertex normals, when every corner names one.
    pub normals: Option<Vec<[f64; 3]>>,
    /// The scene modifier that colours the face (`usemtl`, else the group); `None` = void.
    pub material: Option<String>,
    /// 1-based line of the `f` statement.
    pub line: usize,
}

/// The faces of an OBJ file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjFile {
    pub faces: Vec<ObjFace>,
}

/// Read an OBJ file.
pub fn read_obj(path: &Path) -> Result<ObjFile> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
    let text = String::from_utf8_lossy(&bytes);
    parse_obj(&text, &name)
}

type Ref = (i64, Option<i64>, Option<i64>);

/// `v`, `v/vt`, `v//vn`, `v/vt/vn`.
fn vref(i: &str) -> nom::IResult<&str, Ref> {
    let (i, v) = int(i)?;
    let (i, rest) = opt(preceded(
        tag("/"),
        (opt(int), opt(preceded(tag("/"), opt(int)))),
    ))
    .parse(i)?;
    Ok(match rest {
        None => (i, (v, None, None)),
        Some((t, n)) => (i, (v, t, n.flatten())),
    })
}

fn reals(n: usize) -> impl Fn(&str) -> nom::IResult<&str, Vec<f64>> {
    move |i: &str| {
        let (mut i, mut out) = (i, Vec::with_capacity(n));
        for _ in 0..n {
            let (r, v) = preceded(space1, double).parse(i)?;
            out.push(v);
            i = r;
        }
        Ok((i, out))
    }
}

/// Parse OBJ text (`name` labels errors).
pub fn parse_obj(text: &str, name: &str) -> Result<ObjFile> {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut vn: Vec<[f64; 3]> = Vec::new();
    let mut nvt = 0usize;
    let mut material = String::new();
    let mut group = String::new();
    let mut faces = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let bad = |what: &str| {
            Error::parse(
                Location::line(name, line_no),
                format!("expected {what}, found '{line}'"),
            )
        };
        let (kw, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest_ws = &line[kw.len()..];
        match kw {
            "v" => {
                let (_, r) = all_consuming((reals(3), opt(reals(1)), space0))
                    .parse(rest_ws)
                    .map_err(|_: nom::Err<nom::error::Error<&str>>| bad("a vertex 'v x y z'"))?;
                let p = [r.0[0], r.0[1], r.0[2]];
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(bad("finite vertex coordinates"));
                }
                v.push(p);
            }
            "vn" => {
                let (_, r) = all_consuming((reals(3), space0))
                    .parse(rest_ws)
                    .map_err(|_: nom::Err<nom::error::Error<&str>>| bad("a normal 'vn x y z'"))?;
                vn.push([r.0[0], r.0[1], r.0[2]]);
            }
            "vt" => nvt += 1,
            "usemtl" => material = rest.split_whitespace().next().unwrap_or("").into(),
            "g" => group = rest.split_whitespace().next().unwrap_or("").into(),
            "f" => {
                let (_, (refs, _)) = all_consuming((many1(preceded(space1, vref)), space0))
                    .parse(rest_ws)
                    .map_err(|_: nom::Err<nom::error::Error<&str>>| {
                        bad("a face 'f v1 v2 v3 ...' with v, v/vt, v//vn or v/vt/vn references")
                    })?;
                if refs.len() < 3 {
                    return Err(bad("a face with at least 3 vertices"));
                }
                // 1-based, or negative: relative to the end (wfconv.c `cvtndx`).
                let index = |r: i64, n: usize, what: &str| -> Result<usize> {
                    let i = if r > 0 { r - 1 } else { r + n as i64 };
                    if r == 0 || i < 0 || i as usize >= n {
                        return Err(Error::parse(
                            Location::line(name, line_no),
                            format!("face refers to {what} {r}, but {n} are defined so far"),
                        ));
                    }
                    Ok(i as usize)
                };
                let mut verts = Vec::with_capacity(refs.len());
                let mut norms = Vec::with_capacity(refs.len());
                for &(a, t, n) in &refs {
                    verts.push(v[index(a, v.len(), "vertex")?]);
                    if let Some(t) = t {
                        index(t, nvt, "texture coordinate")?;
                    }
                    if let Some(n) = n {
                        norms.push(vn[index(n, vn.len(), "normal")?]);
                    }
                }
                let name_of = if !material.is_empty() {
                    Some(material.clone())
                } else if !group.is_empty() {
                    Some(group.clone())
                } else {
                    None
                };
                faces.push(ObjFace {
                    normals: (norms.len() == verts.len()).then_some(norms),
                    vertices: verts,
                    material: name_of.filter(|m| m != "void"),
                    line: line_no,
                });
            }
            _ => {}
        }
    }
    Ok(ObjFile { faces })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_materials_and_negative_references() {
        let t = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\ng legs\nf 1 2 3\nusemtl wood\nf -4//1 -3//1 -2//1 -1//1\nusemtl void\nf 1/1 2 3\n";
        let o = parse_obj(&t.replace("f 1/1", "vt 0 0\nf 1/1"), "t.obj").unwrap();
        assert_eq!(o.faces.len(), 3);
        assert_eq!(o.faces[0].material.as_deref(), Some("legs"));
        assert_eq!(o.faces[1].material.as_deref(), Some("wood"));
        assert_eq!(o.faces[1].vertices.len(), 4);
        assert_eq!(o.faces[1].normals.as_ref().unwrap()[3], [0.0, 0.0, 1.0]);
        assert_eq!(o.faces[2].material, None);
    }

    #[test]
    fn bad_lines_name_file_and_line() {
        let e = parse_obj("v 0 0 0\nv 1 0\n", "t.obj")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.obj:2: expected a vertex"), "{e}");
        let e = parse_obj("v 0 0 0\nf 1 2 3\n", "t.obj")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.obj:2: face refers to vertex 2"), "{e}");
    }
}
