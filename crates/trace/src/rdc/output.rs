//! # `rdc` output: headers and rows as Radiance writes them
//!
//! Matrix header in rcontrib's order (radiance-notes.md 2.3, `rc2.c: printheader`): the
//! command line, `VIEW=` (pictures), `SOFTWARE=`, `CAPDATE=`, `GMT=`, `NCOMP=`,
//! `WAVELENGTH_SPLITS=` (NCOMP > 3), `NROWS=`, `NCOLS=`, `BigEndian=` (float/double),
//! `FORMAT=` (padded to the element size when standard output is a regular file, as
//! `fputformat`). For `-fc` (RGBE / Radiance_spectra rows) the size goes in a resolution
//! string instead (`-Y NROWS +X NCOLS`), as rcontrib and rmtxop write it.
//!
//! ASCII rows as rcontrib's `put_contrib` and rtrace: each component `%.6e` and a TAB, a
//! newline after each record. Pictures: the header rpict writes (command, `VIEW=`,
//! `SOFTWARE=`, dates, `FORMAT=32-bit_rle_rgbe`), new-style RLE scanlines, top row first.
//!
//! `-o FILE` (rpict's and rtpict's option letter for an output file) writes the picture to
//! FILE instead, replacing it only once the picture is complete: OpenEXR when the name ends
//! in `.exr` (32-bit float `R G B`, or one `S0.<centre>nm` channel per band in the spectral
//! layout of Fichet et al. 2021, [`crate::formats::picture::exr`]), which keeps the values
//! unquantised; otherwise the same RGBE/Radiance_spectra picture as on standard output.

use super::run::RecordResult;
use crate::error::{Error, Result};
use crate::formats::header::Header;
use crate::formats::matrix::ascii::push_e;
use crate::formats::matrix::{DataFormat, MatrixWriter, WriteOptions};
use crate::formats::picture::exr::write_exr_to;
use crate::formats::picture::resolution::Resolution;
use crate::formats::picture::{Picture, PictureWriter, PixelFormat};
use crate::formats::view::View;
use crate::radiometry::Channels;
use std::io::Write;

/// The name of standard output in messages.
const STDOUT: &str = "<stdout>";

/// `SOFTWARE=` value.
pub fn software() -> String {
    format!(" rdaylight {} rdc", env!("CARGO_PKG_VERSION"))
}

/// Header in rcontrib's order. `nrows`/`ncols` are written for ascii, float and double
/// (`nrows = None` omits NROWS); `ncols = 0` omits NCOLS (pictures).
pub fn header(
    command: &[String],
    view: Option<&View>,
    channels: &Channels,
    nrows: Option<usize>,
    ncols: usize,
    format: DataFormat,
) -> Header {
    let mut h = Header::new();
    h.push_command(command);
    if let Some(v) = view {
        h.push(v.header_line());
    }
    h.set("SOFTWARE", software());
    h.push_dates();
    if ncols > 0 {
        if !matches!(format, DataFormat::Rgbe) || channels.ncomp > 3 {
            h.set_channels(*channels);
        }
        if !format.is_picture() {
            if let Some(n) = nrows {
                h.set("NROWS", n);
            }
            h.set("NCOLS", ncols);
        }
        if matches!(format, DataFormat::Float | DataFormat::Double) {
            h.set("BigEndian", u8::from(cfg!(target_endian = "big")));
        }
        let name = if format == DataFormat::Rgbe && channels.ncomp > 3 {
            DataFormat::Spectra.name()
        } else {
            format.name()
        };
        h.set("FORMAT", name);
    }
    h
}

/// Where rows go.
pub enum Sink<W: Write> {
    /// rcontrib-style ascii (`%.6e\t`).
    Ascii { w: W, row: Vec<u8> },
    /// float, double, RGBE or spectra rows through [`MatrixWriter`] (header written here).
    Matrix(MatrixWriter<W>),
    /// A picture: one row = one scanline.
    Picture(PictureWriter<W>, Vec<f32>),
    /// `-o FILE`: the picture collected in memory and written on [`Sink::finish`], as
    /// OpenEXR when the name ends in `.exr`, else as a Radiance picture; atomically.
    File {
        path: String,
        picture: Picture,
        next_row: usize,
    },
}

