//! # `ruplift`'s command line
//!
//! The tools layer's half of `ruplift`: the clap structs and their conversion into the
//! library's typed configurations: [`crate::uplift::colours`] (`rgb`, `batch`: the
//! uplifting method) and [`crate::uplift::run`] (`photo`, `proxy`, `validate`: reflectance
//! from pictures and the validation).

use crate::uplift::colours::{self, Config};
use crate::uplift::kriging::Family;
use crate::uplift::photo::Cat;
use crate::uplift::{Method, RgbSpace, proxy, run};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples:
  A plastic with a measured-like spectrum for a Radiance RGB colour:
    ruplift rgb 0.6 0.35 0.2 --name wall > wall.rad
    oconv wall.rad room.rad > room.oct; rtrace -cs 20 -co ...
  An sRGB swatch (gamma-encoded, D65) as a specfile data file:
    ruplift rgb 0.8 0.5 0.3 --space srgb --format specfile > swatch.dat
  Jakob & Hanika with a precomputed coefficient table (built on first use):
    ruplift batch --method jakob --table jakob32.tab colours.txt > materials.rad
  Many colours (lines 'name R G B') to scene text or CSV:
    ruplift batch colours.txt > materials.rad
    ruplift batch --format csv colours.txt > spectra.csv
  The validation tables and plot (docs/uplift-validation.md):
    ruplift validate --plot docs/uplift-error-per-wavelength.png
  Materials from a phone photo with a white card (Ferwerda), legend lines 'rrggbb, name':
    ruplift photo room.jpg --mask mask.png --legend legend.csv --csv out.csv > mat.rad
  Grey-world white instead of a card, spectra through the uplifting:
    ruplift photo room.jpg --mask mask.png --grey-world 0.4 --spectrum > mat.rad
  Illuminance proxy on a calibrated HDR with known points, 5/95 % trimmed means:
    ruplift proxy wall.hdr --points known.csv --mask mask.png --legend legend.csv \\
      --zones planes.png --trim --map rho.exr > mat.rad";

