//! # The picture commands of `ruplift` as library calls
//!
//! Typed configurations of `ruplift photo` ([`Photo`]), `ruplift proxy` ([`Proxy`]) and
//! their shared material output ([`MaterialOut`]), and one function per command that reads
//! the pictures, estimates and writes the `.rad` materials (and `validate`, the uplifting
//! validation report). Option combinations that cannot work are `Usage` errors naming the
//! options, checked in the order the tool always checked them. The command line (clap) is
//! the tools layer's (`rdaylight::cli::ruplift`).

use crate::mask::{LabelMap, Legend, reflectance_values};
use crate::photo::{self, Cat, White};
use crate::uplift::output::{MaterialRow, write_material_table, write_materials};
use crate::uplift::{Method, RgbSpace, Uplifter};
use crate::{eval, proxy};
use rdaylight_base::error::{Error, IoContext, Result};
use rdaylight_base::io::write_atomically;
use rdaylight_formats::picture::Picture;
use rdaylight_formats::picture::exr::{read_exr, write_exr};
use rdaylight_formats::picture::preview::read_photo;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where and how the per-material estimates are written.
#[derive(Debug, Clone)]
pub struct MaterialOut {
    /// Drop mask pixels within this many pixels of another material.
    pub erode: usize,
    /// Write each material as a spectrum uplifted with this method (`None`: RGB plastics).
    pub spectrum: Option<Method>,
    /// Specularity and roughness of the plastics.
    pub spec: f64,
    pub rough: f64,
    /// Also write the estimates as a CSV table.
    pub csv: Option<PathBuf>,
    /// The `.rad` materials' destination (`None`: `out`).
    pub output: Option<PathBuf>,
}

/// `ruplift photo`: Ferwerda's method on an ordinary photo.
#[derive(Debug, Clone)]
pub struct Photo {
    pub photo: PathBuf,
    pub mask: PathBuf,
    pub legend: Option<PathBuf>,
    /// The white reference as a rectangle x0 y0 x1 y1, of reflectance `white_rho`.
    pub white_rect: Option<[usize; 4]>,
    pub white_rho: Vec<f64>,
    /// Grey world: the masked pixels average to this reflectance.
    pub grey_world: Option<f64>,
    /// Trust the camera's white balance and exposure.
    pub camera_white: bool,
    pub cat: Cat,
    pub out: MaterialOut,
}

/// `ruplift proxy`: the illuminance proxy on a calibrated HDR picture.
#[derive(Debug, Clone)]
pub struct Proxy {
    pub picture: PathBuf,
    pub points: PathBuf,
    pub mask: Option<PathBuf>,
    pub legend: Option<PathBuf>,
    pub zones: Option<PathBuf>,
    pub options: proxy::Options,
    /// Write the reflectance and the kriged illuminance maps (.hdr, or .exr by extension).
    pub map: Option<PathBuf>,
    pub illuminance: Option<PathBuf>,
    pub out: MaterialOut,
}

fn load_mask(mask: &Path, legend: Option<&PathBuf>, erode: usize) -> Result<LabelMap> {
    let legend = legend.map(|p| Legend::open(p)).transpose()?;
    Ok(LabelMap::open(mask, legend)?.erode(erode))
}

/// Write the .rad materials (to `o.output` atomically, or `out`) and the optional CSV table.
pub fn write_outputs(
    rows: &[MaterialRow],
    o: &MaterialOut,
    command: &str,
    out: &mut dyn Write,
) -> Result<()> {
    if rows.is_empty() {
        return Err(Error::Usage(
            "no material has any pixel left in the mask (check colours, legend and --erode)".into(),
        ));
    }
    let uplifter = o.spectrum.map(|m| Uplifter::new(RgbSpace::Radiance, m));
    let rad = |w: &mut dyn Write| -> Result<()> {
        writeln!(w, "# {command}").at_path("<output>")?;
        write_materials(w, rows, uplifter.as_ref(), o.spec, o.rough).at_path("<output>")
    };
    if let Some(t) = &o.csv {
        write_atomically(t, |w| {
            write_material_table(w, rows).at_path(&t.display().to_string())
        })?;
    }
    match &o.output {
        Some(p) => write_atomically(p, rad),
        None => {
            let mut w = std::io::BufWriter::new(out);
            rad(&mut w)?;
            w.flush().at_path("<stdout>")
        }
    }
}

impl Photo {
    /// The white reference the options choose (at most one of them).
    pub fn white(&self) -> Result<White> {
        let chosen = [
            self.white_rect.is_some(),
            self.grey_world.is_some(),
            self.camera_white,
        ];
        if chosen.iter().filter(|c| **c).count() > 1 {
            return Err(Error::Usage(
                "choose one white: --white-rect, --grey-world or --camera-white".into(),
            ));
        }
        Ok(if let Some(rect) = self.white_rect {
            let text: Vec<String> = self.white_rho.iter().map(|v| v.to_string()).collect();
            let known = reflectance_values(&text.join(" "))
                .map_err(|m| Error::Usage(format!("--white-rho: {m}")))?;
            White::Rect { rect, known }
        } else if let Some(g) = self.grey_world {
            White::GreyWorld(g)
        } else if self.camera_white {
            White::Camera
        } else {
            White::Legend
        })
    }
}

