//! `ruplift`: spectral uplifting, RGB -> smooth bounded reflectance spectrum for Radiance 6.
//! The models are in `rdaylight::uplift`; this file parses options, reads and writes.

use clap::{Parser, Subcommand, ValueEnum};
use rdaylight::Error;
use rdaylight::error::IoContext;
use rdaylight::uplift::output::{parse_batch, write_csv, write_rad, write_specfile};
use rdaylight::uplift::{Method, RgbSpace, Spectrum, Uplifted, Uplifter, eval};
use std::io::{Read, Write};

const EXAMPLES: &str = "\
Examples:
  A plastic with a measured-like spectrum for a Radiance RGB colour:
    ruplift rgb 0.6 0.35 0.2 --name wall > wall.rad
    oconv wall.rad room.rad > room.oct; rtrace -cs 20 -co ...
  An sRGB swatch (gamma-encoded, D65) as a specfile data file:
    ruplift rgb 0.8 0.5 0.3 --space srgb --format specfile > swatch.dat
  Many colours (lines 'name R G B') to scene text or CSV:
    ruplift batch colours.txt > materials.rad
    ruplift batch --format csv colours.txt > spectra.csv
  The validation tables (docs/uplift-validation.md):
    ruplift validate";

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
    Validate,
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

fn uplifter(c: &Common) -> Uplifter {
    let space = match c.space {
        Space::Radiance => RgbSpace::Radiance,
        Space::Srgb => RgbSpace::Srgb,
        Space::SrgbLinear => RgbSpace::SrgbLinear,
    };
    let method = match c.method {
        MethodArg::Basis => Method::Basis,
        MethodArg::Jakob => Method::Jakob,
    };
    Uplifter::new(space, method)
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
    let u = uplifter(c);
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
        Command::Validate => {
            let sweep = eval::basis_k_sweep(&[3, 4, 5, 6, 7, 8, 10, 12]);
            let rows = eval::validate()?;
            write!(out, "{}", eval::report(&rows, &sweep)).at_path("<stdout>")?;
        }
    }
    out.flush().at_path("<stdout>")
}

fn main() {
    rdaylight::cli::run("ruplift", real_main)
}
