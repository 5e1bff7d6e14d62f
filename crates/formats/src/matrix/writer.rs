//! Streaming matrix writer: header, then rows as they come.
//!
//! Header as Radiance's `rmx_write_header` writes it (notes §2.1): the caller's lines (our
//! command line), then `NROWS=` (when known), `NCOLS=`, `NCOMP=` (+ `WAVELENGTH_SPLITS=` for
//! NCOMP > 3), `BigEndian=` for binary data, `FORMAT=`, empty line. `FORMAT=` is padded with
//! blanks so binary data starts at a multiple of the element size only when the output is a
//! seekable file, as `fputformat` does when `ftell` works; in pipes it is unpadded.
//!
//! ASCII rows follow `rmx_write_ascii` (rmtxop, rcomb): each component `" %.7e"`, a TAB after
//! each element, a newline after each row. `%.7e` keeps float data exact to float precision
//! (8 significant digits); for double data ask for more digits (16 gives 17 significant
//! digits, which round-trips any f64). Float output rounds each f64 to the nearest f32.

use super::ascii::push_e;
use super::{DataFormat, Shape};
use crate::error::{Error, Location, Result};
use crate::header::Header;
use crate::picture::resolution::Resolution;
use crate::picture::{color, scanline, spectral};
use crate::radiometry::Channels;
use std::io::Write;

/// How to write a matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WriteOptions {
    /// Data format (`-fa`, `-ff`, `-fd`).
    pub format: DataFormat,
    /// Write the information header (`false` = Radiance's `-h`).
    pub header: bool,
    /// The output is a seekable file: pad `FORMAT=` to the element size.
    pub seekable: bool,
    /// Byte order of binary data; native by default.
    pub big_endian: bool,
    /// Digits after the decimal point in ascii output (`%.{digits}e`).
    pub ascii_digits: usize,
}

/// `%.7e`, rmtxop's ascii precision; enough for float-precision data.
pub const FLOAT_DIGITS: usize = 7;
/// `%.16e`: 17 significant digits, enough to round-trip any f64.
pub const DOUBLE_DIGITS: usize = 16;

impl WriteOptions {
    pub fn new(format: DataFormat) -> Self {
        WriteOptions {
            format,
            header: true,
            seekable: false,
            big_endian: cfg!(target_endian = "big"),
            ascii_digits: FLOAT_DIGITS,
        }
    }
}

/// Writes a matrix row by row.
pub struct MatrixWriter<W: Write> {
    w: W,
    name: String,
    opts: WriteOptions,
    shape: Shape,
    rows: usize,
    out: Vec<u8>,
}

impl<W: Write> MatrixWriter<W> {
    /// Write the header now (unless `opts.header` is false). `header` carries the caller's
    /// lines (command line, notes); the size and format variables are set here. `nrows` may
    /// be unknown (`None`) when rows are streamed from an input without `NROWS=`.
    pub fn new(
        mut w: W,
        name: &str,
        mut header: Header,
        nrows: Option<usize>,
        ncols: usize,
        channels: Channels,
        opts: WriteOptions,
    ) -> Result<Self> {
        let picture = opts.format.is_picture();
        if picture {
            // Picture-coded rows need the row count up front for the resolution string, and
            // RGBE/XYZE hold 3 components (1 is written as grey, as rmtxop does).
            if nrows.is_none() {
                return Err(Error::Usage(format!(
                    "{name}: a {} matrix needs its number of rows in advance; write \
                     float or double instead",
                    opts.format.name()
                )));
            }
            if opts.format != DataFormat::Spectra && !matches!(channels.ncomp, 1 | 3) {
                return Err(Error::Usage(format!(
                    "{name}: {} holds 1 or 3 components, not NCOMP={}; use -fa, -ff or -fd",
                    opts.format.name(),
                    channels.ncomp
                )));
            }
        }
        if opts.header {
            for k in [
                "NROWS",
                "NCOLS",
                "NCOMP",
                "WAVELENGTH_SPLITS",
                "BigEndian",
                "FORMAT",
            ] {
                header.remove(k);
            }
            if !picture {
                if let Some(n) = nrows {
                    header.set("NROWS", n);
                }
                header.set("NCOLS", ncols);
            }
            if opts.format == DataFormat::Spectra || !picture {
                header.set_channels(channels);
            }
            let binary = matches!(opts.format, DataFormat::Float | DataFormat::Double);
            if binary {
                header.set("BigEndian", u8::from(opts.big_endian));
            }
            header.set("FORMAT", opts.format.name());
            let align = if binary && opts.seekable {
                opts.format.elem_size()
            } else {
                1
            };
            header
                .write(&mut w, align)
                .map_err(|e| Error::io(name, e))?;
        }
        if picture {
            // The resolution string follows the header even with -h (it is part of the data).
            let res = Resolution::standard(ncols, nrows.unwrap_or(0));
            w.write_all(res.to_line().as_bytes())
                .map_err(|e| Error::io(name, e))?;
        }
        Ok(MatrixWriter {
            w,
            name: name.to_string(),
            opts,
            shape: Shape {
                nrows,
                ncols,
                ncomp: channels.ncomp,
            },
            rows: 0,
            out: Vec::new(),
        })
    }

