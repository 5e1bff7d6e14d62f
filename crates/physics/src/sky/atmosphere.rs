//! # Clear-sky atmosphere: Bruneton's precomputed atmospheric scattering, 20 spectral bands
//!
//! The physically based clear sky behind Radiance 6's `genssky` (issue 8), written from the
//! published method: E. Bruneton and F. Neyret, "Precomputed Atmospheric Scattering",
//! Computer Graphics Forum 27(4), 2008, in the formulation of E. Bruneton's 2017 reference
//! implementation ("precomputed_atmospheric_scattering", functions.glsl: texture
//! parametrisations, single scattering, scattering density, multiple scattering, ground
//! irradiance), with the spectral and aerosol choices genssky made (T. Wang, Radiance
//! `src/gen/atmos.c`, read to match its behaviour, not copied):
//!
//! - 20 bands of 20 nm, 380–780 nm (band centres 390 … 770 nm), [`NSSAMP`];
//! - spherical Earth of radius 6360 km, atmosphere 60 km thick;
//! - Rayleigh: sea-level coefficients of one of five standard atmospheres (Anderson et al.
//!   1986, AFGL-TR-86-0110: mid-latitude summer/winter, sub-arctic summer/winter, tropical)
//!   with an exponential profile of the scale height genssky tuned per climate;
//! - ozone: absorption only, Bruneton 2017's tent profile (peak at 25 km, 15 km half-width);
//! - aerosols (Mie): a tabulated altitude profile of scattering coefficients per band (the
//!   OPAC continental-average profile genssky ships as `mie_ca.dat`, computed with
//!   libRadtran; read at run time, see [`MieProfile`]) scaled by `AOD / 0.115`; extinction
//!   equals scattering; Cornette–Shanks phase function with g = 0.7;
//! - ground: Lambertian with the given reflectance;
//! - scattering orders 1 to 4.
//!
//! Four tables are precomputed ([`Tables`]): transmittance to the top of the atmosphere
//! T(r, mu), the Rayleigh + multiple scattering S(r, mu, mu_s, nu) (stored without the
//! Rayleigh phase function, Bruneton's "combined" texture), the single Mie scattering
//! (without phase) and the indirect ground irradiance E(r, mu_s). Their sizes and
//! parametrisations are genssky's (transmittance 64 x 256, scattering 16 x 64 x 16 x 4,
//! irradiance 16 x 64), and so are two of its quirks that change the result by a few
//! percent, kept so that both tools give the same sky:
//! - texel k of an n-texel axis is computed at texture coordinate k/n but looked up as if it
//!   were at k/(n-1) (Radiance's `data.c` puts samples on the ends of `[0, 1]`);
//! - lookups use `data.c`'s interpolation: linear inside, linear extrapolation up to one
//!   division outside, then tapering harmonically to zero ([`radiance_coefficients`]).
//!
//! Everything is deterministic quadrature (trapezoids along rays, midpoint rules over the
//! sphere): no Monte Carlo, so the thread count never changes a value. The precomputation
//! runs in parallel with rayon over the radius axis and is cached on disk ([`cache`]);
//! a cache entry is keyed by every input that changes a table (including the ground
//! reflectance, which genssky's own cache name leaves out), carries a checksum and is
//! recomputed when it is truncated, corrupt or stale.

pub mod cache;

use crate::error::{Error, Location, Result};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Number of spectral bands (20 nm each, 380–780 nm).
pub const NSSAMP: usize = 20;
/// Lowest and highest band edge in nm.
pub const WL_MIN: f64 = 380.0;
pub const WL_MAX: f64 = 780.0;
/// Band width in nm.
pub const BAND_WIDTH: f64 = 20.0;
/// Radiance's spectral convention: a channel value is the mean spectral radiance (per nm)
/// times the visible span, 400 nm, so equal-energy white of 1 W/sr/m^2 reads 1 everywhere.
pub const SPAN: f64 = WL_MAX - WL_MIN;

/// Earth radius in m (Bruneton 2017 demo value, as genssky).
pub const EARTH_RADIUS: f64 = 6_360_000.0;
/// Top of the atmosphere in m.
pub const TOP_RADIUS: f64 = 6_420_000.0;
/// Thickness of the atmosphere in m.
pub const THICKNESS: f64 = TOP_RADIUS - EARTH_RADIUS;
/// Angular radius of the sun in radians (Bruneton 2017).
pub const SUN_ANGULAR_RADIUS: f64 = 0.004625;
/// Solid angle of a 0.533-degree disc, sr (Radiance's `gensky`/`genssky` `SOLOMG`).
pub const SUN_SOLID_ANGLE: f64 = 6.7967e-5;
/// Cosine of the largest sun zenith angle the scattering tables cover (Bruneton 2017).
pub const MU_S_MIN: f64 = -0.2;
/// Broadband aerosol optical depth of the OPAC continental-average profile; `-d AOD`
/// scales the profile by `AOD / AOD_CONTINENTAL`.
pub const AOD_CONTINENTAL: f64 = 0.115;
/// Asymmetry of the Mie phase function (Bruneton 2017 demo value).
pub const MIE_G: f64 = 0.7;

/// Extraterrestrial solar spectral irradiance, W m^-2 nm^-1, 20-nm band means 380–780 nm,
/// as genssky tabulates them (`atmos.c: EXTSOL`).
pub const EXTRATERRESTRIAL: [f64; NSSAMP] = [
    1.11099345, 1.75363199, 1.67126921, 1.97235667, 2.01863015, 1.93612482, 1.87310758, 1.88792588,
    1.86274213, 1.84433248, 1.80370942, 1.73020456, 1.67036654, 1.57482149, 1.53646383, 1.45515319,
    1.38207435, 1.3265141, 1.26648111, 1.20592043,
];

/// Ozone absorption coefficients at the profile's peak density, m^-1, per band (genssky
/// `atmos.c: AO0`, from the ozone cross-sections used by Bruneton 2017 at 300 Dobson units).
pub const OZONE: [f64; NSSAMP] = [
    3.5661864e-09,
    1.4848362e-08,
    4.5415674e-08,
    1.2446184e-07,
    2.6461576e-07,
    4.8451984e-07,
    8.609148e-07,
    1.480537e-06,
    1.8809e-06,
    2.5107328e-06,
    2.5263174e-06,
    2.313507e-06,
    1.727741e-06,
    1.2027012e-06,
    7.915902e-07,
    5.0639202e-07,
    3.5285684e-07,
    2.23021e-07,
    1.7395638e-07,
    1.5052574e-07,
];

/// One of Anderson et al. (1986)'s standard atmospheres: Rayleigh coefficients at sea
/// level and the exponential scale height (m) genssky fitted to libRadtran for each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Climate {
    MidLatitudeSummer,
    MidLatitudeWinter,
    SubarcticSummer,
    SubarcticWinter,
    Tropical,
}

