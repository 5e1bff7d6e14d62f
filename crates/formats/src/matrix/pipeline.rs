//! # Convert, multiply or stack matrices in one streamed pass (`rmtx`)
//!
//! The `rmtxop`/`dctimestep` counterpart as a typed job: [`Pipeline::run`] reads every
//! header (and loads every right operand) before anything is written, so a shape or
//! NCOMP mismatch is reported first; then the first input is streamed row by row through
//! the multiplications, the channel transform (`rmtxop -c`) and the scale (`rmtxop -s`).
//! When holding the right-most operand (a sky matrix: thousands of time steps) would cost
//! more than holding the first input's rows and the whole result, the loops turn around:
//! the first input is read whole, the right-most operand's rows are added into the result
//! one at a time ([`Outer`], same bits), and the result's rows are then written.
//! With [`Pipeline::stack`] the inputs' row blocks are concatenated instead, with
//! [`Pipeline::columns`] their column blocks (side by side). [`Pipeline::hours`] computes
//! one time chunk of a product (columns `A..B` of the right-most matrix, 0-based,
//! half-open), and `columns` merges such chunks back into the whole product's bytes
//! ([`crate::hours`]).
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
    ChannelTransform, DataFormat, Matrix, MatrixReader, MatrixWriter, Operand, Outer, ReadOptions,
    RowOps, Shape, WriteOptions,
};
use crate::error::{Error, Result};
use crate::header::Header;
use crate::hours::{ChunkManifest, HOURS_VAR, HourSpan, HoursInfo};
use crate::progress::{Progress, Stage};
use crate::radiometry::Channels;
use crate::shard::{InputSum, Manifest, SHARD_VAR, ShardInfo};
use std::io::{BufRead, Read, Write};
use std::ops::Range;

/// One `rmtx` run.
#[derive(Debug, Clone, PartialEq)]
pub struct Pipeline {
    /// Matrix files; `-` is standard input (at most once; none means `-`).
    pub inputs: Vec<String>,
    /// Concatenate row blocks of inputs with equal NCOLS and NCOMP instead of multiplying.
    pub stack: bool,
    /// Concatenate column blocks of inputs with equal NROWS and NCOMP (side by side)
    /// instead of multiplying; `rmtx --hours` chunks are checked and merged verbatim.
    pub columns: bool,
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
    /// and the inputs before the merge ([`crate::shard::check_manifests`]); with `columns`:
    /// the hour chunks' manifests ([`crate::hours::check_manifests`]).
    pub manifests: Vec<String>,
    /// Compute only these hours: columns of the right-most matrix (the sky's time steps),
    /// 0-based, half-open ([`crate::hours`]); the header gets a `HOURS=` line.
    pub hours: Option<HourSpan>,
    /// With `hours`: write the chunk's manifest here once the output is complete.
    pub manifest: Option<String>,
    /// Check each input, an `rdc --shard` output, against its manifest alone (one per
    /// input in `manifests`) and report one line per shard instead of merging: what a
    /// resume needs to know which shards to run again ([`Pipeline::verify_shards`]).
    pub verify: bool,
    /// Further product chains added to the product of `inputs`, each times its factor
    /// (rmtxop's `+`): the five-phase combination `V T D s - Vd T Dd sd + Cds ssun` in one
    /// streamed pass. Every term must give the same NROWS, NCOLS and NCOMP; `coefs`,
    /// `scale` and `hours` apply to the sum (hours: to each term's right-most matrix).
    pub terms: Vec<Term>,
    /// Inputs already in memory as Radiance matrix bytes (header included), read in place
    /// of the file of the same name in products and sums: the tools layer puts the
    /// transmission matrix of a BSDF XML file named among the inputs here (dctimestep's
    /// `T.xml`), since reading XML belongs to a layer above this one.
    pub in_memory: Vec<(String, Vec<u8>)>,
}

/// One added term of a sum ([`Pipeline::terms`]): a product chain and its factor.
#[derive(Debug, Clone, PartialEq)]
pub struct Term {
    /// Matrix files multiplied left to right, as [`Pipeline::inputs`].
    pub inputs: Vec<String>,
    /// Factor of the term (`-1` subtracts it).
    pub scale: f64,
}

/// The inputs, opened and checked, ready to stream.
struct Opened {
    /// Streamed inputs (the first, or all with `stack` or `columns`).
    readers: Vec<MatrixReader<Box<dyn BufRead>>>,
    /// Right operands, in memory.
    chain: Vec<Operand>,
    nrows: Option<usize>,
    in_format: DataFormat,
    all_double: bool,
    /// Read the readers side by side (`columns`) rather than one after the other.
    side_by_side: bool,
    /// With `stack`: the reader being read.
    current: usize,
    /// Rows delivered so far.
    rows: usize,
    /// With `hours`: the chunk's columns and the whole product's.
    hours: Option<HoursInfo>,
    /// With `hours` and no right operand: the columns kept of each streamed row.
    keep: Option<Range<usize>>,
    scratch: Vec<f64>,
    /// The whole product, computed in the other loop order when holding the right-most
    /// operand would take more memory ([`Opened::multiply_outer`]); its rows are then
    /// what [`Opened::next_row`] delivers.
    product: Option<Outer>,
}

