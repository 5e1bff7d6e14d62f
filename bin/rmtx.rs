//! `rmtx`: Radiance matrix conversion, multiplication and concatenation; the start of the
//! `rmtxop`/`dctimestep` counterpart. All format and arithmetic code is in
//! `rdaylight::formats::matrix`; this file parses options, opens streams and reports.

use clap::{CommandFactory, FromArgMatches, Parser};
use rdaylight::Error;
use rdaylight::formats::header::Header;
use rdaylight::formats::matrix::ops::{check_multiply, check_stack, scale_factors};
use rdaylight::formats::matrix::writer::{DOUBLE_DIGITS, FLOAT_DIGITS};
use rdaylight::formats::matrix::{
    ChannelTransform, DataFormat, Matrix, MatrixReader, MatrixWriter, ReadOptions, RowOps,
    WriteOptions,
};
use rdaylight::radiometry::Channels;

const EXAMPLES: &str = "\
Examples:
  Daylight coefficients times a sky matrix, to illuminance in lux (as dctimestep | rmtxop):
    gendaymtx -m 1 -of site.wea > sky.smx
    rmtx dc.mtx sky.smx -c 47.4 119.9 11.6 -fa > ill.txt
  Convert rcontrib's headerless ascii (-h, no -y) to float with a header:
    rcontrib -h -I+ ... | rmtx -ia -ff - > dc.mtx
  Spectral coefficients times a spectral sky matrix, to illuminance and Radiance's M:
    rmtx dc18.mtx sky18.smx -c YM -fa > ill_M.txt
  Stack sensor blocks computed on two machines:
    rmtx --cat part1.mtx part2.mtx > dc.mtx";

/// Radiance matrix operations (rmtxop/dctimestep counterpart).
///
/// With one input: convert it (format, -c, -s, -t). With several: multiply them left to
/// right, per channel (RGB x RGB multiplies red by red, as dctimestep and rmtxop do); the
/// first input is streamed row by row, the others are held in memory. Shapes and NCOMP of
/// every input are checked before anything is written. -c, -s and -t apply to the result
/// wherever they appear (unlike rmtxop, where options before a matrix apply to that matrix).
/// EXPOSURE=/COLORCORR= in input headers are divided out on load, as rmtxop does.
#[derive(Parser, Debug)]
#[command(name = "rmtx", disable_help_flag = true, after_help = EXAMPLES)]
struct Cli {
    /// Output format a|f|d|c (-fa ascii, -ff float, -fd double, -fc RGBE picture rows or
    /// Radiance_spectra for NCOMP > 3; rmtxop -f). Default: the
    /// lowest-precision input format in Radiance's order (float < ascii < double), i.e. a
    /// single input keeps its own format.
    #[arg(short = 'f', value_name = "a|f|d|c")]
    format: Option<String>,

    /// Write no header (Radiance -h).
    #[arg(short = 'h')]
    no_header: bool,

    /// Transpose the result (rmtxop -t after the last matrix). Holds the result in memory.
    #[arg(short = 't')]
    transpose: bool,

    /// Channel transform of the result (rmtxop -c): N x NCOMP coefficients, e.g.
    /// `-c 47.4 119.9 11.6` (RGB irradiance to lux), or one symbolic word, one output
    /// component per letter: R G B, X Y Z (x 179), S scotopic (x 412), M melanopic (x 179,
    /// Radiance's equal-energy-normalised value: m-EDI = 0.9233 M), A mean; lower case
    /// without the factor. On RGB, `-c Y` = 179 x (0.265106 0.670106 0.064788); on
    /// spectral matrices (NCOMP > 3) the bands come from WAVELENGTH_SPLITS and are weighted
    /// with Radiance's own observer tables, as rmtxop does.
    #[arg(short = 'c', num_args = 1.., allow_negative_numbers = true, value_name = "W")]
    coefs: Vec<String>,