/// Rayleigh scattering coefficients at sea level, m^-1, per 20-nm band, for the standard
/// atmospheres of Anderson et al. 1986 (AFGL-TR-86-0110), as tabulated in genssky.
const BR0_MS: [f64; NSSAMP] = [
    4.63889967e-05,
    3.76703293e-05,
    3.09193474e-05,
    2.56223081e-05,
    2.14198405e-05,
    1.80483398e-05,
    1.53177709e-05,
    1.30867298e-05,
    1.12487269e-05,
    9.72370830e-06,
    8.44932642e-06,
    7.37769845e-06,
    6.47116653e-06,
    5.70005327e-06,
    5.04091603e-06,
    4.47430240e-06,
    3.98549839e-06,
    3.56178512e-06,
    3.19293761e-06,
    2.87072599e-06,
];
const BR0_MW: [f64; NSSAMP] = [
    5.03857564e-05,
    4.09159104e-05,
    3.35832809e-05,
    2.78298619e-05,
    2.32653203e-05,
    1.96033395e-05,
    1.66375116e-05,
    1.42142496e-05,
    1.22178890e-05,
    1.05614786e-05,
    9.17729921e-06,
    8.01334246e-06,
    7.02870602e-06,
    6.19115557e-06,
    5.47522872e-06,
    4.85979708e-06,
    4.32887894e-06,
    3.86865960e-06,
    3.46803311e-06,
    3.11806054e-06,
];
const BR0_SS: [f64; NSSAMP] = [
    4.73789047e-05,
    3.84741872e-05,
    3.15791442e-05,
    2.61690698e-05,
    2.18769246e-05,
    1.84334785e-05,
    1.56446412e-05,
    1.33659912e-05,
    1.14887667e-05,
    9.93120528e-06,
    8.62962901e-06,
    7.53513326e-06,
    6.60925660e-06,
    5.82168833e-06,
    5.14848557e-06,
    4.56978082e-06,
    4.07054608e-06,
    3.63779107e-06,
    3.26107261e-06,
    2.93198523e-06,
];
const BR0_SW: [f64; NSSAMP] = [
    5.30623659e-05,
    4.30894595e-05,
    3.53673035e-05,
    2.93082494e-05,
    2.45012287e-05,
    2.06447149e-05,
    1.75213353e-05,
    1.49693438e-05,
    1.28669320e-05,
    1.11225291e-05,
    9.66481886e-06,
    8.43902999e-06,
    7.40208736e-06,
    6.52004427e-06,
    5.76608570e-06,
    5.11796089e-06,
    4.55883914e-06,
    4.07417187e-06,
    3.65226316e-06,
    3.28369923e-06,
];
const BR0_T: [f64; NSSAMP] = [
    4.55376661e-05,
    3.69790036e-05,
    3.03519157e-05,
    2.51520876e-05,
    2.10267438e-05,
    1.77171168e-05,
    1.50366593e-05,
    1.28465622e-05,
    1.10422904e-05,
    9.54525887e-06,
    8.29426444e-06,
    7.24230298e-06,
    6.35240772e-06,
    5.59544593e-06,
    4.94840517e-06,
    4.39219003e-06,
    3.91235655e-06,
    3.49641927e-06,
    3.13434084e-06,
    2.81804244e-06,
];

impl Climate {
    /// genssky's choice from latitude and month: sub-arctic beyond 67 degrees, tropical
    /// within 23 degrees, summer April–September (October–March in the south).
    pub fn for_site(latitude_deg: f64, month: u32) -> Climate {
        let mut summer = (4..=9).contains(&month);
        if latitude_deg < 0.0 {
            summer = !summer;
        }
        let a = latitude_deg.abs();
        if a > 67.0 {
            if summer {
                Climate::SubarcticSummer
            } else {
                Climate::SubarcticWinter
            }
        } else if a > 23.0 {
            if summer {
                Climate::MidLatitudeSummer
            } else {
                Climate::MidLatitudeWinter
            }
        } else {
            Climate::Tropical
        }
    }

    /// genssky's two-letter tag (`ms`, `mw`, `ss`, `sw`, `tr`).
    pub fn tag(self) -> &'static str {
        match self {
            Climate::MidLatitudeSummer => "ms",
            Climate::MidLatitudeWinter => "mw",
            Climate::SubarcticSummer => "ss",
            Climate::SubarcticWinter => "sw",
            Climate::Tropical => "tr",
        }
    }

    /// Rayleigh scale height in m (genssky's fits to libRadtran).
    pub fn scale_height(self) -> f64 {
        match self {
            Climate::MidLatitudeSummer => 8820.0,
            Climate::MidLatitudeWinter => 8100.0,
            Climate::SubarcticSummer => 8550.0,
            Climate::SubarcticWinter => 7600.0,
            Climate::Tropical => 9050.0,
        }
    }

    /// Sea-level Rayleigh coefficients, m^-1.
    pub fn rayleigh(self) -> &'static [f64; NSSAMP] {
        match self {
            Climate::MidLatitudeSummer => &BR0_MS,
            Climate::MidLatitudeWinter => &BR0_MW,
            Climate::SubarcticSummer => &BR0_SS,
            Climate::SubarcticWinter => &BR0_SW,
            Climate::Tropical => &BR0_T,
        }
    }
}

/// Relative Rayleigh density, exp(-h/H) clamped to [0, 1].
fn rayleigh_density(climate: Climate, altitude: f64) -> f64 {
    (-altitude / climate.scale_height()).exp().clamp(0.0, 1.0)
}

/// Relative ozone density: Bruneton 2017's tent, rising from 10 km to 1 at 25 km and back
/// to 0 at 40 km.
fn ozone_density(altitude: f64) -> f64 {
    let d = if altitude < 25_000.0 {
        altitude / 15_000.0 - 2.0 / 3.0
    } else {
        -altitude / 15_000.0 + 8.0 / 3.0
    };
    d.clamp(0.0, 1.0)
}

// ------------------------------------------------------------------------------------
// Radiance data-array interpolation
// ------------------------------------------------------------------------------------

/// Lower index and the two weights Radiance's `data.c: data_interp` uses at fractional
/// index `x` on an axis of `n` samples: linear between neighbours, linear extrapolation up
/// to one division beyond the ends, then tapering to zero as 1/distance.
pub fn radiance_coefficients(x: f64, n: usize) -> (usize, f64, f64) {
    let top = n.saturating_sub(2) as i64;
    // C's (int) conversion truncates toward zero.
    let i = (x.trunc() as i64).clamp(0, top);
    let (c0, c1) = crate::scene::specdata::data_interp_weights(i as f64, x);
    (i as usize, c0, c1)
}

/// A regular table over `[0, 1]^D` with a vector of [`NSSAMP`] values per node, looked
/// up like a Radiance data array whose axes run from 0 to 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Nodes per axis, slowest first.
    pub dims: Vec<usize>,
    /// `product(dims) * NSSAMP` values, last axis fastest, then the band.
    pub data: Vec<f64>,
}

impl Table {
    fn zeros(dims: &[usize]) -> Table {
        let n: usize = dims.iter().product::<usize>() * NSSAMP;
        Table {
            dims: dims.to_vec(),
            data: vec![0.0; n],
        }
    }

    /// Interpolated vector at texture coordinates `pt` (one per axis, nominally [0, 1]).
    pub fn lookup(&self, pt: &[f64]) -> [f64; NSSAMP] {
        let nd = self.dims.len();
        let mut idx = [0usize; 4];
        let mut w = [[0.0f64; 2]; 4];
        for a in 0..nd {
            let n = self.dims[a];
            let (i, c0, c1) = radiance_coefficients(pt[a] * (n - 1) as f64, n);
            idx[a] = i;
            w[a] = [c0, c1];
        }
        let mut out = [0.0; NSSAMP];
        for corner in 0..(1usize << nd) {
            let mut weight = 1.0;
            let mut off = 0usize;
            for a in 0..nd {
                let bit = (corner >> (nd - 1 - a)) & 1;
                weight *= w[a][bit];
                off = off * self.dims[a] + idx[a] + bit;
            }
            if weight == 0.0 {
                continue;
            }
            let v = &self.data[off * NSSAMP..(off + 1) * NSSAMP];
            for (o, x) in out.iter_mut().zip(v) {
                *o += weight * x;
            }
        }
        out
    }
}

