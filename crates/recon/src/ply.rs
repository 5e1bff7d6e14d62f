//! PLY point clouds (Turk 1994; the format as Paul Bourke's page and rply describe it):
//! reading ascii, binary little-endian and binary big-endian files, and writing binary
//! little-endian ones.
//!
//! Header: `ply`, `format <ascii|binary_little_endian|binary_big_endian> 1.0`, any
//! `comment`/`obj_info` lines, `element <name> <count>` each followed by its
//! `property <type> <name>` or `property list <count type> <item type> <name>` lines, then
//! `end_header`. Types: `char uchar short ushort int uint float double` and their sized
//! aliases `int8 uint8 int16 uint16 int32 uint32 float32 float64`. Elements follow in header
//! order; ascii rows are one per line.
//!
//! From the `vertex` element we take `x y z` (required), `nx ny nz` (all three or none),
//! `red green blue` (or `r g b`, `diffuse_red ...`; uchar as is, floats in 0..1 scaled to 255)
//! and `station` (the scanner index our simulator writes); other properties and elements
//! (faces of a mesh) are read past. Comments `comment station x y z` give station positions.
//!
//! Errors name the file and the header line (`scan.ply:3: ...`), the body line for ascii
//! files, or the byte offset for binary ones. Counts from the header are checked against the
//! bytes that follow before anything is allocated for them.

use super::cloud::PointCloud;
use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::{tag, take_while1},
    character::complete::{digit1, space0, space1},
    combinator::{all_consuming, map, map_res, rest, value},
    number::{Endianness, complete as num},
    sequence::preceded,
};
use std::io::Write;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Binary(Endianness),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Debug, Clone, PartialEq)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug, Clone, PartialEq)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Debug, Clone, PartialEq)]
enum HeaderLine {
    Magic,
    Format(Format),
    Comment(String),
    Element(String, usize),
    Property(Property),
    End,
}

fn word(i: &str) -> IResult<&str, &str> {
    take_while1(|c: char| !c.is_whitespace()).parse(i)
}

fn scalar(i: &str) -> IResult<&str, Scalar> {
    alt((
        value(Scalar::I8, alt((tag("int8"), tag("char")))),
        value(Scalar::U8, alt((tag("uint8"), tag("uchar")))),
        value(Scalar::I16, alt((tag("int16"), tag("short")))),
        value(Scalar::U16, alt((tag("uint16"), tag("ushort")))),
        value(Scalar::I32, alt((tag("int32"), tag("int")))),
        value(Scalar::U32, alt((tag("uint32"), tag("uint")))),
        value(Scalar::F32, alt((tag("float32"), tag("float")))),
        value(Scalar::F64, alt((tag("float64"), tag("double")))),
    ))
    .parse(i)
}

/// One header line (without its line end).
fn header_line(i: &str) -> IResult<&str, HeaderLine> {
    all_consuming(alt((
        value(HeaderLine::Magic, tag("ply")),
        map(
            (
                tag("format"),
                space1,
                alt((
                    value(Format::Ascii, tag("ascii")),
                    value(
                        Format::Binary(Endianness::Little),
                        tag("binary_little_endian"),
                    ),
                    value(Format::Binary(Endianness::Big), tag("binary_big_endian")),
                )),
                space1,
                tag("1.0"),
                space0,
            ),
            |(_, _, f, _, _, _)| HeaderLine::Format(f),
        ),
        map(
            preceded(alt((tag("comment"), tag("obj_info"))), rest),
            |s: &str| HeaderLine::Comment(s.trim().to_string()),
        ),
        map(
            (
                tag("element"),
                space1,
                word,
                space1,
                map_res(digit1, str::parse::<usize>),
                space0,
            ),
            |(_, _, n, _, c, _)| HeaderLine::Element(n.to_string(), c),
        ),
        map(
            (
                tag("property"),
                space1,
                alt((
                    map(
                        (tag("list"), space1, scalar, space1, scalar),
                        |(_, _, c, _, t)| Kind::List(c, t),
                    ),
                    map(scalar, Kind::Scalar),
                )),
                space1,
                word,
                space0,
            ),
            |(_, _, kind, _, name, _)| {
                HeaderLine::Property(Property {
                    name: name.to_string(),
                    kind,
                })
            },
        ),
        value(HeaderLine::End, (tag("end_header"), space0)),
    )))
    .parse(i)
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    comments: Vec<String>,
    /// Byte offset of the body.
    body: usize,
    /// Line number of the first body line.
    body_line: usize,
}

