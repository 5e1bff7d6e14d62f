//! OpenEXR input and output through the `exr` crate.
//!
//! EXR stores linear floats, so a picture goes out with its exposure divided out
//! ([`Picture::radiance_values`]) and comes back with `EXPOSURE` 1. Channel names:
//!
//! | picture | EXR channels |
//! |---|---|
//! | RGBE | `R`, `G`, `B` (32-bit float, W/sr/m²) |
//! | XYZE | `X`, `Y`, `Z` (Y in cd/m²) |
//! | spectral, N bands | `S0.<centre>nm`, one per band, centre wavelength with a comma as decimal separator, e.g. `S0.746,666667nm` (the spectral EXR layout of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for Spectral Images", JCGT 10(3), 2021) |
//!
//! Reading accepts `R G B` (with or without `A`, which is dropped), `X Y Z`, a lone `Y`
//! (grey: R = G = B = Y), or three or more spectral channels named `<prefix>.<wl>nm` or
//! `<wl>nm` with equal spacing, which become a Radiance spectral picture ordered from the
//! longest wavelength down, the band edges half a spacing either side of the centres.
//! Rows are stored top first, as in a Radiance picture in standard orientation.

use super::{Picture, PixelFormat};
use crate::error::{Error, Location, Result};
use crate::header::Header;
use crate::radiometry::{Channels, DEFAULT_SPLITS};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, ReadChannels,
    ReadLayers, SmallVec, WritableImage,
};
use std::io::{Read, Seek, Write};
use std::path::Path;

/// Name of the EXR channel for band `i` of a spectral layout.
pub fn spectral_channel_name(ch: &Channels, i: usize) -> String {
    let (hi, lo) = ch.band(i);
    format!("S0.{:.6}nm", 0.5 * (hi + lo))
        .replace('.', ",")
        .replacen(',', ".", 1)
}

/// Wavelength (nm) encoded in a spectral channel name, `None` if it is not one.
fn channel_wavelength(name: &str) -> Option<f64> {
    let stem = name.strip_suffix("nm")?;
    // The wavelength is the whole stem ("550.5nm", "550nm"), or follows the last '.' with
    // ',' as decimal separator ("S0.550,5nm").
    let candidates = [
        Some(stem.replace(',', ".")),
        stem.rsplit_once('.').map(|(_, w)| w.replace(',', ".")),
    ];
    candidates
        .into_iter()
        .flatten()
        .find_map(|w| w.parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0))
}

fn exr_error(name: &str, e: impl std::fmt::Display) -> Error {
    Error::parse(
        Location::file(name),
        format!("not a readable OpenEXR file: {e}"),
    )
}

