//! Common-exponent pixels: RGBE / XYZE (4 bytes) and Radiance 6 spectral `SCOLR`
//! (NCOMP mantissas + 1 exponent).
//!
//! Source: Radiance `src/common/color.c` (`setcolr`, `scolor2scolr`, `scolr2scolor`, the
//! `cxponent` table) and `color.h` (`cx2real`, `COLXS`); `doc/filefmts.md`.
//!
//! ```text
//! encode:  p = max_i v_i;  p <= 1e-32  =>  all bytes 0
//!          m, e = frexp(p)   (p = m 2^e, 0.5 <= m < 1)
//!          f = m * 256 / p   (= 2^(8-e))
//!          byte_i = v_i > 0 ? trunc(v_i f) : 0      exponent byte = e + 128
//! decode:  v_i = (byte_i + 0.5) * 2^(E - 136),  E = 0 => v_i = 0
//! ```
//! So white (1,1,1) is `(128,128,128,129)`; encoding truncates and decoding adds half a
//! step, which is what makes `decode(encode(decode(c))) == decode(c)` for every pixel
//! Radiance writes (the largest mantissa is always >= 128).
//!
//! The two encoders differ in one detail that matters for byte compatibility: `setcolr`
//! (RGBE) multiplies in `double`, `scolor2scolr` (spectral) keeps the factor in a `float`
//! and multiplies in `float`. We reproduce both.

/// Exponent excess (`COLXS`).
pub const COLXS: i32 = 128;

/// Values at or below this encode as black (`setcolr`, `scolor2scolr`).
const TINY: f64 = 1e-32;

/// `cxponent[e]`: the scale of one mantissa step for exponent byte `e`, `2^(e-136)`, with
/// `cxponent[0] = 0` so that exponent 0 is black whatever the mantissas say.
#[inline]
pub fn cxponent(e: u8) -> f32 {
    if e == 0 {
        0.0
    } else {
        // 2^(e-136) lies in [2^-135, 2^119]: exact in f64 and in f32 (2^-135 is a
        // subnormal f32, still exact), so the cast loses nothing. The f64 is built from
        // its exponent bits (a power of two is a bare exponent field), not by powi's
        // repeated products: this runs for every pixel read.
        f64::from_bits(((e as i64 - 136 + 1023) as u64) << 52) as f32
    }
}

/// `frexp`: `x = m 2^e` with `0.5 <= m < 1`, for finite positive `x`.
fn frexp(x: f64) -> (f64, i32) {
    debug_assert!(x.is_finite() && x > 0.0);
    let bits = x.to_bits();
    let exp_field = ((bits >> 52) & 0x7ff) as i32;
    if exp_field == 0 {
        // Subnormal: scale up first (cannot happen above TINY, kept for completeness).
        let (m, e) = frexp(x * (2f64).powi(64));
        return (m, e - 64);
    }
    let e = exp_field - 1022;
    let m = f64::from_bits((bits & !(0x7ffu64 << 52)) | (1022u64 << 52));
    (m, e)
}

/// Exponent byte for `e + COLXS`, or `None` when the value is too large for a pixel.
/// Radiance would silently wrap the byte; we saturate instead (see `encode_rgbe`).
fn exponent_byte(e: i32) -> Option<u8> {
    u8::try_from(e + COLXS).ok()
}

/// Encode one RGB (or XYZ) value as Radiance's `setcolr` does.
///
/// Deviations, for inputs Radiance never meets in practice: NaN encodes as black, and values
/// of 2^127 or more saturate to the largest pixel (Radiance would wrap the exponent byte).
pub fn encode_rgbe(r: f32, g: f32, b: f32) -> [u8; 4] {
    let (r, g, b) = (r as f64, g as f64, b as f64);
    // C's `r > g ? r : g` ignores NaN the same way Rust's comparison does: NaN never wins.
    let mut d = if r > g { r } else { g };
    if b > d {
        d = b;
    }
    if d.is_nan() || d <= TINY {
        return [0, 0, 0, 0];
    }
    if !d.is_finite() {
        return [255, 255, 255, 255];
    }
    let (m, e) = frexp(d);
    let Some(eb) = exponent_byte(e) else {
        return [255, 255, 255, 255];
    };
    let f = m * 256.0 / d;
    let byte = |v: f64| if v > 0.0 { (v * f) as u8 } else { 0 };
    [byte(r), byte(g), byte(b), eb]
}

/// Decode an RGBE (or XYZE) pixel (`colr_color`): `(m + 0.5) * 2^(E-136)`, in `float`.
#[inline]
pub fn decode_rgbe(c: [u8; 4]) -> [f32; 3] {
    let f = cxponent(c[3]);
    [
        (c[0] as f32 + 0.5) * f,
        (c[1] as f32 + 0.5) * f,
        (c[2] as f32 + 0.5) * f,
    ]
}

/// Encode `values.len()` spectral samples into `out` (`values.len() + 1` bytes), as
/// `scolor2scolr` does (factor and products in `float`).
///
/// # Panics
/// If `out.len() != values.len() + 1` (a programming error, never input dependent).
pub fn encode_scolr(values: &[f32], out: &mut [u8]) {
    assert_eq!(out.len(), values.len() + 1, "encode_scolr: buffer size");
    let n = values.len();
    let mut p = f32::NEG_INFINITY;
    for &v in values {
        if v > p {
            p = v;
        }
    }
    if p.is_nan() || p as f64 <= TINY {
        out.fill(0);
        return;
    }
    if !p.is_finite() {
        out.fill(255);
        return;
    }
    let (m, e) = frexp(p as f64);
    let Some(eb) = exponent_byte(e) else {
        out.fill(255);
        return;
    };
    // The C code stores the factor back into the float `p`.
    let f = (m * 256.0 / p as f64) as f32;
    out[n] = eb;
    for (o, &v) in out.iter_mut().zip(values) {
        *o = if v > 0.0 { (v * f) as u8 } else { 0 };
    }
}