impl Pipeline {
    fn inputs(&self) -> Vec<String> {
        if self.inputs.is_empty() {
            vec!["-".into()]
        } else {
            self.inputs.clone()
        }
    }

    /// Option combinations that make no sense, refused before anything is read.
    fn check_options(&self, inputs: &[String]) -> Result<()> {
        if inputs.iter().filter(|p| *p == "-").count() > 1 {
            return Err(Error::Usage(
                "standard input used for more than one matrix".into(),
            ));
        }
        if self.verify
            && (self.stack || self.columns || self.hours.is_some() || inputs.contains(&"-".into()))
        {
            return Err(Error::Usage(
                "--verify checks shard files against their manifests: no --cat, \
                 --cat-columns, --hours or standard input"
                    .into(),
            ));
        }
        if self.stack && self.columns {
            return Err(Error::Usage(
                "--cat stacks rows, --cat-columns joins columns: give one of them".into(),
            ));
        }
        if !self.manifests.is_empty() && !self.stack && !self.columns && !self.verify {
            return Err(Error::Usage(
                "--manifests checks shards or hour chunks: it needs --cat, --cat-columns or \
                 --verify"
                    .into(),
            ));
        }
        if self.hours.is_some() && (self.stack || self.columns) {
            return Err(Error::Usage(
                "--hours computes one chunk of a product, --cat/--cat-columns merge: not both"
                    .into(),
            ));
        }
        if self.hours.is_some() && self.transpose {
            return Err(Error::Usage(
                "--hours with -t: chunks are merged along columns; transpose the merged \
                 product instead"
                    .into(),
            ));
        }
        if self.manifest.is_some() && self.hours.is_none() {
            return Err(Error::Usage(
                "--manifest describes an hour chunk: it needs --hours A:B or K/N".into(),
            ));
        }
        if self.manifest.is_some() && inputs.iter().any(|p| p == "-") {
            return Err(Error::Usage(
                "--manifest hashes the inputs: give matrix files, not standard input".into(),
            ));
        }
        Ok(())
    }