impl Table {
    /// A 4-axis table interpolated on its first three axes at `pt`, leaving the values on
    /// the last axis's nodes. Radiance's interpolation is a tensor product, so finishing
    /// with [`interpolate_nodes`] gives the same value as [`Table::lookup`].
    fn reduce3(&self, pt: [f64; 3]) -> Vec<[f64; NSSAMP]> {
        let d = &self.dims;
        let last = d[3];
        let mut out = vec![[0.0; NSSAMP]; last];
        let c: [(usize, f64, f64); 3] =
            std::array::from_fn(|a| radiance_coefficients(pt[a] * (d[a] - 1) as f64, d[a]));
        for corner in 0..8usize {
            let bits = [(corner >> 2) & 1, (corner >> 1) & 1, corner & 1];
            let mut w = 1.0;
            let mut off = 0;
            for a in 0..3 {
                w *= if bits[a] == 0 { c[a].1 } else { c[a].2 };
                off = off * d[a] + c[a].0 + bits[a];
            }
            if w == 0.0 {
                continue;
            }
            for (n, o) in out.iter_mut().enumerate() {
                let at = (off * last + n) * NSSAMP;
                for (x, v) in o.iter_mut().zip(&self.data[at..at + NSSAMP]) {
                    *x += w * v;
                }
            }
        }
        out
    }
}

/// Interpolate values on an axis's nodes at texture coordinate `u` (Radiance's rule).
fn interpolate_nodes(nodes: &[[f64; NSSAMP]], u: f64) -> [f64; NSSAMP] {
    let n = nodes.len();
    let (i, c0, c1) = radiance_coefficients(u * (n - 1) as f64, n);
    let mut out = [0.0; NSSAMP];
    for b in 0..NSSAMP {
        out[b] = c0 * nodes[i][b] + c1 * nodes[i + 1][b];
    }
    out
}

// ------------------------------------------------------------------------------------
// Aerosol profile
// ------------------------------------------------------------------------------------

/// Aerosol (Mie) scattering coefficients per band against altitude.
#[derive(Debug, Clone, PartialEq)]
pub struct MieProfile {
    /// Altitudes in m, strictly increasing.
    pub altitudes: Vec<f64>,
    /// Scattering coefficient per altitude and band, m^-1.
    pub coefficients: Vec<[f64; NSSAMP]>,
    /// Short name used in cache keys (genssky's: the file's base name, `mie_ca`).
    pub name: String,
    /// Where the profile came from, for output headers.
    pub source: String,
}

/// Scale height of the fallback aerosol profile, m: the effective height (optical depth over
/// sea-level coefficient, 1.88 km at 550 nm) of the OPAC continental-average profile (Hess,
/// Koepke and Schult 1998) that genssky ships as `mie_ca.dat`.
pub const FALLBACK_MIE_SCALE_HEIGHT: f64 = 1900.0;
/// Angstrom exponent of the fallback profile (that profile's 410-770 nm slope, 1.30; also
/// Angstrom 1929's classic continental value 1.3).
pub const FALLBACK_ANGSTROM: f64 = 1.3;
/// Aerosol optical depth at 550 nm of the fallback profile at `-d 0.115` (that of the same
/// OPAC profile, 0.0955).
pub const FALLBACK_TAU550: f64 = 0.0955;

impl MieProfile {
    /// Parse a Radiance data file (`getdata` format) with two axes: altitude in m (regular
    /// `begin end n` or irregular `0 0 n p0 .. pn-1`) and 20 bands. `#` starts a comment.
    pub fn parse(text: &str, name: &str) -> Result<MieProfile> {
        let mut toks = Tokens::new(text, name);
        let nd = toks.int("the number of dimensions")?;
        if nd != 2 {
            return Err(toks.err_here(format!(
                "{nd} dimensions; expected 2 (altitude, then {NSSAMP} bands)"
            )));
        }
        let a0 = toks.number("the altitude axis start")?;
        let a1 = toks.number("the altitude axis end")?;
        let na = toks.int("the number of altitudes")?;
        if !(2..=100_000).contains(&na) {
            return Err(toks.err_here(format!("{na} altitudes; expected 2 to 100000")));
        }
        let altitudes: Vec<f64> = if a1 - a0 == 0.0 {
            let mut p = Vec::with_capacity(na);
            for _ in 0..na {
                p.push(toks.number("an altitude")?);
            }
            if p.windows(2).any(|w| w[1] <= w[0]) {
                return Err(toks.err_here("altitudes not strictly increasing; expected m"));
            }
            p
        } else if a1 > a0 {
            (0..na)
                .map(|k| a0 + (a1 - a0) * k as f64 / (na - 1) as f64)
                .collect()
        } else {
            return Err(toks.err_here("altitude axis decreasing; expected begin < end"));
        };
        let _b0 = toks.number("the band axis start")?;
        let _b1 = toks.number("the band axis end")?;
        let nb = toks.int("the number of bands")?;
        if nb != NSSAMP {
            return Err(toks.err_here(format!(
                "{nb} bands; expected {NSSAMP} (380-780 nm in 20 nm steps)"
            )));
        }
        let mut coefficients = Vec::with_capacity(na);
        for _ in 0..na {
            let mut v = [0.0; NSSAMP];
            for x in v.iter_mut() {
                *x = toks.number("a scattering coefficient (m^-1)")?;
                if *x < 0.0 {
                    return Err(toks.err_here("negative scattering coefficient"));
                }
            }
            coefficients.push(v);
        }
        let base = std::path::Path::new(name)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "mie".into());
        Ok(MieProfile {
            altitudes,
            coefficients,
            name: base,
            source: name.to_string(),
        })
    }

    /// Read a profile file.
    pub fn read(path: &std::path::Path) -> Result<MieProfile> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(&shown, e))?;
        MieProfile::parse(&text, &shown)
    }

    /// `mie_ca.dat` from the `RAYPATH` folders (as genssky's `getpath`), if present.
    pub fn find_default() -> Option<std::path::PathBuf> {
        let rp = std::env::var("RAYPATH").ok()?;
        std::env::split_paths(&rp)
            .map(|d| d.join("mie_ca.dat"))
            .find(|p| p.is_file())
    }

    /// The fallback when no profile file is found: exponential density with scale height
    /// [`FALLBACK_MIE_SCALE_HEIGHT`], spectral dependence (lambda/550 nm)^-1.3 and optical
    /// depth [`FALLBACK_TAU550`] at 550 nm, i.e. an exponential fit of the OPAC
    /// continental-average profile. Measured against genssky with `mie_ca.dat`
    /// (tests/all/spectral_genssky.rs, `fallback_profile_against_genssky`): see the module
    /// doc of [`crate::sky::genssky`].
    pub fn fallback() -> MieProfile {
        let h = FALLBACK_MIE_SCALE_HEIGHT;
        // 100 m steps where the profile changes, 1 km above 12 km.
        let altitudes: Vec<f64> = (0..120)
            .map(|k| k as f64 * 100.0)
            .chain((12..=60).map(|k| k as f64 * 1000.0))
            .collect();
        // Optical depth of exp(-z/h) up to 60 km is h (the tail is negligible).
        let beta550 = FALLBACK_TAU550 / h;
        let coefficients = altitudes
            .iter()
            .map(|z| {
                let mut v = [0.0; NSSAMP];
                for (b, x) in v.iter_mut().enumerate() {
                    let wl = WL_MIN + BAND_WIDTH * (b as f64 + 0.5);
                    *x = beta550 * (wl / 550.0).powf(-FALLBACK_ANGSTROM) * (-z / h).exp();
                }
                v
            })
            .collect();
        MieProfile {
            altitudes,
            coefficients,
            name: "mie_exp1900".into(),
            source: format!(
                "exponential aerosol profile (scale height {h} m, Angstrom exponent \
                 {FALLBACK_ANGSTROM}, tau550 {FALLBACK_TAU550} at -d 0.115; no mie_ca.dat \
                 found)"
            ),
        }
    }

    /// Coefficients at an altitude, interpolated as Radiance's `data.c` does on an
    /// irregular axis.
    pub fn at(&self, altitude: f64) -> [f64; NSSAMP] {
        let p = &self.altitudes;
        let n = p.len();
        let i = p
            .partition_point(|&a| a <= altitude)
            .saturating_sub(1)
            .min(n - 2);
        let x = i as f64 + (altitude - p[i]) / (p[i + 1] - p[i]);
        let (i, c0, c1) = radiance_coefficients_at(x, i);
        let mut out = [0.0; NSSAMP];
        for (b, o) in out.iter_mut().enumerate() {
            *o = c0 * self.coefficients[i][b] + c1 * self.coefficients[i + 1][b];
        }
        out
    }

    /// A fingerprint of the values, for cache keys.
    pub fn fingerprint(&self) -> u64 {
        let mut h = cache::Fnv::new();
        for a in &self.altitudes {
            h.write(&a.to_le_bytes());
        }
        for v in &self.coefficients {
            for x in v {
                h.write(&x.to_le_bytes());
            }
        }
        h.finish()
    }
}