    /// Scale the result (rmtxop -s): one factor, or one per output component.
    #[arg(short = 's', num_args = 1.., allow_negative_numbers = true, value_name = "F")]
    scale: Vec<String>,

    /// Concatenate row blocks of inputs with equal NCOLS and NCOMP instead of multiplying
    /// (like `cat` of headerless blocks; rcollate/rcomb have no single equivalent).
    #[arg(long = "cat")]
    cat: bool,

    /// Format a|f|d of inputs without a header (dctimestep -i; rcontrib/rtrace/gendaymtx -h).
    #[arg(short = 'i', value_name = "a|f|d")]
    iformat: Option<String>,

    /// NCOMP of inputs without a header (default 3).
    #[arg(long = "ncomp", value_name = "N")]
    ncomp: Option<usize>,

    /// NCOLS of inputs without a header (headerless ascii: inferred from the first line).
    #[arg(long = "ncols", value_name = "N")]
    ncols: Option<usize>,

    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    help: Option<bool>,

    /// Matrix files; `-` is standard input (the default when none is given).
    #[arg(value_name = "FILE|-")]
    inputs: Vec<String>,
}

fn main() {
    rdaylight::cli::run("rmtx", real_main)
}

/// Parse options; `-c`/`-s` take numbers up to the first non-number as rmtxop does, so file
/// names that clap gave them go back to the inputs, in command-line order.
fn parse_args() -> Cli {
    let m = Cli::command().get_matches();
    let mut cli = Cli::from_arg_matches(&m).unwrap_or_else(|e| e.exit());
    let mut inputs: Vec<(usize, String)> = indexed(&m, "inputs");
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
    cli.coefs = split("coefs", true, &mut inputs);
    cli.scale = split("scale", false, &mut inputs);
    inputs.sort_by_key(|(i, _)| *i);
    cli.inputs = inputs.into_iter().map(|(_, v)| v).collect();
    cli
}

fn indexed(m: &clap::ArgMatches, id: &str) -> Vec<(usize, String)> {
    match (m.indices_of(id), m.get_many::<String>(id)) {
        (Some(i), Some(v)) => i.zip(v.cloned()).collect(),
        _ => Vec::new(),
    }
}

