//! # Convert, multiply or stack matrices in one streamed pass (`rmtx`)
//!
//! The `rmtxop`/`dctimestep` counterpart as a typed job: [`Pipeline::run`] reads every
//! header (and loads every right operand) before anything is written, so a shape or
//! NCOMP mismatch is reported first; then the first input is streamed row by row through
//! the multiplications, the channel transform (`rmtxop -c`) and the scale (`rmtxop -s`).
//! With [`Pipeline::stack`] the inputs' row blocks are concatenated instead.
//!
//! Channels multiply per channel (RGB x RGB multiplies red by red, as dctimestep and rmtxop
//! do). `-c`, `-s` and `-t` apply to the result (unlike rmtxop, where options before a
//! matrix apply to that matrix).
//!
//! Nothing is written before the streamed inputs are known to be whole: binary files by
//! their size, ascii and RGBE files by a first decoding pass. Standard input can be read
//! only once, so a damaged stream is reported after the rows before the damage.

use super::ops::{check_multiply, check_stack, scale_factors};
use super::writer::{DOUBLE_DIGITS, FLOAT_DIGITS};
use super::{
    ChannelTransform, DataFormat, Matrix, MatrixReader, MatrixWriter, ReadOptions, RowOps, Shape,
    WriteOptions,
};
use crate::error::{Error, Result};
use crate::header::Header;
use crate::radiometry::Channels;
use crate::shard::{Manifest, SHARD_VAR, ShardInfo};
use std::io::{BufRead, Write};

/// One `rmtx` run.
#[derive(Debug, Clone, PartialEq)]
pub struct Pipeline {
    /// Matrix files; `-` is standard input (at most once; none means `-`).
    pub inputs: Vec<String>,
    /// Concatenate row blocks of inputs with equal NCOLS and NCOMP instead of multiplying.
    pub stack: bool,
    /// How inputs without a header are read (`EXPOSURE=`/`COLORCORR=` are divided out).
    pub read: ReadOptions,
    /// Channel transform of the result (`rmtxop -c`): coefficients or one symbolic word.
    pub coefs: Vec<String>,
    /// Scale of the result (`rmtxop -s`): one factor, or one per output component.
    pub scale: Vec<f64>,
    /// Output format; default: the lowest-precision input format in Radiance's order
    /// (float < ascii < double). `Rgbe` means `-fc`: RGBE, or Radiance_spectra beyond 3
    /// components.
    pub format: Option<DataFormat>,
    /// Transpose the result (held in memory).
    pub transpose: bool,
    /// Write the header.
    pub header: bool,
    /// The command line for the header.
    pub command: Vec<String>,
    /// The output is a seekable file.
    pub seekable: bool,
    /// With `stack`: the shards' manifests (`rdc --manifest`), checked against each other
    /// and the inputs before the merge ([`crate::shard::check_manifests`]).
    pub manifests: Vec<String>,
}

/// The inputs, opened and checked, ready to stream.
struct Opened {
    /// Streamed inputs (the first, or all with `stack`).
    readers: Vec<MatrixReader<Box<dyn BufRead>>>,
    /// Right operands, in memory.
    chain: Vec<Matrix>,
    nrows: Option<usize>,
    in_format: DataFormat,
    all_double: bool,
}

impl Pipeline {
    fn inputs(&self) -> Vec<String> {
        if self.inputs.is_empty() {
            vec!["-".into()]
        } else {
            self.inputs.clone()
        }
    }