/// [`radiance_coefficients`] with the lower index already chosen (irregular axes).
fn radiance_coefficients_at(x: f64, i: usize) -> (usize, f64, f64) {
    let fi = i as f64;
    let (c0, c1) = if x > fi + 2.0 {
        let c0 = 1.0 / (fi - 1.0 - x);
        (c0, -2.0 * c0)
    } else if x < fi - 1.0 {
        let c1 = 1.0 / (x - fi);
        (-2.0 * c1, c1)
    } else {
        (fi + 1.0 - x, x - fi)
    };
    (i, c0, c1)
}

/// Whitespace-separated numbers with `#` comments, remembering line numbers.
struct Tokens<'a> {
    words: Vec<(&'a str, usize)>,
    at: usize,
    name: &'a str,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str, name: &'a str) -> Self {
        let mut words = Vec::new();
        let mut last_line = 1;
        for (n, line) in text.lines().enumerate() {
            let body = line.split('#').next().unwrap_or("");
            for w in body.split_whitespace() {
                words.push((w, n + 1));
            }
            last_line = n + 1;
        }
        Tokens {
            words,
            at: 0,
            name,
            last_line,
        }
    }

    fn err_here(&self, msg: impl Into<String>) -> Error {
        let line = self
            .words
            .get(self.at.saturating_sub(1))
            .map(|w| w.1)
            .unwrap_or(self.last_line);
        Error::parse(Location::line(self.name, line), msg)
    }

    fn number(&mut self, what: &str) -> Result<f64> {
        let Some(&(w, line)) = self.words.get(self.at) else {
            return Err(Error::parse(
                Location::line(self.name, self.last_line),
                format!("end of file; expected {what}"),
            ));
        };
        self.at += 1;
        let parsed: nom::IResult<&str, f64> =
            nom::combinator::all_consuming(nom::number::complete::double).parse_complete(w);
        match parsed {
            Ok((_, v)) if v.is_finite() => Ok(v),
            _ => Err(Error::parse(
                Location::line(self.name, line),
                format!("\"{w}\"; expected {what}"),
            )),
        }
    }

    fn int(&mut self, what: &str) -> Result<usize> {
        let v = self.number(what)?;
        if v < 0.0 || v.fract() != 0.0 || v > 1e9 {
            return Err(self.err_here(format!("{v}; expected {what} (a whole number)")));
        }
        Ok(v as usize)
    }
}

use nom::Parser;

// ------------------------------------------------------------------------------------
// Atmosphere and geometry
// ------------------------------------------------------------------------------------

/// Everything that changes the precomputed tables.
#[derive(Debug, Clone, PartialEq)]
pub struct Atmosphere {
    pub climate: Climate,
    /// Broadband aerosol optical depth (genssky `-d`, default 0.115).
    pub aod: f64,
    /// Lambertian ground reflectance (genssky `-g`, default 0.2).
    pub ground_reflectance: f64,
    pub mie: MieProfile,
    /// Highest scattering order (genssky's default 4, at least 2).
    pub scattering_order: usize,
}

impl Atmosphere {
    fn mie_scale(&self) -> f64 {
        self.aod / AOD_CONTINENTAL
    }

    /// Scattering coefficients (Rayleigh, Mie) at an altitude.
    fn scattering_at(&self, altitude: f64) -> ([f64; NSSAMP], [f64; NSSAMP]) {
        let rho = rayleigh_density(self.climate, altitude);
        let br = self.climate.rayleigh();
        let mie = self.mie.at(altitude);
        let s = self.mie_scale();
        let mut r = [0.0; NSSAMP];
        let mut m = [0.0; NSSAMP];
        for b in 0..NSSAMP {
            r[b] = br[b] * rho;
            m[b] = mie[b] * s;
        }
        (r, m)
    }
}

fn safe_sqrt(a: f64) -> f64 {
    a.max(0.0).sqrt()
}

fn clamp_cosine(mu: f64) -> f64 {
    mu.clamp(-1.0, 1.0)
}

fn clamp_radius(r: f64) -> f64 {
    r.clamp(EARTH_RADIUS, TOP_RADIUS)
}

/// Distance from radius `r` along direction cosine `mu` to the top of the atmosphere.
pub fn distance_to_top(r: f64, mu: f64) -> f64 {
    let disc = r * r * (mu * mu - 1.0) + TOP_RADIUS * TOP_RADIUS;
    (-r * mu + safe_sqrt(disc)).max(0.0)
}

/// Distance from radius `r` along direction cosine `mu` to the ground.
pub fn distance_to_ground(r: f64, mu: f64) -> f64 {
    let disc = r * r * (mu * mu - 1.0) + EARTH_RADIUS * EARTH_RADIUS;
    (-r * mu - safe_sqrt(disc)).max(0.0)
}

/// Whether the ray (r, mu) meets the ground.
pub fn hits_ground(r: f64, mu: f64) -> bool {
    mu < 0.0 && r * r * (mu * mu - 1.0) + EARTH_RADIUS * EARTH_RADIUS >= 0.0
}

fn horizon_h() -> f64 {
    (TOP_RADIUS * TOP_RADIUS - EARTH_RADIUS * EARTH_RADIUS).sqrt()
}

fn texture_coord_from_unit(x: f64, n: usize) -> f64 {
    0.5 / n as f64 + x * (1.0 - 1.0 / n as f64)
}

fn unit_from_texture_coord(u: f64, n: usize) -> f64 {
    (u - 0.5 / n as f64) / (1.0 - 1.0 / n as f64)
}

// Table sizes (genssky's, half of Bruneton 2017's scattering resolution).
const T_W: usize = 256;
const T_H: usize = 64;
const S_R: usize = 16;
const S_MU: usize = 64;
const S_MU_S: usize = 16;
const S_NU: usize = 4;
const I_W: usize = 64;
const I_H: usize = 16;

/// Transmittance-table coordinates (u for mu, v for r), Bruneton 2017 sec. 4.1.
fn transmittance_uv(r: f64, mu: f64) -> (f64, f64) {
    let h = horizon_h();
    let rho = safe_sqrt(r * r - EARTH_RADIUS * EARTH_RADIUS);
    let d = distance_to_top(r, mu);
    let d_min = TOP_RADIUS - r;
    let d_max = rho + h;
    (
        ((d - d_min) / (d_max - d_min)).clamp(0.0, 1.0),
        (rho / h).clamp(0.0, 1.0),
    )
}

fn transmittance_params(u: f64, v: f64) -> (f64, f64) {
    let h = horizon_h();
    let rho = h * v;
    let r = (rho * rho + EARTH_RADIUS * EARTH_RADIUS).sqrt();
    let d_min = TOP_RADIUS - r;
    let d_max = rho + h;
    let d = d_min + u * (d_max - d_min);
    let mu = if d == 0.0 {
        1.0
    } else {
        (h * h - rho * rho - d * d) / (2.0 * r * d)
    };
    (r, clamp_cosine(mu))
}