fn parse_header(data: &[u8], name: &str) -> Result<Header> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut comments = Vec::new();
    loop {
        line_no += 1;
        let loc = || Location::line(name, line_no);
        let Some(nl) = data[pos..].iter().position(|&b| b == b'\n') else {
            return Err(Error::parse(
                loc(),
                "header ends before 'end_header'; expected a complete PLY header",
            ));
        };
        let raw = &data[pos..pos + nl];
        pos += nl + 1;
        let text = std::str::from_utf8(raw)
            .map_err(|_| Error::parse(loc(), "header line is not text; expected ASCII"))?;
        let text = text.trim_end_matches('\r');
        let parsed = header_line(text).map(|(_, l)| l).map_err(|_| {
            Error::parse(
                loc(),
                format!(
                    "'{}' is not a PLY header line; expected format, comment, element, property \
                     or end_header",
                    text.chars().take(60).collect::<String>()
                ),
            )
        })?;
        match (line_no, parsed) {
            (1, HeaderLine::Magic) => {}
            (1, _) => {
                return Err(Error::parse(
                    loc(),
                    "not a PLY file; expected 'ply' on the first line",
                ));
            }
            (_, HeaderLine::Magic) => {
                return Err(Error::parse(
                    loc(),
                    "'ply' repeated; expected a header line",
                ));
            }
            (_, HeaderLine::Format(f)) => format = Some(f),
            (_, HeaderLine::Comment(c)) => comments.push(c),
            (_, HeaderLine::Element(n, count)) => elements.push(Element {
                name: n,
                count,
                props: Vec::new(),
            }),
            (_, HeaderLine::Property(p)) => match elements.last_mut() {
                Some(e) => e.props.push(p),
                None => {
                    return Err(Error::parse(
                        loc(),
                        "property before any element; expected 'element <name> <count>' first",
                    ));
                }
            },
            (_, HeaderLine::End) => {
                let format = format.ok_or_else(|| {
                    Error::parse(loc(), "no 'format' line; expected one before end_header")
                })?;
                return Ok(Header {
                    format,
                    elements,
                    comments,
                    body: pos,
                    body_line: line_no + 1,
                });
            }
        }
    }
}

/// Which vertex properties feed which output.
struct VertexMap {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    color: Option<([usize; 3], bool)>,
    station: Option<usize>,
}

fn vertex_map(e: &Element, name: &str) -> Result<VertexMap> {
    let find = |names: &[&str]| {
        e.props
            .iter()
            .position(|p| names.contains(&p.name.as_str()) && matches!(p.kind, Kind::Scalar(_)))
    };
    let need = |n: &str| {
        find(&[n]).ok_or_else(|| {
            Error::parse(
                Location::file(name),
                format!("vertex element has no scalar property '{n}'; expected x, y and z"),
            )
        })
    };
    let xyz = [need("x")?, need("y")?, need("z")?];
    let normal = match (find(&["nx"]), find(&["ny"]), find(&["nz"])) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let color = match (
        find(&["red", "r", "diffuse_red"]),
        find(&["green", "g", "diffuse_green"]),
        find(&["blue", "b", "diffuse_blue"]),
    ) {
        (Some(a), Some(b), Some(c)) => {
            let float = matches!(e.props[a].kind, Kind::Scalar(s) if s.is_float());
            Some(([a, b, c], float))
        }
        _ => None,
    };
    Ok(VertexMap {
        xyz,
        normal,
        color,
        station: find(&["station", "scan_index"]),
    })
}

fn push_vertex(cloud: &mut PointCloud, m: &VertexMap, row: &[f64]) {
    cloud.points.push(m.xyz.map(|k| row[k]));
    if let (Some(n), Some(out)) = (m.normal, cloud.normals.as_mut()) {
        out.push(n.map(|k| row[k]));
    }
    if let (Some((c, float)), Some(out)) = (m.color, cloud.colors.as_mut()) {
        out.push(c.map(|k| {
            let v = if float { row[k] * 255.0 } else { row[k] };
            v.round().clamp(0.0, 255.0) as u8
        }));
    }
    if let (Some(s), Some(out)) = (m.station, cloud.station_of.as_mut()) {
        out.push(row[s].clamp(0.0, u16::MAX as f64) as u16);
    }
}