    /// Run the job, writing to `out` (`name` in errors); `progress(rows, finished)` is
    /// called every 256 rows and once at the end.
    pub fn run<W: Write>(&self, out: W, name: &str, progress: &dyn Fn(usize, bool)) -> Result<()> {
        let inputs = self.inputs();
        if inputs.iter().filter(|p| *p == "-").count() > 1 {
            return Err(Error::Usage(
                "standard input used for more than one matrix".into(),
            ));
        }
        if !self.manifests.is_empty() && !self.stack {
            return Err(Error::Usage(
                "--manifests checks shards: it needs --cat".into(),
            ));
        }
        if self.stack {
            if let Some(shards) = self.shard_headers(&inputs)? {
                return self.merge_shards(&inputs, shards, out, name, progress);
            }
            if !self.manifests.is_empty() {
                return Err(Error::Mismatch(format!(
                    "--manifests: {} has no SHARD= line (not an rdc --shard output)",
                    inputs[0]
                )));
            }
        }
        let mut o = self.open(&inputs)?;
        let first_ch = o.readers[0].info().channels;
        let (ncols, ncomp) = (o.readers[0].ncols(), o.readers[0].ncomp());
        let transform = if self.coefs.is_empty() {
            None
        } else {
            // Symbolic words on spectral data need the bands: the first input's header.
            let ch = Channels { ncomp, ..first_ch };
            Some(ChannelTransform::parse_for(&self.coefs, &ch, "result")?)
        };
        let out_ncomp = transform.as_ref().map_or(ncomp, |t| t.nout);
        let factors = if self.scale.is_empty() {
            None
        } else {
            Some(scale_factors(&self.scale, out_ncomp)?)
        };
        let chain = std::mem::take(&mut o.chain);
        let mut ops = RowOps::new(ncomp, chain, transform, factors);
        let channels = Channels {
            ncomp: out_ncomp,
            ..first_ch
        };
        let wopts = self.write_options(&o, out_ncomp);
        let mut header = Header::new();
        header.push_command(&self.command);
        let out_ncols = ops.out_ncols(ncols);
        let mut row = vec![0.0; ncols * ncomp];
        let mut done = 0usize;
        let mut each = |r: &mut MatrixReader<Box<dyn BufRead>>,
                        f: &mut dyn FnMut(&[f64]) -> Result<()>|
         -> Result<()> {
            while r.read_row(&mut row)? {
                f(ops.apply(&row))?;
                done += 1;
                if done % 256 == 0 {
                    progress(done, false);
                }
            }
            Ok(())
        };
        if self.transpose {
            let mut data = Vec::new();
            for r in &mut o.readers {
                each(r, &mut |v| {
                    data.extend_from_slice(v);
                    Ok(())
                })?;
            }
            let m = Matrix {
                nrows: done,
                ncols: out_ncols,
                channels,
                data,
            };
            m.transpose().write(out, name, header, wopts)?;
        } else {
            let mut w = MatrixWriter::new(out, name, header, o.nrows, out_ncols, channels, wopts)?;
            for r in &mut o.readers {
                each(r, &mut |v| w.write_row(v))?;
            }
            w.finish()?;
        }
        progress(done, true);
        Ok(())
    }

    /// Open every input; check shapes (and bands) before any large load, and the streamed
    /// files' data before anything is written ([`super::reader::check_data`]).
    fn open(&self, inputs: &[String]) -> Result<Opened> {
        let mut readers = Vec::new();
        let streamed = if self.stack { inputs } else { &inputs[..1] };
        for p in streamed {
            readers.push(MatrixReader::open(p, &self.read)?);
        }
        let first = &readers[0];
        let in_format = first.info().format;
        let mut o = Opened {
            nrows: first.nrows(),
            in_format,
            all_double: in_format == DataFormat::Double,
            readers,
            chain: Vec::new(),
        };
        if self.stack {
            o.check_stack()?;
        } else {
            o.load_chain(&inputs[1..], &self.read)?;
        }
        // A transposed result is held whole before it is written: no need to read twice.
        if !self.transpose {
            for p in streamed {
                super::reader::check_data(p, &self.read)?;
            }
        }
        Ok(o)
    }

    fn write_options(&self, o: &Opened, out_ncomp: usize) -> WriteOptions {
        let mut format = self.format.unwrap_or(o.in_format);
        // -fc: RGBE for 1 or 3 components, Radiance_spectra beyond (as rmtxop -fc).
        if format == DataFormat::Rgbe && out_ncomp > 3 {
            format = DataFormat::Spectra;
        }
        let mut wopts = WriteOptions::new(format);
        wopts.header = self.header;
        wopts.seekable = self.seekable;
        wopts.ascii_digits = if o.all_double {
            DOUBLE_DIGITS
        } else {
            FLOAT_DIGITS
        };
        wopts
    }
}

