//! # Point-in-time Perez skies as Radiance scene text (gendaylit)
//!
//! One sky for one instant, written as Radiance's `gendaylit` writes it
//! (`LBNL-ETA/Radiance: src/gen/gendaylit.c: printsky`), followed by the sky and ground
//! glow sources that make it a light source for `rtrace`/`rpict` (the lines of
//! `radiance-fixtures/skies/skyglow.rad`):
//!
//! ```text
//! void light solar  0 0 3 R R R           R = sun radiance (W sr^-1 m^-2), sun colour 1
//! solar source sun  0 0 4 dx dy dz 0.533  direction toward the sun, disc 0.533 deg
//! void brightfunc skyfunc 2 skybright perezlum.cal 0 10 A1..A10
//! skyfunc glow skyglow 0 0 4 r g b 0          sky colour (-c, default 1 1 1)
//! skyglow source sky 0 0 4 0 0 1 180
//! skyfunc glow groundglow 0 0 4 r g b 0       ground colour (see below)
//! groundglow source ground 0 0 4 0 0 -1 180
//! ```
//!
//! A1..A10 and R come from [`GendaylitSky`] (gendaylit's own Perez implementation,
//! including its 87 deg altitude cap, its default dew point and its "error sky" for a sun
//! below the horizon, which is written without sun lines and with A1..A7 = 0). Numbers are
//! written with full `f64` precision (gendaylit prints 4 significant digits).
//!
//! gendaylit takes one grey ground reflectance, which scales A2 (the ground brightness that
//! `perezlum.cal` also blends into the sky just below the horizon). A coloured reflectance
//! `r g b` is split into its mean `m` (used for A2, so the blend is gendaylit's for a grey
//! ground of the same mean) and the colour `r/m g/m b/m` of the ground glow.

use super::gendaylit::{GendaylitInput, GendaylitSky};
use super::solar::SunPosition;
use crate::formats::weather::{WeaUnits, Weather};
use std::fmt::Write;

/// Colours of a point-in-time sky description.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSkyColours {
    /// Sky glow colour (`-c`; 1 1 1 like `skyglow.rad`).
    pub sky: [f64; 3],
    /// Ground glow colour relative to the grey reflectance already in A2.
    pub ground: [f64; 3],
}

/// Split a ground reflectance into gendaylit's grey value (the mean) and the glow colour.
pub fn split_ground_reflectance(rgb: [f64; 3]) -> (f64, [f64; 3]) {
    let m = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
    if m > 0.0 {
        (m, [rgb[0] / m, rgb[1] / m, rgb[2] / m])
    } else {
        (0.0, [0.0; 3])
    }
}

/// gendaylit's input for the weather record at `month day hour` (the record's own decimal
/// hour, e.g. 12.5; EPW hours as [`crate::formats::weather`] maps them), in the file's units
/// (`.wea` units 1, 2, 3 are gendaylit's `-W`, `-G`, `-L`). `None` if there is no such record.
pub fn record_input(w: &Weather, month: u32, day: u32, hour: f64) -> Option<GendaylitInput> {
    let s = w.steps.iter().find(|s| {
        u32::from(s.month) == month && u32::from(s.day) == day && (s.hour - hour).abs() < 1e-6
    })?;
    let (direct, diffuse) = (s.direct, s.diffuse);
    Some(match w.units {
        WeaUnits::NormalIrradiance => GendaylitInput::DirectNormalIrradiance { direct, diffuse },
        WeaUnits::HorizontalIrradiance => {
            GendaylitInput::DirectHorizontalIrradiance { direct, diffuse }
        }
        WeaUnits::NormalIlluminance => GendaylitInput::DirectNormalIlluminance { direct, diffuse },
    })
}

