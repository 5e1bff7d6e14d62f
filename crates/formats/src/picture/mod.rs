//! Radiance pictures (`.hdr`, `.pic`): RGBE and XYZE with flat, old and new run-length
//! scanlines, Radiance 6 hyperspectral pictures, and conversions to OpenEXR and PNG/JPEG.
//!
//! Source: Radiance `doc/filefmts.md` (Picture File Format), `src/common/color.[ch]`,
//! `src/common/resolu.[ch]`, `src/common/header.c`.
//!
//! ```text
//! #?RADIANCE
//! <header lines: commands, VIEW=, EXPOSURE=, PRIMARIES=, ...>
//! FORMAT=32-bit_rle_rgbe        or 32-bit_rle_xyze, or Radiance_spectra (+ NCOMP=)
//! <empty line>
//! -Y 512 +X 768                 resolution string (see [`resolution`])
//! <512 scanlines of 768 pixels> (see [`scanline`], [`color`], [`spectral`])
//! ```
//! A pixel value of (1,1,1) is 1 W/sr/m² over the visible spectrum; the stored value is that
//! radiance times the product of every `EXPOSURE=` (and, per primary, `COLORCORR=`) in the
//! header. In XYZE pictures Y is already in cd/m² (179 lm/W applied).
//!
//! [`Picture`] holds a whole picture in memory, always in standard orientation (top row
//! first, left to right) whatever order the file used. [`PictureReader`] and
//! [`PictureWriter`] stream one scanline at a time in file order for large pictures.
//!
//! Deliberate differences from Radiance: a header without `FORMAT=` is read as RGBE, as
//! Radiance's `checkheader` allows, but a file without any `#?` header is rejected; the
//! resolution string must have the written shape (see [`resolution`]).

pub mod color;
pub mod exr;
pub mod preview;
pub mod resolution;
pub mod scanline;
pub mod spectral;

use crate::error::{Error, Location, Result};
use crate::header::{Header, parse_f64};
use crate::radiometry::{Channels, MAX_SAMPLES};
use resolution::{Resolution, STANDARD};
use scanline::ScanlineError;
use std::io::{BufRead, Write};

/// `FORMAT=` of RGBE pictures (`COLRFMT`).
pub const RGBE_FORMAT: &str = "32-bit_rle_rgbe";
/// `FORMAT=` of XYZE pictures (`CIEFMT`).
pub const XYZE_FORMAT: &str = "32-bit_rle_xyze";
/// `FORMAT=` of hyperspectral pictures (`SPECFMT`).
pub const SPECTRA_FORMAT: &str = "Radiance_spectra";

/// Largest number of values [`Picture::read`] keeps in memory (2 GiB of `f32`); larger
/// pictures must be streamed with [`PictureReader`].
pub const MAX_VALUES: usize = 1 << 29;

/// The size check every whole-picture reader and renderer makes before it allocates or
/// decodes (issue #19: an OpenEXR header claiming 100000 x 100000 pixels made `ruplift
/// proxy` allocate 40 GB): `width x height x ncomp` values at most [`MAX_VALUES`]
/// (2 GiB of `f32`, e.g. 16384 x 10922 RGB), larger pictures being streamed or split.
/// `what` names the file or the options (`-x 9 -y 9`) in the one-line error.
pub fn check_size(what: &str, width: usize, height: usize, ncomp: usize) -> Result<()> {
    let values = width
        .checked_mul(height)
        .and_then(|p| p.checked_mul(ncomp.max(1)));
    match values {
        Some(v) if v <= MAX_VALUES => Ok(()),
        _ => Err(Error::Usage(format!(
            "{what}: a picture of {width} x {height} pixels x {ncomp} components is more than \
             {MAX_VALUES} values (2 GiB in memory); use a smaller resolution or split the picture"
        ))),
    }
}