/// Decode `bytes` (`out.len() + 1` bytes: mantissas then exponent) into `out`
/// (`scolr2scolor`).
///
/// # Panics
/// If `bytes.len() != out.len() + 1` (a programming error).
pub fn decode_scolr(bytes: &[u8], out: &mut [f32]) {
    assert_eq!(bytes.len(), out.len() + 1, "decode_scolr: buffer size");
    let f = cxponent(bytes[out.len()]);
    for (o, &b) in out.iter_mut().zip(bytes) {
        *o = (b as f32 + 0.5) * f;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every exponent byte's scale is 2^(e-136) exactly (0 for byte 0), as powi gives it.
    #[test]
    fn cxponent_is_the_power_of_two() {
        assert_eq!(cxponent(0), 0.0);
        for e in 1..=255u8 {
            let want = (2f64).powi(e as i32 - 136) as f32;
            assert_eq!(cxponent(e).to_bits(), want.to_bits(), "exponent byte {e}");
            assert!(want > 0.0, "exponent byte {e}");
        }
        assert_eq!(cxponent(136), 1.0);
        // 2^-135 = 2^14 · 2^-149, the subnormal f32 with mantissa bits 1 << 14
        assert_eq!(cxponent(1).to_bits(), 1 << 14);
    }

    #[test]
    fn white_is_128_128_128_129() {
        assert_eq!(encode_rgbe(1.0, 1.0, 1.0), [128, 128, 128, 129]);
        // (128 + .5) * 2^(129-136) = 128.5 / 128
        assert_eq!(decode_rgbe([128, 128, 128, 129]), [128.5 / 128.0; 3]);
    }

    #[test]
    fn zero_exponent_is_black() {
        assert_eq!(decode_rgbe([0, 0, 0, 0]), [0.0; 3]);
        assert_eq!(decode_rgbe([200, 17, 3, 0]), [0.0; 3]);
        // A zero mantissa with a non-zero exponent is half a step, not zero.
        assert_eq!(decode_rgbe([0, 0, 0, 136]), [0.5; 3]);
    }

    #[test]
    fn tiny_and_negative_values() {
        assert_eq!(encode_rgbe(1e-33, 0.0, 0.0), [0, 0, 0, 0]);
        assert_eq!(encode_rgbe(0.0, 0.0, 0.0), [0, 0, 0, 0]);
        assert_eq!(encode_rgbe(-5.0, -1.0, -2.0), [0, 0, 0, 0]);
        // Negative components become 0 next to a positive one.
        assert_eq!(encode_rgbe(1.0, -1.0, 0.5), [128, 0, 64, 129]);
        assert_eq!(encode_rgbe(f32::NAN, 0.0, 0.0), [0, 0, 0, 0]);
    }

    #[test]
    fn truncation_not_rounding() {
        // 0.999: frexp -> (0.999, 0): factor 256; 0.999*256 = 255.744 -> 255, exp 128.
        assert_eq!(encode_rgbe(0.999, 0.5, 0.001), [255, 128, 0, 128]);
        // 3.0 = 0.75 * 2^2: factor 64; 3*64 = 192; 1*64 = 64; 0.1*64 = 6.4 -> 6.
        assert_eq!(encode_rgbe(3.0, 1.0, 0.1), [192, 64, 6, 130]);
        // Decoding adds half a step: 192.5 * 2^(130-136).
        assert_eq!(
            decode_rgbe([192, 64, 6, 130]),
            [3.0078125, 1.0078125, 0.1015625]
        );
    }

    #[test]
    fn every_normalised_pixel_round_trips() {
        for e in 1..=255u8 {
            for m in 128..=255u8 {
                for other in [0u8, 1, 77, 128, m] {
                    let c = [other, m, 3, e];
                    let v = decode_rgbe(c);
                    if (m as f64 + 0.5) * (cxponent(e) as f64) <= TINY {
                        continue;
                    }
                    assert_eq!(encode_rgbe(v[0], v[1], v[2]), c, "{c:?}");
                }
            }
        }
    }

    #[test]
    fn spectral_round_trip_and_rules() {
        let mut out = [0u8; 7];
        encode_scolr(&[1.0, 0.5, 0.25, 0.0, -1.0, 3.0], &mut out);
        // max 3 = 0.75 * 2^2 -> factor 64.
        assert_eq!(out, [64, 32, 16, 0, 0, 192, 130]);
        let mut v = [0f32; 6];
        decode_scolr(&out, &mut v);
        assert_eq!(v[5], 192.5 / 64.0);
        let mut again = [0u8; 7];
        encode_scolr(&v, &mut again);
        assert_eq!(again, out);
        encode_scolr(&[0.0; 6], &mut out);
        assert_eq!(out, [0; 7]);
        decode_scolr(&[9, 9, 9, 9, 9, 9, 0], &mut v);
        assert_eq!(v, [0.0; 6]);
    }

    #[test]
    fn huge_values_saturate() {
        assert_eq!(encode_rgbe(f32::MAX, 0.0, 0.0), [255, 255, 255, 255]);
        assert_eq!(encode_rgbe(f32::INFINITY, 0.0, 0.0), [255, 255, 255, 255]);
        // 2^126 still fits: exponent 127 + 128 = 255.
        let c = encode_rgbe(2f32.powi(126), 0.0, 0.0);
        assert_eq!(c, [128, 0, 0, 255]);
    }
}
