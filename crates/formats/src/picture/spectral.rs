//! Radiance 6 hyperspectral pictures (`FORMAT=Radiance_spectra`): NCOMP mantissa bytes and
//! one common exponent per pixel, never run-length encoded.
//!
//! Source: Radiance `src/common/color.c` (`freadscolrs`, `fwritescolrs`, `scolor2color`),
//! `color.h` (`SPECFMT`, `NCOMPSTR`, `WLSPLTSTR`), `doc/notes/hyperspectral.txt`.
//!
//! ```text
//! #?RADIANCE
//! NCOMP=6
//! WAVELENGTH_SPLITS= 780 588 480 380
//! FORMAT=Radiance_spectra
//!
//! -Y N +X M
//! N x M x (NCOMP + 1) bytes        band 0 = longest wavelength
//! ```
//! With `NCOMP=3` Radiance's readers and writers fall back to the RGBE scanline codec
//! (`freadscolrs`: `if (nc == 3) return freadcolrs(...)`), and so do we.

use super::color::{decode_scolr, encode_scolr};
use super::scanline::ScanlineError;
use std::io::{self, BufRead, Write};

/// Read one flat spectral scanline of `out.len() / ncomp` pixels into `out`, using `bytes`
/// as scratch space.
pub fn read_scanline<R: BufRead + ?Sized>(
    r: &mut R,
    ncomp: usize,
    bytes: &mut Vec<u8>,
    out: &mut [f32],
) -> Result<(), ScanlineError> {
    let len = out.len() / ncomp;
    bytes.resize(len * (ncomp + 1), 0);
    r.read_exact(bytes)?;
    for (px, v) in bytes
        .chunks_exact(ncomp + 1)
        .zip(out.chunks_exact_mut(ncomp))
    {
        decode_scolr(px, v);
    }
    Ok(())
}

/// Encode and write one flat spectral scanline (`fwritesscan`).
pub fn write_scanline<W: Write + ?Sized>(
    w: &mut W,
    ncomp: usize,
    values: &[f32],
    bytes: &mut Vec<u8>,
) -> io::Result<()> {
    let len = values.len() / ncomp;
    bytes.resize(len * (ncomp + 1), 0);
    for (px, v) in bytes
        .chunks_exact_mut(ncomp + 1)
        .zip(values.chunks_exact(ncomp))
    {
        encode_scolr(v, px);
    }
    w.write_all(bytes)
}

/// RGB from a spectrum as Radiance's `scolor2color` does: R, G and B are the averages of
/// the bands whose centre wavelengths fall in `[splits[1], splits[0]]`, `[splits[2],
/// splits[1])` and `[splits[3], splits[2])`.
pub fn to_rgb(values: &[f32], splits: [f64; 4]) -> [f32; 3] {
    let n = values.len();
    let mut col = [0f32; 3];
    if n == 0 {
        return col;
    }
    let step = (splits[3] - splits[0]) / n as f64;
    let mut cwl = splits[0] + 0.5 * step;
    let (mut j, mut cnt) = (0usize, 0u32);
    for &v in values {
        // `j < 2` guards odd splits; with valid ones the centre never passes splits[3].
        if j < 2 && cwl < splits[j + 1] {
            if cnt > 1 {
                col[j] /= cnt as f32;
            }
            j += 1;
            cnt = 0;
        }
        col[j] += v;
        cnt += 1;
        cwl += step;
    }
    if cnt > 1 {
        col[j] /= cnt as f32;
    }
    col
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_averages_bands_by_centre() {
        // 8 bands of 50 nm from 780: centres 755 705 655 605 | 555 505 | 455 405.
        let v = [1.0, 2.0, 3.0, 4.0, 10.0, 20.0, 100.0, 300.0];
        assert_eq!(to_rgb(&v, [780.0, 588.0, 480.0, 380.0]), [2.5, 15.0, 200.0]);
    }

    #[test]
    fn flat_round_trip() {
        let vals: Vec<f32> = (0..12).map(|i| i as f32 * 0.37).collect();
        let mut out = Vec::new();
        let mut scratch = Vec::new();
        write_scanline(&mut out, 6, &vals, &mut scratch).unwrap();
        assert_eq!(out.len(), 14);
        let mut back = vec![0f32; 12];
        read_scanline(&mut &out[..], 6, &mut scratch, &mut back).unwrap();
        for (a, b) in vals.iter().zip(&back) {
            // Half a mantissa step of the largest value (4.07 < 2^3: step 2^-5).
            assert!((a - b).abs() <= 0.5 / 32.0, "{a} {b}");
        }
        let mut short = vec![0f32; 18];
        assert!(matches!(
            read_scanline(&mut &out[..], 6, &mut scratch, &mut short),
            Err(ScanlineError::Eof)
        ));
    }
}