fn read_scalar(s: Scalar, e: Endianness, i: &[u8]) -> IResult<&[u8], f64> {
    match s {
        Scalar::I8 => map(num::i8, f64::from).parse(i),
        Scalar::U8 => map(num::u8, f64::from).parse(i),
        Scalar::I16 => map(num::i16(e), f64::from).parse(i),
        Scalar::U16 => map(num::u16(e), f64::from).parse(i),
        Scalar::I32 => map(num::i32(e), f64::from).parse(i),
        Scalar::U32 => map(num::u32(e), f64::from).parse(i),
        Scalar::F32 => map(num::f32(e), f64::from).parse(i),
        Scalar::F64 => num::f64(e).parse(i),
    }
}

fn ascii_number(i: &str) -> IResult<&str, f64> {
    preceded(space0, num::double).parse(i)
}

/// Read a PLY file's bytes; `name` is used in error messages.
pub fn read(data: &[u8], name: &str) -> Result<PointCloud> {
    let h = parse_header(data, name)?;
    let Some(vi) = h.elements.iter().position(|e| e.name == "vertex") else {
        return Err(Error::parse(
            Location::file(name),
            "no 'vertex' element; expected a point cloud",
        ));
    };
    let vmap = vertex_map(&h.elements[vi], name)?;
    let mut cloud = PointCloud::default();
    for c in &h.comments {
        let mut w = c.split_whitespace();
        if w.next() == Some("station") {
            let v: Vec<f64> = w.filter_map(|s| s.parse().ok()).collect();
            if let [x, y, z] = v[..] {
                cloud.stations.push([x, y, z]);
            }
        }
    }
    let body = &data[h.body..];
    // Reserve no more than the body can hold (at least 2 bytes per ascii vertex row, a row's
    // size for binary), whatever the header claims.
    let min_row = match h.format {
        Format::Ascii => 6,
        Format::Binary(_) => h.elements[vi]
            .props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size(),
                Kind::List(c, _) => c.size(),
            })
            .sum::<usize>()
            .max(1),
    };
    let cap = h.elements[vi].count.min(body.len() / min_row);
    cloud.points.reserve(cap);
    if vmap.normal.is_some() {
        cloud.normals = Some(Vec::with_capacity(cap));
    }
    if vmap.color.is_some() {
        cloud.colors = Some(Vec::with_capacity(cap));
    }
    if vmap.station.is_some() {
        cloud.station_of = Some(Vec::with_capacity(cap));
    }
    match h.format {
        Format::Ascii => read_ascii(body, &h, vi, &vmap, &mut cloud, name)?,
        Format::Binary(e) => read_binary(body, h.body, e, &h, vi, &vmap, &mut cloud, name)?,
    }
    if let Some(s) = &cloud.station_of
        && let Some(&bad) = s
            .iter()
            .find(|&&s| !cloud.stations.is_empty() && s as usize >= cloud.stations.len())
    {
        return Err(Error::parse(
            Location::file(name),
            format!(
                "a vertex names station {bad} but the header gives {} 'comment station' lines",
                cloud.stations.len()
            ),
        ));
    }
    Ok(cloud)
}

