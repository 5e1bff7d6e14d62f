//! A point cloud in memory, and the checks every input passes before reconstruction.
//!
//! Points are metres in a right-handed frame with +z up (the frame of the `.rad` model that
//! comes out). Optional per-point data: normals, 8-bit colours, and the index of the scanner
//! station that saw the point (our simulator writes it as the PLY property `station`); the
//! station positions themselves travel as PLY comments `comment station x y z`.
//!
//! [`PointCloud::check`] refuses what would silently give nonsense: an empty cloud, a
//! non-finite coordinate (named by point index), and a cloud whose size says it is not in
//! metres (a room is 1-200 m across; 5,000 "metres" is a millimetre scan). The message
//! reports the bounding box and the unit it looks like, with the option that fixes it.

use crate::error::{Error, Location, Result};

/// Points with optional normals, colours and scanner stations.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    pub points: Vec<[f64; 3]>,
    /// Unit normals, one per point, when the file has them (or after normal estimation).
    pub normals: Option<Vec<[f64; 3]>>,
    pub colors: Option<Vec<[u8; 3]>>,
    /// Index into [`PointCloud::stations`] of the station that measured each point.
    pub station_of: Option<Vec<u16>>,
    /// Scanner positions, when known.
    pub stations: Vec<[f64; 3]>,
}

/// Axis-aligned bounds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Bounds {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl Bounds {
    pub fn of(points: &[[f64; 3]]) -> Option<Bounds> {
        let first = *points.first()?;
        let mut b = Bounds {
            lo: first,
            hi: first,
        };
        for p in points {
            for (k, v) in p.iter().enumerate() {
                b.lo[k] = b.lo[k].min(*v);
                b.hi[k] = b.hi[k].max(*v);
            }
        }
        Some(b)
    }
    pub fn size(&self) -> [f64; 3] {
        [
            self.hi[0] - self.lo[0],
            self.hi[1] - self.lo[1],
            self.hi[2] - self.lo[2],
        ]
    }
    pub fn diagonal(&self) -> f64 {
        let s = self.size();
        (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
    }
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        (0..3).all(|k| p[k] >= self.lo[k] && p[k] <= self.hi[k])
    }
}

impl std::fmt::Display for Bounds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let g = |v: f64| format!("{v:.4}");
        write!(
            f,
            "({} {} {}) .. ({} {} {})",
            g(self.lo[0]),
            g(self.lo[1]),
            g(self.lo[2]),
            g(self.hi[0]),
            g(self.hi[1]),
            g(self.hi[2])
        )
    }
}

/// Length units a scan may come in, with their size in metres.
pub const UNITS: [(&str, f64); 5] = [
    ("m", 1.0),
    ("cm", 0.01),
    ("mm", 0.001),
    ("in", 0.0254),
    ("ft", 0.3048),
];

/// The scale in metres of a unit name (`m`, `cm`, `mm`, `in`, `ft`).
pub fn unit_scale(name: &str) -> Result<f64> {
    UNITS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, s)| s)
        .ok_or_else(|| {
            Error::Usage(format!(
                "unknown unit '{name}'; expected one of m, cm, mm, in, ft"
            ))
        })
}

/// The unit a room-sized cloud of this bounding-box diagonal is probably in: the one that
/// brings the diagonal closest to 10 m (rooms span 2-100 m; a factor of 10 separates m, cm
/// and mm, so the nearest in log scale is unambiguous for them).
pub fn guess_unit(diagonal: f64) -> &'static str {
    let mut best = ("m", f64::INFINITY);
    for &(name, s) in &[("m", 1.0), ("cm", 0.01), ("mm", 0.001)] {
        let d = (diagonal * s / 10.0).ln().abs();
        if d < best.1 {
            best = (name, d);
        }
    }
    best.0
}

/// A room in metres is between these diagonals (a cupboard to a large hall); outside them the
/// cloud is almost certainly in another unit.
pub const ROOM_DIAGONAL_M: (f64, f64) = (0.5, 500.0);

impl PointCloud {
    pub fn len(&self) -> usize {
        self.points.len()
    }
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Multiply coordinates and station positions by `s` (unit conversion).
    pub fn scale(&mut self, s: f64) {
        for p in self.points.iter_mut().chain(self.stations.iter_mut()) {
            for v in p.iter_mut() {
                *v *= s;
            }
        }
    }

    /// Keep the points for which `keep(i)` is true (all per-point arrays together).
    pub fn retain_indices(&mut self, keep: &[usize]) {
        self.points = keep.iter().map(|&i| self.points[i]).collect();
        if let Some(n) = &self.normals {
            self.normals = Some(keep.iter().map(|&i| n[i]).collect());
        }
        if let Some(c) = &self.colors {
            self.colors = Some(keep.iter().map(|&i| c[i]).collect());
        }
        if let Some(s) = &self.station_of {
            self.station_of = Some(keep.iter().map(|&i| s[i]).collect());
        }
    }

    /// Refuse empty, non-finite and wrongly scaled clouds (see the module documentation).
    /// `name` is the file name for messages.
    pub fn check(&self, name: &str) -> Result<Bounds> {
        let loc = || Location::file(name);
        let bounds = Bounds::of(&self.points).ok_or_else(|| {
            Error::parse(
                loc(),
                "the point cloud is empty; expected at least one point",
            )
        })?;
        if let Some(i) = self
            .points
            .iter()
            .position(|p| p.iter().any(|v| !v.is_finite()))
        {
            let p = self.points[i];
            return Err(Error::parse(
                loc(),
                format!(
                    "point {i} has a non-finite coordinate ({} {} {}); expected finite numbers",
                    p[0], p[1], p[2]
                ),
            ));
        }
        let diag = bounds.diagonal();
        if !(ROOM_DIAGONAL_M.0..=ROOM_DIAGONAL_M.1).contains(&diag) {
            let unit = guess_unit(diag);
            let hint = if unit == "m" {
                "; is this a room scan?".to_string()
            } else {
                format!("; it looks like {unit}: convert with --units {unit}")
            };
            return Err(Error::parse(
                loc(),
                format!(
                    "bounding box {bounds} has a diagonal of {diag:.4} units, not a room in metres \
                     (expected {}-{} m){hint}",
                    ROOM_DIAGONAL_M.0, ROOM_DIAGONAL_M.1
                ),
            ));
        }
        Ok(bounds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_nonfinite_and_millimetres_are_refused() {
        let e = PointCloud::default()
            .check("a.ply")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "a.ply: the point cloud is empty; expected at least one point"
        );
        let mut c = PointCloud {
            points: vec![[0.0; 3], [1.0, f64::NAN, 0.0]],
            ..Default::default()
        };
        let e = c.check("a.ply").unwrap_err().to_string();
        assert!(
            e.starts_with("a.ply: point 1 has a non-finite coordinate"),
            "{e}"
        );
        c.points = vec![[0.0; 3], [5000.0, 4000.0, 2700.0]];
        let e = c.check("a.ply").unwrap_err().to_string();
        assert!(e.contains("looks like mm: convert with --units mm"), "{e}");
        assert!(e.contains("(0.0000 0.0000 0.0000) .. (5000.0000 4000.0000 2700.0000)"));
        c.scale(unit_scale("mm").unwrap());
        assert!(c.check("a.ply").is_ok());
        assert_eq!(guess_unit(700.0), "cm");
    }
}
