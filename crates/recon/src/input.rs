//! Opening a point cloud by name: `-` (standard input, PLY or XYZ by its first bytes) or a
//! file whose extension picks the reader: PLY, LAS (uncompressed, [`super::las`]), E57
//! ([`super::e57`]) or XYZ text. LAZ is refused with the conversion that works (`pdal
//! translate` or `laszip` decompress it in one command).

use super::cloud::PointCloud;
use super::{e57, las, ply, xyz};
use crate::error::{Error, Location, Result};
use std::io::Read;

/// Read `path` (`-` = standard input).
pub fn read_cloud(path: &str) -> Result<PointCloud> {
    let lower = path.to_ascii_lowercase();
    let ext = lower.rsplit_once('.').map(|(_, e)| e).unwrap_or("");
    if ext == "e57" {
        return e57::read(path);
    }
    if ext == "laz" {
        return Err(Error::unsupported(
            Location::file(path),
            format!(
                "point cloud format .{ext}; convert it to PLY first (e.g. `pdal translate {path} \
                 scan.ply` or CloudCompare's 'Save as PLY')"
            ),
        ));
    }
    let mut data = Vec::new();
    let name = if path == "-" { "<stdin>" } else { path };
    if path == "-" {
        std::io::stdin()
            .lock()
            .read_to_end(&mut data)
            .map_err(|e| Error::io(name, e))?;
    } else {
        data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    }
    if data.starts_with(b"LASF") || ext == "las" {
        las::read(&data, name)
    } else if data.starts_with(b"ply") || ext == "ply" {
        ply::read(&data, name)
    } else {
        xyz::read(&data, name)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn laz_says_how_to_convert() {
        let e = super::read_cloud("scan.LAZ").unwrap_err().to_string();
        assert!(
            e.starts_with("scan.LAZ: unsupported point cloud format .laz; convert it to PLY"),
            "{e}"
        );
    }
}