/// How pixels are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelFormat {
    /// Red, green, blue (Radiance primaries) with a common exponent.
    Rgbe,
    /// CIE X, Y, Z with a common exponent; Y in cd/m².
    Xyze,
    /// NCOMP spectral bands, longest wavelength first, with a common exponent.
    Spectra,
}

impl PixelFormat {
    /// The `FORMAT=` value.
    pub fn name(self) -> &'static str {
        match self {
            PixelFormat::Rgbe => RGBE_FORMAT,
            PixelFormat::Xyze => XYZE_FORMAT,
            PixelFormat::Spectra => SPECTRA_FORMAT,
        }
    }

    /// The pixel format and channel layout a picture header declares, checked for
    /// consistency (`NCOMP` must be 3 for RGBE/XYZE, 3 to 24 for spectra).
    pub fn from_header(h: &Header, name: &str) -> Result<(PixelFormat, Channels)> {
        let fmt_line = h.line_of("FORMAT").unwrap_or(1);
        let format = match h.format() {
            None | Some(RGBE_FORMAT) => PixelFormat::Rgbe,
            Some(XYZE_FORMAT) => PixelFormat::Xyze,
            Some(SPECTRA_FORMAT) => PixelFormat::Spectra,
            Some(other) => {
                return Err(Error::parse(
                    Location::line(name, fmt_line),
                    format!(
                        "FORMAT={other}: expected a picture ({RGBE_FORMAT}, {XYZE_FORMAT} \
                         or {SPECTRA_FORMAT})"
                    ),
                ));
            }
        };
        let channels = h.channels(name)?;
        let ncomp_line = Location::line(name, h.line_of("NCOMP").unwrap_or(fmt_line));
        match format {
            PixelFormat::Rgbe | PixelFormat::Xyze if channels.ncomp != 3 => Err(Error::parse(
                ncomp_line,
                format!(
                    "NCOMP={} with FORMAT={}: expected NCOMP=3 (or FORMAT={SPECTRA_FORMAT})",
                    channels.ncomp,
                    format.name()
                ),
            )),
            PixelFormat::Spectra if !(3..=MAX_SAMPLES).contains(&channels.ncomp) => {
                Err(Error::parse(
                    ncomp_line,
                    format!(
                        "NCOMP={} with FORMAT={SPECTRA_FORMAT}: expected 3 to {MAX_SAMPLES} \
                         spectral samples",
                        channels.ncomp
                    ),
                ))
            }
            _ => Ok((format, channels)),
        }
    }

    /// Whether scanlines use the 4-byte RGBE codec (with run-length encoding) rather than
    /// flat NCOMP+1-byte pixels.
    fn uses_colrs(self, ncomp: usize) -> bool {
        self != PixelFormat::Spectra || ncomp == 3
    }
}

/// The header a picture is written with: `header` plus FORMAT, NCOMP and wavelength splits.
fn picture_header(header: &Header, format: PixelFormat, channels: &Channels) -> Header {
    let mut h = header.clone();
    if h.magic.is_none() {
        h.magic = Some("RADIANCE".into());
    }
    match format {
        PixelFormat::Spectra => h.set_channels(*channels),
        PixelFormat::Rgbe | PixelFormat::Xyze => {
            h.remove("NCOMP");
            h.remove("WAVELENGTH_SPLITS");
        }
    }
    h.set("FORMAT", format.name());
    h
}

/// Streaming reader: the header, then one scanline at a time in file order.
pub struct PictureReader<R> {
    inner: R,
    name: String,
    /// The information header as read.
    pub header: Header,
    /// Pixel storage declared by `FORMAT=`.
    pub format: PixelFormat,
    /// Channel layout (3, or NCOMP spectral bands).
    pub channels: Channels,
    /// Dimensions and scanline order of the file.
    pub resolution: Resolution,
    next_scan: usize,
    colrs: Vec<[u8; 4]>,
    bytes: Vec<u8>,
}