impl Pipeline {
    /// With `--cat`: the inputs' headers and NROWS when they are `rdc --shard` outputs
    /// (any file with a `SHARD=` line), `None` for ordinary matrices.
    fn shard_headers(&self, inputs: &[String]) -> Result<Option<Vec<(String, Header, usize)>>> {
        let mut headers = Vec::new();
        for p in inputs.iter().filter(|p| *p != "-") {
            let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
            let h = Header::read(&mut std::io::BufReader::new(f), p)?;
            headers.push((p.clone(), h));
        }
        if !headers.iter().any(|(_, h)| h.get(SHARD_VAR).is_some()) {
            return Ok(None);
        }
        if inputs.iter().any(|p| p == "-") {
            return Err(Error::Usage(
                "rdc shards are merged from files, not standard input".into(),
            ));
        }
        headers
            .into_iter()
            .map(|(p, h)| {
                let nrows = h.get_usize("NROWS", &p)?.ok_or_else(|| {
                    Error::Mismatch(format!("{p}: a shard without NROWS= cannot be checked"))
                })?;
                Ok((p, h, nrows))
            })
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// `rmtx --cat` of `rdc --shard` outputs: check they are all N shards of one run (and
    /// their manifests agree), write the unsharded header, copy the rows verbatim, so the
    /// result has the bytes of the unsharded run (module docs of [`crate::shard`]).
    fn merge_shards<W: Write>(
        &self,
        inputs: &[String],
        shards: Vec<(String, Header, usize)>,
        mut out: W,
        name: &str,
        progress: &dyn Fn(usize, bool),
    ) -> Result<()> {
        if !self.coefs.is_empty() || !self.scale.is_empty() || self.transpose {
            return Err(Error::Usage(
                "rmtx --cat of rdc shards copies rows verbatim: no -c, -s or -t (convert the \
                 merged matrix with a second rmtx)"
                    .into(),
            ));
        }
        // Shapes and formats first (NCOLS, NCOMP), with the usual messages.
        let mut readers = Vec::new();
        for p in inputs {
            readers.push(MatrixReader::open(p, &self.read)?);
        }
        let mut o = Opened {
            nrows: None,
            in_format: readers[0].info().format,
            all_double: false,
            readers,
            chain: Vec::new(),
        };
        o.check_stack()?;
        let info = o.readers[0].info().clone();
        drop(o);
        if info.format.is_picture() {
            return Err(Error::Usage(format!(
                "{}: shards in {} rows cannot be merged; write them with -faa, -faf or -fad",
                inputs[0],
                info.format.name()
            )));
        }
        if self.format.is_some_and(|f| f != info.format) {
            return Err(Error::Usage(
                "rmtx --cat of rdc shards copies rows verbatim: no -f (convert the merged \
                 matrix with a second rmtx)"
                    .into(),
            ));
        }
        for p in inputs {
            super::reader::check_data(p, &self.read)?;
        }
        let header = crate::shard::merged_header(&shards)?;
        if !self.manifests.is_empty() {
            self.check_manifests(&shards)?;
        }
        let binary = matches!(info.format, DataFormat::Float | DataFormat::Double);
        if self.header {
            let align = if binary && self.seekable {
                info.format.elem_size()
            } else {
                1
            };
            header
                .write(&mut out, align)
                .map_err(|e| Error::io(name, e))?;
        }
        let mut total = 0;
        for (p, _, nrows) in &shards {
            let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
            let mut r = std::io::BufReader::with_capacity(1 << 16, f);
            Header::read(&mut r, p)?;
            let (bytes, lines) = copy_counting(&mut r, &mut out, p, name)?;
            // Rows of the data as written: whole binary rows, or one ascii line per row.
            let rows = if binary {
                let row = info.row_len() * info.format.elem_size();
                (bytes % row as u64 == 0).then(|| (bytes / row as u64) as usize)
            } else {
                Some(lines)
            };
            if rows != Some(*nrows) {
                return Err(Error::Mismatch(format!(
                    "{p}: NROWS={nrows} but the data holds {bytes} bytes ({lines} lines): an \
                     incomplete shard?"
                )));
            }
            total += nrows;
        }
        out.flush().map_err(|e| Error::io(name, e))?;
        progress(total, true);
        Ok(())
    }

    /// `--manifests`: one per shard, in the shards' order, all of one run.
    fn check_manifests(&self, shards: &[(String, Header, usize)]) -> Result<()> {
        let mut ms = Vec::new();
        for p in &self.manifests {
            ms.push((p.clone(), Manifest::read(p)?));
        }
        crate::shard::check_manifests(&ms)?;
        if ms.len() != shards.len() {
            return Err(Error::Mismatch(format!(
                "{} manifests for {} shards: give one manifest per shard, in the same order",
                ms.len(),
                shards.len()
            )));
        }
        for ((mp, m), (p, h, nrows)) in ms.iter().zip(shards) {
            let s = ShardInfo::of(h, p)?.map(|i| (i.shard, i.first, i.total));
            if s != Some((m.shard, m.first_row, m.total_rows)) || m.rows != *nrows {
                return Err(Error::Mismatch(format!(
                    "{mp} describes shard {} (rows {}..{} of {}) but {p} is not that shard",
                    m.shard,
                    m.first_row,
                    m.first_row + m.rows,
                    m.total_rows
                )));
            }
        }
        Ok(())
    }
}

/// Copy `r` to `w` to the end; the bytes and newlines copied.
fn copy_counting<R: BufRead, W: Write>(
    r: &mut R,
    w: &mut W,
    name: &str,
    out_name: &str,
) -> Result<(u64, usize)> {
    let (mut bytes, mut lines) = (0u64, 0usize);
    loop {
        let buf = r.fill_buf().map_err(|e| Error::io(name, e))?;
        if buf.is_empty() {
            return Ok((bytes, lines));
        }
        w.write_all(buf).map_err(|e| Error::io(out_name, e))?;
        lines += buf.iter().filter(|&&b| b == b'\n').count();
        bytes += buf.len() as u64;
        let n = buf.len();
        r.consume(n);
    }
}

impl Opened {
    fn first(&self) -> (String, Shape) {
        let f = &self.readers[0];
        (f.name().to_string(), f.info().shape())
    }

