//! `ruplift`: spectral uplifting, RGB -> smooth bounded reflectance spectrum for Radiance 6.
//! The models are in `rdaylight::uplift`; this file parses options, reads and writes.

use clap::{Parser, Subcommand, ValueEnum};
use rdaylight::Error;
use rdaylight::error::IoContext;
use rdaylight::formats::picture::Picture;
use rdaylight::formats::picture::exr::{read_exr, write_exr};
use rdaylight::formats::picture::preview::read_photo;
use rdaylight::uplift::kriging::Family;
use rdaylight::uplift::mask::{LabelMap, Legend, reflectance_values};
use rdaylight::uplift::output::{MaterialRow, write_material_table, write_materials};
use rdaylight::uplift::output::{parse_batch, write_csv, write_rad, write_specfile};
use rdaylight::uplift::photo::{self, Cat, White};
use rdaylight::uplift::proxy;
use rdaylight::uplift::table::JakobTable;
use rdaylight::uplift::{Method, RgbSpace, Spectrum, Uplifted, Uplifter, eval};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
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
#[command(name = "ruplift", after_help = EXAMPLES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Debug)]
struct Common {
    /// Colour space of the input: `radiance` (linear, Radiance's standard primaries,
    /// equal-energy white), `srgb` (gamma-encoded, D65) or `srgb-linear`.
    #[arg(long, value_enum, default_value = "radiance")]
    space: Space,
    /// Uplifting method.
    #[arg(long, value_enum, default_value = "basis")]
    method: MethodArg,
    /// Output: `rad` (spectrum + plastic), `specfile` (Radiance data file), `csv`.
    #[arg(long, value_enum, default_value = "rad")]
    format: Format,
    /// Specularity of the plastic (rad output).
    #[arg(long, default_value_t = 0.0)]
    spec: f64,
    /// Roughness of the plastic (rad output).
    #[arg(long, default_value_t = 0.0)]
    rough: f64,
    /// Jakob & Hanika coefficient table (with --method jakob): read FILE if it exists,
    /// else build it (--table-res) and save it there. Lookups start the fit near the answer.
    #[arg(long, value_name = "FILE")]
    table: Option<PathBuf>,
    /// Resolution of a table being built (entries per axis; 3 res^3 fits).
    #[arg(long, default_value_t = 32, value_name = "N")]
    table_res: usize,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Uplift one colour.
    Rgb {
        /// Red, green, blue: linear reflectance-like values in 0..1 for `radiance` and
        /// `srgb-linear`, encoded 0..1 values for `srgb`. Values outside the gamut are
        /// accepted (closest spectrum, warning on stderr).
        #[arg(allow_negative_numbers = true)]
        r: f64,
        #[arg(allow_negative_numbers = true)]
        g: f64,
        #[arg(allow_negative_numbers = true)]
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
struct ProxyArgs {
    /// Calibrated HDR picture: Radiance (.hdr, .pic; RGBE or XYZE) or OpenEXR (.exr).
    picture: PathBuf,
    /// Known points: lines `x, y, rho` or `x, y, r, g, b` (pixels from the top left,
    /// 0-based; Radiance RGB reflectance). RGB points on an RGB picture give three-channel
    /// maps; otherwise luminance.
    #[arg(long)]
    points: PathBuf,
    /// Material mask (PNG, one colour per material) for the per-material means.
    #[arg(long)]
    mask: Option<PathBuf>,
    /// Legend of the mask (`rrggbb, name` lines).
    #[arg(long)]
    legend: Option<PathBuf>,
    /// Illumination zones (PNG, one colour per planar surface): kriging per zone.
    #[arg(long)]
    zones: Option<PathBuf>,
    /// Variogram model fitted to the points' illuminance.
    #[arg(long, value_enum, default_value = "spherical")]
    variogram: VariogramArg,
    /// Half width of the window averaged at each known point (pixels of the same material).
    #[arg(long, default_value_t = 1)]
    window: usize,
    /// Drop reflectances below the 5th and above the 95th percentile of each region.
    #[arg(long)]
    trim: bool,
    /// Luminance only, even with an RGB picture and RGB points.
    #[arg(long)]
    mono: bool,
    /// Write the pixel-wise reflectance map (.hdr, or .exr by extension).
    #[arg(long, value_name = "FILE")]
    map: Option<PathBuf>,
    /// Write the kriged illuminance map (.hdr or .exr).
    #[arg(long, value_name = "FILE")]
    illuminance: Option<PathBuf>,
    #[command(flatten)]
    out: MaterialOut,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum VariogramArg {
    Spherical,
    Exponential,
}

#[derive(clap::Args, Debug)]
struct PhotoArgs {
    /// The photo (JPEG or PNG, sRGB-encoded).
    photo: PathBuf,
    /// Mask picture (PNG): one flat colour per material, same size as the photo.
    #[arg(long)]
    mask: PathBuf,
    /// Legend (CSV lines `rrggbb, name[, known reflectance][, reference]`); without it every
    /// non-black mask colour is a material named m_rrggbb. An entry with a known reflectance
    /// (1 or 3 values) is a white/grey reference card.
    #[arg(long)]
    legend: Option<PathBuf>,
    /// The white reference as a rectangle of the photo: x0 y0 x1 y1 (pixels, inclusive, y
    /// from the top); give its reflectance with --white-rho.
    #[arg(long, num_args = 4, value_names = ["X0", "Y0", "X1", "Y1"])]
    white_rect: Option<Vec<usize>>,
    /// Reflectance of the --white-rect card: 1 (grey) or 3 (Radiance RGB) values.
    #[arg(long, num_args = 1..=3, default_values_t = [0.9])]
    white_rho: Vec<f64>,
    /// Grey world: the masked pixels average to this grey reflectance (no card).
    #[arg(long, value_name = "RHO")]
    grey_world: Option<f64>,
    /// Trust the camera's white balance and exposure (sRGB white = reflectance 1): the plain
    /// D65 -> equal-energy adaptation.
    #[arg(long)]
    camera_white: bool,
    /// Chromatic adaptation transform.
    #[arg(long, value_enum, default_value = "bradford")]
    cat: CatArg,
    #[command(flatten)]
    out: MaterialOut,
}

#[derive(clap::Args, Debug)]
struct MaterialOut {
    /// Drop mask pixels within N pixels of another material (mixed edge pixels).
    #[arg(long, default_value_t = 1, value_name = "N")]
    erode: usize,
    /// Write each material as a spectrum (uplifted with --method) + plastic instead of an
    /// RGB plastic.
    #[arg(long)]
    spectrum: bool,
    /// Uplifting method for --spectrum.
    #[arg(long, value_enum, default_value = "basis")]
    method: MethodArg,
    /// Specularity of the plastics.
    #[arg(long, default_value_t = 0.0)]
    spec: f64,
    /// Roughness of the plastics.
    #[arg(long, default_value_t = 0.0)]
    rough: f64,
    /// Also write the estimates as a CSV table (name,pixels,r,g,b,photopic,note).
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write the .rad materials here instead of standard output.
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum CatArg {
    Bradford,
    VonKries,
    XyzScaling,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum Space {
    Radiance,
    Srgb,
    SrgbLinear,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum MethodArg {
    Basis,
    Jakob,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
enum Format {
    Rad,
    Specfile,
    Csv,
}

fn uplifter(c: &Common) -> Result<Uplifter, Error> {
    let space = match c.space {
        Space::Radiance => RgbSpace::Radiance,
        Space::Srgb => RgbSpace::Srgb,
        Space::SrgbLinear => RgbSpace::SrgbLinear,
    };
    let method = match c.method {
        MethodArg::Basis => Method::Basis,
        MethodArg::Jakob => Method::Jakob,
    };
    let u = Uplifter::new(space, method);
    let Some(path) = &c.table else {
        return Ok(u);
    };
    let shown = path.display().to_string();
    let table = if path.exists() {
        let bytes = std::fs::read(path).at_path(&shown)?;
        JakobTable::read(&bytes, &shown)?
    } else {
        if method != Method::Jakob {
            return Err(Error::Usage("--table is for --method jakob".into()));
        }
        let t = JakobTable::build(space, c.table_res)?;
        rdaylight::io::write_atomically(path, |w| t.write(w).at_path(&shown))?;
        t
    };
    u.with_table(table)
}

fn describe(name: &str, rgb: [f64; 3], c: &Common, up: &Uplifted) -> String {
    format!(
        "ruplift: {name} rgb {} {} {} ({:?}), method {:?}, dE*ab {:.2e}",
        rgb[0], rgb[1], rgb[2], c.space, c.method, up.delta_e
    )
}

/// Uplifts beyond this Delta E*ab are reported as out of gamut.
const GAMUT_WARN: f64 = 0.01;

fn emit(out: &mut dyn Write, items: &[(String, [f64; 3])], c: &Common) -> Result<(), Error> {
    if c.format == Format::Specfile && items.len() != 1 {
        return Err(Error::Usage(
            "--format specfile writes one spectrum; use rad or csv for batches".into(),
        ));
    }
    let u = uplifter(c)?;
    let mut csv: Vec<(String, Spectrum)> = Vec::new();
    for (name, rgb) in items {
        let up = u.uplift_rgb(*rgb);
        let note = describe(name, *rgb, c, &up);
        if up.delta_e > GAMUT_WARN {
            eprintln!("{note}: out of gamut, closest spectrum written");
        }
        match c.format {
            Format::Rad => {
                writeln!(out, "# {note}").at_path("<stdout>")?;
                write_rad(out, name, &up.spectrum, c.spec, c.rough).at_path("<stdout>")?;
            }
            Format::Specfile => write_specfile(out, &note, &up.spectrum).at_path("<stdout>")?,
            Format::Csv => csv.push((name.clone(), up.spectrum)),
        }
    }
    if c.format == Format::Csv {
        write_csv(out, &csv).at_path("<stdout>")?;
    }
    Ok(())
}

fn load_mask(mask: &Path, legend: Option<&PathBuf>, erode: usize) -> Result<LabelMap, Error> {
    let legend = legend.map(|p| Legend::open(p)).transpose()?;
    Ok(LabelMap::open(mask, legend)?.erode(erode))
}

/// Write the .rad materials (stdout or -o, atomically) and the optional CSV table.
fn write_outputs(rows: &[MaterialRow], o: &MaterialOut, command: &str) -> Result<(), Error> {
    if rows.is_empty() {
        return Err(Error::Usage(
            "no material has any pixel left in the mask (check colours, legend and --erode)".into(),
        ));
    }
    let uplifter = o.spectrum.then(|| {
        let method = match o.method {
            MethodArg::Basis => Method::Basis,
            MethodArg::Jakob => Method::Jakob,
        };
        Uplifter::new(RgbSpace::Radiance, method)
    });
    let rad = |w: &mut dyn Write| -> Result<(), Error> {
        writeln!(w, "# {command}").at_path("<output>")?;
        write_materials(w, rows, uplifter.as_ref(), o.spec, o.rough).at_path("<output>")
    };
    if let Some(t) = &o.csv {
        rdaylight::io::write_atomically(t, |w| {
            write_material_table(w, rows).at_path(&t.display().to_string())
        })?;
    }
    match &o.output {
        Some(p) => rdaylight::io::write_atomically(p, rad),
        None => {
            let stdout = std::io::stdout();
            let mut out = std::io::BufWriter::new(stdout.lock());
            rad(&mut out)?;
            out.flush().at_path("<stdout>")
        }
    }
}

fn photo_cmd(a: &PhotoArgs) -> Result<(), Error> {
    let picture = read_photo(&a.photo)?;
    let mask = load_mask(&a.mask, a.legend.as_ref(), a.out.erode)?;
    let chosen = [
        a.white_rect.is_some(),
        a.grey_world.is_some(),
        a.camera_white,
    ];
    if chosen.iter().filter(|c| **c).count() > 1 {
        return Err(Error::Usage(
            "choose one white: --white-rect, --grey-world or --camera-white".into(),
        ));
    }
    let white = if let Some(r) = &a.white_rect {
        let text: Vec<String> = a.white_rho.iter().map(|v| v.to_string()).collect();
        let known = reflectance_values(&text.join(" "))
            .map_err(|m| Error::Usage(format!("--white-rho: {m}")))?;
        White::Rect {
            rect: [r[0], r[1], r[2], r[3]],
            known,
        }
    } else if let Some(g) = a.grey_world {
        White::GreyWorld(g)
    } else if a.camera_white {
        White::Camera
    } else {
        White::Legend
    };
    let cat = match a.cat {
        CatArg::Bradford => Cat::Bradford,
        CatArg::VonKries => Cat::VonKries,
        CatArg::XyzScaling => Cat::XyzScaling,
    };
    let est = photo::estimate(&picture, &mask, &white, cat)?;
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
        cat
    );
    write_outputs(&rows, &a.out, &command)
}

fn is_exr(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

fn save_picture(p: &Picture, path: &Path) -> Result<(), Error> {
    if is_exr(path) {
        write_exr(p, path)
    } else {
        p.save(path, true)
    }
}

fn proxy_cmd(a: &ProxyArgs) -> Result<(), Error> {
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
    let opts = proxy::Options {
        family: match a.variogram {
            VariogramArg::Spherical => Family::Spherical,
            VariogramArg::Exponential => Family::Exponential,
        },
        window: a.window,
        trim: a.trim,
        mono: a.mono,
    };
    let r = proxy::run(
        &picture,
        &points,
        mask.as_ref(),
        zones.as_ref(),
        &shown,
        &opts,
    )?;
    for (name, n, v) in &r.zones {
        let v = v.map_or(
            "constant (too few points or no variance)".to_string(),
            |v| {
                format!(
                    "{:?} nugget {:.4e}, partial sill {:.4e}, range {:.1} px",
                    v.family, v.nugget, v.psill, v.range
                )
            },
        );
        eprintln!("ruplift proxy: zone {name}: {n} points, variogram {v}");
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
                if a.trim { ", 5/95 % trimmed" } else { "" }
            ),
        })
        .collect();
    let command = format!(
        "ruplift proxy {} --points {} (illuminance proxy, ordinary kriging)",
        a.picture.display(),
        shown
    );
    write_outputs(&rows, &a.out, &command)
}

fn real_main() -> Result<(), Error> {
    let cli = Cli::parse();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    match cli.command {
        Command::Rgb {
            r,
            g,
            b,
            name,
            common,
        } => {
            if name.is_empty() || name.chars().any(|c| c.is_whitespace()) {
                return Err(Error::Usage(format!(
                    "--name must be one word without white space, got '{name}'"
                )));
            }
            if ![r, g, b].iter().all(|v| v.is_finite()) {
                return Err(Error::Usage(format!(
                    "R G B must be finite numbers, got {r} {g} {b}"
                )));
            }
            emit(&mut out, &[(name, [r, g, b])], &common)?;
        }
        Command::Batch { input, common } => {
            let mut text = String::new();
            if input == "-" {
                std::io::stdin()
                    .read_to_string(&mut text)
                    .at_path("<stdin>")?;
            } else {
                text = std::fs::read_to_string(&input).at_path(&input)?;
            }
            let shown = if input == "-" { "<stdin>" } else { &input };
            let items = parse_batch(&text, shown)?;
            if items.is_empty() {
                return Err(Error::Usage(format!("no 'name R G B' lines in {shown}")));
            }
            emit(&mut out, &items, &common)?;
        }
        Command::Validate { plot } => {
            if let Some(p) = plot {
                let shown = p.display().to_string();
                eval::error_plot()
                    .save(&p)
                    .map_err(|e| Error::Usage(format!("{shown}: cannot write the plot: {e}")))?;
            }
            let sweep = eval::basis_k_sweep(&[3, 4, 5, 6, 7, 8, 10, 12]);
            let rows = eval::validate()?;
            write!(out, "{}", eval::report(&rows, &sweep)).at_path("<stdout>")?;
        }
        Command::Photo(a) => photo_cmd(&a)?,
        Command::Proxy(a) => proxy_cmd(&a)?,
    }
    out.flush().at_path("<stdout>")
}

fn main() {
    rdaylight::cli::run("ruplift", real_main)
}