/// Whether `-o` names an OpenEXR file (by extension, any case).
pub fn is_exr(path: &str) -> bool {
    std::path::Path::new(path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

impl<W: Write> Sink<W> {
    /// Write `header` (unless `-h`) and prepare for `nrows x ncols` rows.
    #[allow(clippy::too_many_arguments)]
    pub fn matrix(
        mut w: W,
        header: Header,
        nrows: usize,
        ncols: usize,
        channels: Channels,
        format: DataFormat,
        write_header: bool,
        seekable: bool,
    ) -> Result<Self> {
        let binary = matches!(format, DataFormat::Float | DataFormat::Double);
        if write_header {
            let align = if binary && seekable {
                format.elem_size()
            } else {
                1
            };
            header
                .write(&mut w, align)
                .map_err(|e| Error::io(STDOUT, e))?;
        }
        if format == DataFormat::Ascii {
            return Ok(Sink::Ascii { w, row: Vec::new() });
        }
        let format = if format == DataFormat::Rgbe && channels.ncomp > 3 {
            DataFormat::Spectra
        } else {
            format
        };
        let mut wo = WriteOptions::new(format);
        wo.header = false;
        Ok(Sink::Matrix(MatrixWriter::new(
            w,
            STDOUT,
            Header::new(),
            Some(nrows),
            ncols,
            channels,
            wo,
        )?))
    }

    /// A picture of `xres x yres` pixels (RGBE for 3 channels, Radiance_spectra otherwise).
    pub fn picture(
        w: W,
        header: Header,
        xres: usize,
        yres: usize,
        channels: Channels,
    ) -> Result<Self> {
        let format = if channels.ncomp == 3 {
            PixelFormat::Rgbe
        } else {
            PixelFormat::Spectra
        };
        let pw = PictureWriter::new(
            w,
            STDOUT,
            &header,
            format,
            &channels,
            Resolution::standard(xres, yres),
            true,
        )?;
        Ok(Sink::Picture(pw, Vec::new()))
    }

    /// A picture to standard output (`out = None`) or to the file `-o` names.
    pub fn picture_to(
        out: Option<&str>,
        w: W,
        header: Header,
        xres: usize,
        yres: usize,
        channels: Channels,
    ) -> Result<Self> {
        let Some(path) = out else {
            return Self::picture(w, header, xres, yres, channels);
        };
        let format = if channels.ncomp == 3 {
            PixelFormat::Rgbe
        } else {
            PixelFormat::Spectra
        };
        let mut picture = Picture::new(xres, yres, channels, format);
        picture.header = header;
        Ok(Sink::File {
            path: path.to_string(),
            picture,
            next_row: 0,
        })
    }

    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        match self {
            Sink::Ascii { w, row } => {
                row.clear();
                for &v in values {
                    push_e(row, v, 6);
                    row.push(b'\t');
                }
                row.push(b'\n');
                w.write_all(row).map_err(|e| Error::io(STDOUT, e))
            }
            Sink::Matrix(m) => m.write_row(values),
            Sink::Picture(p, buf) => {
                buf.clear();
                buf.extend(values.iter().map(|&v| v as f32));
                p.write_scanline(buf)
            }
            Sink::File {
                path,
                picture,
                next_row,
            } => {
                let len = picture.width * picture.ncomp();
                let at = *next_row * len;
                if values.len() != len || at + len > picture.data.len() {
                    return Err(Error::Mismatch(format!(
                        "{path}: scanline {next_row} of {} values; expected {len}",
                        values.len()
                    )));
                }
                for (d, v) in picture.data[at..at + len].iter_mut().zip(values) {
                    *d = *v as f32;
                }
                *next_row += 1;
                Ok(())
            }
        }
    }

    pub fn flush(&mut self) -> Result<()> {
        match self {
            Sink::Ascii { w, .. } => w.flush().map_err(|e| Error::io(STDOUT, e)),
            // MatrixWriter and PictureWriter flush in finish; rows already went to `w`.
            _ => Ok(()),
        }
    }

    pub fn finish(self) -> Result<()> {
        match self {
            Sink::Ascii { mut w, .. } => w.flush().map_err(|e| Error::io(STDOUT, e)),
            Sink::Matrix(m) => m.finish().map(|_| ()),
            Sink::Picture(p, _) => p.finish().map(|_| ()),
            Sink::File {
                path,
                picture,
                next_row,
            } => {
                if next_row != picture.height {
                    return Err(Error::Mismatch(format!(
                        "{path}: {next_row} of {} scanlines computed",
                        picture.height
                    )));
                }
                let exr = is_exr(&path);
                crate::io::write_atomically(std::path::Path::new(&path), |w| {
                    if exr {
                        // The exr crate writes to a seekable stream: build it in memory.
                        let mut buf = std::io::Cursor::new(Vec::new());
                        write_exr_to(&picture, &mut buf)
                            .map_err(|e| Error::Usage(format!("{path}: {e}")))?;
                        w.write_all(buf.get_ref()).map_err(|e| Error::io(&path, e))
                    } else {
                        picture.write(w, true)
                    }
                })
            }
        }
    }
}

/// `--se-out FILE`: per record, relative standard error and samples taken (ascii matrix).
pub struct SeWriter {
    /// The target, the temporary file beside it that is renamed over it by
    /// [`SeWriter::finish`], and the writer (issue #19: an input error replaced the old
    /// file with a header-only one); dropped unfinished, the temporary file is removed.
    inner: Option<(
        String,
        std::path::PathBuf,
        std::io::BufWriter<std::fs::File>,
    )>,
    line: Vec<u8>,
}

impl SeWriter {
    pub fn open(path: Option<&str>, command: &[String], nrows: usize) -> Result<SeWriter> {
        let Some(path) = path else {
            return Ok(SeWriter {
                inner: None,
                line: Vec::new(),
            });
        };
        let tmp = crate::io::temp_beside(std::path::Path::new(path));
        let f = std::fs::File::create(&tmp).map_err(|e| Error::io(path, e))?;
        // From here the guard owns the temporary file: any error below removes it.
        let mut se = SeWriter {
            inner: Some((path.to_string(), tmp, std::io::BufWriter::new(f))),
            line: Vec::new(),
        };
        let mut h = Header::new();
        h.push_command(command);
        h.push("rdc --se-out: relative standard error, samples per record");
        h.set("SOFTWARE", software());
        h.set("NROWS", nrows);
        h.set("NCOLS", 2);
        h.set("NCOMP", 1);
        h.set("FORMAT", "ascii");
        if let Some((_, _, w)) = &mut se.inner {
            h.write(w, 1).map_err(|e| Error::io(path, e))?;
        }
        Ok(se)
    }

    pub fn write(&mut self, r: &RecordResult) -> Result<()> {
        let Some((path, _, w)) = &mut self.inner else {
            return Ok(());
        };
        self.line.clear();
        let se = if r.rel_se.is_finite() { r.rel_se } else { -1.0 };
        push_e(&mut self.line, se, 6);
        self.line.push(b'\t');
        push_e(&mut self.line, r.samples as f64, 6);
        self.line.extend_from_slice(b"\t\n");
        w.write_all(&self.line)
            .map_err(|e| Error::io(path.as_str(), e))
    }

    /// Flush and move the file into place (only a complete run replaces the old file).
    pub fn finish(mut self) -> Result<()> {
        if let Some((path, tmp, w)) = self.inner.take() {
            // Dropping the file closes it before the rename.
            let closed = w.into_inner().map_err(|e| e.into_error()).map(drop);
            crate::io::replace_with(&tmp, &path, closed)?;
        }
        Ok(())
    }
}

impl Drop for SeWriter {
    fn drop(&mut self) {
        if let Some((_, tmp, _)) = self.inner.take() {
            let _ = std::fs::remove_file(tmp);
        }
    }
}