/// Scattering-table coordinates (nu, mu_s, mu, r), Bruneton 2017 sec. 4.2.
fn scattering_uvwz(r: f64, mu: f64, mu_s: f64, nu: f64, ground: bool) -> [f64; 4] {
    let h = horizon_h();
    let rho = safe_sqrt(r * r - EARTH_RADIUS * EARTH_RADIUS);
    let u_r = rho / h;
    let r_mu = r * mu;
    let disc = r_mu * r_mu - r * r + EARTH_RADIUS * EARTH_RADIUS;
    let u_mu = if ground {
        let d = -r_mu - safe_sqrt(disc);
        let d_min = r - EARTH_RADIUS;
        let d_max = rho;
        let x = if d_max == d_min {
            0.0
        } else {
            (d - d_min) / (d_max - d_min)
        };
        0.5 - 0.5 * texture_coord_from_unit(x, S_MU / 2)
    } else {
        let d = -r_mu + (disc + h * h).sqrt();
        let d_min = TOP_RADIUS - r;
        let d_max = rho + h;
        0.5 + 0.5 * texture_coord_from_unit((d - d_min) / (d_max - d_min), S_MU / 2)
    };
    let d = distance_to_top(EARTH_RADIUS, mu_s);
    let (d_min, d_max) = (THICKNESS, h);
    let a = (d - d_min) / (d_max - d_min);
    let big_a = (distance_to_top(EARTH_RADIUS, MU_S_MIN) - d_min) / (d_max - d_min);
    let u_mu_s = texture_coord_from_unit((1.0 - a / big_a).max(0.0) / (1.0 + a), S_MU_S);
    let u_nu = (nu + 1.0) / 2.0;
    // Table axes: r, mu, mu_s, nu.
    [u_r, u_mu, u_mu_s, u_nu]
}

fn scattering_params(x_nu: f64, x_mu_s: f64, x_mu: f64, x_r: f64) -> (f64, f64, f64, f64, bool) {
    let h = horizon_h();
    let rho = h * x_r;
    let r = (rho * rho + EARTH_RADIUS * EARTH_RADIUS).sqrt();
    let (mu, ground) = if x_mu < 0.5 {
        let d_min = r - EARTH_RADIUS;
        let d_max = rho;
        let d = d_min + (d_max - d_min) * unit_from_texture_coord(1.0 - 2.0 * x_mu, S_MU / 2);
        let mu = if d == 0.0 {
            -1.0
        } else {
            clamp_cosine(-(rho * rho + d * d) / (2.0 * r * d))
        };
        (mu, true)
    } else {
        let d_min = TOP_RADIUS - r;
        let d_max = rho + h;
        let d = d_min + (d_max - d_min) * unit_from_texture_coord(2.0 * x_mu - 1.0, S_MU / 2);
        let mu = if d == 0.0 {
            1.0
        } else {
            clamp_cosine((h * h - rho * rho - d * d) / (2.0 * r * d))
        };
        (mu, false)
    };
    let (d_min, d_max) = (THICKNESS, h);
    let big_a = (distance_to_top(EARTH_RADIUS, MU_S_MIN) - d_min) / (d_max - d_min);
    let a = (big_a - x_mu_s * big_a) / (1.0 + x_mu_s * big_a);
    let d = d_min + a.min(big_a) * (d_max - d_min);
    let mu_s = if d == 0.0 {
        1.0
    } else {
        clamp_cosine((h * h - d * d) / (2.0 * EARTH_RADIUS * d))
    };
    let nu = clamp_cosine(x_nu * 2.0 - 1.0);
    // Keep nu consistent with mu and mu_s (Bruneton 2017).
    let s = ((1.0 - mu * mu) * (1.0 - mu_s * mu_s)).sqrt();
    let nu = nu.clamp(mu * mu_s - s, mu * mu_s + s);
    (r, mu, mu_s, nu, ground)
}

/// Rayleigh phase function, 3/(16 pi) (1 + nu^2).
pub fn rayleigh_phase(nu: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + nu * nu)
}

/// Cornette–Shanks Mie phase function (Bruneton 2017's `MiePhaseFunction`).
pub fn mie_phase(g: f64, nu: f64) -> f64 {
    let k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    let x = 1.0 + g * g - 2.0 * g * nu;
    // x^1.5 as x sqrt(x): the same value, much cheaper than powf in the inner loops.
    k * (1.0 + nu * nu) / (x * x.sqrt())
}

/// The four precomputed tables.
#[derive(Debug, Clone, PartialEq)]
pub struct Tables {
    /// Transmittance to the top of the atmosphere, axes (r, mu): 64 x 256.
    pub transmittance: Table,
    /// Rayleigh single + all multiple scattering divided by the Rayleigh phase,
    /// axes (r, mu, mu_s, nu): 16 x 64 x 16 x 4, W m^-2 sr^-1 nm^-1 (times phase).
    pub scattering: Table,
    /// Single Mie scattering without phase, same axes.
    pub single_mie: Table,
    /// Indirect irradiance at altitude, axes (r, mu_s): 16 x 64, W m^-2 nm^-1.
    pub irradiance: Table,
}

impl Tables {
    /// Transmittance from (r, mu) to the top of the atmosphere.
    pub fn transmittance_to_top(&self, r: f64, mu: f64) -> [f64; NSSAMP] {
        let (u, v) = transmittance_uv(r, mu);
        self.transmittance.lookup(&[v, u])
    }

    /// Transmittance along (r, mu) over distance d (Bruneton 2017 `GetTransmittance`).
    pub fn transmittance(&self, r: f64, mu: f64, d: f64, ground: bool) -> [f64; NSSAMP] {
        let r_d = clamp_radius((d * d + 2.0 * r * mu * d + r * r).sqrt());
        let mu_d = clamp_cosine((r * mu + d) / r_d);
        let (a, b) = if ground {
            (
                self.transmittance_to_top(r_d, -mu_d),
                self.transmittance_to_top(r, -mu),
            )
        } else {
            (
                self.transmittance_to_top(r, mu),
                self.transmittance_to_top(r_d, mu_d),
            )
        };
        let mut out = [0.0; NSSAMP];
        for i in 0..NSSAMP {
            out[i] = (a[i] / b[i]).min(1.0);
        }
        out
    }

    /// Transmittance to the sun, faded over the sun's disc at the horizon.
    pub fn transmittance_to_sun(&self, r: f64, mu_s: f64) -> [f64; NSSAMP] {
        let sin_h = EARTH_RADIUS / r;
        let cos_h = -safe_sqrt(1.0 - sin_h * sin_h);
        let mut t = self.transmittance_to_top(r, mu_s);
        let e0 = -sin_h * SUN_ANGULAR_RADIUS;
        let x = ((mu_s - cos_h - e0) / (-2.0 * e0)).clamp(0.0, 1.0);
        let st = x * x * (3.0 - 2.0 * x);
        for v in t.iter_mut() {
            *v *= st;
        }
        t
    }

    /// Sky radiance (per nm) seen from radius r in direction (mu, nu) with the sun at mu_s,
    /// always looked up as a ray that does not meet the ground (as genssky does, also for
    /// the in-scattering in front of the ground).
    pub fn sky_radiance(&self, r: f64, mu: f64, mu_s: f64, nu: f64) -> [f64; NSSAMP] {
        let uvwz = scattering_uvwz(r, mu, mu_s, nu, false);
        let s = self.scattering.lookup(&uvwz);
        let m = self.single_mie.lookup(&uvwz);
        let (pr, pm) = (rayleigh_phase(nu), mie_phase(MIE_G, nu));
        let mut out = [0.0; NSSAMP];
        for i in 0..NSSAMP {
            out[i] = s[i] * pr + m[i] * pm;
        }
        out
    }