fn read_ascii(
    body: &[u8],
    h: &Header,
    vi: usize,
    vmap: &VertexMap,
    cloud: &mut PointCloud,
    name: &str,
) -> Result<()> {
    let text = std::str::from_utf8(body).map_err(|e| {
        Error::parse(
            Location::file(name),
            format!(
                "ascii body is not text at byte offset {}; expected numbers",
                h.body + e.valid_up_to()
            ),
        )
    })?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let mut row = Vec::new();
    for (ei, e) in h.elements.iter().enumerate() {
        for r in 0..e.count {
            let Some((ln, line)) = lines.next() else {
                return Err(Error::parse(
                    Location::line(name, h.body_line + text.lines().count()),
                    format!(
                        "file ends after {r} of {} '{}' rows; expected the rest",
                        e.count, e.name
                    ),
                ));
            };
            let loc = || Location::line(name, h.body_line + ln);
            row.clear();
            let mut rest = line;
            let bad = |what: &str| Error::parse(loc(), format!("'{}' row {r}: {what}", e.name));
            for p in &e.props {
                let (r2, v) = ascii_number(rest)
                    .map_err(|_| bad(&format!("expected a number for '{}'", p.name)))?;
                rest = r2;
                if let Kind::List(_, _) = p.kind {
                    if v < 0.0 || v.fract() != 0.0 || v > 1e6 {
                        return Err(bad(&format!(
                            "list count {v}; expected a small whole number"
                        )));
                    }
                    for _ in 0..v as usize {
                        let (r3, _) = ascii_number(rest).map_err(|_| {
                            bad(&format!("list '{}' ends early; expected {v} items", p.name))
                        })?;
                        rest = r3;
                    }
                }
                row.push(v);
            }
            if !rest.trim().is_empty() {
                return Err(bad(&format!(
                    "extra values '{}'; expected {} properties",
                    rest.trim(),
                    e.props.len()
                )));
            }
            if ei == vi {
                push_vertex(cloud, vmap, &row);
            }
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn read_binary(
    body: &[u8],
    offset: usize,
    end: Endianness,
    h: &Header,
    vi: usize,
    vmap: &VertexMap,
    cloud: &mut PointCloud,
    name: &str,
) -> Result<()> {
    let mut input = body;
    let mut row = Vec::new();
    for (ei, e) in h.elements.iter().enumerate() {
        for r in 0..e.count {
            row.clear();
            for p in &e.props {
                let at = offset + body.len() - input.len();
                let trunc = || {
                    Error::parse(
                        Location::file(name),
                        format!(
                            "byte offset {at}: '{}' row {r} of {} ends early at property '{}'; \
                             expected the rest of the data",
                            e.name, e.count, p.name
                        ),
                    )
                };
                match p.kind {
                    Kind::Scalar(s) => {
                        let (i2, v) = read_scalar(s, end, input).map_err(|_| trunc())?;
                        input = i2;
                        row.push(v);
                    }
                    Kind::List(c, t) => {
                        let (i2, n) = read_scalar(c, end, input).map_err(|_| trunc())?;
                        let bytes = (n.max(0.0) as usize).saturating_mul(t.size());
                        if n < 0.0 || bytes > i2.len() {
                            return Err(trunc());
                        }
                        input = &i2[bytes..];
                        row.push(n);
                    }
                }
            }
            if ei == vi {
                push_vertex(cloud, vmap, &row);
            }
        }
    }
    Ok(())
}

/// Write a binary little-endian PLY: `float x y z`, `float nx ny nz` when normals are given,
/// `ushort station` when stations are, and `comment station x y z` lines.
pub fn write<W: Write>(mut w: W, cloud: &PointCloud) -> std::io::Result<()> {
    writeln!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by rrecon"
    )?;
    for s in &cloud.stations {
        writeln!(w, "comment station {} {} {}", s[0], s[1], s[2])?;
    }
    writeln!(w, "element vertex {}", cloud.points.len())?;
    writeln!(w, "property float x\nproperty float y\nproperty float z")?;
    if cloud.normals.is_some() {
        writeln!(w, "property float nx\nproperty float ny\nproperty float nz")?;
    }
    if cloud.station_of.is_some() {
        writeln!(w, "property ushort station")?;
    }
    writeln!(w, "end_header")?;
    let mut buf = Vec::with_capacity(1 << 16);
    for (i, p) in cloud.points.iter().enumerate() {
        for v in p {
            buf.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        if let Some(n) = cloud.normals.as_ref().and_then(|n| n.get(i)) {
            for v in n {
                buf.extend_from_slice(&(*v as f32).to_le_bytes());
            }
        }
        if let Some(s) = cloud.station_of.as_ref().and_then(|s| s.get(i)) {
            buf.extend_from_slice(&s.to_le_bytes());
        }
        if buf.len() > 60_000 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment station 1 2 1.5\nelement vertex 3\n\
        property float x\nproperty float y\nproperty float z\nproperty float nx\n\
        property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n\
        property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n\
        end_header\n0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n3 0 1 2\n";

    fn binary(end: Endianness) -> Vec<u8> {
        let tag = match end {
            Endianness::Big => "binary_big_endian",
            _ => "binary_little_endian",
        };
        let mut v = format!(
            "ply\nformat {tag} 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
             element vertex 2\nproperty double x\nproperty double y\nproperty double z\n\
             property ushort station\nend_header\n"
        )
        .into_bytes();
        v.push(2);
        for i in [7i32, 9] {
            v.extend(match end {
                Endianness::Big => i.to_be_bytes(),
                _ => i.to_le_bytes(),
            });
        }
        for (p, s) in [([1.0f64, 2.0, 3.0], 0u16), ([4.0, 5.0, 6.5], 1)] {
            for x in p {
                v.extend(match end {
                    Endianness::Big => x.to_be_bytes(),
                    _ => x.to_le_bytes(),
                });
            }
            v.extend(match end {
                Endianness::Big => s.to_be_bytes(),
                _ => s.to_le_bytes(),
            });
        }
        v
    }

    #[test]
    fn ascii_with_normals_colours_and_faces() {
        let c = read(ASCII.as_bytes(), "a.ply").unwrap();
        assert_eq!(c.points, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(c.normals.as_ref().unwrap()[2], [0.0, 0.0, 1.0]);
        assert_eq!(c.colors.as_ref().unwrap()[1], [0, 255, 0]);
        assert_eq!(c.stations, vec![[1.0, 2.0, 1.5]]);
    }

    #[test]
    fn binary_both_endians_skip_preceding_lists() {
        for e in [Endianness::Little, Endianness::Big] {
            let c = read(&binary(e), "b.ply").unwrap();
            assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]]);
            assert_eq!(c.station_of, Some(vec![0, 1]));
            assert!(c.normals.is_none());
        }
    }

    #[test]
    fn write_read_round_trip() {
        let c = PointCloud {
            points: vec![[0.5, 1.25, -2.0], [3.0, 4.0, 5.0]],
            normals: Some(vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
            station_of: Some(vec![1, 0]),
            stations: vec![[0.0; 3], [1.0, 1.0, 1.5]],
            colors: None,
        };
        let mut v = Vec::new();
        write(&mut v, &c).unwrap();
        assert_eq!(read(&v, "c.ply").unwrap(), c);
    }

    #[test]
    fn every_truncated_prefix_is_an_error_not_a_panic() {
        // The ascii file's final newline may go; every other cut must fail.
        let files = [
            (ASCII.as_bytes().to_vec(), 1),
            (binary(Endianness::Little), 0),
            (binary(Endianness::Big), 0),
        ];
        for (f, optional_tail) in &files {
            for n in 0..f.len() - optional_tail {
                assert!(
                    read(&f[..n], "t.ply").is_err(),
                    "prefix {n} of {} accepted",
                    f.len()
                );
            }
        }
    }

    #[test]
    fn error_messages_name_line_or_offset() {
        let e = read(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float q\nend_header\n1\n",
            "x.ply",
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "x.ply: vertex element has no scalar property 'x'; expected x, y and z"
        );
        let bad = ASCII.replace("1 0 0 0 0 1 0 255 0", "1 0 zero 0 0 1 0 255 0");
        let e = read(bad.as_bytes(), "x.ply").unwrap_err().to_string();
        assert_eq!(e, "x.ply:18: 'vertex' row 1: expected a number for 'z'");
        let e = read(b"ply\nformat ascii 2.0\n", "x.ply")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("x.ply:2: 'format ascii 2.0' is not a PLY header line"),
            "{e}"
        );
        let mut b = binary(Endianness::Little);
        b.truncate(b.len() - 3);
        let e = read(&b, "x.ply").unwrap_err().to_string();
        assert!(e.starts_with("x.ply: byte offset "), "{e}");
        assert!(
            e.contains("'vertex' row 1 of 2 ends early at property 'z'"),
            "{e}"
        );
        // A header count far beyond the data allocates nothing large and fails cleanly.
        let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert!(read(huge, "h.ply").is_err());
    }
}