/// Spectral uplifting: an RGB colour -> a smooth reflectance spectrum (0..1) on 380-780 nm
/// (5 nm) whose colour under the space's reference illuminant reproduces the input.
///
/// Methods: `basis` (default; the most probable spectrum under a logit-space PCA model of
/// measured Munsell reflectances that matches the colour exactly) and `jakob` (Jakob & Hanika
/// 2019 sigmoid of a quadratic, fitted in CIELAB). Out-of-gamut colours (no reflectance in
/// 0..1 matches them) get the closest spectrum; the remaining Delta E*ab is printed on
/// stderr.
#[derive(Parser, Debug)]
#[command(name = "ruplift", version, propagate_version = true, after_help = EXAMPLES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(clap::Args, Debug)]
pub struct Common {
    /// Colour space of the input: `radiance` (linear, Radiance's standard primaries,
    /// equal-energy white), `srgb` (gamma-encoded, D65) or `srgb-linear`.
    #[arg(long, value_enum, default_value = "radiance")]
    pub space: Space,
    /// Uplifting method.
    #[arg(long, value_enum, default_value = "basis")]
    pub method: MethodArg,
    /// Output: `rad` (spectrum + plastic), `specfile` (Radiance data file), `csv`.
    #[arg(long, value_enum, default_value = "rad")]
    pub format: Format,
    /// Specularity of the plastic (rad output).
    #[arg(value_parser = super::finite, long, default_value_t = 0.0)]
    pub spec: f64,
    /// Roughness of the plastic (rad output).
    #[arg(value_parser = super::finite, long, default_value_t = 0.0)]
    pub rough: f64,
    /// Jakob & Hanika coefficient table (with --method jakob): read FILE if it exists,
    /// else build it (--table-res) and save it there. Lookups start the fit near the answer.
    #[arg(long, value_name = "FILE")]
    pub table: Option<PathBuf>,
    /// Resolution of a table being built (entries per axis; 3 res^3 fits, so at most 128:
    /// 6.3 million fits).
    #[arg(long, default_value_t = 32, value_name = "N", value_parser = super::at_most::<128>)]
    pub table_res: usize,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Uplift one colour.
    Rgb {
        /// Red, green, blue: linear reflectance-like values in 0..1 for `radiance` and
        /// `srgb-linear`, encoded 0..1 values for `srgb`. Values outside the gamut are
        /// accepted (closest spectrum, warning on stderr).
        #[arg(value_parser = super::finite, allow_negative_numbers = true)]
        r: f64,
        #[arg(value_parser = super::finite, allow_negative_numbers = true)]
        g: f64,
        #[arg(value_parser = super::finite, allow_negative_numbers = true)]
        b: f64,
        /// Name of the material (the pattern is NAME_spec).
        #[arg(long, default_value = "uplifted")]
        name: String,
        #[command(flatten)]
        common: Common,
    },
    /// Uplift every `name R G B` line of a file (or stdin with `-`).
    Batch {
        #[arg(default_value = "-")]
        input: String,
        #[command(flatten)]
        common: Common,
    },
    /// Validate both methods on measured spectra (Munsell, ColorChecker) and print the
    /// Markdown tables of docs/uplift-validation.md.
    Validate {
        /// Also draw the per-wavelength error plot (PNG), e.g.
        /// docs/uplift-error-per-wavelength.png.
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
    /// Reflectance per material from an ordinary photo (JPEG/PNG, sRGB), Ferwerda's method:
    /// sRGB decoding, chromatic adaptation of the camera's white to equal-energy white, mean
    /// over each mask region. Writes a .rad file of plastics (Radiance RGB).
    Photo(PhotoArgs),
    /// Reflectance maps from a calibrated HDR picture and points of known reflectance, the
    /// illuminance-proxy method (Mardaljevic et al.): E = pi L / rho at the points, ordinary
    /// kriging of E (fitted variogram), rho = pi L / E per pixel, means per mask region.
    Proxy(ProxyArgs),
}

#[derive(clap::Args, Debug)]
pub struct ProxyArgs {
    /// Calibrated HDR picture: Radiance (.hdr, .pic; RGBE or XYZE) or OpenEXR (.exr).
    pub picture: PathBuf,
    /// Known points: lines `x, y, rho` or `x, y, r, g, b` (pixels from the top left,
    /// 0-based; Radiance RGB reflectance). RGB points on an RGB picture give three-channel
    /// maps; otherwise luminance.
    #[arg(long)]
    pub points: PathBuf,
    /// Material mask (PNG, one colour per material) for the per-material means.
    #[arg(long)]
    pub mask: Option<PathBuf>,
    /// Legend of the mask (`rrggbb, name` lines).
    #[arg(long)]
    pub legend: Option<PathBuf>,
    /// Illumination zones (PNG, one colour per planar surface): kriging per zone.
    #[arg(long)]
    pub zones: Option<PathBuf>,
    /// Variogram model fitted to the points' illuminance.
    #[arg(long, value_enum, default_value = "spherical")]
    pub variogram: VariogramArg,
    /// Half width of the window averaged at each known point (pixels of the same material;
    /// at most 64: a 129-pixel square is already a region, not a point).
    #[arg(long, default_value_t = 1, value_parser = super::at_most::<64>)]
    pub window: usize,
    /// Drop reflectances below the 5th and above the 95th percentile of each region.
    #[arg(long)]
    pub trim: bool,
    /// Luminance only, even with an RGB picture and RGB points.
    #[arg(long)]
    pub mono: bool,
    /// Write the pixel-wise reflectance map (.hdr, or .exr by extension).
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
    /// Write the kriged illuminance map (.hdr or .exr).
    #[arg(long, value_name = "FILE")]
    pub illuminance: Option<PathBuf>,
    #[command(flatten)]
    pub out: MaterialOut,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum VariogramArg {
    Spherical,
    Exponential,
}

#[derive(clap::Args, Debug)]
pub struct PhotoArgs {
    /// The photo (JPEG or PNG, sRGB-encoded).
    pub photo: PathBuf,
    /// Mask picture (PNG): one flat colour per material, same size as the photo.
    #[arg(long)]
    pub mask: PathBuf,
    /// Legend (CSV lines `rrggbb, name[, known reflectance][, reference]`); without it every
    /// non-black mask colour is a material named m_rrggbb. An entry with a known reflectance
    /// (1 or 3 values) is a white/grey reference card.
    #[arg(long)]
    pub legend: Option<PathBuf>,
    /// The white reference as a rectangle of the photo: x0 y0 x1 y1 (pixels, inclusive, y
    /// from the top); give its reflectance with --white-rho.
    #[arg(long, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"])]
    pub white_rect: Option<Vec<usize>>,
    /// Reflectance of the --white-rect card: 1 (grey) or 3 (Radiance RGB) values.
    #[arg(value_parser = super::finite, long, num_args = 1..=3, default_values_t = [0.9])]
    pub white_rho: Vec<f64>,
    /// Grey world: the masked pixels average to this grey reflectance (no card).
    #[arg(value_parser = super::finite, long, value_name = "RHO")]
    pub grey_world: Option<f64>,
    /// Trust the camera's white balance and exposure (sRGB white = reflectance 1): the plain
    /// D65 -> equal-energy adaptation.
    #[arg(long)]
    pub camera_white: bool,
    /// Chromatic adaptation transform.
    #[arg(long, value_enum, default_value = "bradford")]
    pub cat: CatArg,
    #[command(flatten)]
    pub out: MaterialOut,
}

#[derive(clap::Args, Debug)]
pub struct MaterialOut {
    /// Drop mask pixels within N pixels of another material (mixed edge pixels; at most 64).
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = super::at_most::<64>)]
    pub erode: usize,
    /// Write each material as a spectrum (uplifted with --method) + plastic instead of an
    /// RGB plastic.
    #[arg(long)]
    pub spectrum: bool,
    /// Uplifting method for --spectrum.
    #[arg(long, value_enum, default_value = "basis")]
    pub method: MethodArg,
    /// Specularity of the plastics.
    #[arg(value_parser = super::finite, long, default_value_t = 0.0)]
    pub spec: f64,
    /// Roughness of the plastics.
    #[arg(value_parser = super::finite, long, default_value_t = 0.0)]
    pub rough: f64,
    /// Also write the estimates as a CSV table (name,pixels,r,g,b,photopic,note).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write the .rad materials here instead of standard output.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum CatArg {
    Bradford,
    VonKries,
    XyzScaling,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum Space {
    Radiance,
    Srgb,
    SrgbLinear,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum MethodArg {
    Basis,
    Jakob,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum Format {
    Rad,
    Specfile,
    Csv,
}

impl From<Space> for RgbSpace {
    fn from(s: Space) -> RgbSpace {
        match s {
            Space::Radiance => RgbSpace::Radiance,
            Space::Srgb => RgbSpace::Srgb,
            Space::SrgbLinear => RgbSpace::SrgbLinear,
        }
    }
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Basis => Method::Basis,
            MethodArg::Jakob => Method::Jakob,
        }
    }
}

impl From<CatArg> for Cat {
    fn from(c: CatArg) -> Cat {
        match c {
            CatArg::Bradford => Cat::Bradford,
            CatArg::VonKries => Cat::VonKries,
            CatArg::XyzScaling => Cat::XyzScaling,
        }
    }
}

impl Common {
    pub fn to_config(&self) -> Config {
        Config {
            space: self.space.into(),
            method: self.method.into(),
            format: match self.format {
                Format::Rad => colours::Format::Rad,
                Format::Specfile => colours::Format::Specfile,
                Format::Csv => colours::Format::Csv,
            },
            spec: self.spec,
            rough: self.rough,
            table: self.table.clone(),
            table_res: self.table_res,
            progress: super::progress::Bars::reporter("ruplift"),
        }
    }
}

impl MaterialOut {
    pub fn to_config(&self) -> run::MaterialOut {
        run::MaterialOut {
            erode: self.erode,
            spectrum: self.spectrum.then(|| self.method.into()),
            spec: self.spec,
            rough: self.rough,
            csv: self.csv.clone(),
            output: self.output.clone(),
        }
    }
}

impl PhotoArgs {
    pub fn to_run(&self) -> run::Photo {
        run::Photo {
            photo: self.photo.clone(),
            mask: self.mask.clone(),
            legend: self.legend.clone(),
            // clap takes exactly four values.
            white_rect: self.white_rect.as_ref().map(|r| [r[0], r[1], r[2], r[3]]),
            white_rho: self.white_rho.clone(),
            grey_world: self.grey_world,
            camera_white: self.camera_white,
            cat: self.cat.into(),
            out: self.out.to_config(),
        }
    }
}

impl ProxyArgs {
    pub fn to_run(&self) -> run::Proxy {
        run::Proxy {
            picture: self.picture.clone(),
            points: self.points.clone(),
            mask: self.mask.clone(),
            legend: self.legend.clone(),
            zones: self.zones.clone(),
            options: proxy::Options {
                family: match self.variogram {
                    VariogramArg::Spherical => Family::Spherical,
                    VariogramArg::Exponential => Family::Exponential,
                },
                window: self.window,
                trim: self.trim,
                mono: self.mono,
            },
            map: self.map.clone(),
            illuminance: self.illuminance.clone(),
            out: self.out.to_config(),
        }
    }
}
