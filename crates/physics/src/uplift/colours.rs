//! # Uplifting listed colours to files (`ruplift rgb`, `ruplift batch`)
//!
//! A typed configuration ([`Config`]: colour space, method, output [`Format`], plastic
//! parameters, the Jakob & Hanika coefficient table file) and the calls that uplift named
//! colours and write them: Radiance `spectrum` + `plastic` text, a `specfile` data file or
//! CSV. Colours the gamut cannot reproduce get the closest spectrum and a note (beyond
//! [`GAMUT_WARN`]). The command line (clap) is the tools layer's (`rdaylight::cli::ruplift`).

use super::output::{parse_batch, write_csv, write_rad, write_specfile};
use super::table::JakobTable;
use super::{Method, RgbSpace, Spectrum, Uplifted, Uplifter};
use crate::error::{Error, IoContext, Result};
use std::io::{Read, Write};
use std::path::PathBuf;

/// Uplifts beyond this Delta E*ab are reported as out of gamut.
pub const GAMUT_WARN: f64 = 0.01;

/// What is written per colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `spectrum` + `plastic` scene text.
    Rad,
    /// One spectrum as a Radiance data file (one colour only).
    Specfile,
    /// All spectra as CSV.
    Csv,
}

/// How colours are uplifted and written.
#[derive(Debug, Clone)]
pub struct Config {
    pub space: RgbSpace,
    pub method: Method,
    pub format: Format,
    /// Specularity and roughness of the plastic (rad output).
    pub spec: f64,
    pub rough: f64,
    /// Jakob & Hanika coefficient table: read if it exists, else built and saved there.
    pub table: Option<PathBuf>,
    /// Entries per axis of a table being built.
    pub table_res: usize,
    /// Where building the table reports its progress.
    pub progress: crate::progress::Reporter,
}

impl Config {
    /// The uplifter, with the coefficient table read or built (and saved) when one is named.
    pub fn uplifter(&self) -> Result<Uplifter> {
        let u = Uplifter::new(self.space, self.method);
        let Some(path) = &self.table else {
            return Ok(u);
        };
        let shown = path.display().to_string();
        let table = if path.exists() {
            let bytes = std::fs::read(path).at_path(&shown)?;
            JakobTable::read(&bytes, &shown)?
        } else {
            if self.method != Method::Jakob {
                return Err(Error::Usage("--table is for --method jakob".into()));
            }
            let t = JakobTable::build_reporting(self.space, self.table_res, self.progress.get())?;
            crate::io::write_atomically(path, |w| t.write(w).at_path(&shown))?;
            t
        };
        u.with_table(table)
    }

    fn describe(&self, name: &str, rgb: [f64; 3], up: &Uplifted) -> String {
        format!(
            "ruplift: {name} rgb {} {} {} ({:?}), method {:?}, dE*ab {:.2e}",
            rgb[0], rgb[1], rgb[2], self.space, self.method, up.delta_e
        )
    }
}

/// One named colour, checked: the name one word (`--name`), the values finite.
pub fn colour(name: &str, rgb: [f64; 3]) -> Result<(String, [f64; 3])> {
    if name.is_empty() || name.chars().any(|c| c.is_whitespace()) {
        return Err(Error::Usage(format!(
            "--name must be one word without white space, got '{name}'"
        )));
    }
    let [r, g, b] = rgb;
    if !rgb.iter().all(|v| v.is_finite()) {
        return Err(Error::Usage(format!(
            "R G B must be finite numbers, got {r} {g} {b}"
        )));
    }
    Ok((name.to_string(), rgb))
}

/// The `name R G B` lines of `input` (`-`: standard input), at least one.
pub fn read_batch(input: &str) -> Result<Vec<(String, [f64; 3])>> {
    let mut text = String::new();
    if input == "-" {
        std::io::stdin()
            .read_to_string(&mut text)
            .at_path("<stdin>")?;
    } else {
        text = std::fs::read_to_string(input).at_path(input)?;
    }
    let shown = if input == "-" { "<stdin>" } else { input };
    let items = parse_batch(&text, shown)?;
    if items.is_empty() {
        return Err(Error::Usage(format!("no 'name R G B' lines in {shown}")));
    }
    Ok(items)
}

/// Uplift `items` and write them to `out` as `c.format` says; out-of-gamut notes on `err`.
pub fn emit(
    out: &mut dyn Write,
    err: &mut dyn Write,
    items: &[(String, [f64; 3])],
    c: &Config,
) -> Result<()> {
    if c.format == Format::Specfile && items.len() != 1 {
        return Err(Error::Usage(
            "--format specfile writes one spectrum; use rad or csv for batches".into(),
        ));
    }
    let u = c.uplifter()?;
    let mut csv: Vec<(String, Spectrum)> = Vec::new();
    for (name, rgb) in items {
        let up = u.uplift_rgb(*rgb);
        let note = c.describe(name, *rgb, &up);
        if up.delta_e > GAMUT_WARN {
            let _ = writeln!(err, "{note}: out of gamut, closest spectrum written");
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
