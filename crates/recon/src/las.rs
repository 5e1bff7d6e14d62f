//! ASPRS LAS point clouds (versions 1.0-1.4, uncompressed), the format laser scanners and
//! PDAL/CloudCompare export most. Layout from the ASPRS LAS 1.4 specification (R15, 2019):
//!
//! | offset | field |
//! |---|---|
//! | 0 | `LASF` signature |
//! | 24, 25 | version major, minor |
//! | 94 | header size (u16) |
//! | 96 | offset to point data (u32) |
//! | 104 | point data record format (u8; bit 7 or 6 set = LAZ-compressed) |
//! | 105 | point data record length (u16) |
//! | 107 | legacy number of point records (u32) |
//! | 131..179 | x, y, z scale factors, then x, y, z offsets (f64) |
//! | 247 | number of point records (u64, LAS 1.4 headers of 375 bytes and more) |
//!
//! Every record starts with X, Y, Z as i32 (coordinate = X * scale + offset). RGB (u16
//! each) sits at byte 20 of formats 2, at 28 of formats 3 and 5, and at 30 of formats 7, 8
//! and 10. Little endian throughout. LAZ files are refused with the conversion that works.

use super::cloud::PointCloud;
use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    bytes::complete::take,
    number::complete::{le_f64, le_i32, le_u8, le_u16, le_u32, le_u64},
};

/// Header fields the reader needs.
#[derive(Debug, Clone, PartialEq)]
struct Header {
    version: (u8, u8),
    header_size: u16,
    point_offset: u32,
    format: u8,
    record_len: u16,
    npoints: u64,
    scale: [f64; 3],
    offset: [f64; 3],
}

fn at(data: &[u8], pos: usize) -> &[u8] {
    data.get(pos..).unwrap_or(&[])
}

fn header(data: &[u8]) -> IResult<&[u8], Header> {
    let (_, (major, minor)) = (le_u8, le_u8).parse(at(data, 24))?;
    let (_, (header_size, point_offset)) = (le_u16, le_u32).parse(at(data, 94))?;
    let (_, (format, record_len, legacy)) = (le_u8, le_u16, le_u32).parse(at(data, 104))?;
    let (_, (sx, sy, sz, ox, oy, oz)) =
        (le_f64, le_f64, le_f64, le_f64, le_f64, le_f64).parse(at(data, 131))?;
    let mut npoints = u64::from(legacy);
    if (major, minor) >= (1, 4) && header_size >= 375 {
        let (_, n) = le_u64.parse(at(data, 247))?;
        if n > 0 {
            npoints = n;
        }
    }
    let (rest, _) = take(header_size as usize).parse(data)?;
    Ok((
        rest,
        Header {
            version: (major, minor),
            header_size,
            point_offset,
            format,
            record_len,
            npoints,
            scale: [sx, sy, sz],
            offset: [ox, oy, oz],
        },
    ))
}

/// Byte offset of RGB within a record of `format`, if it has colours.
fn rgb_offset(format: u8) -> Option<usize> {
    match format {
        2 => Some(20),
        3 | 5 => Some(28),
        7 | 8 | 10 => Some(30),
        _ => None,
    }
}

/// Smallest record length of each point format (spec table "Point Data Record Format N").
fn min_record_len(format: u8) -> Option<usize> {
    Some(match format {
        0 => 20,
        1 => 28,
        2 => 26,
        3 => 34,
        4 => 57,
        5 => 63,
        6 => 30,
        7 => 36,
        8 => 38,
        9 => 59,
        10 => 67,
        _ => return None,
    })
}

