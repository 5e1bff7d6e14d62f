//! Streaming matrix reader: header first, then one row at a time into the caller's buffer.
//!
//! Memory is one row (`ncols * ncomp` numbers) plus, for ascii, one text line; a
//! 10,000 x 146 x 3 float matrix read row by row never holds more than one 146 x 3 row
//! (the reader owns only a byte buffer of `row_len * 4` bytes). Rows are decoded exactly:
//! binary rows are read with exact byte counts and swapped when `BigEndian=` differs from
//! the machine (`rmatrix.c: get_dminfo`, `RMF_SWAPIN`).
//!
//! End of data (Radiance reads exactly NROWS rows and ignores the rest; we are stricter so
//! that a wrong NCOLS or a truncated transfer cannot pass unnoticed):
//! - with `NROWS`: a short file is `file: ends after row 41 of 146 (NROWS=146): truncated?`,
//!   extra numbers after the last row are an error too;
//! - without `NROWS` (rcontrib without `-y`): rows are read until the data ends; data that
//!   ends inside a row is an error naming the row and how many numbers it got.

use super::ascii::AsciiScanner;
use super::{DataFormat, MatrixInfo};
use crate::error::{Error, Location, Result};
use crate::header::Header;
use crate::picture::resolution::{Resolution, STANDARD};
use crate::picture::{color, scanline, spectral};
use std::io::{BufRead, BufReader};

/// Largest row we accept (numbers): a bound against absurd `NCOLS` in a damaged header,
/// far above any daylight matrix (8760 time steps x 24 spectral samples = 210,240).
pub const MAX_ROW_LEN: usize = 1 << 26;

/// What the caller knows about the input that its header may not say (headerless `-h`
/// output of rcontrib, rtrace and gendaymtx), and how to load it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// Data format when the header has no `FORMAT=` (default ascii, as Radiance assumes).
    pub format: Option<DataFormat>,
    /// Components per element when the header has no `NCOMP=` (default 3).
    pub ncomp: Option<usize>,
    /// Columns when the header has no `NCOLS=`; for ascii, inferred from the first line
    /// (one record per line, as rcontrib writes) if not given.
    pub ncols: Option<usize>,
    /// Rows when the header has no `NROWS=` (otherwise read to the end of the data).
    pub nrows: Option<usize>,
    /// Divide out `EXPOSURE=`/`COLORCORR=` as `rmtxop`/`rcomb` do on load (`rmx_load`).
    pub undo_exposure: bool,
}

/// Reads a Radiance matrix row by row.
pub struct MatrixReader<R> {
    r: R,
    name: String,
    info: MatrixInfo,
    rows_read: usize,
    ascii: Option<AsciiScanner>,
    bytes: Vec<u8>,
    scale: Option<Vec<f64>>,
    finished: bool,
}

/// Opens `-` as standard input, anything else as a file.
pub fn open_input(path: &str) -> Result<Box<dyn BufRead>> {
    if path == "-" {
        Ok(Box::new(BufReader::with_capacity(
            1 << 16,
            std::io::stdin().lock(),
        )))
    } else {
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        Ok(Box::new(BufReader::with_capacity(1 << 16, f)))
    }
}

impl MatrixReader<Box<dyn BufRead>> {
    /// Open a file (or `-` for standard input) and read its header.
    ///
    /// For a regular binary file with NROWS, the data size is checked against the header
    /// right away, so a truncated file or a wrong NCOLS is reported before a caller writes
    /// any output (a stream can only be checked as it is read). Without NROWS, a regular
    /// binary file's size sets [`MatrixInfo::nrows`].
    pub fn open(path: &str, opts: &ReadOptions) -> Result<Self> {
        if path == "-" {
            return MatrixReader::new(open_input(path)?, "<stdin>", opts);
        }
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let size = f.metadata().ok().filter(|m| m.is_file()).map(|m| m.len());
        let counted = Counted {
            inner: BufReader::with_capacity(1 << 16, f),
            consumed: 0,
        };
        let mut m = MatrixReader::new(counted, path, opts)?;
        let elem = m.info.format.elem_size() as u64;
        let row_bytes = m.row_len() as u64 * elem;
        if let (Some(size), true) = (size, elem > 1 && row_bytes > 0) {
            let data = size.saturating_sub(m.r.consumed);
            match m.info.nrows {
                Some(nrows) => m.check_size(data, nrows as u64, row_bytes)?,
                // No NROWS (rcontrib without -y): a regular file's size says how many rows
                // it holds, so writers downstream can announce NROWS (rmtxop needs it).
                None if data % row_bytes == 0 => m.info.nrows = Some((data / row_bytes) as usize),
                None => {
                    let (rows, rest) = (data / row_bytes, data % row_bytes);
                    return Err(m.ends_inside(
                        rows as usize + 1,
                        rest as usize,
                        row_bytes as usize,
                        "bytes",
                    ));
                }
            }
        }
        Ok(MatrixReader {
            r: Box::new(m.r.inner) as Box<dyn BufRead>,
            name: m.name,
            info: m.info,
            rows_read: m.rows_read,
            ascii: m.ascii,
            bytes: m.bytes,
            scale: m.scale,
            finished: m.finished,
        })
    }
}

