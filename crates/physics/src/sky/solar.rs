//! # Solar position (Radiance `sun.c`)
//!
//! The simple IES formulas Radiance's `gensky`, `gendaylit` and `gendaymtx` use
//! (`LBNL-ETA/Radiance: src/gen/sun.c`), and the Michalsky (1988) almanac algorithm used by
//! `gensky -y year` ("The Astronomical Almanac's Algorithm for Approximate Solar Position
//! (1950-2050)", Solar Energy 40(3)).
//!
//! ```text
//! jd        = day of year, no leap years (Jan 1 = 1, Mar 1 = 60)
//! decl      = 0.4093 sin(2 pi (jd - 81) / 365)                               (rad)
//! st        = hour + 0.170 sin(4 pi (jd - 80) / 373) - 0.129 sin(2 pi (jd - 8) / 355)
//!                  + 12 (meridian - longitude) / pi                          (hours)
//! altitude  = asin(sin lat sin decl - cos lat cos decl cos(pi st / 12))
//! azimuth   = -atan2(cos decl sin(pi st / 12),
//!                    -cos lat sin decl - sin lat cos decl cos(pi st / 12))   (west of south)
//! direction = (-sin az cos alt, -cos az cos alt, sin alt)     (+X east, +Y north, +Z up)
//! ```
//!
//! The formulas use gensky's sign conventions: `-a lat` degrees **north**, `-o lon` degrees
//! **west** of Greenwich, `-m meridian` degrees **west** (the standard meridian of the time
//! zone, 15 deg per hour: GMT 0, CET -15, EST 75, PST 120). They take the workspace's one
//! east-positive [`Site`] and read the west-positive numbers from [`Site::longitude_west`]
//! and [`Site::meridian_west`]. Hours are local standard time
//! unless given as solar time (gensky `+hour`). gensky prints azimuth west of south;
//! gendaymtx converts it to east of north by adding pi (and subtracting its `-r` rotation).
//!
//! Leap days (gendaymtx `main`): a Feb 29 record gets `jd = 60` and every later record of
//! that run is shifted by +1 day ([`LeapDayTracker`]); gensky and gendaylit ignore leap
//! years except with `-y year` (Michalsky), where the year decides.

use crate::formats::weather::Site;
use std::f64::consts::PI;

/// gensky's compiled-in default site (San Francisco area: `-a 37.815 -o 122.04 -m 120`,
/// from `s_latitude = 0.66`, `s_longitude = 2.13` radians in `sun.c`), converted once from
/// gensky's west-positive numbers into the east-positive [`Site`].
pub fn gensky_default_site() -> Site {
    Site {
        latitude_deg_n: 0.66f64.to_degrees(),
        longitude_deg_e: -(2.13f64.to_degrees()),
        meridian_deg_e: -120.0,
        ..Site::default()
    }
}

/// Day of year without leap years (`sun.c: jdate`); `month` 1-12, `day` 1-31.
pub use rdaylight_base::calendar::julian_day as day_of_year;

/// Solar declination in radians (`sun.c: sdec`, with the 2019 correction 368 -> 365).
pub fn declination(jd: u32) -> f64 {
    0.4093 * ((2.0 * PI / 365.0) * (jd as f64 - 81.0)).sin()
}

/// Hours to add to local standard time to get solar time (`sun.c: stadj`): equation of
/// time plus the longitude correction `12 (meridian - longitude) / pi` (radians west).
pub fn solar_time_adjust(jd: u32, site: &Site) -> f64 {
    let jd = jd as f64;
    0.170 * ((4.0 * PI / 373.0) * (jd - 80.0)).sin()
        - 0.129 * ((2.0 * PI / 355.0) * (jd - 8.0)).sin()
        + (12.0 / PI) * (site.meridian_west().to_radians() - site.longitude_west().to_radians())
}

/// Where the sun is, in Radiance's conventions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Altitude above the horizon (radians).
    pub altitude: f64,
    /// Azimuth measured from south toward west (radians), as gensky prints it.
    pub azimuth: f64,
    /// Local solar time (hours) the position was computed for.
    pub solar_time: f64,
}

impl SunPosition {
    /// Position from declination and solar time (`sun.c: salt, sazi`).
    pub fn from_declination(site: &Site, decl: f64, solar_time: f64) -> SunPosition {
        let lat = site.latitude_deg_n.to_radians();
        let h = solar_time * (PI / 12.0);
        let altitude = (lat.sin() * decl.sin() - lat.cos() * decl.cos() * h.cos()).asin();
        let azimuth = -(decl.cos() * h.sin())
            .atan2(-lat.cos() * decl.sin() - lat.sin() * decl.cos() * h.cos());
        SunPosition {
            altitude,
            azimuth,
            solar_time,
        }
    }