    /// Run the job, writing to `out` (`name` in errors); the rows written are a stage of
    /// `progress` (a unit per row).
    pub fn run<W: Write>(&self, out: W, name: &str, progress: &dyn Progress) -> Result<()> {
        let inputs = self.inputs();
        self.check_options(&inputs)?;
        if self.verify {
            return self.verify_shards(&inputs, out, name);
        }
        if !self.terms.is_empty() {
            return self.run_sum(&inputs, out, name, progress);
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
        if self.columns {
            if let Some(chunks) = self.chunk_headers(&inputs)? {
                return self.merge_hours(&inputs, chunks, out, name, progress);
            }
            if !self.manifests.is_empty() {
                return Err(Error::Mismatch(format!(
                    "--manifests: {} has no HOURS= line (not an rmtx --hours output)",
                    inputs[0]
                )));
            }
        }
        // Hash before reading: the manifest names what this chunk was computed from.
        let sums = match &self.manifest {
            Some(_) => inputs
                .iter()
                .map(|p| InputSum::of_file(p))
                .collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        let mut o = self.open(&inputs)?;
        let first_ch = o.readers[0].info().channels;
        let ncomp = o.readers[0].ncomp();
        let ncols = o.in_ncols();
        let (transform, out_ncomp, factors) = self.result_ops(ncomp, first_ch)?;
        let chain = std::mem::take(&mut o.chain);
        let mut ops = RowOps::new(ncomp, chain, transform, factors);
        let channels = Channels {
            ncomp: out_ncomp,
            ..first_ch
        };
        let wopts = self.write_options(&o, out_ncomp);
        let mut header = Header::new();
        header.push_command(&self.command);
        if let Some(h) = &o.hours {
            header.push(h.line());
        }
        let out_ncols = ops.out_ncols(ncols);
        let mut row = vec![0.0; ncols * ncomp];
        let mut done = 0usize;
        let what = match (self.stack, self.columns, inputs.len()) {
            (true, _, _) => "concatenating",
            (_, true, _) => "joining columns",
            (_, _, 1) => "converting",
            _ => "product",
        };
        let stage = Stage::new(progress, what, o.nrows.map(|n| n as u64), "rows");
        let mut each = |o: &mut Opened, f: &mut dyn FnMut(&[f64]) -> Result<()>| -> Result<()> {
            while o.next_row(&mut row)? {
                f(ops.apply(&row))?;
                done += 1;
                stage.advance(1);
            }
            Ok(())
        };
        if self.transpose {
            let mut data = Vec::new();
            each(&mut o, &mut |v| {
                data.extend_from_slice(v);
                Ok(())
            })?;
            let m = Matrix {
                nrows: done,
                ncols: out_ncols,
                channels,
                data,
            };
            m.transpose().write(out, name, header, wopts)?;
        } else {
            let mut w = MatrixWriter::new(out, name, header, o.nrows, out_ncols, channels, wopts)?;
            each(&mut o, &mut |v| w.write_row(v))?;
            w.finish()?;
        }
        drop(stage);
        if let (Some(path), Some(h)) = (&self.manifest, &o.hours) {
            ChunkManifest {
                tool: "rmtx".into(),
                version: env!("CARGO_PKG_VERSION").into(),
                command: self.command.clone(),
                first_hour: h.first,
                end_hour: h.end,
                total_hours: h.total,
                inputs: sums,
            }
            .write(path)?;
        }
        Ok(())
    }

    /// Open every input; check shapes (and bands) before any large load, and the streamed
    /// files' data before anything is written ([`super::reader::check_data`]).
    fn open(&self, inputs: &[String]) -> Result<Opened> {
        let mut readers = Vec::new();
        let streamed = if self.stack || self.columns {
            inputs
        } else {
            &inputs[..1]
        };
        for p in streamed {
            readers.push(self.reader(p)?);
        }
        let first = &readers[0];
        let in_format = first.info().format;
        let mut o = Opened {
            nrows: first.nrows(),
            in_format,
            all_double: in_format == DataFormat::Double,
            readers,
            chain: Vec::new(),
            side_by_side: self.columns,
            current: 0,
            rows: 0,
            hours: None,
            keep: None,
            scratch: Vec::new(),
            product: None,
        };
        if self.stack {
            o.check_stack()?;
        } else if self.columns {
            o.check_columns()?;
        } else {
            o.load_chain(&inputs[1..], &self.read, self.hours, &self.in_memory)?;
        }
        // A transposed result is held whole before it is written, and a product computed
        // in the outer order has read its left input whole: no need to read them twice.
        if !self.transpose && o.product.is_none() {
            for p in streamed
                .iter()
                .filter(|p| !self.in_memory.iter().any(|(n, _)| n == *p))
            {
                super::reader::check_data(p, &self.read)?;
            }
        }
        Ok(o)
    }

    /// The result's channel transform (`-c`), its component count and the scale factors
    /// (`-s`), for `ncomp` components of the first input's `channels` (symbolic words on
    /// spectral data need its bands).
    #[allow(clippy::type_complexity)]
    fn result_ops(
        &self,
        ncomp: usize,
        channels: Channels,
    ) -> Result<(Option<ChannelTransform>, usize, Option<Vec<f64>>)> {
        let transform = if self.coefs.is_empty() {
            None
        } else {
            let ch = Channels { ncomp, ..channels };
            Some(ChannelTransform::parse_for(&self.coefs, &ch, "result")?)
        };
        let out_ncomp = transform.as_ref().map_or(ncomp, |t| t.nout);
        let factors = if self.scale.is_empty() {
            None
        } else {
            Some(scale_factors(&self.scale, out_ncomp)?)
        };
        Ok((transform, out_ncomp, factors))
    }

    /// An input's reader: from [`Pipeline::in_memory`] when it is there, else the file.
    fn reader(&self, p: &str) -> Result<MatrixReader<Box<dyn BufRead>>> {
        open_reader(p, &self.read, &self.in_memory)
    }

    /// [`Pipeline::terms`]: every term's first input streamed in lock step, each row
    /// multiplied through its own chain and factor, the sum transformed and scaled.
    fn run_sum<W: Write>(
        &self,
        inputs: &[String],
        out: W,
        name: &str,
        progress: &dyn Progress,
    ) -> Result<()> {
        if self.stack || self.columns || self.manifest.is_some() {
            return Err(Error::Usage(
                "a sum of products (+) takes no --cat, --cat-columns or --manifest".into(),
            ));
        }
        let mut terms = vec![Term {
            inputs: inputs.to_vec(),
            scale: 1.0,
        }];
        terms.extend(self.terms.iter().cloned());
        let all: Vec<String> = terms.iter().flat_map(|t| t.inputs.clone()).collect();
        self.check_options(&all)?;
        if let Some(t) = terms.iter().find(|t| t.inputs.is_empty()) {
            return Err(Error::Usage(format!(
                "+ with no matrix after it (term factor {}): expected a matrix file",
                t.scale
            )));
        }
        if let Some(t) = terms.iter().find(|t| !t.scale.is_finite()) {
            return Err(Error::Usage(format!(
                "-s {}: expected a finite factor",
                t.scale
            )));
        }
        let mut opened = Vec::new();
        let mut ops = Vec::new();
        for t in &terms {
            let mut o = self.open(&t.inputs)?;
            let ncomp = o.readers[0].ncomp();
            let chain = std::mem::take(&mut o.chain);
            ops.push(RowOps::new(ncomp, chain, None, Some(vec![t.scale; ncomp])));
            opened.push(o);
        }
        // Every term's shape, before anything is written.
        let shape = |k: usize, o: &Opened, r: &RowOps| {
            (o.nrows, r.out_ncols(o.in_ncols()), o.readers[0].ncomp(), k)
        };
        let (nrows, ncols, ncomp, _) = shape(0, &opened[0], &ops[0]);
        for (k, (o, r)) in opened.iter().zip(&ops).enumerate().skip(1) {
            let (n, c, m, _) = shape(k, o, r);
            if (n.is_some() && nrows.is_some() && n != nrows) || c != ncols || m != ncomp {
                let show = |n: Option<usize>| n.map_or("?".to_string(), |n| n.to_string());
                return Err(Error::Mismatch(format!(
                    "term {} of the sum ({}) gives {} x {} x {} but the first term ({}) gives \
                     {} x {} x {} (rows x columns x components): every term must have the \
                     same shape",
                    k + 1,
                    terms[k].inputs.join(" "),
                    show(n),
                    c,
                    m,
                    terms[0].inputs.join(" "),
                    show(nrows),
                    ncols,
                    ncomp
                )));
            }
        }
        let first_ch = opened[0].readers[0].info().channels;
        let (transform, out_ncomp, factors) = self.result_ops(ncomp, first_ch)?;
        let mut last = RowOps::new(ncomp, Vec::new(), transform, factors);
        let channels = Channels {
            ncomp: out_ncomp,
            ..first_ch
        };
        let mut wopts = self.write_options(&opened[0], out_ncomp);
        if opened.iter().all(|o| o.all_double) {
            wopts.ascii_digits = DOUBLE_DIGITS;
        }
        let mut header = Header::new();
        header.push_command(&self.command);
        if let Some(h) = &opened[0].hours {
            header.push(h.line());
        }
        let nrows = opened.iter().find_map(|o| o.nrows);
        let mut rows: Vec<Vec<f64>> = opened
            .iter()
            .map(|o| vec![0.0; o.in_ncols() * ncomp])
            .collect();
        let mut acc = vec![0.0; ncols * ncomp];
        let stage = Stage::new(progress, "sum of products", nrows.map(|n| n as u64), "rows");
        let mut result = Vec::new();
        // The writer, or the output waiting for the transposed result.
        let mut sink = if self.transpose {
            Err(out)
        } else {
            Ok(MatrixWriter::new(
                out,
                name,
                header.clone(),
                nrows,
                ncols,
                channels,
                wopts,
            )?)
        };
        let mut done = 0usize;
        loop {
            let mut more = Vec::with_capacity(opened.len());
            for (o, row) in opened.iter_mut().zip(rows.iter_mut()) {
                more.push(o.next_row(row)?);
            }
            if more.iter().all(|m| !m) {
                break;
            }
            if let Some(k) = more.iter().position(|m| !m) {
                return Err(Error::Mismatch(format!(
                    "term {} of the sum ({}) ended after {done} rows while the others go on",
                    k + 1,
                    terms[k].inputs.join(" ")
                )));
            }
            acc.iter_mut().for_each(|a| *a = 0.0);
            for (r, row) in ops.iter_mut().zip(&rows) {
                for (a, v) in acc.iter_mut().zip(r.apply(row)) {
                    *a += v;
                }
            }
            let v = last.apply(&acc);
            match &mut sink {
                Ok(w) => w.write_row(v)?,
                Err(_) => result.extend_from_slice(v),
            }
            done += 1;
            stage.advance(1);
        }
        drop(stage);
        match sink {
            Ok(w) => w.finish().map(|_| ()),
            Err(out) => Matrix {
                nrows: done,
                ncols,
                channels,
                data: result,
            }
            .transpose()
            .write(out, name, header, wopts)
            .map(|_| ()),
        }
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

/// The inputs' headers when any of them carries the header variable `var` (the mark of a
/// piece of a larger run: `SHARD=`, `HOURS=`), `None` for ordinary matrices. Pieces are
/// merged from files only (their headers are read twice); `what` names them in the error.
fn marked_headers(
    inputs: &[String],
    var: &str,
    what: &str,
) -> Result<Option<Vec<(String, Header)>>> {
    let mut headers = Vec::new();
    for p in inputs.iter().filter(|p| *p != "-") {
        headers.push((p.clone(), read_header(p)?));
    }
    if !headers.iter().any(|(_, h)| h.get(var).is_some()) {
        return Ok(None);
    }
    if inputs.iter().any(|p| p == "-") {
        return Err(Error::Usage(format!(
            "{what} are merged from files, not standard input"
        )));
    }
    Ok(Some(headers))
}

impl Pipeline {
    /// With `--cat`: the inputs' headers and NROWS when they are `rdc --shard` outputs
    /// (any file with a `SHARD=` line), `None` for ordinary matrices.
    fn shard_headers(&self, inputs: &[String]) -> Result<Option<Vec<(String, Header, usize)>>> {
        let Some(headers) = marked_headers(inputs, SHARD_VAR, "rdc shards")? else {
            return Ok(None);
        };
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
        progress: &dyn Progress,
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
            side_by_side: false,
            current: 0,
            rows: 0,
            hours: None,
            keep: None,
            scratch: Vec::new(),
            product: None,
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
        let stage = Stage::new(
            progress,
            "merging shards",
            Some(shards.iter().map(|(_, _, n)| *n as u64).sum()),
            "rows",
        );
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
            stage.advance(*nrows as u64);
        }
        out.flush().map_err(|e| Error::io(name, e))?;
        Ok(())
    }

    /// `--manifests`: one per shard, in the shards' order, all of one run.
    fn check_manifests(&self, shards: &[(String, Header, usize)]) -> Result<()> {
        let mut ms = Vec::new();
        for p in &self.manifests {
            ms.push((p.clone(), Manifest::read(p)?));
        }
        let mut pieces = Vec::new();
        for (p, h, nrows) in shards {
            let info = ShardInfo::of(h, p)?
                .ok_or_else(|| Error::Mismatch(format!("{p} has no {SHARD_VAR}= line")))?;
            pieces.push((p.as_str(), info, *nrows));
        }
        crate::shard::check_manifests_for(&ms, &pieces)?;
        // The bytes each shard's job wrote (a second read, before anything is written).
        for ((_, m), (p, _, _)) in ms.iter().zip(shards) {
            m.check_output(p)?;
        }
        Ok(())
    }

    /// `--verify`: each input against its own manifest: the `SHARD=` line and rows it
    /// describes, the data's size and the output's hash. One line per shard on `out`
    /// (`dc.3.mtx: complete (shard 3/8, rows 60..80 of 165)` or what is wrong); an error
    /// naming the shards that are not complete.
    fn verify_shards<W: Write>(&self, inputs: &[String], mut out: W, name: &str) -> Result<()> {
        if self.manifests.len() != inputs.len() {
            return Err(Error::Usage(format!(
                "--verify: {} shard files and {} manifests; give one manifest per shard, in \
                 the same order (--manifests last)",
                inputs.len(),
                self.manifests.len()
            )));
        }
        let mut bad = Vec::new();
        for (p, mp) in inputs.iter().zip(&self.manifests) {
            let line = match self.verify_one(p, mp) {
                Ok(s) => format!("{p}: complete ({s})"),
                Err(e) => {
                    bad.push(p.as_str());
                    format!(
                        "{p}: {}",
                        e.to_string().trim_start_matches(&format!("{p}: "))
                    )
                }
            };
            writeln!(out, "{line}").map_err(|e| Error::io(name, e))?;
        }
        out.flush().map_err(|e| Error::io(name, e))?;
        if bad.is_empty() {
            return Ok(());
        }
        Err(Error::Mismatch(format!(
            "{} of {} shards missing, incomplete or corrupt: {}",
            bad.len(),
            inputs.len(),
            bad.join(" ")
        )))
    }

    /// One shard against its manifest; the shard's description when it is complete.
    fn verify_one(&self, p: &str, mp: &str) -> Result<String> {
        let m = Manifest::read(mp)?;
        let h = read_header(p)?;
        let info = ShardInfo::of(&h, p)?
            .ok_or_else(|| Error::Mismatch(format!("{p}: no {SHARD_VAR}= line: not a shard")))?;
        let nrows = h.get_usize("NROWS", p)?;
        // A header without NROWS cannot be the shard (usize::MAX matches no manifest).
        m.check_piece(mp, p, &info, nrows.unwrap_or(usize::MAX))?;
        // Opening checks a binary shard's size against NROWS; the hash checks every byte.
        MatrixReader::open(p, &self.read)?;
        if m.output.is_none() {
            let (lines, whole) = data_lines(p)?;
            let binary = h.format().is_some_and(|f| f == "float" || f == "double");
            if !binary && (lines != m.rows || !whole) {
                return Err(Error::Mismatch(format!(
                    "{p}: NROWS={} but the data holds {lines} lines: an incomplete shard",
                    m.rows
                )));
            }
        }
        m.check_output(p)?;
        Ok(format!(
            "shard {}, rows {}..{} of {}",
            m.shard,
            m.first_row,
            m.first_row + m.rows,
            m.total_rows
        ))
    }
}

impl Pipeline {
    /// With `--cat-columns`: the inputs' headers when they are `rmtx --hours` chunks (any
    /// file with an `HOURS=` line), `None` for ordinary matrices.
    fn chunk_headers(&self, inputs: &[String]) -> Result<Option<Vec<(String, Header)>>> {
        marked_headers(inputs, HOURS_VAR, "rmtx --hours chunks")
    }

    /// `rmtx --cat-columns` of `rmtx --hours` chunks: check they are the chunks of one
    /// product tiling its hours (and their manifests agree), write the whole product's
    /// header, then each row as the chunks' row pieces verbatim, so the result has the
    /// whole product's bytes (module docs of [`crate::hours`]). Every check, sizes
    /// included, comes before the first byte is written.
    fn merge_hours<W: Write>(
        &self,
        inputs: &[String],
        chunks: Vec<(String, Header)>,
        mut out: W,
        name: &str,
        progress: &dyn Progress,
    ) -> Result<()> {
        if !self.coefs.is_empty() || !self.scale.is_empty() || self.transpose {
            return Err(Error::Usage(
                "rmtx --cat-columns of hour chunks copies them verbatim: no -c, -s or -t \
                 (convert the merged matrix with a second rmtx)"
                    .into(),
            ));
        }
        let (header, infos) = crate::hours::merged_header(&chunks)?;
        // Opening checks each binary chunk's size against its NROWS and NCOLS.
        let mut readers = Vec::new();
        for p in inputs {
            readers.push(MatrixReader::open(p, &self.read)?);
        }
        let info = readers[0].info().clone();
        let elem = info.format.elem_size();
        let row_bytes: Vec<usize> = readers.iter().map(|r| r.row_len() * elem).collect();
        drop(readers);
        let nrows = info.nrows.ok_or_else(|| {
            Error::Mismatch(format!(
                "{}: a chunk without NROWS= cannot be checked; give the product's first \
                 matrix a header with NROWS",
                inputs[0]
            ))
        })?;
        if info.format.is_picture() {
            return Err(Error::Usage(format!(
                "{}: chunks in {} rows cannot be merged; write them with -fa, -ff or -fd",
                inputs[0],
                info.format.name()
            )));
        }
        if self.format.is_some_and(|f| f != info.format) {
            return Err(Error::Usage(
                "rmtx --cat-columns of hour chunks copies them verbatim: no -f (convert the \
                 merged matrix with a second rmtx)"
                    .into(),
            ));
        }
        if !self.manifests.is_empty() {
            let mut ms = Vec::new();
            for p in &self.manifests {
                ms.push((p.clone(), ChunkManifest::read(p)?));
            }
            let named: Vec<(String, HoursInfo)> = chunks
                .iter()
                .map(|(p, _)| p.clone())
                .zip(infos.iter().copied())
                .collect();
            crate::hours::check_manifests(&ms, &named)?;
        }
        let binary = matches!(info.format, DataFormat::Float | DataFormat::Double);
        if !binary {
            // One line per row (our ascii writer's layout): count them before writing.
            for p in inputs {
                let (lines, whole) = data_lines(p)?;
                if lines != nrows || !whole {
                    return Err(Error::Mismatch(format!(
                        "{p}: NROWS={nrows} but the data holds {lines} lines{}: an \
                         incomplete chunk?",
                        if whole { "" } else { " and a partial one" }
                    )));
                }
            }
        }
        let mut files = Vec::new();
        for p in inputs {
            let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
            let mut r = std::io::BufReader::with_capacity(1 << 16, f);
            Header::read(&mut r, p)?;
            files.push(r);
        }
        if self.header {
            let align = if binary && self.seekable { elem } else { 1 };
            header
                .write(&mut out, align)
                .map_err(|e| Error::io(name, e))?;
        }
        let last = files.len() - 1;
        let mut piece = Vec::new();
        let stage = Stage::new(progress, "merging hour chunks", Some(nrows as u64), "rows");
        for _ in 0..nrows {
            for (k, (r, p)) in files.iter_mut().zip(inputs).enumerate() {
                if binary {
                    piece.resize(row_bytes[k], 0);
                    r.read_exact(&mut piece).map_err(|e| Error::io(p, e))?;
                } else {
                    piece.clear();
                    r.read_until(b'\n', &mut piece)
                        .map_err(|e| Error::io(p, e))?;
                    // A row's pieces join into one line: only the last keeps its newline.
                    if k < last && piece.last() == Some(&b'\n') {
                        piece.pop();
                    }
                }
                out.write_all(&piece).map_err(|e| Error::io(name, e))?;
            }
            stage.advance(1);
        }
        out.flush().map_err(|e| Error::io(name, e))?;
        Ok(())
    }
}

/// The header of matrix file `p`.
/// `p`'s reader: its bytes from `in_memory` when listed there, else the file (or standard
/// input for `-`).
fn open_reader(
    p: &str,
    ropts: &ReadOptions,
    in_memory: &[(String, Vec<u8>)],
) -> Result<MatrixReader<Box<dyn BufRead>>> {
    match in_memory.iter().find(|(n, _)| n == p) {
        Some((_, bytes)) => {
            MatrixReader::new(Box::new(std::io::Cursor::new(bytes.clone())), p, ropts)
        }
        None => MatrixReader::open(p, ropts),
    }
}

fn read_header(p: &str) -> Result<Header> {
    let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
    Header::read(&mut std::io::BufReader::new(f), p)
}

/// The newlines in the data of file `p` (after its header) and whether the data ends with
/// one (or is empty).
fn data_lines(p: &str) -> Result<(usize, bool)> {
    let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
    let mut r = std::io::BufReader::with_capacity(1 << 16, f);
    Header::read(&mut r, p)?;
    let (mut lines, mut last) = (0usize, b'\n');
    loop {
        let buf = r.fill_buf().map_err(|e| Error::io(p, e))?;
        let Some(&b) = buf.last() else {
            return Ok((lines, last == b'\n'));
        };
        lines += buf.iter().filter(|&&c| c == b'\n').count();
        last = b;
        let n = buf.len();
        r.consume(n);
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

    /// Open the right operands, check their headers, then load them. With `hours`, only
    /// those columns of the right-most matrix are kept (of the streamed rows when there is
    /// no right operand).
    fn load_chain(
        &mut self,
        paths: &[String],
        ropts: &ReadOptions,
        hours: Option<HourSpan>,
        in_memory: &[(String, Vec<u8>)],
    ) -> Result<()> {
        let mut right = Vec::new();
        for p in paths {
            right.push(open_reader(p, ropts, in_memory)?);
        }
        // Cheap header checks first, so a mismatch is reported before any large load.
        self.check_headers(&right)?;
        let cols = match hours {
            None => None,
            Some(span) => {
                let last = right.last().unwrap_or(&self.readers[0]);
                let total = last.ncols();
                let cols = span.resolve(total, last.name())?;
                self.hours = Some(HoursInfo {
                    first: cols.start,
                    end: cols.end,
                    total,
                });
                Some(cols)
            }
        };
        if right.is_empty() {
            self.keep = cols;
            return Ok(());
        }
        let nright = right.len();
        let mut prev = self.first();
        for (i, mut r) in right.into_iter().enumerate() {
            let name = r.name().to_string();
            self.note_format(r.info().format);
            let last = i + 1 == nright;
            let keep = cols.clone().filter(|_| last);
            // The right-most operand (the sky: thousands of time steps) is held only while
            // it costs less than the product in the outer order, which needs the left
            // input's rows to be known.
            let budget = match (last, self.nrows) {
                (true, Some(n)) => {
                    let ncols = keep.as_ref().map_or(r.ncols(), |k| k.len());
                    Outer::bytes(n, prev.1.ncols, ncols, r.ncomp())
                }
                _ => usize::MAX,
            };
            let (m, complete) = Operand::read_within(&mut r, keep.clone(), budget)?;
            if !complete {
                let p = self.multiply_outer(m, &mut r, keep, prev.1.ncols)?;
                let got = Shape {
                    nrows: Some(p.rows_added()),
                    ncols: p.ncols(),
                    ncomp: r.ncomp(),
                };
                check_multiply(&prev.0, prev.1, &name, got)?;
                self.product = Some(p);
                return Ok(());
            }
            check_multiply(&prev.0, prev.1, &name, m.shape())?;
            prev = (name, m.shape());
            self.chain.push(m);
        }
        Ok(())
    }

    /// The product of the streamed input, the operands in `chain` and the right-most
    /// operand `r` (its first rows already in `held`), computed in the outer order
    /// ([`Outer`]): the streamed input's rows times `chain` are held, `r`'s rows added one
    /// at a time. Memory: [`Outer::bytes`], whatever `r`'s size. `inner`: NCOLS of the
    /// held rows (NROWS of `r`).
    fn multiply_outer(
        &mut self,
        held: Operand,
        r: &mut MatrixReader<Box<dyn BufRead>>,
        keep: Option<Range<usize>>,
        inner: usize,
    ) -> Result<Outer> {
        let nleft = self.nrows.unwrap_or(0);
        let nc = r.ncomp();
        let keep = keep.unwrap_or(0..r.ncols());
        let mut p = Outer::new(nleft, inner, keep.len(), nc);
        let mut left = RowOps::new(nc, std::mem::take(&mut self.chain), None, None);
        let first = &mut self.readers[0];
        let mut row = vec![0.0; first.row_len()];
        let mut i = 0;
        // The reader refuses rows beyond NROWS (the header's, or a binary file's size).
        while first.read_row(&mut row)? {
            p.set_left_row(i, left.apply(&row));
            i += 1;
        }
        if i != nleft {
            return Err(Error::Mismatch(format!(
                "{}: {i} rows where {nleft} were expected",
                first.name()
            )));
        }
        p.add_operand(&held);
        drop(held);
        let mut buf = vec![0.0; r.row_len()];
        while r.read_row(&mut buf)? {
            p.add_values(&buf[keep.start * nc..keep.end * nc]);
        }
        Ok(p)
    }

    /// Columns of the rows [`Opened::next_row`] delivers.
    fn in_ncols(&self) -> usize {
        if let Some(p) = &self.product {
            p.ncols()
        } else if self.side_by_side {
            self.readers.iter().map(|r| r.ncols()).sum()
        } else if let Some(k) = &self.keep {
            k.len()
        } else {
            self.readers[0].ncols()
        }
    }

    /// The next input row (`in_ncols * ncomp` numbers): the readers one after the other,
    /// or side by side; `false` at the end.
    fn next_row(&mut self, row: &mut [f64]) -> Result<bool> {
        if let Some(p) = &self.product {
            if self.rows == p.nrows() {
                return Ok(false);
            }
            row.copy_from_slice(p.row(self.rows));
            self.rows += 1;
            return Ok(true);
        }
        if self.side_by_side {
            let mut off = 0;
            let mut ended: Vec<usize> = Vec::new();
            for (i, r) in self.readers.iter_mut().enumerate() {
                let n = r.row_len();
                if !r.read_row(&mut row[off..off + n])? {
                    ended.push(i);
                }
                off += n;
            }
            if ended.is_empty() {
                self.rows += 1;
                return Ok(true);
            }
            if ended.len() == self.readers.len() {
                return Ok(false);
            }
            let short = &self.readers[ended[0]];
            let long = (0..self.readers.len())
                .find(|i| !ended.contains(i))
                .map_or("", |i| self.readers[i].name());
            return Err(Error::Mismatch(format!(
                "{} ends after {} rows but {long} has more: matrices joined side by side \
                 need equal NROWS",
                short.name(),
                self.rows
            )));
        }
        if let Some(k) = &self.keep {
            let nc = self.readers[0].ncomp();
            self.scratch.resize(self.readers[0].row_len(), 0.0);
            if !self.readers[0].read_row(&mut self.scratch)? {
                return Ok(false);
            }
            row.copy_from_slice(&self.scratch[k.start * nc..k.end * nc]);
            self.rows += 1;
            return Ok(true);
        }
        while self.current < self.readers.len() {
            if self.readers[self.current].read_row(row)? {
                self.rows += 1;
                return Ok(true);
            }
            self.current += 1;
        }
        Ok(false)
    }

    /// `--cat-columns`: equal NROWS (where known) and NCOMP.
    fn check_columns(&mut self) -> Result<()> {
        let (fname, fshape) = self.first();
        let mut formats = Vec::new();
        for r in &self.readers[1..] {
            let s = r.info().shape();
            let rows_differ = matches!((fshape.nrows, s.nrows), (Some(a), Some(b)) if a != b);
            if s.ncomp != fshape.ncomp || rows_differ {
                return Err(Error::Mismatch(format!(
                    "{} ({s}) cannot be joined beside {fname} ({fshape}): NROWS and NCOMP \
                     must agree",
                    r.name()
                )));
            }
            if s.nrows.is_none() {
                self.nrows = None;
            }
            formats.push(r.info().format);
        }
        for f in formats {
            self.note_format(f);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn product(inputs: &[String]) -> Pipeline {
        Pipeline {
            inputs: inputs.to_vec(),
            stack: false,
            columns: false,
            read: ReadOptions::default(),
            coefs: Vec::new(),
            scale: Vec::new(),
            format: None,
            transpose: false,
            header: true,
            command: vec!["rmtx".into()],
            seekable: false,
            manifests: Vec::new(),
            hours: None,
            manifest: None,
            verify: false,
            terms: Vec::new(),
            in_memory: Vec::new(),
        }
    }

    /// An ascii file of `nrows x ncols x 1`, every element `v`.
    fn write(dir: &std::path::Path, name: &str, nrows: usize, ncols: usize, v: f64) -> String {
        let row = vec![v.to_string(); ncols].join(" ");
        let text = format!(
            "#?RADIANCE\nNROWS={nrows}\nNCOLS={ncols}\nNCOMP=1\nFORMAT=ascii\n\n{}",
            format!("{row}\n").repeat(nrows)
        );
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    }

    /// The outer order is taken exactly when holding the right-most operand would cost
    /// more than [`Outer::bytes`]: 2 x 30 by 30 x 400 (dense, 96 kB held) goes outer
    /// (2 x (30 x 4 + 400 x 8) = 6.6 kB), 100 x 30 by the same stays held (332 kB outer).
    #[test]
    fn the_outer_order_is_taken_when_it_holds_less() {
        let t = tempfile::tempdir().unwrap();
        let sky = write(t.path(), "sky", 30, 400, 0.5);
        let few = write(t.path(), "few", 2, 30, 0.25);
        let many = write(t.path(), "many", 100, 30, 0.25);
        let o = product(&[few.clone(), sky.clone()])
            .open(&[few, sky.clone()])
            .unwrap();
        let p = o.product.as_ref().expect("outer order");
        assert_eq!((p.nrows(), p.ncols(), p.rows_added()), (2, 400, 30));
        assert!(p.row(1).iter().all(|&v| v == 30.0 * 0.125));
        let o = product(&[many.clone(), sky.clone()])
            .open(&[many, sky])
            .unwrap();
        assert!(o.product.is_none() && o.chain.len() == 1);
    }
}