/// The scene text for a sky. `comments` become `# ` lines at the top (command line, sun
/// position, as gendaylit prints them).
pub fn point_sky_text(
    comments: &[String],
    pos: &SunPosition,
    sky: &GendaylitSky,
    colours: &PointSkyColours,
) -> String {
    let mut s = String::new();
    // Writing to a String cannot fail.
    for c in comments {
        let _ = writeln!(s, "# {c}");
    }
    let _ = writeln!(
        s,
        "# Solar altitude and azimuth: {:.4} {:.4}",
        pos.altitude.to_degrees(),
        pos.azimuth.to_degrees()
    );
    if !sky.error {
        let _ = writeln!(
            s,
            "# epsilon, delta, atmospheric precipitable water content : {} {} {}",
            sky.epsilon, sky.delta, sky.precip_water
        );
    }
    let a = &sky.args;
    if let Some(r) = sky.solar {
        let _ = write!(
            s,
            "\nvoid light solar\n0\n0\n3 {r:e} {r:e} {r:e}\n\nsolar source sun\n0\n0\n\
             4 {:e} {:e} {:e} 0.533\n",
            a[7], a[8], a[9]
        );
    }
    let _ = write!(
        s,
        "\nvoid brightfunc skyfunc\n2 skybright perezlum.cal\n0\n10"
    );
    for v in a {
        let _ = write!(s, " {v:e}");
    }
    let [r, g, b] = colours.sky;
    let [gr, gg, gb] = colours.ground;
    let _ = write!(
        s,
        "\n\nskyfunc glow skyglow\n0\n0\n4 {r:e} {g:e} {b:e} 0\n\nskyglow source sky\n0\n0\n\
         4 0 0 1 180\n\nskyfunc glow groundglow\n0\n0\n4 {gr:e} {gg:e} {gb:e} 0\n\n\
         groundglow source ground\n0\n0\n4 0 0 -1 180\n"
    );
    s
}

#[cfg(test)]
mod tests {
    use super::super::gendaylit::GendaylitOptions;
    use super::*;
    use crate::formats::weather::Site;

    #[test]
    fn records_are_found_by_date_and_hour_in_their_units() {
        let wea = "place A_B\nlatitude 51.15\nlongitude 0.18\ntime_zone 0\n\
                   site_elevation 0\nweather_data_file_units 3\n3 2 12.5 80000 9000\n";
        let w = Weather::parse(wea, "t.wea").unwrap();
        assert_eq!(
            record_input(&w, 3, 2, 12.5),
            Some(GendaylitInput::DirectNormalIlluminance {
                direct: 80000.0,
                diffuse: 9000.0
            })
        );
        assert_eq!(record_input(&w, 3, 2, 12.0), None);
        assert_eq!(record_input(&w, 3, 3, 12.5), None);
    }

    #[test]
    fn ground_split_keeps_the_reflectance() {
        let (m, c) = split_ground_reflectance([0.1, 0.2, 0.3]);
        assert!((m - 0.2).abs() < 1e-12);
        for (k, want) in [0.1, 0.2, 0.3].iter().enumerate() {
            assert!((m * c[k] - want).abs() < 1e-12);
        }
        assert_eq!(split_ground_reflectance([0.0; 3]), (0.0, [0.0; 3]));
    }

    #[test]
    fn text_has_sun_sky_and_glows_with_exact_arguments() {
        let site = Site {
            latitude_deg_n: 51.15,
            longitude_deg_e: -0.18,
            meridian_deg_e: 0.0,
            ..Site::default()
        };
        let o = GendaylitOptions::new(GendaylitInput::DirectNormalIrradiance {
            direct: 838.0,
            diffuse: 79.0,
        });
        let (pos, sky) = GendaylitSky::for_date(&site, 3, 2, 12.5, false, None, &o);
        let colours = PointSkyColours {
            sky: [1.0; 3],
            ground: [1.0; 3],
        };
        let t = point_sky_text(&["x".into()], &pos, &sky, &colours);
        assert!(t.starts_with("# x\n"));
        let line = t.lines().find(|l| l.starts_with("10 ")).unwrap();
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        assert_eq!(&v[1..], &sky.args[..]);
        assert!(t.contains("\nsolar source sun\n"));
        assert!(t.contains("skyglow source sky\n0\n0\n4 0 0 1 180"));
        assert!(t.contains("groundglow source ground\n0\n0\n4 0 0 -1 180"));
        // Night: an error sky without sun lines.
        let (_, night) = GendaylitSky::for_date(&site, 3, 2, 2.5, false, None, &o);
        let t = point_sky_text(&[], &pos, &night, &colours);
        assert!(!t.contains("solar"));
        assert!(t.contains("skybright perezlum.cal"));
    }
}