/// Read a LAS file's points (and colours, when its format has them).
pub fn read(data: &[u8], name: &str) -> Result<PointCloud> {
    let err = |msg: String| Error::parse(Location::file(name), msg);
    if !data.starts_with(b"LASF") {
        return Err(err(
            "byte 0: expected the LAS signature 'LASF'; is this a LAS file?".into(),
        ));
    }
    let (_, h) = header(data).map_err(|_| {
        err("truncated LAS header (expected at least 227 bytes); the file is damaged".into())
    })?;
    if h.format & 0xc0 != 0 {
        return Err(Error::unsupported(
            Location::file(name),
            format!(
                "LAZ-compressed point records (format byte {}); decompress first (e.g. `pdal \
                 translate {name} scan.las` or `laszip -i {name} -o scan.las`)",
                h.format
            ),
        ));
    }
    let Some(min_len) = min_record_len(h.format) else {
        return Err(err(format!(
            "byte 104: point data record format {} (LAS {}.{}); expected 0 to 10",
            h.format, h.version.0, h.version.1
        )));
    };
    let rec = h.record_len as usize;
    if rec < min_len {
        return Err(err(format!(
            "byte 105: record length {rec} is shorter than point format {}'s {min_len} bytes",
            h.format
        )));
    }
    if (h.point_offset as usize) < h.header_size as usize {
        return Err(err(format!(
            "byte 96: point data offset {} lies inside the {}-byte header",
            h.point_offset, h.header_size
        )));
    }
    if h.scale.iter().any(|s| !s.is_finite() || *s == 0.0)
        || h.offset.iter().any(|o| !o.is_finite())
    {
        return Err(err(
            "byte 131: scale factors must be finite and non-zero, offsets finite".into(),
        ));
    }
    let body = at(data, h.point_offset as usize);
    // The count comes from the header: check it against the bytes present before
    // allocating (a damaged header cannot force a huge allocation).
    let available = (body.len() / rec) as u64;
    if h.npoints > available {
        return Err(err(format!(
            "the header announces {} points but the file holds {available} records of {rec} \
             bytes after byte {}; the file is truncated",
            h.npoints, h.point_offset
        )));
    }
    let n = h.npoints as usize;
    let mut points = Vec::with_capacity(n);
    let rgb_at = rgb_offset(h.format);
    let mut colors: Vec<[u16; 3]> = Vec::with_capacity(if rgb_at.is_some() { n } else { 0 });
    for r in body.chunks_exact(rec).take(n) {
        let (_, (x, y, z)) = (le_i32::<_, ()>, le_i32, le_i32)
            .parse(r)
            .map_err(|_| err("short point record".into()))?;
        points.push([
            f64::from(x) * h.scale[0] + h.offset[0],
            f64::from(y) * h.scale[1] + h.offset[1],
            f64::from(z) * h.scale[2] + h.offset[2],
        ]);
        if let Some(o) = rgb_at {
            let (_, (cr, cg, cb)) = (le_u16::<_, ()>, le_u16, le_u16)
                .parse(at(r, o))
                .map_err(|_| err("short point record".into()))?;
            colors.push([cr, cg, cb]);
        }
    }
    // LAS colours are 16-bit by the specification, but many writers store 8-bit values:
    // scale down only when some value needs more than 8 bits.
    let colors = rgb_at.map(|_| {
        let wide = colors.iter().flatten().any(|&c| c > 255);
        colors
            .iter()
            .map(|c| c.map(|v| if wide { (v / 257) as u8 } else { v as u8 }))
            .collect()
    });
    Ok(PointCloud {
        points,
        colors,
        ..PointCloud::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A LAS 1.2 file of point format `format` with `pts` (and 16-bit colours).
    pub(crate) fn las_file(format: u8, pts: &[[f64; 3]], rgb: &[[u16; 3]]) -> Vec<u8> {
        let rec = min_record_len(format).unwrap();
        let mut h = vec![0u8; 227];
        h[..4].copy_from_slice(b"LASF");
        h[24] = 1;
        h[25] = 2;
        h[94..96].copy_from_slice(&227u16.to_le_bytes());
        h[96..100].copy_from_slice(&227u32.to_le_bytes());
        h[104] = format;
        h[105..107].copy_from_slice(&(rec as u16).to_le_bytes());
        h[107..111].copy_from_slice(&(pts.len() as u32).to_le_bytes());
        let scale = [0.001f64, 0.001, 0.001];
        let offset = [1000.0f64, 2000.0, 0.0];
        for (k, v) in scale.iter().chain(&offset).enumerate() {
            h[131 + 8 * k..139 + 8 * k].copy_from_slice(&v.to_le_bytes());
        }
        for (i, p) in pts.iter().enumerate() {
            let mut r = vec![0u8; rec];
            for k in 0..3 {
                let q = ((p[k] - offset[k]) / scale[k]).round() as i32;
                r[4 * k..4 * k + 4].copy_from_slice(&q.to_le_bytes());
            }
            if let (Some(o), Some(c)) = (rgb_offset(format), rgb.get(i)) {
                for k in 0..3 {
                    r[o + 2 * k..o + 2 * k + 2].copy_from_slice(&c[k].to_le_bytes());
                }
            }
            h.extend(r);
        }
        h
    }

    #[test]
    fn reads_points_and_colours_back() {
        let pts = [
            [1000.5, 2001.25, 0.8],
            [1003.0, 2004.0, 2.999],
            [1000.0, 2000.0, 0.0],
        ];
        let rgb = [[65535, 0, 257 * 128], [0, 65535, 0], [257, 514, 771]];
        for format in [0u8, 1, 2, 3, 5, 6, 7, 8, 10] {
            let c = read(&las_file(format, &pts, &rgb), "t.las").unwrap();
            assert_eq!(c.points.len(), 3);
            for (a, b) in c.points.iter().zip(&pts) {
                for k in 0..3 {
                    assert!(
                        (a[k] - b[k]).abs() < 1e-9,
                        "format {format}: {a:?} vs {b:?}"
                    );
                }
            }
            match rgb_offset(format) {
                Some(_) => assert_eq!(
                    c.colors.as_deref(),
                    Some(&[[255, 0, 128], [0, 255, 0], [1, 2, 3]][..])
                ),
                None => assert!(c.colors.is_none()),
            }
        }
    }

    #[test]
    fn damaged_files_are_errors_never_panics() {
        let good = las_file(
            3,
            &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
            &[[1, 2, 3], [4, 5, 6]],
        );
        for n in 0..good.len() {
            assert!(read(&good[..n], "t.las").is_err(), "prefix {n}");
        }
        let mut laz = good.clone();
        laz[104] |= 0x80;
        let e = read(&laz, "t.laz").unwrap_err().to_string();
        assert!(
            e.starts_with("t.laz: ") && e.contains("decompress first"),
            "{e}"
        );
        let mut huge = good.clone();
        huge[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = read(&huge, "t.las").unwrap_err().to_string();
        assert!(e.contains("the file is truncated"), "{e}");
        let e = read(b"PLY junk", "t.las").unwrap_err().to_string();
        assert!(e.contains("'LASF'"), "{e}");
        let mut bad = good;
        bad[104] = 42;
        let e = read(&bad, "t.las").unwrap_err().to_string();
        assert!(e.contains("record format 42"), "{e}");
    }
}