    /// Numbers per row.
    pub fn row_len(&self) -> usize {
        self.shape.ncols * self.shape.ncomp
    }

    /// Rows written so far.
    pub fn rows_written(&self) -> usize {
        self.rows
    }

    /// Append one row of `ncols * ncomp` numbers.
    pub fn write_row(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.row_len() {
            return Err(Error::Usage(format!(
                "{}: a row of {} numbers given, expected {} (NCOLS={} x NCOMP={})",
                self.name,
                row.len(),
                self.row_len(),
                self.shape.ncols,
                self.shape.ncomp
            )));
        }
        if let Some(n) = self.shape.nrows {
            if self.rows >= n {
                return Err(Error::Usage(format!(
                    "{}: more than the announced NROWS={n} rows written",
                    self.name
                )));
            }
        }
        self.out.clear();
        let be = self.opts.big_endian;
        match self.opts.format {
            DataFormat::Ascii => {
                let nc = self.shape.ncomp;
                for elem in row.chunks(nc) {
                    for &v in elem {
                        self.out.push(b' ');
                        push_e(&mut self.out, v, self.opts.ascii_digits);
                    }
                    self.out.push(b'\t');
                }
                self.out.push(b'\n');
            }
            DataFormat::Float => {
                for &v in row {
                    let f = v as f32;
                    self.out
                        .extend_from_slice(&if be { f.to_be_bytes() } else { f.to_le_bytes() });
                }
            }
            DataFormat::Double => {
                for &v in row {
                    self.out
                        .extend_from_slice(&if be { v.to_be_bytes() } else { v.to_le_bytes() });
                }
            }
            DataFormat::Spectra => {
                let vals: Vec<f32> = row.iter().map(|&v| v as f32).collect();
                let mut bytes = Vec::new();
                spectral::write_scanline(&mut self.out, self.shape.ncomp, &vals, &mut bytes)
                    .map_err(|e| Error::io(&self.name, e))?;
            }
            _ => {
                let nc = self.shape.ncomp;
                let colrs: Vec<[u8; 4]> = row
                    .chunks_exact(nc)
                    .map(|e| {
                        let (r, g, b) = if nc == 1 {
                            (e[0], e[0], e[0])
                        } else {
                            (e[0], e[1], e[2])
                        };
                        color::encode_rgbe(r as f32, g as f32, b as f32)
                    })
                    .collect();
                scanline::write_colrs(&mut self.out, &colrs)
                    .map_err(|e| Error::io(&self.name, e))?;
            }
        }
        self.w
            .write_all(&self.out)
            .map_err(|e| Error::io(&self.name, e))?;
        self.rows += 1;
        Ok(())
    }

    /// Flush and check that the announced number of rows was written.
    pub fn finish(mut self) -> Result<W> {
        self.w.flush().map_err(|e| Error::io(&self.name, e))?;
        if let Some(n) = self.shape.nrows {
            if self.rows != n {
                return Err(Error::parse(
                    Location::file(&self.name),
                    format!(
                        "{} rows written but the header announced NROWS={n}",
                        self.rows
                    ),
                ));
            }
        }
        Ok(self.w)
    }
}