/// Decode every row of the file at `path` and keep none: for a writer that must not start
/// its output before it knows the input is whole (issue #19: `rmtx -fa truncated.mtx > out`
/// wrote a header promising NROWS=165, then 150 rows). [`MatrixReader::open`] checks a
/// binary file by its size; ascii and RGBE data can only be checked by decoding it, so this
/// reads such a file twice. Standard input (`-`) cannot be read twice: a stream is checked
/// as it is read, and the rows before an error are already written.
pub fn check_data(path: &str, opts: &ReadOptions) -> Result<()> {
    if path == "-" {
        return Ok(());
    }
    let mut m = MatrixReader::open(path, opts)?;
    if matches!(m.info.format, DataFormat::Float | DataFormat::Double) {
        return Ok(());
    }
    let mut row = vec![0.0; m.row_len()];
    while m.read_row(&mut row)? {}
    Ok(())
}

/// A buffered reader that counts the bytes consumed (the header length of a file).
struct Counted<R> {
    inner: R,
    consumed: u64,
}

impl<R: BufRead> std::io::Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.consumed += n as u64;
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counted<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }
    fn consume(&mut self, amt: usize) {
        self.consumed += amt as u64;
        self.inner.consume(amt);
    }
}

impl<R: BufRead> MatrixReader<R> {
    /// Read the header from `r`; `name` is used in messages.
    pub fn new(mut r: R, name: &str, opts: &ReadOptions) -> Result<Self> {
        let header = Header::read(&mut r, name)?;
        let data_line = header.nlines + 1;
        let mut info = MatrixInfo::from_header(header, name, opts)?;
        let mut ascii = None;
        match info.format {
            DataFormat::Ascii => {
                let mut sc = AsciiScanner::new(data_line);
                if info.ncols == 0 {
                    let n = sc.count_first_line(&mut r, name)?;
                    let nc = info.channels.ncomp;
                    if n == 0 {
                        return Err(Error::parse(
                            Location::file(name),
                            "no data: expected ascii numbers after the header",
                        ));
                    }
                    if n % nc != 0 {
                        return Err(Error::parse(
                            Location::line(name, sc.line_no().max(1)),
                            format!(
                                "no NCOLS given and the first data line has {n} numbers, \
                                 not a multiple of NCOMP={nc}: give the number of columns"
                            ),
                        ));
                    }
                    info.ncols = n / nc;
                }
                ascii = Some(sc);
            }
            DataFormat::Float | DataFormat::Double => {}
            _ => {
                // One scanline per row; like rmtxop, only the standard orientation, where
                // scanlines are rows and pixels are columns.
                let res = Resolution::read(&mut r, name, data_line)?;
                if res.order != STANDARD {
                    return Err(Error::parse(
                        Location::line(name, data_line),
                        format!(
                            "resolution '{}' is not the standard orientation (-Y rows +X \
                             columns) a matrix needs",
                            res.to_line().trim_end()
                        ),
                    ));
                }
                info.nrows = Some(res.num_scans());
                info.ncols = res.scan_len();
            }
        }
        if info.row_len() > MAX_ROW_LEN {
            return Err(Error::parse(
                Location::file(name),
                format!(
                    "NCOLS={} x NCOMP={} = {} numbers per row: more than the {MAX_ROW_LEN} \
                     this reader accepts",
                    info.ncols,
                    info.channels.ncomp,
                    info.row_len()
                ),
            ));
        }
        let scale = if opts.undo_exposure {
            info.unexposure()
        } else {
            None
        };
        let bytes = match info.format {
            DataFormat::Float | DataFormat::Double => {
                vec![0u8; info.row_len() * info.format.elem_size()]
            }
            _ => Vec::new(),
        };
        Ok(MatrixReader {
            r,
            name: name.to_string(),
            info,
            rows_read: 0,
            ascii,
            bytes,
            scale,
            finished: false,
        })
    }