    /// Indirect (sky) irradiance on a horizontal surface at radius r, sun at mu_s.
    pub fn indirect_irradiance(&self, r: f64, mu_s: f64) -> [f64; NSSAMP] {
        self.irradiance
            .lookup(&[(r - EARTH_RADIUS) / THICKNESS, mu_s * 0.5 + 0.5])
    }

    /// Radiance (per nm) of the sun's disc: attenuated extraterrestrial radiance plus the
    /// sky radiance in the sun's direction.
    pub fn solar_radiance(&self, r: f64, mu_s: f64) -> [f64; NSSAMP] {
        let t = self.transmittance_to_sun(r, mu_s);
        let s = self.sky_radiance(r, mu_s, mu_s, 1.0);
        let mut out = [0.0; NSSAMP];
        for i in 0..NSSAMP {
            out[i] = s[i] + t[i] * EXTRATERRESTRIAL[i] / SUN_SOLID_ANGLE;
        }
        out
    }

    /// Radiance (per nm) towards a viewer at (0, 0, r) looking down along `dir` (unit,
    /// z up) at the ground: reflected sun and sky light through the air in between plus
    /// the in-scattering. Zero for rays that miss the ground.
    pub fn ground_radiance(
        &self,
        r: f64,
        dir: [f64; 3],
        sun: [f64; 3],
        reflectance: f64,
    ) -> [f64; NSSAMP] {
        let mu = dir[2];
        if !hits_ground(r, mu) {
            return [0.0; NSSAMP];
        }
        let d = distance_to_ground(r, mu);
        let p = [dir[0] * d, dir[1] * d, r + dir[2] * d];
        let pl = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let n = [p[0] / pl, p[1] / pl, p[2] / pl];
        // genssky evaluates the ground irradiance at the Earth's radius with mu_s taken
        // from the ground point's own position.
        let mu_s_ground = (p[0] * sun[0] + p[1] * sun[1] + p[2] * sun[2]) / EARTH_RADIUS;
        let t_sun = self.transmittance_to_sun(EARTH_RADIUS, mu_s_ground);
        let e_sky = self.indirect_irradiance(EARTH_RADIUS, mu_s_ground);
        let cos_sun = (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]).max(0.0);
        let t_view = self.transmittance(r, mu, d, true);
        let nu = dir[0] * sun[0] + dir[1] * sun[1] + dir[2] * sun[2];
        let ins = self.sky_radiance(r, mu, sun[2], nu);
        let mut out = [0.0; NSSAMP];
        for i in 0..NSSAMP {
            let e = e_sky[i] + t_sun[i] * EXTRATERRESTRIAL[i] * cos_sun;
            out[i] = ins[i] + e * t_view[i] * reflectance / PI;
        }
        out
    }
}

// ------------------------------------------------------------------------------------
// Precomputation
// ------------------------------------------------------------------------------------

fn for_each_cell<F>(dims: &[usize], f: F) -> Vec<f64>
where
    F: Fn(&[usize]) -> [f64; NSSAMP] + Sync,
{
    let inner: usize = dims[1..].iter().product();
    let mut out = vec![0.0; dims.iter().product::<usize>() * NSSAMP];
    out.par_chunks_mut(inner * NSSAMP)
        .enumerate()
        .for_each(|(first, chunk)| {
            let mut idx = vec![0usize; dims.len()];
            for (k, cell) in chunk.chunks_exact_mut(NSSAMP).enumerate() {
                idx[0] = first;
                let mut rest = k;
                for a in (1..dims.len()).rev() {
                    idx[a] = rest % dims[a];
                    rest /= dims[a];
                }
                cell.copy_from_slice(&f(&idx));
            }
        });
    out
}

/// Optical depth of Rayleigh, Mie and ozone from (r, mu) to the top, 500 trapezoids.
fn transmittance_to_top_exact(atm: &Atmosphere, r: f64, mu: f64) -> [f64; NSSAMP] {
    const N: usize = 500;
    let dx = distance_to_top(r, mu) / N as f64;
    let (mut tr, mut to) = (0.0, 0.0);
    let mut tm = [0.0; NSSAMP];
    for i in 0..=N {
        let d = i as f64 * dx;
        let ri = (d * d + 2.0 * r * mu * d + r * r).sqrt();
        let h = ri - EARTH_RADIUS;
        let w = if i == 0 || i == N { 0.5 } else { 1.0 };
        tr += rayleigh_density(atm.climate, h) * w * dx;
        to += ozone_density(h) * w * dx;
        let m = atm.mie.at(h);
        for b in 0..NSSAMP {
            tm[b] += m[b] * w * dx;
        }
    }
    let br = atm.climate.rayleigh();
    let s = atm.mie_scale();
    let mut out = [0.0; NSSAMP];
    for b in 0..NSSAMP {
        out[b] = (-(tr * br[b] + tm[b] * s + to * OZONE[b])).exp();
    }
    out
}

/// Single scattering along (r, mu) (Bruneton 2017 `ComputeSingleScattering`, 50
/// trapezoids), Rayleigh and Mie without phase functions.
fn single_scattering(
    atm: &Atmosphere,
    t: &Tables,
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
    ground: bool,
) -> ([f64; NSSAMP], [f64; NSSAMP]) {
    const N: usize = 50;
    let dist = if ground {
        distance_to_ground(r, mu)
    } else {
        distance_to_top(r, mu)
    };
    let dx = dist / N as f64;
    let mut ray = [0.0; NSSAMP];
    let mut mie = [0.0; NSSAMP];
    for i in 0..=N {
        let d = i as f64 * dx;
        let r_d = clamp_radius((d * d + 2.0 * r * mu * d + r * r).sqrt());
        let mu_s_d = clamp_cosine((r * mu_s + d * nu) / r_d);
        let tv = t.transmittance(r, mu, d, ground);
        let ts = t.transmittance_to_sun(r_d, mu_s_d);
        let rho = rayleigh_density(atm.climate, r_d - EARTH_RADIUS);
        let m = atm.mie.at(r_d - EARTH_RADIUS);
        let w = if i == 0 || i == N { 0.5 } else { 1.0 };
        for b in 0..NSSAMP {
            let tt = tv[b] * ts[b];
            ray[b] += tt * rho * w;
            mie[b] += tt * m[b] * w;
        }
    }
    let br = atm.climate.rayleigh();
    let s = atm.mie_scale();
    for b in 0..NSSAMP {
        ray[b] *= dx * EXTRATERRESTRIAL[b] * br[b];
        mie[b] *= dx * EXTRATERRESTRIAL[b] * s;
    }
    (ray, mie)
}

/// Radiance of order `order` arriving at (r, mu): single scattering with phase functions
/// for order 1, the previous multiple-scattering delta otherwise.
struct OrderLookup<'a> {
    order: usize,
    ray1: &'a Table,
    mie1: &'a Table,
    multi: &'a Table,
}

impl OrderLookup<'_> {
    fn get(&self, r: f64, mu: f64, mu_s: f64, nu: f64, ground: bool) -> [f64; NSSAMP] {
        let uvwz = scattering_uvwz(r, mu, mu_s, nu, ground);
        if self.order == 1 {
            let a = self.ray1.lookup(&uvwz);
            let b = self.mie1.lookup(&uvwz);
            let (pr, pm) = (rayleigh_phase(nu), mie_phase(MIE_G, nu));
            let mut out = [0.0; NSSAMP];
            for i in 0..NSSAMP {
                out[i] = a[i] * pr + b[i] * pm;
            }
            out
        } else {
            self.multi.lookup(&uvwz)
        }
    }
}