fn format_opt(v: &Option<String>, opt: &str) -> Result<Option<DataFormat>, Error> {
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

fn real_main() -> Result<(), Error> {
    let cli = parse_args();
    let mut inputs = cli.inputs.clone();
    if inputs.is_empty() {
        inputs.push("-".into());
    }
    if inputs.iter().filter(|p| *p == "-").count() > 1 {
        return Err(Error::Usage(
            "standard input used for more than one matrix".into(),
        ));
    }
    let ropts = ReadOptions {
        format: format_opt(&cli.iformat, "-i")?,
        ncomp: cli.ncomp,
        ncols: cli.ncols,
        nrows: None,
        undo_exposure: true,
    };
    let scale: Vec<f64> = cli.scale.iter().filter_map(|s| s.parse().ok()).collect();

    // Read every header (and load every right operand) before writing anything.
    let mut readers = Vec::new();
    for p in if cli.cat { &inputs[..] } else { &inputs[..1] } {
        readers.push(MatrixReader::open(p, &ropts)?);
    }
    let first = &readers[0];
    let (fname, fshape) = (first.name().to_string(), first.info().shape());
    let (ncols, ncomp) = (first.ncols(), first.ncomp());
    let mut in_format = first.info().format;
    let mut all_double = in_format == DataFormat::Double;
    let mut nrows = first.nrows();
    let mut chain = Vec::new();
    if cli.cat {
        for r in &readers[1..] {
            check_stack(&fname, fshape, r.name(), r.info().shape())?;
            nrows = nrows.zip(r.nrows()).map(|(a, b)| a + b);
            in_format = in_format.combine(r.info().format);
            all_double &= r.info().format == DataFormat::Double;
        }
    } else {
        let mut right = Vec::new();
        for p in &inputs[1..] {
            right.push(MatrixReader::open(p, &ropts)?);
        }
        // Cheap header checks first, so a mismatch is reported before any large load.
        let mut prev = (fname.clone(), fshape);
        let first_ch = readers[0].info().channels;
        for r in &right {
            let s = r.info().shape();
            // Spectral operands must cover the same bands (rmtxop does not check: it would
            // multiply band i of one range by band i of another).
            let ch = r.info().channels;
            if ncomp > 3 && ch.ncomp == ncomp && ch.splits != first_ch.splits {
                return Err(Error::Mismatch(format!(
                    "{} (WAVELENGTH_SPLITS {:?}) cannot multiply {} ({:?}): the bands differ",
                    fname,
                    first_ch.splits,
                    r.name(),
                    ch.splits
                )));
            }
            if s.nrows.is_some() {
                check_multiply(&prev.0, prev.1, r.name(), s)?;
            }
            prev = (r.name().to_string(), s);
        }
        let mut prev = (fname.clone(), fshape);
        for mut r in right {
            let name = r.name().to_string();
            in_format = in_format.combine(r.info().format);
            all_double &= r.info().format == DataFormat::Double;
            let m = Matrix::read_all(&mut r)?;
            check_multiply(&prev.0, prev.1, &name, m.shape())?;
            prev = (name, m.shape());
            chain.push(m);
        }
    }
    let transform = if cli.coefs.is_empty() {
        None
    } else {
        // Symbolic words on spectral data need the bands: the first input's header.
        Some(ChannelTransform::parse_for(
            &cli.coefs,
            &Channels {
                ncomp,
                ..readers[0].info().channels
            },
            "result",
        )?)
    };
    let out_ncomp = transform.as_ref().map_or(ncomp, |t| t.nout);
    let factors = if cli.scale.is_empty() {
        None
    } else {
        Some(scale_factors(&scale, out_ncomp)?)
    };
    let mut ops = RowOps::new(ncomp, chain, transform, factors);
    let out_ncols = ops.out_ncols(ncols);

    let mut format = format_opt(&cli.format, "-f")?.unwrap_or(in_format);
    // -fc: RGBE for 1 or 3 components, Radiance_spectra beyond (as rmtxop -fc).
    if format == DataFormat::Rgbe && out_ncomp > 3 {
        format = DataFormat::Spectra;
    }
    let mut wopts = WriteOptions::new(format);
    wopts.header = !cli.no_header;
    wopts.seekable = rdaylight::io::stdout_is_file();
    wopts.ascii_digits = if all_double {
        DOUBLE_DIGITS
    } else {
        FLOAT_DIGITS
    };
    let mut header = Header::new();
    header.push_command(std::env::args());
    let channels = Channels {
        ncomp: out_ncomp,
        ..readers[0].info().channels
    };

    let stdout = std::io::stdout().lock();
    let out = std::io::BufWriter::with_capacity(1 << 16, stdout);
    let progress = rdaylight::io::show_progress();
    let mut row = vec![0.0; ncols * ncomp];
    let mut done = 0usize;
    let tick = |done: usize| {
        if progress && done % 256 == 0 {
            eprint!("\rrmtx: {done} rows");
        }
    };
    if cli.transpose {
        let mut data = Vec::new();
        for r in &mut readers {
            while r.read_row(&mut row)? {
                data.extend_from_slice(ops.apply(&row));
                done += 1;
                tick(done);
            }
        }
        let m = Matrix {
            nrows: done,
            ncols: out_ncols,
            channels,
            data,
        }
        .transpose();
        m.write(out, "<stdout>", header, wopts)?;
    } else {
        let mut w = MatrixWriter::new(out, "<stdout>", header, nrows, out_ncols, channels, wopts)?;
        for r in &mut readers {
            while r.read_row(&mut row)? {
                w.write_row(ops.apply(&row))?;
                done += 1;
                tick(done);
            }
        }
        w.finish()?;
    }
    if progress {
        eprintln!("\rrmtx: {done} rows");
    }
    Ok(())
}