/// Run `ruplift photo`.
pub fn photo_run(a: &Photo, out: &mut dyn Write) -> Result<()> {
    let picture = read_photo(&a.photo)?;
    let mask = load_mask(&a.mask, a.legend.as_ref(), a.out.erode)?;
    let white = a.white()?;
    let est = photo::estimate(&picture, &mask, &white, a.cat)?;
    let rows: Vec<MaterialRow> = est
        .iter()
        .map(|e| MaterialRow {
            name: e.name.clone(),
            rgb: e.rgb,
            pixels: e.pixels,
            note: format!(
                "white {}{}{}",
                e.white,
                if e.is_reference {
                    ", reference patch"
                } else {
                    ""
                },
                if e.clipped > 0 {
                    format!(", {} clipped pixels left out", e.clipped)
                } else {
                    String::new()
                }
            ),
        })
        .collect();
    let command = format!(
        "ruplift photo {} (Ferwerda: sRGB decoded, {:?} CAT to equal-energy white)",
        a.photo.display(),
        a.cat
    );
    write_outputs(&rows, &a.out, &command, out)
}

fn is_exr(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Save a picture as OpenEXR (by extension) or Radiance HDR.
pub fn save_picture(p: &Picture, path: &Path) -> Result<()> {
    if is_exr(path) {
        write_exr(p, path)
    } else {
        p.save(path, true)
    }
}

/// The zone's fitted variogram, as the note on standard error says it.
fn variogram_note(v: &Option<crate::kriging::Variogram>) -> String {
    v.as_ref().map_or(
        "constant (too few points or no variance)".to_string(),
        |v| {
            format!(
                "{:?} nugget {:.4e}, partial sill {:.4e}, range {:.1} px",
                v.family, v.nugget, v.psill, v.range
            )
        },
    )
}

/// Run `ruplift proxy`: maps and materials written, one note per zone on `err`.
pub fn proxy_run(a: &Proxy, out: &mut dyn Write, err: &mut dyn Write) -> Result<()> {
    if a.mask.is_none() && a.map.is_none() && a.illuminance.is_none() {
        return Err(Error::Usage(
            "nothing to write: give --mask for per-material means or --map for the \
             reflectance map"
                .into(),
        ));
    }
    let picture = if is_exr(&a.picture) {
        read_exr(&a.picture)?
    } else {
        Picture::open(&a.picture)?
    };
    let shown = a.points.display().to_string();
    let text = std::fs::read_to_string(&a.points).at_path(&shown)?;
    let points = proxy::parse_points(&text, &shown)?;
    let mask = match &a.mask {
        Some(m) => Some(load_mask(m, a.legend.as_ref(), a.out.erode)?),
        None if a.legend.is_some() => {
            return Err(Error::Usage("--legend needs --mask".into()));
        }
        None => None,
    };
    let zones = a
        .zones
        .as_ref()
        .map(|z| LabelMap::open(z, None))
        .transpose()?;
    let r = proxy::run(
        &picture,
        &points,
        mask.as_ref(),
        zones.as_ref(),
        &shown,
        &a.options,
    )?;
    for (name, n, v) in &r.zones {
        let _ = writeln!(
            err,
            "ruplift proxy: zone {name}: {n} points, variogram {}",
            variogram_note(v)
        );
    }
    if let Some(p) = &a.map {
        save_picture(&r.reflectance, p)?;
    }
    if let Some(p) = &a.illuminance {
        save_picture(&r.illuminance, p)?;
    }
    if mask.is_none() {
        return Ok(());
    }
    let rows: Vec<MaterialRow> = r
        .regions
        .iter()
        .map(|m| MaterialRow {
            name: m.name.clone(),
            rgb: m.rgb,
            pixels: m.pixels,
            note: format!(
                "illuminance proxy, {} channel{}, {} known points on it{}",
                r.nchan,
                if r.nchan == 3 { "s" } else { "" },
                m.points,
                if a.options.trim {
                    ", 5/95 % trimmed"
                } else {
                    ""
                }
            ),
        })
        .collect();
    let command = format!(
        "ruplift proxy {} --points {} (illuminance proxy, ordinary kriging)",
        a.picture.display(),
        shown
    );
    write_outputs(&rows, &a.out, &command, out)
}

/// Basis sizes of the validation's sweep (`docs/uplift-validation.md`).
pub const BASIS_SWEEP: [usize; 8] = [3, 4, 5, 6, 7, 8, 10, 12];

/// Run `ruplift validate`: the Markdown tables to `out`, the error plot to `plot`.
pub fn validate_run(plot: Option<&Path>, out: &mut dyn Write) -> Result<()> {
    if let Some(p) = plot {
        let shown = p.display().to_string();
        eval::error_plot()
            .save(p)
            .map_err(|e| Error::Usage(format!("{shown}: cannot write the plot: {e}")))?;
    }
    let sweep = eval::basis_k_sweep(&BASIS_SWEEP);
    let rows = eval::validate()?;
    write!(out, "{}", eval::report(&rows, &sweep)).at_path("<stdout>")
}