impl<R: BufRead> PictureReader<R> {
    /// Read the header and the resolution string.
    pub fn new(mut inner: R, name: &str) -> Result<Self> {
        let header = Header::read(&mut inner, name)?;
        if header.magic.is_none() {
            return Err(Error::parse(
                Location::line(name, 1),
                "no header: expected a Radiance picture starting with '#?RADIANCE'",
            ));
        }
        let (format, channels) = PixelFormat::from_header(&header, name)?;
        let resolution = Resolution::read(&mut inner, name, header.nlines + 1)?;
        Ok(PictureReader {
            inner,
            name: name.to_string(),
            header,
            format,
            channels,
            resolution,
            next_scan: 0,
            colrs: Vec::new(),
            bytes: Vec::new(),
        })
    }

    /// The name used in error messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Values per pixel.
    pub fn ncomp(&self) -> usize {
        self.channels.ncomp
    }

    /// Index (0-based, file order) of the next scanline to be read.
    pub fn next_scanline(&self) -> usize {
        self.next_scan
    }

    fn scan_error(&self, e: ScanlineError) -> Error {
        let (k, n) = (self.next_scan + 1, self.resolution.num_scans());
        let loc = Location::file(&self.name);
        match e {
            ScanlineError::Eof => Error::parse(loc, format!("scanline {k} of {n} ends early")),
            ScanlineError::Corrupt(m) => Error::parse(loc, format!("scanline {k} of {n}: {m}")),
            ScanlineError::Io(e) => Error::io(&self.name, e),
        }
    }

    /// Read the next scanline of 4-byte pixels (RGBE/XYZE, or spectra with NCOMP=3).
    /// Returns `Ok(false)` when all scanlines were read.
    pub fn read_colrs(&mut self, out: &mut [[u8; 4]]) -> Result<bool> {
        if !self.format.uses_colrs(self.ncomp()) {
            return Err(Error::Mismatch(format!(
                "{}: spectral pixels are not 4-byte RGBE pixels",
                self.name
            )));
        }
        if self.next_scan >= self.resolution.num_scans() {
            return Ok(false);
        }
        if out.len() != self.resolution.scan_len() {
            return Err(Error::Mismatch(format!(
                "{}: scanline buffer of {} pixels for scanlines of {}",
                self.name,
                out.len(),
                self.resolution.scan_len()
            )));
        }
        scanline::read_colrs(&mut self.inner, out).map_err(|e| self.scan_error(e))?;
        self.next_scan += 1;
        Ok(true)
    }

    /// Read and decode the next scanline into `out` (`scan_len * ncomp` values).
    /// Returns `Ok(false)` when all scanlines were read.
    pub fn read_scanline(&mut self, out: &mut [f32]) -> Result<bool> {
        let (len, nc) = (self.resolution.scan_len(), self.ncomp());
        if out.len() != len * nc {
            return Err(Error::Mismatch(format!(
                "{}: scanline buffer of {} values for scanlines of {len} x {nc}",
                self.name,
                out.len()
            )));
        }
        if self.next_scan >= self.resolution.num_scans() {
            return Ok(false);
        }
        if self.format.uses_colrs(nc) {
            let mut colrs = std::mem::take(&mut self.colrs);
            colrs.resize(len, [0; 4]);
            let r = scanline::read_colrs(&mut self.inner, &mut colrs);
            if let Err(e) = r {
                return Err(self.scan_error(e));
            }
            for (c, v) in colrs.iter().zip(out.chunks_exact_mut(3)) {
                v.copy_from_slice(&color::decode_rgbe(*c));
            }
            self.colrs = colrs;
        } else {
            let r = spectral::read_scanline(&mut self.inner, nc, &mut self.bytes, out);
            if let Err(e) = r {
                return Err(self.scan_error(e));
            }
        }
        self.next_scan += 1;
        Ok(true)
    }

    /// The underlying reader, positioned after the scanlines read so far.
    pub fn into_inner(self) -> R {
        self.inner
    }
}

