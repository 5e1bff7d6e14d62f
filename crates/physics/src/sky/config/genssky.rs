//! # Radiance 6 genssky's point-in-time spectral sky, as one typed config
//!
//! [`GensskyConfig::write`] loads (or computes and caches) the atmosphere tables, writes the
//! sky picture `<dir>/<prefix>_sky.hsr` and the scene text that refers to it, with genssky's
//! comment lines plus where the tables came from ([`crate::sky::genssky`]).

use super::Messages;
use crate::error::{Error, Result};
use crate::sky::atmosphere::cache::{self, CacheStatus};
use crate::sky::genssky::{GensskyOptions, load_mie, rad_text, sky_path, spectral_sky};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Everything `rspecsky genssky` takes (genssky's letters in brackets).
#[derive(Debug, Clone, PartialEq)]
pub struct GensskyConfig {
    /// Date, time, site and sky (`-a -o -m -y -d -c -g -r -L`).
    pub options: GensskyOptions,
    /// `-l`: aerosol profile (default `mie_ca.dat` on RAYPATH, else the fallback profile).
    pub mie: Option<PathBuf>,
    /// `-p`: folder for the sky picture and `atmos_data/` (default: picture in the current
    /// folder, tables in [`cache::default_dir`]).
    pub dir: Option<String>,
    /// `-f`: picture name prefix (`out`: `out_sky.hsr`).
    pub prefix: String,
    /// `-n`: threads for the precomputation (0: all; results do not depend on it).
    pub threads: usize,
    /// `-i`: highest scattering order.
    pub scattering_order: usize,
    /// The words of the first comment line (the command line).
    pub command: Vec<String>,
}

impl GensskyConfig {
    /// genssky's defaults for `options`.
    pub fn new(options: GensskyOptions) -> Self {
        GensskyConfig {
            options,
            mie: None,
            dir: None,
            prefix: "out".into(),
            threads: 0,
            scattering_order: 4,
            command: Vec::new(),
        }
    }

    /// Validate, compute, save the sky picture and write the scene text to `out`.
    pub fn write(&self, mut out: impl Write, name: &str, msgs: &dyn Messages) -> Result<()> {
        let o = &self.options;
        o.validate()?;
        use crate::error::{MAX_THREADS, at_most};
        let cores = "beyond the cores, threads only cost memory";
        at_most("-n", self.threads as u64, MAX_THREADS as u64, cores)?;
        // Each order is one more pass over the full tables; genssky's default is 4 and
        // orders beyond 10 change the sky by less than the tables' own interpolation.
        let orders = "each order is a pass over the whole tables; 4 is genssky's default";
        at_most("-i", self.scattering_order as u64, 20, orders)?;
        crate::formats::picture::check_size(
            &format!("-r {}", o.resolution),
            o.resolution,
            o.resolution / 2,
            crate::radiometry::MAX_SAMPLES,
        )?;
        // The warning gensky and genssky print: a meridian far from the longitude is
        // usually a sign mistake.
        if o.hour.zone_meridian.is_none()
            && !o.hour.solar
            && (o.site.meridian_west() - o.site.longitude_west()).abs() > 45.0
        {
            msgs.warn(&format!(
                "warning - {:.1} hours btwn. standard meridian and longitude",
                (o.site.longitude_west() - o.site.meridian_west()) / 15.0
            ));
        }
        let mie = load_mie(self.mie.as_deref())?;
        let mie_source = mie.source.clone();
        let mut atm = o.atmosphere(mie);
        atm.scattering_order = self.scattering_order;
        let out_dir = self.dir.clone().unwrap_or_else(|| ".".into());
        let out_dir = if out_dir.len() > 1 {
            out_dir.trim_end_matches('/').to_string()
        } else {
            out_dir
        };
        let cache_dir = match &self.dir {
            Some(_) => PathBuf::from(&out_dir),
            None => cache::default_dir(),
        };
        let start = std::time::Instant::now();
        let work = || cache::load_or_compute_reporting(&cache_dir, &atm, msgs.progress());
        let (tables, status) = if self.threads > 0 {
            rayon::ThreadPoolBuilder::new()
                .num_threads(self.threads)
                .build()
                .map_err(|e| Error::Usage(format!("-n {}: {e}", self.threads)))?
                .install(work)?
        } else {
            work()?
        };
        let secs = start.elapsed().as_secs_f64();
        let sky = spectral_sky(&tables, o);
        let hsr = sky_path(Path::new(&out_dir), &self.prefix);
        let sky_name = format!("{out_dir}/{}_sky.hsr", self.prefix);
        sky.picture.save(&hsr, false)?;
        if let CacheStatus::Recomputed(p, why) = &status {
            msgs.warn(&format!("{}: {why}; recomputed", p.display()));
        }
        let comments = vec![
            format!("# {} ", self.command.join(" ")),
            format!("#Cloud cover: {}", o.cloud_cover),
            format!("#Ground reflectance: {}", o.ground_reflectance),
            format!("#Sky map resolution: {}", o.resolution),
            format!("#Aerosol profile: {mie_source}"),
            tables_note(&status, secs),
        ];
        let text = rad_text(&sky, &comments, &sky_name);
        out.write_all(text.as_bytes())
            .and_then(|_| out.flush())
            .map_err(|e| Error::io(name, e))
    }
}

/// The comment line saying where the tables came from.
fn tables_note(status: &CacheStatus, secs: f64) -> String {
    match status {
        CacheStatus::Hit(p) => format!("#Atmosphere tables: {} (cached)", p.display()),
        CacheStatus::Computed(p) => format!(
            "#Atmosphere tables: {} (computed in {secs:.1} s)",
            p.display()
        ),
        CacheStatus::Recomputed(p, why) => format!(
            "#Atmosphere tables: {} (recomputed in {secs:.1} s: {why})",
            p.display()
        ),
    }
}
