//! On-disk cache of the precomputed atmosphere tables.
//!
//! genssky keeps its tables as Radiance data files in `<dir>/atmos_data`, named by climate,
//! aerosol profile and AOD (rounded to two decimals, and without the ground reflectance,
//! although the tables depend on it). Ours live in the same folder under their own names,
//! one binary file per atmosphere:
//!
//! ```text
//! b"RDAYATM1"                         magic and format version
//! u32 n, n bytes                      the key: every input that changes a value
//! 4 x (u32 nd, nd x u32 dims, values) transmittance, scattering, single Mie, irradiance;
//!                                     product(dims) * 20 little-endian f32 each
//! u64                                 FNV-1a 64 of everything before it
//! ```
//!
//! Values are rounded to f32 also when freshly computed, so a cached sky is bit-identical to
//! a fresh one. A file that is short, has another key, other dimensions or a wrong checksum
//! is reported and recomputed (then replaced atomically); it never stops the run.

use super::{Atmosphere, NSSAMP, Table, Tables, precompute_reporting};
use crate::error::{Error, Result};
use crate::progress::{Progress, QUIET, Stage};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"RDAYATM1";

/// FNV-1a of the keys and bodies (`rdaylight_base::hash`).
pub use rdaylight_base::hash::Fnv64 as Fnv;

/// Everything that changes a table value, as text.
pub fn key(atm: &Atmosphere) -> String {
    format!(
        "rdaylight-atmosphere v1 climate={} aod={:e} ground={:e} order={} mie={}:{:016x}",
        atm.climate.tag(),
        atm.aod,
        atm.ground_reflectance,
        atm.scattering_order,
        atm.mie.name,
        atm.mie.fingerprint()
    )
}

/// The cache file for an atmosphere inside `dir/atmos_data`.
pub fn path(dir: &Path, atm: &Atmosphere) -> PathBuf {
    let mut h = Fnv::new();
    h.write(key(atm).as_bytes());
    dir.join("atmos_data").join(format!(
        "rdaylight_{}_{}_{:.3}_{:.3}_{:08x}.bin",
        atm.climate.tag(),
        atm.mie.name,
        atm.aod,
        atm.ground_reflectance,
        h.finish() as u32
    ))
}

/// What happened to the cache.
#[derive(Debug, Clone, PartialEq)]
pub enum CacheStatus {
    /// Read from this file.
    Hit(PathBuf),
    /// Computed and written to this file.
    Computed(PathBuf),
    /// The file was unusable (reason), so the tables were recomputed and it was replaced.
    Recomputed(PathBuf, String),
}

/// Round every value to f32 (what the cache stores).
pub fn round_to_f32(t: &mut Tables) {
    for tab in [
        &mut t.transmittance,
        &mut t.scattering,
        &mut t.single_mie,
        &mut t.irradiance,
    ] {
        for v in tab.data.iter_mut() {
            *v = *v as f32 as f64;
        }
    }
}

/// Serialise tables with their key.
pub fn encode(t: &Tables, key: &str) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(key.len() as u32).to_le_bytes());
    out.extend_from_slice(key.as_bytes());
    for tab in [
        &t.transmittance,
        &t.scattering,
        &t.single_mie,
        &t.irradiance,
    ] {
        out.extend_from_slice(&(tab.dims.len() as u32).to_le_bytes());
        for d in &tab.dims {
            out.extend_from_slice(&(*d as u32).to_le_bytes());
        }
        for v in &tab.data {
            out.extend_from_slice(&(*v as f32).to_le_bytes());
        }
    }
    let mut h = Fnv::new();
    h.write(&out);
    out.extend_from_slice(&h.finish().to_le_bytes());
    out
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> std::result::Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.b.len());
        let Some(end) = end else {
            return Err(format!("truncated at byte {}", self.b.len()));
        };
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self) -> std::result::Result<u32, String> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
}