/// Streaming writer: writes the header and resolution string, then takes scanlines in file
/// order.
pub struct PictureWriter<W> {
    inner: W,
    name: String,
    format: PixelFormat,
    ncomp: usize,
    resolution: Resolution,
    rle: bool,
    next_scan: usize,
    colrs: Vec<[u8; 4]>,
    bytes: Vec<u8>,
}

impl<W: Write> PictureWriter<W> {
    /// Write `header` (with FORMAT, NCOMP and WAVELENGTH_SPLITS set from `format` and
    /// `channels`) and the resolution string. `rle` asks for run-length encoded scanlines
    /// where Radiance would use them (RGBE/XYZE, 17 to 32767 pixels); spectral pictures
    /// are always flat. `name` is used in error messages.
    pub fn new(
        mut inner: W,
        name: &str,
        header: &Header,
        format: PixelFormat,
        channels: &Channels,
        resolution: Resolution,
        rle: bool,
    ) -> Result<Self> {
        let ncomp = channels.ncomp;
        let ok = match format {
            PixelFormat::Rgbe | PixelFormat::Xyze => ncomp == 3,
            PixelFormat::Spectra => (3..=MAX_SAMPLES).contains(&ncomp),
        };
        if !ok {
            return Err(Error::Mismatch(format!(
                "{name}: cannot write {ncomp} channels as FORMAT={}",
                format.name()
            )));
        }
        let h = picture_header(header, format, channels);
        h.write(&mut inner, 1).map_err(|e| Error::io(name, e))?;
        inner
            .write_all(resolution.to_line().as_bytes())
            .map_err(|e| Error::io(name, e))?;
        Ok(PictureWriter {
            inner,
            name: name.to_string(),
            format,
            ncomp,
            resolution,
            rle,
            next_scan: 0,
            colrs: Vec::new(),
            bytes: Vec::new(),
        })
    }

    /// Encode and write the next scanline (`scan_len * ncomp` values, file order).
    pub fn write_scanline(&mut self, values: &[f32]) -> Result<()> {
        let len = self.resolution.scan_len();
        if values.len() != len * self.ncomp {
            return Err(Error::Mismatch(format!(
                "{}: scanline of {} values; expected {len} x {}",
                self.name,
                values.len(),
                self.ncomp
            )));
        }
        if self.next_scan >= self.resolution.num_scans() {
            return Err(Error::Mismatch(format!(
                "{}: more than {} scanlines written",
                self.name,
                self.resolution.num_scans()
            )));
        }
        let io = |e| Error::io(&self.name, e);
        if self.format.uses_colrs(self.ncomp) {
            self.colrs.clear();
            self.colrs.extend(
                values
                    .chunks_exact(3)
                    .map(|v| color::encode_rgbe(v[0], v[1], v[2])),
            );
            if self.rle {
                scanline::write_colrs(&mut self.inner, &self.colrs).map_err(io)?;
            } else {
                scanline::write_flat(&mut self.inner, &self.colrs).map_err(io)?;
            }
        } else {
            spectral::write_scanline(&mut self.inner, self.ncomp, values, &mut self.bytes)
                .map_err(io)?;
        }
        self.next_scan += 1;
        Ok(())
    }

    /// Check that every scanline was written, flush, and return the writer.
    pub fn finish(mut self) -> Result<W> {
        if self.next_scan != self.resolution.num_scans() {
            return Err(Error::Mismatch(format!(
                "{}: {} of {} scanlines written",
                self.name,
                self.next_scan,
                self.resolution.num_scans()
            )));
        }
        self.inner.flush().map_err(|e| Error::io(&self.name, e))?;
        Ok(self.inner)
    }
}

/// A whole picture in memory, in standard orientation.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Channel layout; `channels.ncomp` values per pixel.
    pub channels: Channels,
    /// Row-major values, top row first, left to right, `ncomp` per pixel, exactly as
    /// stored (exposure not divided out; see [`Picture::radiance_values`]).
    pub data: Vec<f32>,
    /// The information header (FORMAT/NCOMP are rewritten from `format` on output).
    pub header: Header,
    /// Pixel storage.
    pub format: PixelFormat,
}