    /// gensky's position for a date and hour (local standard time, or solar time when
    /// `solar_time` is true, gensky's `+hour`). `year` selects Michalsky's algorithm like
    /// `gensky -y` (leap years then count).
    pub fn gensky(
        site: &Site,
        month: u32,
        day: u32,
        hour: f64,
        solar_time: bool,
        year: Option<i32>,
    ) -> SunPosition {
        match year {
            Some(y) => {
                let mjd = michalsky_date(site, y, month, day, hour);
                let (decl, st) = michalsky_declination(site, mjd);
                SunPosition::from_declination(site, decl, if solar_time { hour } else { st })
            }
            None => {
                let jd = day_of_year(month, day);
                let st = if solar_time {
                    hour
                } else {
                    hour + solar_time_adjust(jd, site)
                };
                SunPosition::from_declination(site, declination(jd), st)
            }
        }
    }

    /// gendaymtx's / gendaylit's position for day of year `jd` (already leap-adjusted) and
    /// local standard time `hour`.
    pub fn at(site: &Site, jd: u32, hour: f64) -> SunPosition {
        SunPosition::from_declination(site, declination(jd), hour + solar_time_adjust(jd, site))
    }

    /// Azimuth east of north (gendaymtx's convention), minus a sky rotation in degrees
    /// (gendaymtx `-r`).
    pub fn azimuth_east_of_north(&self, rotation_deg: f64) -> f64 {
        self.azimuth + PI - rotation_deg.to_radians()
    }

    /// Unit vector toward the sun (+X east, +Y north, +Z up), as gensky's `sundir`.
    pub fn direction(&self) -> [f64; 3] {
        let c = self.altitude.cos();
        [
            -self.azimuth.sin() * c,
            -self.azimuth.cos() * c,
            self.altitude.sin(),
        ]
    }
}

/// gendaymtx's leap-day rule: Feb 29 maps to day 60 and, once seen, every later date of the
/// same run is one day later than [`day_of_year`] says.
#[derive(Debug, Clone, Copy, Default)]
pub struct LeapDayTracker {
    seen: bool,
}

impl LeapDayTracker {
    pub fn new() -> Self {
        Self::default()
    }

    /// Day of year for the next record (call in file order).
    pub fn day_of_year(&mut self, month: u32, day: u32) -> u32 {
        if month == 2 && day == 29 {
            self.seen = true;
            60
        } else {
            day_of_year(month, day) + u32::from(self.seen)
        }
    }
}

/// Michalsky's almanac date: days from noon UT, 1 Jan 2000 (`sun.c: mjdate`).
pub fn michalsky_date(site: &Site, year: i32, month: u32, day: u32, hour: f64) -> f64 {
    let mut jd = day_of_year(month, day) as i32;
    if month > 2 && (year & 3) == 0 {
        jd += 1;
    }
    jd += (year - 1949) * 365 + (year - 1949) / 4;
    let hour = hour + site.meridian_west().to_radians() * (12.0 / PI);
    jd as f64 + hour / 24.0 + (2432916.5 - 2451545.0)
}

/// Michalsky declination (radians) and local solar time (hours) (`sun.c: msdec`).
pub fn michalsky_declination(site: &Site, mjd: f64) -> (f64, f64) {
    let deg = PI / 180.0;
    let circ = |r: f64, p: f64| r.rem_euclid(p);
    let l0 = circ(280.460 * deg + 0.9856474 * deg * mjd, 2.0 * PI);
    let g = circ(357.528 * deg + 0.9856003 * deg * mjd, 2.0 * PI);
    let l = l0 + 1.915 * deg * g.sin() + 0.020 * deg * (2.0 * g).sin();
    let ep = 23.439 * deg - 4e-7 * deg * mjd;
    let ra = (l.sin() * ep.cos()).atan2(l.cos());
    let utime = 24.0 * (mjd - mjd.floor()) + 12.0;
    let gmst = 6.697375 + 0.0657098242 * mjd + utime;
    let lmst = gmst - site.longitude_west().to_radians() * (12.0 / PI);
    let st = circ(lmst - ra * (12.0 / PI) + 12.0, 24.0);
    ((ep.sin() * l.sin()).asin(), st)
}

/// gendaymtx's sunrise/sunset (local solar time, hours) for its `-i` interval correction
/// (`gendaymtx.c: solar_sunrise/solar_sunset`; uses the un-shifted day of year and a C
/// `float` intermediate, reproduced here).
pub fn sunrise_sunset(site: &Site, month: u32, day: u32) -> (f64, f64) {
    let w = (-(site.latitude_deg_n.to_radians().tan() * declination(day_of_year(month, day)).tan()))
        as f32 as f64;
    let half = (PI / 2.0 - w.atan2((1.0 - w * w).sqrt())) * 180.0 / (PI * 15.0);
    (12.0 - half, 12.0 + half)
}
