//! Radiance matrices: the `rcontrib`/`rmtxop`/`dctimestep`/`gendaymtx` data format.
//!
//! Layout (`src/util/rmatrix.c`, `src/util/cmconst.c`, man `rmtxop.1`; notes §2):
//! ```text
//! #?RADIANCE
//! <command lines>
//! NROWS=<int>            absent in rcontrib output without -y: read rows to end of data
//! NCOLS=<int>
//! NCOMP=<int>            default 3
//! WAVELENGTH_SPLITS= 780 588 480 380   (NCOMP > 3 only)
//! BigEndian=0|1          binary only; absent = native byte order
//! FORMAT=ascii|float|double|32-bit_rle_rgbe|32-bit_rle_xyze|Radiance_spectra
//! <empty line>
//! <data>                 row-major; within a row, columns; within a column, NCOMP values
//! ```
//! Variables may come in any order (rcontrib writes NCOMP first, rmtxop NROWS first). A
//! missing `FORMAT=` means ascii, as `rmx_load_header` assumes. `EXPOSURE=`/`COLORCORR=` are
//! exposed and, on request ([`ReadOptions::undo_exposure`]), divided out as `rmx_load` does.
//!
//! The pieces, one per file:
//! - [`reader`]: [`MatrixReader`], one row at a time into a caller's buffer (streams).
//! - [`writer`]: [`MatrixWriter`], header then rows; checks the announced NROWS.
//! - [`ascii`]: the number tokenizer (nom) and C-style `%.Ne` formatting.
//! - [`memory`]: [`Matrix`], a whole small matrix in memory (load, save, transpose).
//! - [`ops`]: shape checks, per-channel multiplication and channel transforms (`rmtxop -c`).

pub mod ascii;
pub mod memory;
pub mod ops;
pub mod reader;
pub mod writer;

pub use memory::Matrix;
pub use ops::{ChannelTransform, RowOps, Shape};
pub use reader::{MatrixReader, ReadOptions};
pub use writer::{MatrixWriter, WriteOptions};

use crate::error::{Error, Location, Result};
use crate::formats::header::Header;
use crate::radiometry::Channels;

/// Data formats of Radiance matrices, named as in `FORMAT=` (`cmconst.c: cm_fmt_id`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataFormat {
    /// Whitespace-separated decimal numbers.
    Ascii,
    /// IEEE-754 binary32.
    Float,
    /// IEEE-754 binary64.
    Double,
    /// One RGBE picture scanline per row (`32-bit_rle_rgbe`).
    Rgbe,
    /// One XYZE picture scanline per row (`32-bit_rle_xyze`).
    Xyze,
    /// Radiance 6 spectral picture rows (`Radiance_spectra`).
    Spectra,
}

impl DataFormat {
    /// Recognise a `FORMAT=` value (already trimmed of padding).
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "ascii" => DataFormat::Ascii,
            "float" => DataFormat::Float,
            "double" => DataFormat::Double,
            "32-bit_rle_rgbe" => DataFormat::Rgbe,
            "32-bit_rle_xyze" => DataFormat::Xyze,
            "Radiance_spectra" => DataFormat::Spectra,
            _ => return None,
        })
    }

    /// Radiance's single-letter option for the format (`-fa`, `-ff`, `-fd`, `-fc`).
    pub fn from_letter(letter: &str) -> Option<Self> {
        Some(match letter {
            "a" => DataFormat::Ascii,
            "f" => DataFormat::Float,
            "d" => DataFormat::Double,
            "c" => DataFormat::Rgbe,
            _ => return None,
        })
    }

    /// The `FORMAT=` value.
    pub fn name(self) -> &'static str {
        match self {
            DataFormat::Ascii => "ascii",
            DataFormat::Float => "float",
            DataFormat::Double => "double",
            DataFormat::Rgbe => "32-bit_rle_rgbe",
            DataFormat::Xyze => "32-bit_rle_xyze",
            DataFormat::Spectra => "Radiance_spectra",
        }
    }

    /// Bytes per number in binary formats (also the FORMAT padding alignment); 1 otherwise.
    pub fn elem_size(self) -> usize {
        match self {
            DataFormat::Float => 4,
            DataFormat::Double => 8,
            _ => 1,
        }
    }

    /// True for the picture-coded formats whose codec lives in `formats::picture`.
    pub fn is_picture(self) -> bool {
        matches!(
            self,
            DataFormat::Rgbe | DataFormat::Xyze | DataFormat::Spectra
        )
    }

    /// Radiance's format rank (`cm_fmt_id` index): `rmx_newtype` keeps the lower of two,
    /// so float (4) beats ascii (5) beats double (6). This is what "lowest precision input
    /// format" means for rmtxop's default output.
    fn rank(self) -> u8 {
        match self {
            DataFormat::Rgbe => 1,
            DataFormat::Xyze => 2,
            DataFormat::Spectra => 3,
            DataFormat::Float => 4,
            DataFormat::Ascii => 5,
            DataFormat::Double => 6,
        }
    }

    /// The result format of combining two inputs, as `rmx_newtype` decides.
    pub fn combine(self, other: DataFormat) -> DataFormat {
        if self.rank() <= other.rank() {
            self
        } else {
            other
        }
    }
}