impl Picture {
    /// A black picture with a fresh header.
    pub fn new(width: usize, height: usize, channels: Channels, format: PixelFormat) -> Self {
        Picture {
            width,
            height,
            channels,
            data: vec![0.0; width * height * channels.ncomp],
            header: Header::new(),
            format,
        }
    }

    /// Values per pixel.
    pub fn ncomp(&self) -> usize {
        self.channels.ncomp
    }

    /// Read a whole picture, reordering it to standard orientation.
    pub fn read<R: BufRead>(r: R, name: &str) -> Result<Picture> {
        let mut rd = PictureReader::new(r, name)?;
        let res = rd.resolution;
        let nc = rd.ncomp();
        check_size(name, res.xres, res.yres, nc)?;
        let total = res.xres * res.yres * nc;
        let line_vals = res.scan_len() * nc;
        // Grow with the data actually read, so a corrupt header cannot reserve gigabytes.
        let mut file_order: Vec<f32> = Vec::with_capacity(total.min(1 << 22));
        let mut line = vec![0f32; line_vals];
        while rd.read_scanline(&mut line)? {
            file_order.extend_from_slice(&line);
        }
        let data = if res.order == STANDARD {
            file_order
        } else {
            let mut data = vec![0f32; total];
            for (s, line) in file_order.chunks_exact(line_vals).enumerate() {
                for (p, px) in line.chunks_exact(nc).enumerate() {
                    let (row, col) = res.to_standard(s, p);
                    let at = (row * res.xres + col) * nc;
                    data[at..at + nc].copy_from_slice(px);
                }
            }
            data
        };
        Ok(Picture {
            width: res.xres,
            height: res.yres,
            channels: rd.channels,
            data,
            header: rd.header,
            format: rd.format,
        })
    }