/// Scattering density of order `order` at (r, mu, mu_s, nu): Bruneton 2017
/// `ComputeScatteringDensity`, a 16 x 32 midpoint rule over the sphere of incident
/// directions, including light reflected once more by the ground.
#[allow(clippy::too_many_arguments)]
fn scattering_density(
    atm: &Atmosphere,
    t: &Tables,
    prev: &OrderLookup,
    ground_irradiance: &Table,
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
) -> [f64; NSSAMP] {
    const N: usize = 16;
    let height = r - EARTH_RADIUS;
    let om0 = 1.0 - mu * mu;
    let om0 = if om0.abs() <= 1e-6 { 0.0 } else { om0.sqrt() };
    let omega = [om0, 0.0, mu];
    let sx = if om0 == 0.0 {
        0.0
    } else {
        (nu - mu * mu_s) / om0
    };
    let sy = safe_sqrt(1.0 - sx * sx - mu_s * mu_s);
    let omega_s = [sx, sy, mu_s];
    let dphi = PI / N as f64;
    let dtheta = PI / N as f64;
    let (rs, ms) = atm.scattering_at(height);
    let mut out = [0.0; NSSAMP];
    for l in 0..N {
        let theta = (l as f64 + 0.5) * dtheta;
        let (st, ct) = theta.sin_cos();
        let ground = hits_ground(r, ct);
        let mut dist_g = 0.0;
        let mut t_g = [0.0; NSSAMP];
        let mut albedo = 0.0;
        if ground {
            dist_g = distance_to_ground(r, ct);
            t_g = t.transmittance(r, ct, dist_g, true);
            albedo = atm.ground_reflectance;
        }
        // The previous order's radiance for this zenith angle depends on the direction
        // only through nu: interpolate r, mu and mu_s once (exact, see `Table::reduce3`).
        let uvwz = scattering_uvwz(r, ct, mu_s, 0.0, ground);
        let pt = [uvwz[0], uvwz[1], uvwz[2]];
        let (red_a, red_b) = if prev.order == 1 {
            (prev.ray1.reduce3(pt), prev.mie1.reduce3(pt))
        } else {
            (prev.multi.reduce3(pt), Vec::new())
        };
        for m in 0..2 * N {
            let phi = (m as f64 + 0.5) * dphi;
            let (sp, cp) = phi.sin_cos();
            let wi = [cp * st, sp * st, ct];
            let domega = dtheta * dphi * st;
            let mut nu1 = omega_s[0] * wi[0] + omega_s[1] * wi[1] + omega_s[2] * wi[2];
            // genssky nudges exact (anti)alignment off the table's end.
            if nu1 <= -1.0 {
                nu1 += 0.1;
            } else if nu1 >= 1.0 {
                nu1 -= 0.1;
            }
            let u_nu = (nu1 + 1.0) / 2.0;
            let mut li = interpolate_nodes(&red_a, u_nu);
            if prev.order == 1 {
                let b = interpolate_nodes(&red_b, u_nu);
                let (pr, pm) = (rayleigh_phase(nu1), mie_phase(MIE_G, nu1));
                for k in 0..NSSAMP {
                    li[k] = li[k] * pr + b[k] * pm;
                }
            }
            // Light reflected by the ground (zero transmittance when the ray misses it).
            if ground {
                let gn = [wi[0] * dist_g, wi[1] * dist_g, r + wi[2] * dist_g];
                let gl = (gn[0] * gn[0] + gn[1] * gn[1] + gn[2] * gn[2]).sqrt();
                let gmu = (gn[0] * omega_s[0] + gn[1] * omega_s[1] + gn[2] * omega_s[2]) / gl;
                let eg = ground_irradiance.lookup(&[0.0, gmu * 0.5 + 0.5]);
                for b in 0..NSSAMP {
                    li[b] += t_g[b] * albedo / PI * eg[b];
                }
            }
            let nu2 = omega[0] * wi[0] + omega[1] * wi[1] + omega[2] * wi[2];
            let (pr, pm) = (rayleigh_phase(nu2), mie_phase(MIE_G, nu2));
            for b in 0..NSSAMP {
                out[b] += li[b] * domega * (rs[b] * pr + ms[b] * pm);
            }
        }
    }
    out
}

/// Indirect irradiance of order `order + 1` on a horizontal surface (Bruneton 2017
/// `ComputeIndirectIrradiance`, 16 x 64 midpoint rule over the upper hemisphere).
fn indirect_irradiance(prev: &OrderLookup, r: f64, mu_s: f64) -> [f64; NSSAMP] {
    const N: usize = 32;
    let dphi = PI / N as f64;
    let dtheta = PI / N as f64;
    let omega_s = [safe_sqrt(1.0 - mu_s * mu_s), 0.0, mu_s];
    let mut out = [0.0; NSSAMP];
    for j in 0..N / 2 {
        let theta = (j as f64 + 0.5) * dtheta;
        let (st, ct) = theta.sin_cos();
        for i in 0..2 * N {
            let phi = (i as f64 + 0.5) * dphi;
            let w = [st * phi.cos(), st * phi.sin(), ct];
            let domega = dtheta * dphi * st;
            let nu = w[0] * omega_s[0] + w[2] * omega_s[2];
            let l = prev.get(r, w[2], mu_s, nu, false);
            for b in 0..NSSAMP {
                out[b] += l[b] * w[2] * domega;
            }
        }
    }
    out
}

/// Multiple scattering of one order along (r, mu): the density integrated with the
/// transmittance (Bruneton 2017 `ComputeMultipleScattering`, 50 trapezoids).
fn multiple_scattering(
    t: &Tables,
    density: &Table,
    r: f64,
    mu: f64,
    mu_s: f64,
    nu: f64,
    ground: bool,
) -> [f64; NSSAMP] {
    const N: usize = 50;
    let dist = if ground {
        distance_to_ground(r, mu)
    } else {
        distance_to_top(r, mu)
    };
    let dx = dist / N as f64;
    let mut out = [0.0; NSSAMP];
    for i in 0..=N {
        let d = i as f64 * dx;
        let ri = clamp_radius((d * d + 2.0 * r * mu * d + r * r).sqrt());
        let mui = clamp_cosine((r * mu + d) / ri);
        let musi = clamp_cosine((r * mu_s + d * nu) / ri);
        let s = density.lookup(&scattering_uvwz(ri, mui, musi, nu, ground));
        let tr = t.transmittance(r, mu, d, ground);
        let w = if i == 0 || i == N { 0.5 } else { 1.0 };
        for b in 0..NSSAMP {
            out[b] += s[b] * tr[b] * dx * w;
        }
    }
    out
}

fn cell_params(idx: &[usize]) -> (f64, f64, f64, f64, bool) {
    scattering_params(
        idx[3] as f64 / S_NU as f64,
        idx[2] as f64 / S_MU_S as f64,
        idx[1] as f64 / S_MU as f64,
        idx[0] as f64 / S_R as f64,
    )
}

/// Precompute all tables (parallel over the radius axis; deterministic).
pub fn precompute(atm: &Atmosphere) -> Result<Tables> {
    precompute_reporting(atm, &crate::progress::QUIET)
}