/// The error for picture-coded matrices until the picture codec is wired in.
pub(crate) fn picture_unsupported(name: &str, format: DataFormat) -> Error {
    // TODO(merge): decode/encode 32-bit_rle_rgbe, 32-bit_rle_xyze and Radiance_spectra rows
    // with the scanline codec of `formats::picture` (one scanline per matrix row, notes §2.2).
    Error::unsupported(
        Location::file(name),
        format!(
            "matrix data format '{}' (picture-coded rows; use ascii, float or double)",
            format.name()
        ),
    )
}

/// Everything the header of a matrix says, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixInfo {
    /// `NROWS=`; `None` when absent (read rows to the end of the data).
    pub nrows: Option<usize>,
    /// `NCOLS=`.
    pub ncols: usize,
    /// `NCOMP=` (default 3) and `WAVELENGTH_SPLITS=`.
    pub channels: Channels,
    /// `FORMAT=` (ascii when absent).
    pub format: DataFormat,
    /// `BigEndian=`; `None` when absent (native order).
    pub big_endian: Option<bool>,
    /// Product of `EXPOSURE=` values (1 when absent).
    pub exposure: f64,
    /// Product of `COLORCORR=` triples (1 1 1 when absent).
    pub colorcorr: [f64; 3],
    /// The header itself (`magic == None` for headerless input).
    pub header: Header,
}

impl MatrixInfo {
    /// Numbers per row: `ncols * ncomp`.
    pub fn row_len(&self) -> usize {
        self.ncols * self.channels.ncomp
    }

    /// True when binary data must be byte-swapped to native order.
    pub fn swap(&self) -> bool {
        self.big_endian
            .is_some_and(|b| b != cfg!(target_endian = "big"))
    }

    /// The shape for messages and checks.
    pub fn shape(&self) -> Shape {
        Shape {
            nrows: self.nrows,
            ncols: self.ncols,
            ncomp: self.channels.ncomp,
        }
    }

    /// Per-component factors that undo `EXPOSURE=`/`COLORCORR=` as `rmx_load` does:
    /// component k < 3 is divided by `exposure * colorcorr[k]`, higher (spectral) components
    /// by the green factor (Radiance's own "XXX hack"). `None` when there is nothing to undo.
    pub fn unexposure(&self) -> Option<Vec<f64>> {
        let cexp: Vec<f64> = self.colorcorr.iter().map(|c| c * self.exposure).collect();
        if cexp.iter().all(|&c| c == 1.0) {
            return None;
        }
        Some(
            (0..self.channels.ncomp)
                .map(|k| 1.0 / cexp[if k < 3 { k } else { 1 }])
                .collect(),
        )
    }

    /// Interpret a header, filling what it lacks from `opts` (headerless input).
    pub fn from_header(header: Header, name: &str, opts: &ReadOptions) -> Result<MatrixInfo> {
        let line_of = |k: &str| Location::line(name, header.line_of(k).unwrap_or(1));
        let format = match header.format() {
            Some(v) => DataFormat::from_name(v).ok_or_else(|| {
                Error::parse(
                    line_of("FORMAT"),
                    format!(
                        "FORMAT={v}: expected ascii, float, double, 32-bit_rle_rgbe, \
                         32-bit_rle_xyze or Radiance_spectra"
                    ),
                )
            })?,
            // Radiance's reader assumes ascii without FORMAT (`rmx_load_header`); a caller
            // that knows better (headerless `-h` binary output) says so in `opts`.
            None => opts.format.unwrap_or(DataFormat::Ascii),
        };
        let mut channels = Channels::from_header(&header, name)?;
        if header.get("NCOMP").is_none() {
            if let Some(n) = opts.ncomp {
                channels.ncomp = n;
            }
        }
        if channels.ncomp == 0 {
            return Err(Error::Usage(format!("{name}: NCOMP must be at least 1")));
        }
        let nrows = header.get_usize("NROWS", name)?.or(opts.nrows);
        let ncols = header.get_usize("NCOLS", name)?.or(opts.ncols);
        let big_endian = header.big_endian(name)?;
        let exposure = header.exposure();
        let colorcorr = header.colorcorr();
        if !(exposure > 0.0 && colorcorr.iter().all(|&c| c > 0.0)) {
            return Err(Error::parse(
                line_of("EXPOSURE"),
                "EXPOSURE/COLORCORR must be positive",
            ));
        }
        if format.is_picture() {
            return Err(picture_unsupported(name, format));
        }
        let ncols = match ncols {
            Some(0) => {
                return Err(Error::parse(
                    line_of("NCOLS"),
                    "NCOLS=0: expected at least one column",
                ));
            }
            Some(n) => n,
            // Headerless ascii: the reader infers NCOLS from the first line.
            None if format == DataFormat::Ascii => 0,
            None => {
                return Err(Error::parse(
                    Location::file(name),
                    format!(
                        "no NCOLS in the header of this {} matrix: give the number of columns",
                        format.name()
                    ),
                ));
            }
        };
        Ok(MatrixInfo {
            nrows,
            ncols,
            channels,
            format,
            big_endian,
            exposure,
            colorcorr,
            header,
        })
    }
}
