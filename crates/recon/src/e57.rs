//! ASTM E57 point clouds (the exchange format of terrestrial laser scanners), read with the
//! pure-Rust `e57` crate: every scan in the file, Cartesian points (spherical ones converted)
//! with each scan's pose applied, so several stations land in one frame; colours when the
//! scan has them. Each scan's pose translation is kept as a scanner station, which the
//! normal orientation of [`super::preprocess`] uses.

use super::cloud::PointCloud;
use crate::error::{Error, Location, Result};
use e57::{CartesianCoordinate, E57Reader};
use std::io::{Read, Seek};

/// Read every scan of an E57 file.
pub fn read(path: &str) -> Result<PointCloud> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    read_from(std::io::BufReader::new(file), path)
}

/// Read every scan of an E57 stream (`name` for messages): what [`read`] does after
/// opening the file, and what the fuzz target feeds bytes to.
pub fn read_from<R: Read + Seek>(stream: R, name: &str) -> Result<PointCloud> {
    let fail = |what: &str, e: e57::Error| {
        Error::parse(
            Location::file(name),
            format!("{what}: {e}; expected an ASTM E57 file (convert it to PLY if it is not)"),
        )
    };
    let mut reader = E57Reader::new(stream).map_err(|e| fail("cannot open E57", e))?;
    let mut cloud = PointCloud::default();
    let mut colors: Vec<[u8; 3]> = Vec::new();
    let mut any_color = false;
    let mut station_of: Vec<u16> = Vec::new();
    let scans = reader.pointclouds();
    if scans.len() > usize::from(u16::MAX) {
        return Err(Error::parse(
            Location::file(name),
            format!("{} scans; at most {} are supported", scans.len(), u16::MAX),
        ));
    }
    for (k, pc) in scans.iter().enumerate() {
        let t = pc.transform.as_ref().map(|t| t.translation.clone());
        cloud.stations.push(t.map_or([0.0; 3], |t| [t.x, t.y, t.z]));
        any_color |= pc.has_color();
        let points = reader
            .pointcloud_simple(pc)
            .map_err(|e| fail(&format!("scan {k}"), e))?;
        for p in points {
            let p = p.map_err(|e| fail(&format!("scan {k}"), e))?;
            // Direction-only and invalid returns (no range: sky, glass) carry no point.
            if let CartesianCoordinate::Valid { x, y, z } = p.cartesian {
                cloud.points.push([x, y, z]);
                station_of.push(k as u16);
                let c = p.color.map_or([0; 3], |c| {
                    [c.red, c.green, c.blue].map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
                });
                colors.push(c);
            }
        }
    }
    if any_color {
        cloud.colors = Some(colors);
    }
    cloud.station_of = Some(station_of);
    Ok(cloud)
}

#[cfg(test)]
mod tests {
    use e57::{E57Writer, Record, RecordValue, Transform, Translation};

    #[test]
    fn scans_are_read_with_their_poses() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.e57");
        {
            let mut w = E57Writer::from_file(&path, "file-guid").unwrap();
            for (s, dx) in [(0, 0.0), (1, 10.0)] {
                let proto = vec![
                    Record::CARTESIAN_X_F64,
                    Record::CARTESIAN_Y_F64,
                    Record::CARTESIAN_Z_F64,
                ];
                let mut pc = w.add_pointcloud(&format!("scan-{s}"), proto).unwrap();
                pc.set_transform(Some(Transform {
                    translation: Translation {
                        x: dx,
                        y: 0.0,
                        z: 1.5,
                    },
                    ..Transform::default()
                }));
                for i in 0..5 {
                    let v = i as f64;
                    pc.add_point(vec![
                        RecordValue::Double(v),
                        RecordValue::Double(2.0 * v),
                        RecordValue::Double(0.5),
                    ])
                    .unwrap();
                }
                pc.finalize().unwrap();
            }
            w.finalize().unwrap();
        }
        let c = super::read(path.to_str().unwrap()).unwrap();
        assert_eq!(c.points.len(), 10);
        assert_eq!(c.stations, vec![[0.0, 0.0, 1.5], [10.0, 0.0, 1.5]]);
        assert_eq!(c.points[3], [3.0, 6.0, 2.0]);
        assert_eq!(c.points[8], [13.0, 6.0, 2.0]);
        assert_eq!(c.station_of.as_deref().unwrap()[7], 1);
        assert!(c.colors.is_none());

        // Damaged files are errors naming the file, never panics.
        let bytes = std::fs::read(&path).unwrap();
        for n in [0, 10, 100, bytes.len() / 2, bytes.len() - 1] {
            let p = dir.path().join(format!("cut{n}.e57"));
            std::fs::write(&p, &bytes[..n]).unwrap();
            let ps = p.to_str().unwrap();
            match super::read(ps) {
                Err(e) => assert!(e.to_string().starts_with(ps), "{e}"),
                Ok(c) => assert!(c.points.len() < 10, "prefix {n} read whole"),
            }
        }
    }
}
