//! # `rmtx`'s command line: rmtxop's and dctimestep's letters
//!
//! The tools layer's half of `rmtx`: the clap struct and its conversion into the library's
//! typed job ([`Pipeline`], `rdaylight::formats::matrix::pipeline`), which opens, checks,
//! multiplies and writes. `-c`/`-s` take numbers up to the first non-number as rmtxop does
//! ([`Options::parse_from`] gives the file names clap took for them back to the inputs).

use crate::error::{Error, Result};
use crate::formats::hours::HourSpan;
use crate::formats::matrix::{DataFormat, Pipeline, ReadOptions, Term};
use clap::{CommandFactory, FromArgMatches, Parser};

pub const EXAMPLES: &str = "\
Examples:
  The three-phase product with a BSDF file for T (as dctimestep V T D s):
    rmtx -ff -c 47.4 119.9 11.6 view.vmx blinds.xml daylight.dmx sky.smx > ill.mtx
  Daylight coefficients times a sky matrix, to illuminance in lux (as dctimestep | rmtxop):
    gendaymtx -m 1 -of site.wea > sky.smx
    rmtx dc.mtx sky.smx -c 47.4 119.9 11.6 -fa > ill.txt
  Convert rcontrib's headerless ascii (-h, no -y) to float with a header:
    rcontrib -h -I+ ... | rmtx -ia -ff - > dc.mtx
  Spectral coefficients times a spectral sky matrix, to illuminance and Radiance's M:
    rmtx dc18.mtx sky18.smx -c YM -fa > ill_M.txt
  Stack sensor blocks computed on two machines:
    rmtx --cat part1.mtx part2.mtx > dc.mtx
  Merge the shards of rdc --shard K/3 (checked: one run, all shards, in order; the result
  has the unsharded run's bytes), with their manifests (checked: same inputs and version):
    rmtx --cat dc.0.mtx dc.1.mtx dc.2.mtx --manifests m0.json m1.json m2.json > dc.mtx
  An annual product in time chunks (hours 0-based, A included, B not), merged back into
  the whole product's bytes:
    rmtx -ff -c 47.4 119.9 11.6 --hours 0:4380 dc.mtx sky.smx > ill.0.mtx
    rmtx -ff -c 47.4 119.9 11.6 --hours 4380:8760 dc.mtx sky.smx > ill.1.mtx
    rmtx --cat-columns ill.0.mtx ill.1.mtx > ill.mtx
  The same as array task K of N (the K-th of N blocks of hours), with manifests:
    rmtx -ff dc.mtx sky.smx --hours $K/$N --manifest ill.$K.json > ill.$K.mtx
  The five-phase combination in one streamed pass (3-phase total, minus its direct part,
  plus the sun coefficients; products bind tighter than +):
    rmtx -fa V.mtx T.xml D.mtx sky.smx + -s -1 Vd.mtx T.xml Dd.mtx skyd.smx + cds.mtx suns.smx
  Which rdc shards are complete (one line each; status 1 names the others):
    rmtx --verify dc.0.mtx dc.1.mtx dc.2.mtx --manifests m0.json m1.json m2.json";

/// Radiance matrix operations (rmtxop/dctimestep counterpart).
///
/// With one input: convert it (format, -c, -s, -t). With several: multiply them left to
/// right, per channel (RGB x RGB multiplies red by red, as dctimestep and rmtxop do); the
/// first input is streamed row by row, the others are held in memory, except the last (the
/// sky) when holding it costs more than the first input's rows and the result: then its rows
/// are streamed into the result (same bytes; an MF 4 year takes 78 MB). Shapes and NCOMP of
/// every input are checked before anything is written. -c, -s and -t apply to the result
/// wherever they appear (unlike rmtxop, where options before a matrix apply to that matrix).
/// EXPOSURE=/COLORCORR= in input headers are divided out on load, as rmtxop does. `+`
/// between inputs adds products, each streamed in lock step; products bind tighter than
/// `+` (rmtxop evaluates strictly left to right: the same wherever each added term is a
/// single matrix).
#[derive(Parser, Debug)]
#[command(name = "rmtx", version, disable_help_flag = true, after_help = EXAMPLES)]
pub struct Options {
    /// Output format a|f|d|c (-fa ascii, -ff float, -fd double, -fc RGBE picture rows or
    /// Radiance_spectra for NCOMP > 3; rmtxop -f). Default: the
    /// lowest-precision input format in Radiance's order (float < ascii < double), i.e. a
    /// single input keeps its own format.
    #[arg(short = 'f', value_name = "a|f|d|c")]
    pub format: Option<String>,

    /// Write no header (Radiance -h).
    #[arg(short = 'h')]
    pub no_header: bool,

    /// Transpose the result (rmtxop -t after the last matrix). Holds the result in memory.
    #[arg(short = 't')]
    pub transpose: bool,

    /// Channel transform of the result (rmtxop -c): N x NCOMP coefficients, e.g.
    /// `-c 47.4 119.9 11.6` (RGB irradiance to lux), or one symbolic word, one output
    /// component per letter: R G B, X Y Z (x 179), S scotopic (x 412), M melanopic (x 179,
    /// Radiance's equal-energy-normalised value: m-EDI = 0.9233 M), A mean; lower case
    /// without the factor. On RGB, `-c Y` = 179 x (0.265106 0.670106 0.064788); on
    /// spectral matrices (NCOMP > 3) the bands come from WAVELENGTH_SPLITS and are weighted
    /// with Radiance's own observer tables, as rmtxop does.
    #[arg(short = 'c', num_args = 1.., allow_negative_numbers = true, value_name = "W")]
    pub coefs: Vec<String>,

    /// Scale the result (rmtxop -s): one factor, or one per output component.
    #[arg(short = 's', num_args = 1.., allow_negative_numbers = true, value_name = "F")]
    pub scale: Vec<String>,

    /// Concatenate row blocks of inputs with equal NCOLS and NCOMP instead of multiplying
    /// (like `cat` of headerless blocks; rcollate/rcomb have no single equivalent). Outputs
    /// of rdc --shard K/N (a SHARD= header line) are checked to be all N shards of one run,
    /// in order, and merged verbatim under the unsharded run's header.
    #[arg(long = "cat")]
    pub cat: bool,

    /// Join column blocks of inputs with equal NROWS and NCOMP side by side instead of
    /// multiplying. Outputs of rmtx --hours (a HOURS= header line) are checked to be the
    /// chunks of one product whose hours follow each other from 0 to its NCOLS, in order,
    /// and merged verbatim under the whole product's header.
    #[arg(long = "cat-columns")]
    pub cat_columns: bool,

    /// With --cat of rdc shards or --cat-columns of hour chunks: their manifests (rdc
    /// --manifest, rmtx --manifest), one per piece in the same order; refuses pieces of
    /// different inputs, versions or seeds and names missing shard indices. Takes every
    /// following word: put it last.
    #[arg(long = "manifests", num_args = 1.., value_name = "JSON")]
    pub manifests: Vec<String>,

    /// Only hours A:B of the result: columns A to B of the right-most matrix (the sky's
    /// time steps), 0-based, A included and B not (0:730 is the first 730 hours; chunks
    /// 0:730 and 730:1460 follow each other), 0 <= A < B <= NCOLS. K/N: the K-th (0-based)
    /// of N blocks, NCOLS/N hours each, the first NCOLS%N one more. The header gets
    /// HOURS= A:B TOTAL; rmtx --cat-columns of all chunks equals the whole product byte for
    /// byte. Only the chunk's columns of the sky are held in memory.
    #[arg(long = "hours", value_name = "A:B|K/N")]
    pub hours: Option<String>,

    /// Check rdc shard files, each against its own manifest (--manifests, same order): its
    /// SHARD= line and rows, the data's size and the FNV-1a hash of the bytes the job
    /// wrote. Prints one line per shard (complete, or what is wrong) and fails naming
    /// those that are missing, incomplete or corrupt; merges nothing. What
    /// examples/slurm/resume.sh runs to decide which array tasks to submit again.
    #[arg(long = "verify")]
    pub verify: bool,

    /// With --hours: write the chunk's manifest (JSON: version, command, hours, each input
    /// file's size and FNV-1a 64 hash) once the output is complete.
    #[arg(long = "manifest", value_name = "FILE")]
    pub manifest: Option<String>,

    /// Format a|f|d of inputs without a header (dctimestep -i; rcontrib/rtrace/gendaymtx -h).
    #[arg(short = 'i', value_name = "a|f|d")]
    pub iformat: Option<String>,

    /// NCOMP of inputs without a header (default 3; at most 1024 bands).
    #[arg(long = "ncomp", value_name = "N", value_parser = super::at_most::<1024>)]
    pub ncomp: Option<usize>,

    /// NCOLS of inputs without a header (headerless ascii: inferred from the first line; at
    /// most 10 million, a minute-by-minute decade).
    #[arg(long = "ncols", value_name = "N", value_parser = super::at_most::<10_000_000>)]
    pub ncols: Option<usize>,

    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    pub help: Option<bool>,

    /// Matrix files; `-` is standard input (the default when none is given). `+` between
    /// them adds products (rmtxop's `+`): `rmtx V T D s + -s -1 Vd T Dd sd + Cds ssun` is
    /// the five-phase combination; `-s F` right after a `+` scales that term, any other
    /// `-s`/`-c` the sum.
    #[arg(value_name = "FILE|-|+")]
    pub inputs: Vec<String>,

    /// The terms after the first `+`, with their factors (filled by [`Options::parse_from`]).
    #[arg(skip)]
    pub terms: Vec<(Vec<String>, f64)>,
}

/// Split command-line inputs (with their positions) at `+` into the first product chain and
/// the added terms; a `-s` value written between a `+` and the term's first matrix is that
/// term's factor (rmtxop's rule), every other `-s` value scales the sum.
#[allow(clippy::type_complexity)]
fn sum_terms(
    inputs: &[(usize, String)],
    scale_at: &[(usize, String)],
) -> Result<(Vec<String>, Vec<(Vec<String>, f64)>, Vec<f64>)> {
    let mut chains: Vec<(usize, Vec<String>)> = vec![(0, Vec::new())];
    for (i, v) in inputs {
        if v == "+" {
            chains.push((*i, Vec::new()));
        } else if let Some(c) = chains.last_mut() {
            c.1.push(v.clone());
        }
    }
    let first_matrix = inputs.iter().find(|(_, v)| v != "+").map(|(i, _)| *i);
    let mut factors = vec![1.0; chains.len()];
    let mut result_scale = Vec::new();
    for (i, v) in scale_at {
        let x: f64 = v.parse().unwrap_or(f64::NAN);
        // The term whose `+` precedes this value with no matrix in between.
        let term = chains.iter().enumerate().skip(1).find(|(_, (plus, _))| {
            *plus < *i
                && !inputs
                    .iter()
                    .any(|(j, w)| w != "+" && *j > *plus && *j < *i)
        });
        match term {
            Some((k, _)) => {
                if factors[k] != 1.0 || !x.is_finite() {
                    return Err(Error::Usage(format!(
                        "-s after the + of term {}: one finite factor per term",
                        k + 1
                    )));
                }
                factors[k] = x;
            }
            None if first_matrix.is_some_and(|f| *i < f) => {
                return Err(Error::Usage(
                    "-s before the first matrix of a sum is ambiguous: write it after a + \
                     to scale that term, or after the last matrix to scale the sum"
                        .into(),
                ));
            }
            None => result_scale.push(x),
        }
    }
    if let Some(k) = chains.iter().position(|(_, c)| c.is_empty()) {
        return Err(Error::Usage(if k == 0 {
            "+ with no matrix before it: expected matrix files on both sides of +".into()
        } else {
            format!("+ number {k} has no matrix after it: expected matrix files on both sides of +")
        }));
    }
    let mut it = chains.into_iter().map(|(_, c)| c);
    let first = it.next().unwrap_or_default();
    let terms = it.zip(factors.into_iter().skip(1)).collect();
    Ok((first, terms, result_scale))
}

impl Options {
    /// Parse `args` (program name first); clap errors follow [`super::usage_error`].
    /// `-c`/`-s` take numbers up to the first non-number as rmtxop does,
    /// so file names that clap gave them go back to the inputs, in command-line order.
    pub fn parse_from(args: Vec<String>) -> Result<Options> {
        let m = Options::command()
            .try_get_matches_from(args)
            .map_err(super::usage_error)?;
        let mut opts = Options::from_arg_matches(&m).map_err(super::usage_error)?;
        let mut inputs: Vec<(usize, String)> = indexed(&m, "inputs");
        // A number that is not finite is an error, not a file name (`-c nan`, `-s inf`).
        for (id, opt) in [("coefs", "-c"), ("scale", "-s")] {
            if let Some((_, v)) = indexed(&m, id)
                .into_iter()
                .find(|(_, v)| v.parse::<f64>().is_ok_and(|x| !x.is_finite()))
            {
                return Err(Error::Usage(format!("{opt} {v}: expected finite numbers")));
            }
        }
        let split = |id: &str, symbolic: bool, inputs: &mut Vec<(usize, String)>| {
            let vals = indexed(&m, id);
            let mut n = vals
                .iter()
                .take_while(|(_, v)| v.parse::<f64>().is_ok())
                .count();
            if n == 0 && symbolic && !vals.is_empty() {
                n = 1;
            }
            inputs.extend(vals[n..].iter().cloned());
            vals[..n].iter().map(|(_, v)| v.clone()).collect::<Vec<_>>()
        };
        opts.coefs = split("coefs", true, &mut inputs);
        let scale_at: Vec<(usize, String)> = indexed(&m, "scale")
            .into_iter()
            .take_while(|(_, v)| v.parse::<f64>().is_ok())
            .collect();
        opts.scale = split("scale", false, &mut inputs);
        inputs.sort_by_key(|(i, _)| *i);
        if inputs.iter().any(|(_, v)| v == "+") {
            let (first, terms, scale) = sum_terms(&inputs, &scale_at)?;
            opts.inputs = first;
            opts.terms = terms;
            opts.scale = scale.iter().map(|x| x.to_string()).collect();
        } else {
            opts.inputs = inputs.into_iter().map(|(_, v)| v).collect();
        }
        Ok(opts)
    }

    /// The library's job; `command` goes into the header.
    pub fn to_pipeline(&self, command: Vec<String>) -> Result<Pipeline> {
        let read = ReadOptions {
            format: format_opt(&self.iformat, "-i")?,
            ncomp: self.ncomp,
            ncols: self.ncols,
            nrows: None,
            undo_exposure: true,
        };
        Ok(Pipeline {
            inputs: self.inputs.clone(),
            stack: self.cat,
            columns: self.cat_columns,
            read,
            coefs: self.coefs.clone(),
            scale: self.scale.iter().filter_map(|s| s.parse().ok()).collect(),
            format: format_opt(&self.format, "-f")?,
            transpose: self.transpose,
            header: !self.no_header,
            command: super::without_options(&command, &["--hours", "--manifest"]),
            seekable: crate::io::stdout_is_file(),
            manifests: self.manifests.clone(),
            hours: self
                .hours
                .as_deref()
                .map(|h| HourSpan::parse(h, "--hours"))
                .transpose()?,
            manifest: self.manifest.clone(),
            verify: self.verify,
            terms: self
                .terms
                .iter()
                .map(|(inputs, scale)| Term {
                    inputs: inputs.clone(),
                    scale: *scale,
                })
                .collect(),
            in_memory: xml_operands(
                self.inputs
                    .iter()
                    .chain(self.terms.iter().flat_map(|(t, _)| t.iter())),
            )?,
        })
    }
}

/// dctimestep's `T.xml`: an input ending in `.xml` is a BSDF file (LBNL WINDOW XML, Klems
/// data); its transmission matrix (rows: outgoing patches into the room, columns: incident
/// patches, each BSDF value times the incident patch's projected solid angle, RGB from
/// CIE X, Y, Z when the file has them: `material::bsdf::transmission_matrix`) is handed to
/// the pipeline in memory, in double precision.
fn xml_operands<'a>(inputs: impl Iterator<Item = &'a String>) -> Result<Vec<(String, Vec<u8>)>> {
    use crate::formats::header::Header;
    use crate::formats::matrix::{Matrix, WriteOptions};
    let mut out: Vec<(String, Vec<u8>)> = Vec::new();
    for p in inputs.filter(|p| p.to_ascii_lowercase().ends_with(".xml")) {
        if out.iter().any(|(n, _)| n == p) {
            continue;
        }
        let xml = crate::bsdf::load(std::path::Path::new(p))?;
        let t = crate::material::bsdf::transmission_matrix(&xml, p)?;
        let m = Matrix {
            nrows: t.nrows,
            ncols: t.ncols,
            channels: crate::radiometry::Channels::rgb(),
            data: t.rgb.iter().flatten().copied().collect(),
        };
        let bytes = m.write(
            Vec::new(),
            p,
            Header::new(),
            WriteOptions::new(DataFormat::Double),
        )?;
        out.push((p.clone(), bytes));
    }
    Ok(out)
}

fn indexed(m: &clap::ArgMatches, id: &str) -> Vec<(usize, String)> {
    match (m.indices_of(id), m.get_many::<String>(id)) {
        (Some(i), Some(v)) => i.zip(v.cloned()).collect(),
        _ => Vec::new(),
    }
}

/// `-f` (a, f, d or c) and `-i` (a, f or d) letters.
fn format_opt(v: &Option<String>, opt: &str) -> Result<Option<DataFormat>> {
    match v.as_deref() {
        None => Ok(None),
        Some(l) => match DataFormat::from_letter(l) {
            Some(f) if f != DataFormat::Rgbe || opt == "-f" => Ok(Some(f)),
            _ => Err(Error::Usage(format!(
                "{opt}{l}: expected {opt}a, {opt}f or {opt}d"
            ))),
        },
    }
}
