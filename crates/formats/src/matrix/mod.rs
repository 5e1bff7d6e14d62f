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
//! - [`operand`]: [`Operand`], the right operand of a streamed product, each row dense or
//!   sparse (a sun-only sky matrix is 99.99 % zeros).
//! - [`ops`]: shape checks, per-channel multiplication and channel transforms (`rmtxop -c`).
//! - [`pipeline`]: [`Pipeline`], one streamed convert / multiply / stack job (`rmtx`).

pub mod ascii;
pub mod memory;
pub mod operand;
pub mod ops;
pub mod pipeline;
pub mod reader;
pub mod writer;

pub use memory::Matrix;
pub use operand::{Operand, Outer};
pub use ops::{ChannelTransform, RowOps, Shape};
pub use pipeline::{Pipeline, Term};
pub use reader::{MatrixReader, ReadOptions};
pub use writer::{MatrixWriter, WriteOptions};

use crate::error::{Error, Location, Result};
use crate::header::Header;
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

/// Everything the header of a matrix says, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixInfo {
    /// `NROWS=`; `None` when absent (read rows to the end of the data). For a regular binary
    /// file opened with [`MatrixReader::open`] it is derived from the file size instead.
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
        // Saturating: absurd header values must reach the reader's size check, not overflow.
        self.ncols.saturating_mul(self.channels.ncomp)
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
        let mut channels = header.channels(name)?;
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
            // Picture-coded rows (notes §2.2): the size comes from the resolution string
            // after the header, read by `MatrixReader`; RGBE/XYZE carry 3 components.
            if format != DataFormat::Spectra && channels.ncomp != 3 {
                return Err(Error::parse(
                    line_of("NCOMP"),
                    format!(
                        "NCOMP={} in a {} matrix: expected 3",
                        channels.ncomp,
                        format.name()
                    ),
                ));
            }
            return Ok(MatrixInfo {
                nrows,
                ncols: ncols.unwrap_or(0),
                channels,
                format,
                big_endian,
                exposure,
                colorcorr,
                header,
            });
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    /// A 3x4x3 matrix whose values need every bit of a double (and of a float once rounded).
    fn sample(ncomp: usize) -> Matrix {
        let mut m = Matrix::zeros(
            3,
            4,
            Channels {
                ncomp,
                ..Channels::rgb()
            },
        );
        for (i, v) in m.data.iter_mut().enumerate() {
            *v = (i as f64 + 0.1).sqrt() * if i % 3 == 0 { -1e-7 } else { 12345.678 };
        }
        m
    }

    fn write(m: &Matrix, opts: WriteOptions) -> Vec<u8> {
        let mut h = Header::new();
        h.push_command(["rmtx", "-ff", "x"]);
        m.write(Vec::new(), "t", h, opts).unwrap()
    }

    fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Matrix> {
        Matrix::from_reader(Cursor::new(bytes), "t.mtx", opts)
    }

    fn to_f32(m: &Matrix) -> Matrix {
        let mut m = m.clone();
        m.data.iter_mut().for_each(|v| *v = *v as f32 as f64);
        m
    }

    #[test]
    fn binary_round_trips_are_bit_exact_in_both_byte_orders_and_paddings() {
        let m = sample(3);
        for format in [DataFormat::Float, DataFormat::Double] {
            for big in [false, true] {
                for seekable in [false, true] {
                    let mut o = WriteOptions::new(format);
                    o.big_endian = big;
                    o.seekable = seekable;
                    let bytes = write(&m, o);
                    let text = String::from_utf8_lossy(&bytes);
                    assert!(text.contains(&format!("BigEndian={}\n", u8::from(big))));
                    let header_len = text.find("\n\n").unwrap() + 2;
                    if seekable {
                        assert_eq!(header_len % format.elem_size(), 0, "{text}");
                    } else {
                        assert!(text.contains(&format!("FORMAT={}\n\n", format.name())));
                    }
                    let back = read(&bytes, &ReadOptions::default()).unwrap();
                    let want = if format == DataFormat::Float {
                        to_f32(&m)
                    } else {
                        m.clone()
                    };
                    assert_eq!(back.shape(), want.shape());
                    for (a, b) in back.data.iter().zip(&want.data) {
                        assert_eq!(a.to_bits(), b.to_bits());
                    }
                }
            }
        }
    }

    #[test]
    fn ascii_round_trip_to_requested_digits() {
        let m = sample(1);
        let mut o = WriteOptions::new(DataFormat::Ascii);
        o.ascii_digits = writer::DOUBLE_DIGITS;
        let back = read(&write(&m, o), &ReadOptions::default()).unwrap();
        assert_eq!(back, m, "17 significant digits round-trip f64 exactly");
        let o = WriteOptions::new(DataFormat::Ascii);
        let bytes = write(&m, o);
        let text = String::from_utf8(bytes.clone()).unwrap();
        // rmx_write_ascii layout: " %.7e" per component, TAB per element, newline per row.
        let data = &text[text.find("\n\n").unwrap() + 2..];
        assert!(data.starts_with(" -3.1622777e-08\t 1.2948"), "{data}");
        assert_eq!(data.lines().count(), 3);
        assert!(
            data.lines()
                .all(|l| l.matches('\t').count() == 4 && l.ends_with('\t'))
        );
        let back = read(&bytes, &ReadOptions::default()).unwrap();
        assert!(back.max_rel_diff(&m, 0.0).unwrap() < 1e-7);
    }

    #[test]
    fn variables_in_any_order_and_padding_ignored() {
        let mut data =
            b"#?RADIANCE\nFORMAT=float    \nBigEndian=1\nNCOLS=2\nNCOMP=1\nNROWS=1\n\n".to_vec();
        data.extend_from_slice(&1.5f32.to_be_bytes());
        data.extend_from_slice(&(-2.25f32).to_be_bytes());
        let m = read(&data, &ReadOptions::default()).unwrap();
        assert_eq!(m.data, vec![1.5, -2.25]);
        assert_eq!(m.shape().to_string(), "1x2x1");
    }

    #[test]
    fn missing_format_means_ascii_and_missing_nrows_reads_to_end() {
        let m = read(
            b"#?RADIANCE\nNCOLS=2\n\n1 2 3 4 5 6\n7 8 9 10 11 12\n",
            &ReadOptions::default(),
        )
        .unwrap();
        assert_eq!((m.nrows, m.ncols, m.ncomp()), (2, 2, 3));
        assert_eq!(m.get(1, 0), &[7.0, 8.0, 9.0]);
    }

    #[test]
    fn headerless_ascii_infers_ncols_from_first_line() {
        let opts = ReadOptions {
            ncomp: Some(1),
            ..ReadOptions::default()
        };
        let m = read(b"1\t2\t3\t\n4\t5\t6\t\n", &opts).unwrap();
        assert_eq!((m.nrows, m.ncols), (2, 3));
        let e = read(b"1 2\n", &ReadOptions::default()).unwrap_err();
        assert!(e.to_string().starts_with("t.mtx:1: no NCOLS given"), "{e}");
    }

    #[test]
    fn headerless_binary_needs_format_and_ncols() {
        let bytes: Vec<u8> = [1.0f64, 2.0, 3.0]
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        let opts = ReadOptions {
            format: Some(DataFormat::Double),
            ncols: Some(1),
            ..ReadOptions::default()
        };
        let m = read(&bytes, &opts).unwrap();
        assert_eq!(m.data, vec![1.0, 2.0, 3.0]);
        let e = read(
            &bytes,
            &ReadOptions {
                ncols: None,
                ..opts
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("no NCOLS"), "{e}");
    }

    #[test]
    fn exposure_is_exposed_and_undone_on_request() {
        let text = b"#?RADIANCE\nEXPOSURE=2\nCOLORCORR= 1 2 4\nNROWS=1\nNCOLS=1\n\n8 8 8\n";
        let raw = read(text, &ReadOptions::default()).unwrap();
        assert_eq!(raw.data, vec![8.0, 8.0, 8.0]);
        let opts = ReadOptions {
            undo_exposure: true,
            ..ReadOptions::default()
        };
        let undone = read(text, &opts).unwrap();
        assert_eq!(undone.data, vec![4.0, 2.0, 1.0]);
        let r = MatrixReader::new(Cursor::new(&text[..]), "t", &opts).unwrap();
        assert_eq!(r.info().exposure, 2.0);
        assert_eq!(r.info().colorcorr, [1.0, 2.0, 4.0]);
    }

    #[test]
    fn nrows_mismatch_is_reported() {
        let m = sample(3);
        let bytes = write(&m, WriteOptions::new(DataFormat::Float));
        let short = &bytes[..bytes.len() - 4 * 12];
        let e = read(short, &ReadOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.mtx: ends after row 2 of 3 (NROWS=3): truncated?"
        );
        let mut long = bytes.clone();
        long.extend_from_slice(&[0; 4]);
        let e = read(&long, &ReadOptions::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("t.mtx: more data after row 3 of 3"),
            "{e}"
        );
        let text = b"#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=1\n\n1\n\n2\n";
        let e = read(text, &ReadOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with("t.mtx:8: more data after row 1"),
            "{e}"
        );
    }

    #[test]
    fn picture_coded_rows_round_trip_and_fail_cleanly() {
        // RGBE and spectral rows written and read back (values exact to the 8-bit mantissa:
        // 0.5 and 0.25 are exactly representable); a row cut short is a one-line error.
        for (f, nc) in [(DataFormat::Rgbe, 3), (DataFormat::Spectra, 6)] {
            let channels = Channels {
                ncomp: nc,
                ..Channels::rgb()
            };
            let mut w = MatrixWriter::new(
                Vec::new(),
                "out",
                Header::new(),
                Some(2),
                20,
                channels,
                WriteOptions::new(f),
            )
            .unwrap();
            let row: Vec<f64> = (0..20 * nc)
                .map(|i| if i % 2 == 0 { 0.5 } else { 0.25 })
                .collect();
            w.write_row(&row).unwrap();
            w.write_row(&row).unwrap();
            let bytes = w.finish().unwrap();
            let m = read(&bytes, &ReadOptions::default()).unwrap();
            assert_eq!((m.nrows, m.ncols, m.channels.ncomp), (2, 20, nc));
            // Radiance decodes a mantissa m as (m + 0.5) / 256 of the element's scale: with a
            // shared scale of 1 (max 0.5 = 128/256) every value reads back 1/512 high.
            let want: Vec<f64> = row.iter().map(|v| v + 1.0 / 512.0).collect();
            assert_eq!(m.row(1), &want[..]);
            for cut in [bytes.len() - 1, bytes.len() / 2] {
                let e = read(&bytes[..cut], &ReadOptions::default()).unwrap_err();
                assert!(e.to_string().starts_with("t.mtx"), "{e}");
            }
        }
        let e = read(
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 1 +X 1\nxxxx",
            &ReadOptions::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("standard orientation"), "{e}");
        let e = read(b"#?RADIANCE\nFORMAT=int16\n\n", &ReadOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with("t.mtx:2: FORMAT=int16: expected"),
            "{e}"
        );
    }

    #[test]
    fn writer_checks_announced_rows() {
        let mut w = MatrixWriter::new(
            Vec::new(),
            "out",
            Header::new(),
            Some(2),
            1,
            Channels::mono(),
            WriteOptions::new(DataFormat::Ascii),
        )
        .unwrap();
        w.write_row(&[1.0]).unwrap();
        let e = w.finish().unwrap_err();
        assert_eq!(
            e.to_string(),
            "out: 1 rows written but the header announced NROWS=2"
        );
    }

    #[test]
    fn transpose_moves_whole_elements() {
        let m = sample(3);
        let t = m.transpose();
        assert_eq!((t.nrows, t.ncols), (4, 3));
        for r in 0..3 {
            for c in 0..4 {
                assert_eq!(m.get(r, c), t.get(c, r));
            }
        }
        assert_eq!(t.transpose(), m);
    }

    #[test]
    fn every_truncated_prefix_is_an_error_or_fewer_rows_never_a_panic() {
        let m = sample(3);
        for format in [DataFormat::Float, DataFormat::Double, DataFormat::Ascii] {
            let bytes = write(&m, WriteOptions::new(format));
            // Where the last number starts: ascii prefixes that only cut its digits or the
            // trailing white space still parse (text cannot tell), every other cut must fail.
            let last = bytes[..bytes.len() - 2]
                .iter()
                .rposition(|b| b.is_ascii_whitespace())
                .unwrap();
            for n in 0..bytes.len() {
                match read(&bytes[..n], &ReadOptions::default()) {
                    Err(_) => {}
                    Ok(got) => {
                        assert!(format == DataFormat::Ascii && n > last + 1, "prefix {n}");
                        assert_eq!(got.nrows, m.nrows);
                    }
                }
            }
            // Without NROWS a cut between rows is a shorter matrix, a cut inside a row an
            // error.
            let text = String::from_utf8_lossy(&bytes).replace("NROWS=3\n", "");
            if format == DataFormat::Ascii {
                let bytes = text.into_bytes();
                for n in 0..bytes.len() {
                    if let Ok(got) = read(&bytes[..n], &ReadOptions::default()) {
                        assert!(got.nrows <= m.nrows, "prefix {n}");
                    }
                }
            } else {
                let find = |b: &[u8], pat: &[u8]| b.windows(pat.len()).position(|w| w == pat);
                let mut bytes = bytes.clone();
                let nrows_line = find(&bytes, b"NROWS=3\n").unwrap();
                bytes.drain(nrows_line..nrows_line + 8);
                let header = find(&bytes, b"\n\n").unwrap() + 2;
                let row = m.row_len() * format.elem_size();
                for n in header..bytes.len() {
                    match read(&bytes[..n], &ReadOptions::default()) {
                        Ok(got) => assert_eq!(got.nrows * row, n - header, "prefix {n}"),
                        Err(e) => assert!((n - header) % row != 0, "prefix {n}: {e}"),
                    }
                }
            }
        }
    }

    #[test]
    fn absurd_sizes_are_errors_not_allocations() {
        let text =
            b"#?RADIANCE\nNCOLS=9223372036854775807\nNCOMP=9223372036854775807\nFORMAT=float\n\n";
        let e = read(text, &ReadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("numbers per row: more than"), "{e}");
    }

    #[test]
    fn random_bytes_never_panic() {
        // A small xorshift stream: garbage after a valid header, and garbage alone.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for round in 0..200 {
            let mut data = if round % 2 == 0 {
                b"#?RADIANCE\nNCOLS=3\nFORMAT=ascii\n\n".to_vec()
            } else {
                Vec::new()
            };
            for _ in 0..(round * 3) {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                data.push((x & 0xff) as u8);
            }
            let _ = read(&data, &ReadOptions::default());
        }
    }
}