/// Write `p` as a single-layer 32-bit float EXR (lossless run-length compression).
pub fn write_exr_to<W: Write + Seek>(p: &Picture, w: W) -> Result<()> {
    p.check_shape()?;
    let nc = p.ncomp();
    let vals = p.radiance_values();
    let names: Vec<String> = match p.format {
        PixelFormat::Rgbe => vec!["R".into(), "G".into(), "B".into()],
        PixelFormat::Xyze => vec!["X".into(), "Y".into(), "Z".into()],
        PixelFormat::Spectra => (0..nc)
            .map(|i| spectral_channel_name(&p.channels, i))
            .collect(),
    };
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = names
        .iter()
        .enumerate()
        .map(|(c, n)| {
            let samples: Vec<f32> = vals.iter().skip(c).step_by(nc).copied().collect();
            AnyChannel::new(n.as_str(), FlatSamples::F32(samples))
        })
        .collect();
    let layer = Layer::new(
        (p.width, p.height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .to_buffered(w)
        .map_err(|e| Error::Usage(format!("cannot write OpenEXR: {e}")))
}

/// Write `p` to an EXR file.
pub fn write_exr(p: &Picture, path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    let f = std::fs::File::create(path).map_err(|e| Error::io(&shown, e))?;
    write_exr_to(p, std::io::BufWriter::new(f)).map_err(|e| Error::Usage(format!("{shown}: {e}")))
}

/// Read the first layer of an EXR stream; see the module documentation for the channels.
pub fn read_exr_from<R: Read + Seek>(mut r: R, name: &str) -> Result<Picture> {
    // The exr crate validates its input, but a decoder bug must not take the caller down:
    // a panic inside it becomes an ordinary error.
    let gave_up = || exr_error(name, "the decoder gave up on corrupt data");
    // The headers first: the decoder allocates every layer's pixels as its header claims,
    // so sizes are checked before any pixel is decoded.
    let start = r.stream_position().map_err(|e| Error::io(name, e))?;
    let meta = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        exr::meta::MetaData::read_from_buffered(&mut r, false)
    }))
    .map_err(|_| gave_up())?
    .map_err(|e| exr_error(name, e))?;
    for h in &meta.headers {
        let (w, h_px) = (h.layer_size.0, h.layer_size.1);
        super::check_size(name, w, h_px, h.channels.list.len())?;
    }
    r.seek(std::io::SeekFrom::Start(start))
        .map_err(|e| Error::io(name, e))?;
    let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(r)
    }));
    let image = match decoded {
        Ok(r) => r.map_err(|e| exr_error(name, e))?,
        Err(_) => return Err(gave_up()),
    };
    let layer = image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    let chans = &layer.channel_data.list;
    let find = |n: &str| chans.iter().find(|c| c.name.to_string() == n);
    let values =
        |c: &AnyChannel<FlatSamples>| -> Vec<f32> { c.sample_data.values_as_f32().collect() };
    let names: Vec<String> = chans.iter().map(|c| c.name.to_string()).collect();
    let (format, channels, planes): (PixelFormat, Channels, Vec<Vec<f32>>) =
        if let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) {
            (
                PixelFormat::Rgbe,
                Channels::rgb(),
                vec![values(r), values(g), values(b)],
            )
        } else if let (Some(x), Some(y), Some(z)) = (find("X"), find("Y"), find("Z")) {
            (
                PixelFormat::Xyze,
                Channels::rgb(),
                vec![values(x), values(y), values(z)],
            )
        } else if let (Some(y), 1) = (find("Y"), chans.len()) {
            let v = values(y);
            (
                PixelFormat::Rgbe,
                Channels::rgb(),
                vec![v.clone(), v.clone(), v],
            )
        } else {
            let mut bands: Vec<(f64, &AnyChannel<FlatSamples>)> = chans
                .iter()
                .filter_map(|c| channel_wavelength(&c.name.to_string()).map(|wl| (wl, c)))
                .collect();
            bands.sort_by(|a, b| b.0.total_cmp(&a.0));
            let n = bands.len();
            if !(3..=crate::radiometry::MAX_SAMPLES).contains(&n) {
                return Err(Error::parse(
                    Location::file(name),
                    format!(
                        "EXR channels {names:?}: expected R G B, X Y Z, Y, or 3 to {} \
                         spectral channels named like 'S0.550,000000nm'",
                        crate::radiometry::MAX_SAMPLES
                    ),
                ));
            }
            let step = (bands[0].0 - bands[n - 1].0) / (n - 1) as f64;
            let even = bands
                .windows(2)
                .all(|p| ((p[0].0 - p[1].0) - step).abs() <= 1e-3 * step.max(1e-9));
            if step.is_nan() || step <= 0.0 || !even {
                return Err(Error::parse(
                    Location::file(name),
                    format!("EXR spectral channels {names:?}: expected equally spaced wavelengths"),
                ));
            }
            // Centres are written with 6 decimals: round the edges to 1e-3 nm so that
            // 780 and 380 come back as such.
            let round = |v: f64| (v * 1000.0).round() / 1000.0;
            let wl_max = round(bands[0].0 + 0.5 * step);
            let wl_min = round(bands[n - 1].0 - 0.5 * step);
            let mut splits = DEFAULT_SPLITS;
            splits[0] = wl_max;
            splits[3] = wl_min;
            splits[1] = splits[1].clamp(wl_min, wl_max);
            splits[2] = splits[2].clamp(wl_min, wl_max);
            let ch = Channels { ncomp: n, splits };
            (
                PixelFormat::Spectra,
                ch,
                bands.iter().map(|(_, c)| values(c)).collect(),
            )
        };
    let nc = planes.len();
    if planes.iter().any(|p| p.len() != w * h) {
        return Err(Error::unsupported(
            Location::file(name),
            "subsampled EXR channels",
        ));
    }
    let mut data = vec![0f32; w * h * nc];
    for (c, plane) in planes.iter().enumerate() {
        for (i, &v) in plane.iter().enumerate() {
            data[i * nc + c] = v;
        }
    }
    let mut header = Header::new();
    header.push(format!("converted from OpenEXR {name}"));
    Ok(Picture {
        width: w,
        height: h,
        channels,
        data,
        header,
        format,
    })
}

/// Read an EXR file.
pub fn read_exr(path: impl AsRef<Path>) -> Result<Picture> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| Error::io(&shown, e))?;
    read_exr_from(std::io::BufReader::new(f), &shown)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue #19: a header claiming 100000 x 100000 pixels made the decoder allocate
    /// 40 GB; the size is checked from the headers before any pixel is decoded.
    #[test]
    fn huge_header_is_refused_before_decoding() {
        let p = Picture::new(2, 2, Channels::rgb(), PixelFormat::Rgbe);
        let mut bytes = std::io::Cursor::new(Vec::new());
        write_exr_to(&p, &mut bytes).unwrap();
        let mut bytes = bytes.into_inner();
        // Both windows: name, "box2i", size 16, then xmin ymin xmax ymax (i32 LE).
        for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
            let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
            bytes[at + 8..at + 12].copy_from_slice(&99_999i32.to_le_bytes());
            bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
        }
        let e = read_exr_from(std::io::Cursor::new(bytes), "huge.exr")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("huge.exr: a picture of 100000 x 100000 pixels"),
            "{e}"
        );
    }

    #[test]
    fn channel_names() {
        let ch = Channels::spectral(6, 380.0, 780.0).unwrap();
        assert_eq!(spectral_channel_name(&ch, 0), "S0.746,666667nm");
        assert_eq!(channel_wavelength("S0.746,666667nm"), Some(746.666667));
        assert_eq!(channel_wavelength("550nm"), Some(550.0));
        assert_eq!(channel_wavelength("550.5nm"), Some(550.5));
        assert_eq!(channel_wavelength("R"), None);
    }
}