    fn note_format(&mut self, f: DataFormat) {
        self.in_format = self.in_format.combine(f);
        self.all_double &= f == DataFormat::Double;
    }

    fn check_stack(&mut self) -> Result<()> {
        let (fname, fshape) = self.first();
        let mut formats = Vec::new();
        for r in &self.readers[1..] {
            check_stack(&fname, fshape, r.name(), r.info().shape())?;
            self.nrows = self.nrows.zip(r.nrows()).map(|(a, b)| a + b);
            formats.push(r.info().format);
        }
        for f in formats {
            self.note_format(f);
        }
        Ok(())
    }

    /// Open the right operands, check their headers, then load them.
    fn load_chain(&mut self, paths: &[String], ropts: &ReadOptions) -> Result<()> {
        let mut right = Vec::new();
        for p in paths {
            right.push(MatrixReader::open(p, ropts)?);
        }
        // Cheap header checks first, so a mismatch is reported before any large load.
        self.check_headers(&right)?;
        let mut prev = self.first();
        for mut r in right {
            let name = r.name().to_string();
            self.note_format(r.info().format);
            let m = Matrix::read_all(&mut r)?;
            check_multiply(&prev.0, prev.1, &name, m.shape())?;
            prev = (name, m.shape());
            self.chain.push(m);
        }
        Ok(())
    }

    fn check_headers(&self, right: &[MatrixReader<Box<dyn BufRead>>]) -> Result<()> {
        let (fname, fshape) = self.first();
        let first_ch = self.readers[0].info().channels;
        let ncomp = self.readers[0].ncomp();
        let mut prev = (fname.clone(), fshape);
        for r in right {
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
        Ok(())
    }
}