/// Deserialise, checking the magic, key, dimensions (`expected`) and checksum.
pub fn decode(
    bytes: &[u8],
    want_key: &str,
    expected: &[&[usize]; 4],
) -> std::result::Result<Tables, String> {
    if bytes.len() < MAGIC.len() + 8 || &bytes[..MAGIC.len()] != MAGIC {
        return Err("not an rdaylight atmosphere cache (bad magic)".into());
    }
    let (body, sum) = bytes.split_at(bytes.len() - 8);
    let mut h = Fnv::new();
    h.write(body);
    let stored = u64::from_le_bytes(sum.try_into().map_err(|_| "short checksum")?);
    if h.finish() != stored {
        return Err("checksum mismatch (truncated or corrupt)".into());
    }
    let mut r = Reader {
        b: body,
        at: MAGIC.len(),
    };
    let klen = r.u32()? as usize;
    let k = r.take(klen)?;
    if k != want_key.as_bytes() {
        return Err(format!(
            "stale: made for \"{}\"",
            String::from_utf8_lossy(k)
        ));
    }
    let mut tabs = Vec::with_capacity(4);
    for want in expected {
        let nd = r.u32()? as usize;
        if nd != want.len() {
            return Err(format!("table with {nd} axes; expected {}", want.len()));
        }
        let mut dims = Vec::with_capacity(nd);
        for _ in 0..nd {
            dims.push(r.u32()? as usize);
        }
        if dims != *want {
            return Err(format!("table of {dims:?}; expected {want:?}"));
        }
        let n = dims.iter().product::<usize>() * NSSAMP;
        let raw = r.take(n * 4)?;
        let data = raw
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
            .collect();
        tabs.push(Table { dims, data });
    }
    if r.at != body.len() {
        return Err("trailing bytes".into());
    }
    let mut it = tabs.into_iter();
    match (it.next(), it.next(), it.next(), it.next()) {
        (Some(transmittance), Some(scattering), Some(single_mie), Some(irradiance)) => Ok(Tables {
            transmittance,
            scattering,
            single_mie,
            irradiance,
        }),
        _ => Err("missing tables".into()),
    }
}

/// Dimensions of the four tables.
pub const DIMS: [&[usize]; 4] = [&[64, 256], &[16, 64, 16, 4], &[16, 64, 16, 4], &[16, 64]];

/// Precompute with rounding to f32 (so fresh and cached tables are identical).
pub fn compute(atm: &Atmosphere) -> Result<Tables> {
    compute_reporting(atm, &QUIET)
}

/// [`compute`] as one stage of `progress`, a unit per scattering order.
pub fn compute_reporting(atm: &Atmosphere, progress: &dyn Progress) -> Result<Tables> {
    let name = format!("atmosphere tables ({}, AOD {})", atm.climate.tag(), atm.aod);
    let stage = Stage::new(
        progress,
        &name,
        Some(atm.scattering_order.max(1) as u64),
        "scattering orders",
    );
    let mut t = precompute_reporting(atm, stage.progress())?;
    round_to_f32(&mut t);
    Ok(t)
}

/// The folder of the tables when none is given (gensdaymtx/genssky `-p`): the user's cache
/// folder, `$XDG_CACHE_HOME/rdaylight`, else `~/.cache/rdaylight` (the XDG base directory
/// default), else the current folder; tables are computed once per climate and AOD and
/// shared by every run of the user.
pub fn default_dir() -> PathBuf {
    if let Some(x) = std::env::var_os("XDG_CACHE_HOME").filter(|x| !x.is_empty()) {
        return PathBuf::from(x).join("rdaylight");
    }
    if let Some(h) = std::env::var_os("HOME").filter(|x| !x.is_empty()) {
        return PathBuf::from(h).join(".cache").join("rdaylight");
    }
    PathBuf::from(".")
}

/// Tables for `atm`, from `dir/atmos_data` when a valid entry exists, else computed and
/// stored there (the folder is created).
pub fn load_or_compute(dir: &Path, atm: &Atmosphere) -> Result<(Tables, CacheStatus)> {
    load_or_compute_reporting(dir, atm, &QUIET)
}

/// [`load_or_compute`]; a computation is a stage of `progress` ([`compute_reporting`]).
pub fn load_or_compute_reporting(
    dir: &Path,
    atm: &Atmosphere,
    progress: &dyn Progress,
) -> Result<(Tables, CacheStatus)> {
    let file = path(dir, atm);
    let k = key(atm);
    let mut reason = None;
    match std::fs::read(&file) {
        Ok(bytes) => match decode(&bytes, &k, &DIMS) {
            Ok(t) => return Ok((t, CacheStatus::Hit(file))),
            Err(why) => reason = Some(why),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => reason = Some(e.to_string()),
    }
    let t = compute_reporting(atm, progress)?;
    let parent = file.parent().unwrap_or(dir);
    std::fs::create_dir_all(parent).map_err(|e| Error::io(parent.display().to_string(), e))?;
    let bytes = encode(&t, &k);
    crate::io::write_atomically(&file, |w| {
        w.write_all(&bytes)
            .map_err(|e| Error::io(file.display().to_string(), e))
    })?;
    let status = match reason {
        Some(r) => CacheStatus::Recomputed(file, r),
        None => CacheStatus::Computed(file),
    };
    Ok((t, status))
}