    pub fn info(&self) -> &MatrixInfo {
        &self.info
    }
    pub fn name(&self) -> &str {
        &self.name
    }
    pub fn nrows(&self) -> Option<usize> {
        self.info.nrows
    }
    pub fn ncols(&self) -> usize {
        self.info.ncols
    }
    pub fn ncomp(&self) -> usize {
        self.info.channels.ncomp
    }
    /// Numbers per row (`ncols * ncomp`): the size of the buffer [`read_row`] fills.
    ///
    /// [`read_row`]: MatrixReader::read_row
    pub fn row_len(&self) -> usize {
        self.info.row_len()
    }
    /// Rows delivered so far.
    pub fn rows_read(&self) -> usize {
        self.rows_read
    }

    /// Read the next row into `buf` (length [`row_len`](MatrixReader::row_len)).
    /// Returns `false` at the end of the data (after checking it ends where it should).
    pub fn read_row(&mut self, buf: &mut [f64]) -> Result<bool> {
        if buf.len() != self.row_len() {
            return Err(Error::Usage(format!(
                "{}: row buffer holds {} numbers, a row has {}",
                self.name,
                buf.len(),
                self.row_len()
            )));
        }
        if self.finished {
            return Ok(false);
        }
        if let Some(n) = self.info.nrows {
            if self.rows_read >= n {
                self.finished = true;
                self.check_no_extra()?;
                return Ok(false);
            }
        }
        // `got` and `want` count numbers (ascii) or bytes (binary).
        let (got, want, unit) = match self.info.format {
            DataFormat::Ascii => (self.read_ascii_row(buf)?, buf.len(), "numbers"),
            DataFormat::Float | DataFormat::Double => {
                (self.read_binary_row(buf)?, self.bytes.len(), "bytes")
            }
            _ => (self.read_picture_row(buf)?, buf.len(), "values"),
        };
        if got == 0 {
            self.finished = true;
            return match self.info.nrows {
                Some(n) => Err(self.ends_after(self.rows_read, n)),
                None => Ok(false),
            };
        }
        if got < want {
            self.finished = true;
            return Err(self.ends_inside(self.rows_read + 1, got, want, unit));
        }
        if let Some(s) = &self.scale {
            let nc = s.len();
            for (i, v) in buf.iter_mut().enumerate() {
                *v *= s[i % nc];
            }
        }
        self.rows_read += 1;
        Ok(true)
    }

    fn ends_after(&self, rows: usize, nrows: usize) -> Error {
        Error::parse(
            Location::file(&self.name),
            format!("ends after row {rows} of {nrows} (NROWS={nrows}): truncated?"),
        )
    }

    fn ends_inside(&self, row: usize, got: usize, want: usize, unit: &str) -> Error {
        Error::parse(
            self.end_location(),
            format!(
                "ends inside row {row} ({got} of {want} {unit}; NCOLS={} NCOMP={}): \
                 truncated, or wrong NCOLS/NCOMP?",
                self.info.ncols, self.info.channels.ncomp
            ),
        )
    }

    fn extra_data(&self, n: usize) -> Error {
        Error::parse(
            match &self.ascii {
                Some(sc) => Location::line(&self.name, sc.line_no()),
                None => Location::file(&self.name),
            },
            format!(
                "more data after row {n} of {n} (NROWS={n}, NCOLS={}, NCOMP={}): \
                 wrong NROWS or NCOLS?",
                self.info.ncols, self.info.channels.ncomp
            ),
        )
    }