    /// Open a picture file; `-` reads standard input.
    pub fn open(path: impl AsRef<std::path::Path>) -> Result<Picture> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        if shown == "-" {
            let stdin = std::io::stdin();
            return Picture::read(stdin.lock(), "<stdin>");
        }
        let f = std::fs::File::open(path).map_err(|e| Error::io(&shown, e))?;
        Picture::read(std::io::BufReader::with_capacity(1 << 16, f), &shown)
    }

    fn check_shape(&self) -> Result<()> {
        let want = self.width * self.height * self.ncomp();
        if self.data.len() != want || self.width == 0 || self.height == 0 {
            return Err(Error::Mismatch(format!(
                "picture of {} x {} x {} needs {want} values, has {}",
                self.width,
                self.height,
                self.ncomp(),
                self.data.len()
            )));
        }
        Ok(())
    }

    /// Write in standard orientation; `rle` run-length encodes RGBE/XYZE scanlines as
    /// Radiance does (spectral pictures are always flat).
    pub fn write<W: Write + ?Sized>(&self, w: &mut W, rle: bool) -> Result<()> {
        self.write_oriented(w, rle, STANDARD)
    }

    /// Write with scanlines in any of the eight orders (`resolution::{XDECR,YDECR,YMAJOR}`).
    pub fn write_oriented<W: Write + ?Sized>(&self, w: &mut W, rle: bool, order: u8) -> Result<()> {
        self.check_shape()?;
        let res = Resolution {
            order: order & 7,
            xres: self.width,
            yres: self.height,
        };
        let nc = self.ncomp();
        let mut pw = PictureWriter::new(
            w,
            "<output>",
            &self.header,
            self.format,
            &self.channels,
            res,
            rle,
        )?;
        let mut line = vec![0f32; res.scan_len() * nc];
        for s in 0..res.num_scans() {
            for (p, px) in line.chunks_exact_mut(nc).enumerate() {
                let (row, col) = res.to_standard(s, p);
                let at = (row * self.width + col) * nc;
                px.copy_from_slice(&self.data[at..at + nc]);
            }
            pw.write_scanline(&line)?;
        }
        pw.finish()?;
        Ok(())
    }

    /// Write to a file atomically (nothing is left behind on failure); `-` is stdout.
    pub fn save(&self, path: impl AsRef<std::path::Path>, rle: bool) -> Result<()> {
        let path = path.as_ref();
        if path.as_os_str() == "-" {
            let stdout = std::io::stdout();
            let mut lock = std::io::BufWriter::new(stdout.lock());
            self.write(&mut lock, rle)?;
            return lock.flush().map_err(|e| Error::io("<stdout>", e));
        }
        crate::io::write_atomically(path, |w| self.write(w, rle))
    }

    /// The values of pixel (`x` from the left, `y` from the top).
    ///
    /// # Panics
    /// If the pixel lies outside the picture (as slice indexing does).
    pub fn pixel(&self, x: usize, y: usize) -> &[f32] {
        let nc = self.ncomp();
        let at = (y * self.width + x) * nc;
        &self.data[at..at + nc]
    }

    /// What each channel was multiplied by when stored: the product of all `EXPOSURE=`
    /// values times, for RGBE/XYZE, the product of the `COLORCORR=` triples.
    pub fn exposure(&self) -> Vec<f64> {
        let e = self.header.exposure();
        match self.format {
            PixelFormat::Rgbe | PixelFormat::Xyze if self.ncomp() == 3 => {
                self.header.colorcorr().iter().map(|c| c * e).collect()
            }
            _ => vec![e; self.ncomp()],
        }
    }

    /// The data with the exposure divided out: radiance in W/sr/m² (RGBE, spectra) or
    /// X, Y (cd/m²), Z (XYZE). Same layout as `data`.
    pub fn radiance_values(&self) -> Vec<f32> {
        let ex = self.exposure();
        let nc = self.ncomp();
        self.data
            .iter()
            .enumerate()
            .map(|(i, &v)| (v as f64 / ex[i % nc]) as f32)
            .collect()
    }

    /// Luminance (cd/m²) of pixel (`x` from the left, `y` from the top), exposure divided
    /// out. RGBE: `179 (0.265106 R + 0.670106 G + 0.064788 B)` ([`RGB_PHOTOPIC`]) (Radiance's
    /// `luminance()`, standard primaries whatever `PRIMARIES=` says, as pvalue and evalglare
    /// do). XYZE: Y as stored. Spectra: the RGB band averages of `scolor2color`, then as RGBE
    /// (what Radiance's picture tools do with spectral input).
    ///
    /// # Panics
    /// If the pixel lies outside the picture.
    pub fn luminance(&self, x: usize, y: usize) -> f64 {
        let ex = self.exposure();
        let px = self.pixel(x, y);
        let rgb = crate::radiometry::luminance;
        match self.format {
            PixelFormat::Xyze => px[1] as f64 / ex[1],
            PixelFormat::Rgbe => rgb([
                px[0] as f64 / ex[0],
                px[1] as f64 / ex[1],
                px[2] as f64 / ex[2],
            ]),
            PixelFormat::Spectra => {
                let c = spectral::to_rgb(px, self.channels.splits);
                let e = ex.first().copied().unwrap_or(1.0);
                rgb([c[0] as f64 / e, c[1] as f64 / e, c[2] as f64 / e])
            }
        }
    }

    /// The raw `VIEW=` values in header order (cumulative: later ones amend earlier ones).
    /// Parsing them is the view module's job.
    pub fn view_strings(&self) -> Vec<&str> {
        self.header.get_all("VIEW").collect()
    }

    /// Pixel height over width (`PIXASPECT=`, cumulative), 1 when absent.
    pub fn pixaspect(&self) -> f64 {
        self.header.pixaspect()
    }

    /// `PRIMARIES= xr yr xg yg xb yb xw yw`, if present and well formed (last one wins).
    pub fn primaries(&self) -> Option<[f64; 8]> {
        let v = self.header.get("PRIMARIES")?;
        let vals: Vec<f64> = v.split_whitespace().filter_map(parse_f64).collect();
        vals.try_into().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn sample(format: PixelFormat, ncomp: usize, w: usize, h: usize) -> Picture {
        let ch = if ncomp == 3 {
            Channels::rgb()
        } else {
            Channels::spectral(ncomp, 380.0, 780.0).unwrap()
        };
        let mut p = Picture::new(w, h, ch, format);
        for (i, v) in p.data.iter_mut().enumerate() {
            // Grey pixels of exactly representable values, so decode(encode(v)) == v.
            let g = (i / ncomp % 97) as f32 * 0.731;
            *v = color::decode_rgbe(color::encode_rgbe(g, 0.0, 0.0))[0];
        }
        p.header.push("test picture");
        p.header.set("VIEW", " -vta -vh 180 -vv 180");
        p
    }

    #[test]
    fn rgbe_round_trip_every_orientation_and_encoding() {
        for (w, h) in [(20, 3), (5, 7)] {
            let p = sample(PixelFormat::Rgbe, 3, w, h);
            for order in 0..8u8 {
                for rle in [false, true] {
                    let mut out = Vec::new();
                    p.write_oriented(&mut out, rle, order).unwrap();
                    let q = Picture::read(Cursor::new(&out), "t.hdr").unwrap();
                    assert_eq!((q.width, q.height), (w, h));
                    assert_eq!(q.data, p.data, "order {order} rle {rle}");
                    assert_eq!(q.view_strings(), vec![" -vta -vh 180 -vv 180"]);
                }
            }
        }
    }

    #[test]
    fn spectral_round_trip_is_bit_exact() {
        let p = sample(PixelFormat::Spectra, 6, 4, 3);
        let mut out = Vec::new();
        p.write(&mut out, true).unwrap();
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("NCOMP=6\nWAVELENGTH_SPLITS= 780 588 480 380\n"));
        assert!(text.contains("FORMAT=Radiance_spectra\n\n-Y        3 +X        4\n"));
        let q = Picture::read(Cursor::new(&out), "t.hsr").unwrap();
        assert_eq!(q.channels.ncomp, 6);
        // Quantised to the common exponent of each pixel, then exact on re-encoding.
        let mut again = Vec::new();
        q.write(&mut again, true).unwrap();
        assert_eq!(again, out);
    }

    #[test]
    fn three_band_spectra_use_the_rgbe_codec() {
        // freadscolrs/fwritescolrs fall back to the RGBE scanline codec for NCOMP=3.
        let mut p = sample(PixelFormat::Spectra, 3, 20, 2);
        p.channels = Channels::rgb();
        let mut out = Vec::new();
        p.write(&mut out, true).unwrap();
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("NCOMP=3\n"), "{text}");
        let data = &out[out.windows(2).position(|w| w == b"\n\n").unwrap() + 2..];
        let after_res = &data[data.iter().position(|&b| b == b'\n').unwrap() + 1..];
        assert_eq!(&after_res[..4], &[2, 2, 0, 20], "new RLE scanline");
        let q = Picture::read(Cursor::new(&out), "t.hsr").unwrap();
        assert_eq!((q.format, q.ncomp()), (PixelFormat::Spectra, 3));
        assert_eq!(q.data, p.data);
    }

    #[test]
    fn header_errors_are_one_line_with_location() {
        let cases: [(&[u8], &str); 5] = [
            (
                b"#?RADIANCE\nFORMAT=ascii\n\n-Y 1 +X 1\n",
                "p.hdr:2: FORMAT=ascii: expected a picture",
            ),
            (
                b"#?RADIANCE\nNCOMP=6\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n",
                "p.hdr:2: NCOMP=6 with FORMAT=32-bit_rle_rgbe: expected NCOMP=3",
            ),
            (
                b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 X 1\n",
                "p.hdr:4: bad resolution string",
            ),
            (
                b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 1\n\x80\x80\x80\x80",
                "p.hdr: scanline 2 of 2 ends early",
            ),
            (b"-Y 2 +X 1\n", "p.hdr:1: no header"),
        ];
        for (bytes, want) in cases {
            let e = Picture::read(Cursor::new(bytes), "p.hdr")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(want), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn streaming_writer_and_reader() {
        let res = Resolution::standard(40, 3);
        let ch = Channels::rgb();
        let mut w = PictureWriter::new(
            Vec::new(),
            "s.hdr",
            &Header::new(),
            PixelFormat::Rgbe,
            &ch,
            res,
            true,
        )
        .unwrap();
        let line: Vec<f32> = (0..120).map(|i| (i / 3) as f32).collect();
        w.write_scanline(&line).unwrap();
        assert!(w.write_scanline(&line[..3]).is_err());
        w.write_scanline(&line).unwrap();
        let mut w2 = PictureWriter::new(
            Vec::new(),
            "s.hdr",
            &Header::new(),
            PixelFormat::Rgbe,
            &ch,
            res,
            true,
        )
        .unwrap();
        w2.write_scanline(&line).unwrap();
        let e = w2.finish().unwrap_err().to_string();
        assert_eq!(e, "s.hdr: 1 of 3 scanlines written");
        w.write_scanline(&line).unwrap();
        assert!(w.write_scanline(&line).is_err(), "a fourth scanline");
        let bytes = w.finish().unwrap();
        let mut r = PictureReader::new(Cursor::new(&bytes), "s.hdr").unwrap();
        assert_eq!(r.resolution, res);
        let mut buf = vec![0f32; 120];
        let mut n = 0;
        while r.read_scanline(&mut buf).unwrap() {
            // Back within half a mantissa step: 2^(e-9) <= v/256 for 2^(e-1) <= v < 2^e.
            for (a, b) in buf.iter().zip(&line) {
                assert!((a - b).abs() <= b / 256.0, "{a} {b}");
            }
            n += 1;
        }
        assert_eq!((n, r.next_scanline()), (3, 3));
        assert!(!r.read_scanline(&mut buf).unwrap());
        // Raw 4-byte access for the matrix module.
        let mut r = PictureReader::new(Cursor::new(&bytes), "s.hdr").unwrap();
        let mut colrs = vec![[0u8; 4]; 40];
        assert!(r.read_colrs(&mut colrs).unwrap());
        assert_eq!(colrs[1], color::encode_rgbe(1.0, 1.0, 1.0));
    }

    #[test]
    fn exposure_and_luminance() {
        let mut p = Picture::new(1, 1, Channels::rgb(), PixelFormat::Rgbe);
        p.data = vec![2.0, 2.0, 2.0];
        p.header.push("EXPOSURE=2");
        p.header.push("EXPOSURE=0.5");
        p.header.push("EXPOSURE=4");
        p.header.push("COLORCORR= 1 0.5 1");
        assert_eq!(p.exposure(), vec![4.0, 2.0, 4.0]);
        assert_eq!(p.radiance_values(), vec![0.5, 1.0, 0.5]);
        // Radiance's luminance(): 179 x row Y of the standard primaries' RGB-to-XYZ matrix.
        let want = 179.0 * (0.265105820 * 0.5 + 0.670105820 + 0.064788360 * 0.5);
        assert!((p.luminance(0, 0) - want).abs() < 1e-6);
        p.format = PixelFormat::Xyze;
        assert_eq!(p.luminance(0, 0), 1.0);
        p.header
            .push("PRIMARIES= 0.6400 0.3300 0.2900 0.6000 0.1500 0.0600 0.3333 0.3333");
        assert_eq!(p.primaries().unwrap()[7], 0.3333);
    }
}
