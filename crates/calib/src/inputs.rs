//! # Inputs of a calibration run: sensors and weather
//!
//! Sensors come as a `.pts` file (`x y z dx dy dz` per line, ids are the 1-based line
//! numbers `1`, `2`, ...) or as the sensor CSV of [`crate::formats::sensors::read_csv`]
//! (`id,x,y,z,dx,dy,dz`); the CSV is recognised by its header line. The weather is a `.wea`
//! or EPW file read with [`crate::formats::weather::Weather`]: its time steps (measured
//! direct-normal and diffuse-horizontal irradiance) are the conditions of the measurement
//! period.

use crate::error::Result;
use crate::formats::sensors::{Sensor, read_csv, read_sensor_file};

/// Read sensors from a `.pts` or CSV file (see the module doc).
pub fn load_sensors(path: &str) -> Result<Vec<Sensor>> {
    let text = crate::csv::read_text(path)?;
    let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    if first.trim_start().to_ascii_lowercase().starts_with("id") {
        return read_csv(&text, path);
    }
    // A zero direction or an empty file is an error here (the module doc of sensors).
    let rays = read_sensor_file(text.as_bytes(), path)?;
    Ok(rays
        .into_iter()
        .enumerate()
        .map(|(i, ray)| Sensor {
            id: (i + 1).to_string(),
            ray,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pts_ids_are_line_numbers_and_csv_keeps_ids() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.pts");
        std::fs::write(&p, "1 2 0.8 0 0 1\n2 2 0.8 0 0 1\n").unwrap();
        let s = load_sensors(p.to_str().unwrap()).unwrap();
        assert_eq!((s[1].id.as_str(), s[1].ray.org[0]), ("2", 2.0));
        let c = dir.path().join("s.csv");
        std::fs::write(&c, "id,x,y,z,dx,dy,dz\nA,1,2,0.8,0,0,1\n").unwrap();
        let s = load_sensors(c.to_str().unwrap()).unwrap();
        assert_eq!(s[0].id, "A");
    }
}