    /// Binary data of `data` bytes must hold exactly `nrows` rows of `row_bytes`; the
    /// errors are those reading would give.
    fn check_size(&self, data: u64, nrows: u64, row_bytes: u64) -> Result<()> {
        let want = nrows.saturating_mul(row_bytes);
        if data > want {
            return Err(self.extra_data(nrows as usize));
        }
        if data < want && row_bytes > 0 {
            let (rows, rest) = (data / row_bytes, data % row_bytes);
            return Err(if rest == 0 {
                self.ends_after(rows as usize, nrows as usize)
            } else {
                self.ends_inside(
                    rows as usize + 1,
                    rest as usize,
                    row_bytes as usize,
                    "bytes",
                )
            });
        }
        Ok(())
    }

    fn end_location(&self) -> Location {
        match &self.ascii {
            Some(sc) => Location::line(&self.name, sc.line_no()),
            None => Location::file(&self.name),
        }
    }

    /// Numbers read into `buf`; 0 at a clean end of data.
    fn read_ascii_row(&mut self, buf: &mut [f64]) -> Result<usize> {
        let Some(sc) = self.ascii.as_mut() else {
            return Ok(0);
        };
        for (i, slot) in buf.iter_mut().enumerate() {
            match sc.next_number(&mut self.r, &self.name)? {
                Some(v) => *slot = v,
                None => return Ok(i),
            }
        }
        Ok(buf.len())
    }

    /// Bytes read for the row; 0 at a clean end of data.
    fn read_binary_row(&mut self, buf: &mut [f64]) -> Result<usize> {
        let mut filled = 0;
        while filled < self.bytes.len() {
            match self.r.read(&mut self.bytes[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::io(&self.name, e)),
            }
        }
        if filled < self.bytes.len() {
            // A partial row (0 bytes: a clean end between rows).
            return Ok(filled);
        }
        let swap = self.info.swap();
        match self.info.format {
            DataFormat::Float => {
                for (slot, b) in buf.iter_mut().zip(self.bytes.chunks_exact(4)) {
                    let a = [b[0], b[1], b[2], b[3]];
                    let bits = u32::from_ne_bytes(a);
                    *slot = f32::from_bits(if swap { bits.swap_bytes() } else { bits }) as f64;
                }
            }
            _ => {
                for (slot, b) in buf.iter_mut().zip(self.bytes.chunks_exact(8)) {
                    let a = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
                    let bits = u64::from_ne_bytes(a);
                    *slot = f64::from_bits(if swap { bits.swap_bytes() } else { bits });
                }
            }
        }
        Ok(self.bytes.len())
    }

    /// A picture-coded row (RGBE/XYZE scanline, or flat spectral scanline): numbers read, 0
    /// at a clean end of data. Encoding errors are reported with the row.
    fn read_picture_row(&mut self, buf: &mut [f64]) -> Result<usize> {
        if self
            .r
            .fill_buf()
            .map_err(|e| Error::io(&self.name, e))?
            .is_empty()
        {
            return Ok(0);
        }
        let row = self.rows_read + 1;
        let bad = |e: scanline::ScanlineError| {
            Error::parse(Location::file(&self.name), format!("row {row}: {e}"))
        };
        if self.info.format == DataFormat::Spectra {
            let mut vals = vec![0f32; buf.len()];
            spectral::read_scanline(
                &mut self.r,
                self.info.channels.ncomp,
                &mut self.bytes,
                &mut vals,
            )
            .map_err(bad)?;
            for (d, v) in buf.iter_mut().zip(vals) {
                *d = v as f64;
            }
        } else {
            let mut colrs = vec![[0u8; 4]; self.info.ncols];
            scanline::read_colrs(&mut self.r, &mut colrs).map_err(bad)?;
            for (d, c) in buf.chunks_exact_mut(3).zip(colrs) {
                let v = color::decode_rgbe(c);
                for k in 0..3 {
                    d[k] = v[k] as f64;
                }
            }
        }
        Ok(buf.len())
    }

    /// After NROWS rows nothing but (ascii) white space may follow.
    fn check_no_extra(&mut self) -> Result<()> {
        let n = self.rows_read;
        let extra = match self.ascii.as_mut() {
            Some(sc) => !sc.at_end(&mut self.r, &self.name)?,
            None => {
                let buf = self.r.fill_buf().map_err(|e| Error::io(&self.name, e))?;
                !buf.is_empty()
            }
        };
        if extra {
            return Err(self.extra_data(n));
        }
        Ok(())
    }

    /// Give back the underlying reader (e.g. to read what follows the matrix).
    pub fn into_inner(self) -> R {
        self.r
    }
}