/// [`precompute`], advancing `progress` by one per scattering order (single scattering is
/// the first, each multiple-scattering order one more: `atm.scattering_order` in all).
pub fn precompute_reporting(
    atm: &Atmosphere,
    progress: &dyn crate::progress::Progress,
) -> Result<Tables> {
    if atm.scattering_order < 2 {
        return Err(Error::Usage(format!(
            "scattering order {}: expected at least 2",
            atm.scattering_order
        )));
    }
    if !(atm.aod >= 0.0 && atm.aod.is_finite()) {
        return Err(Error::Usage(format!(
            "aerosol optical depth {}: expected a number >= 0",
            atm.aod
        )));
    }
    let mut tables = Tables {
        transmittance: Table::zeros(&[T_H, T_W]),
        scattering: Table::zeros(&[S_R, S_MU, S_MU_S, S_NU]),
        single_mie: Table::zeros(&[S_R, S_MU, S_MU_S, S_NU]),
        irradiance: Table::zeros(&[I_H, I_W]),
    };
    // Transmittance: texel (j, i) at (u, v) = (i/W, j/H), genssky's sampling.
    tables.transmittance.data = for_each_cell(&[T_H, T_W], |ix| {
        let (r, mu) = transmittance_params(ix[1] as f64 / T_W as f64, ix[0] as f64 / T_H as f64);
        transmittance_to_top_exact(atm, r, mu)
    });
    let irr_params = |ix: &[usize]| -> (f64, f64) {
        let r = ix[0] as f64 / I_H as f64 * THICKNESS + EARTH_RADIUS;
        let mu_s = clamp_cosine(ix[1] as f64 / I_W as f64 * 2.0 - 1.0);
        (r, mu_s)
    };
    // Direct irradiance (order 0 of the ground term), Bruneton 2017
    // `ComputeDirectIrradiance` with the sun disc's average cosine.
    let t = &tables;
    let direct = for_each_cell(&[I_H, I_W], |ix| {
        let (r, mu_s) = irr_params(ix);
        let a = SUN_ANGULAR_RADIUS;
        let cosf = if mu_s < -a {
            0.0
        } else if mu_s > a {
            mu_s
        } else {
            (mu_s + a) * (mu_s + a) / (4.0 * a)
        };
        let tr = t.transmittance_to_top(r, mu_s);
        let mut out = [0.0; NSSAMP];
        for b in 0..NSSAMP {
            out[b] = EXTRATERRESTRIAL[b] * tr[b] * cosf;
        }
        out
    });
    let sdims = [S_R, S_MU, S_MU_S, S_NU];
    // Single scattering.
    let pairs: Vec<([f64; NSSAMP], [f64; NSSAMP])> = {
        let n: usize = sdims.iter().product();
        (0..n)
            .into_par_iter()
            .map(|k| {
                let idx = [
                    k / (S_MU * S_MU_S * S_NU),
                    (k / (S_MU_S * S_NU)) % S_MU,
                    (k / S_NU) % S_MU_S,
                    k % S_NU,
                ];
                let (r, mu, mu_s, nu, g) = cell_params(&idx);
                single_scattering(atm, t, r, mu, mu_s, nu, g)
            })
            .collect()
    };
    progress.advance(1);
    let mut ray1 = Table::zeros(&sdims);
    let mut mie1 = Table::zeros(&sdims);
    for (k, (a, b)) in pairs.iter().enumerate() {
        ray1.data[k * NSSAMP..(k + 1) * NSSAMP].copy_from_slice(a);
        mie1.data[k * NSSAMP..(k + 1) * NSSAMP].copy_from_slice(b);
    }
    let mut scattering = ray1.clone();
    let mut delta_irr = Table {
        dims: vec![I_H, I_W],
        data: direct,
    };
    let mut irradiance = Table::zeros(&[I_H, I_W]);
    let mut multi = Table::zeros(&sdims);
    for order in 2..=atm.scattering_order {
        let density = {
            let prev = OrderLookup {
                order: order - 1,
                ray1: &ray1,
                mie1: &mie1,
                multi: &multi,
            };
            let di = &delta_irr;
            Table {
                dims: sdims.to_vec(),
                data: for_each_cell(&sdims, |idx| {
                    let (r, mu, mu_s, nu, _) = cell_params(idx);
                    scattering_density(atm, t, &prev, di, r, mu, mu_s, nu)
                }),
            }
        };
        delta_irr = {
            let prev = OrderLookup {
                order: order - 1,
                ray1: &ray1,
                mie1: &mie1,
                multi: &multi,
            };
            Table {
                dims: vec![I_H, I_W],
                data: for_each_cell(&[I_H, I_W], |ix| {
                    let (r, mu_s) = irr_params(ix);
                    indirect_irradiance(&prev, r, mu_s)
                }),
            }
        };
        for (a, b) in irradiance.data.iter_mut().zip(&delta_irr.data) {
            *a += b;
        }
        multi = Table {
            dims: sdims.to_vec(),
            data: for_each_cell(&sdims, |idx| {
                let (r, mu, mu_s, nu, g) = cell_params(idx);
                multiple_scattering(t, &density, r, mu, mu_s, nu, g)
            }),
        };
        let n: usize = sdims.iter().product();
        for k in 0..n {
            let idx = [
                k / (S_MU * S_MU_S * S_NU),
                (k / (S_MU_S * S_NU)) % S_MU,
                (k / S_NU) % S_MU_S,
                k % S_NU,
            ];
            let (_, _, _, nu, _) = cell_params(&idx);
            let p = rayleigh_phase(nu);
            for b in 0..NSSAMP {
                scattering.data[k * NSSAMP + b] += multi.data[k * NSSAMP + b] / p;
            }
        }
        progress.advance(1);
    }
    tables.scattering = scattering;
    tables.single_mie = mie1;
    tables.irradiance = irradiance;
    Ok(tables)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_matches_radiance_rules() {
        // Inside: linear.
        assert_eq!(radiance_coefficients(1.25, 4), (1, 0.75, 0.25));
        // Beyond the last node by half a division: linear extrapolation.
        let (i, c0, c1) = radiance_coefficients(3.5, 4);
        assert_eq!(i, 2);
        assert!((c0 + 0.5).abs() < 1e-12 && (c1 - 1.5).abs() < 1e-12);
        // Far beyond: tapered (c0 + c1 = -1/(x - i - 1), going to zero).
        let (_, c0, c1) = radiance_coefficients(10.0, 4);
        assert!((c0 + c1).abs() < 0.2);
    }

    #[test]
    fn climate_choice_follows_latitude_and_season() {
        assert_eq!(Climate::for_site(42.0, 3), Climate::MidLatitudeWinter);
        assert_eq!(Climate::for_site(42.0, 6), Climate::MidLatitudeSummer);
        assert_eq!(Climate::for_site(-33.9, 1), Climate::MidLatitudeSummer);
        assert_eq!(Climate::for_site(10.0, 1), Climate::Tropical);
        assert_eq!(Climate::for_site(70.0, 7), Climate::SubarcticSummer);
    }

    #[test]
    fn mie_profile_parses_irregular_axis_and_reports_lines() {
        let mut text = String::from("# c\n2\n0 0 3 0 1000 60000\n0 19 20\n");
        for k in 0..60 {
            text.push_str(&format!("{}e-6\n", k + 1));
        }
        let p = MieProfile::parse(&text, "m.dat").unwrap();
        assert_eq!(p.altitudes, vec![0.0, 1000.0, 60000.0]);
        let v = p.at(500.0);
        assert!((v[0] - 11e-6).abs() < 1e-12);
        let bad = text.replace("5e-6", "x5");
        let e = MieProfile::parse(&bad, "m.dat").unwrap_err().to_string();
        assert!(e.starts_with("m.dat:9: \"x5\""), "{e}");
    }

    #[test]
    fn mie_profile_prefixes_never_panic() {
        let mut text = String::from("2\n0 0 3 0 1000 60000\n0 19 20\n");
        for k in 0..60 {
            text.push_str(&format!("{}e-6\n", k + 1));
        }
        let last_start = text.trim_end().rfind('\n').unwrap();
        for n in 0..text.len() {
            let r = MieProfile::parse(&text[..n], "m.dat");
            if n <= last_start {
                assert!(r.is_err(), "prefix {n} accepted");
            }
        }
    }

    #[test]
    fn fallback_profile_has_the_stated_depth() {
        let p = MieProfile::fallback();
        // Trapezoids over the grid; within 2 % of the stated depth.
        let mut tau = 0.0;
        for w in p.altitudes.windows(2) {
            let (a, b) = (p.at(w[0]), p.at(w[1]));
            tau += 0.5 * (a[8] + b[8]) * (w[1] - w[0]);
        }
        // Band 8 is 540-560 nm.
        let want = FALLBACK_TAU550;
        assert!((tau / want - 1.0).abs() < 0.02, "{tau}");
    }
}
