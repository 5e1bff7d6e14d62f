//! # From simulated bands to a spectral sensor's channels
//!
//! The simulation carries `N` equal bands (`rdc -cs N -cw a b`); band value `v_b` is the
//! band-mean spectral irradiance times 400 nm (Radiance's convention, see
//! [`crate::metrics::melanopic`]), so `E_b = v_b / 400` W m-2 nm-1. A channel reading is a
//! linear map of the bands, `sim_c = Σ_b M_cb v_b`:
//!
//! - **without response curves** a channel is the band that contains its centre wavelength
//!   (a band's lower edge belongs to it; the shortest band also takes its lower edge):
//!   `sim_c = E_b(c)`, spectral irradiance in W m-2 nm-1 at the channel. With the
//!   simulation's own band centres as channels (e.g. 18 channels for `-cs 18 -cw 380 780`)
//!   the channels are the bands. Centre wavelengths outside the simulated range are an
//!   error (no extrapolation).
//! - **with response curves** (`--response`, a CSV `wavelength,<channel>,...`: the
//!   wavelength in nm, then each channel's relative response, linear between the rows and
//!   zero outside them) a channel is the response-weighted integral of the simulated
//!   spectrum, `sim_c = ∫ R_c(λ) E(λ) dλ` with `E` constant over each band (W m-2 for a
//!   dimensionless `R`): the measured values must be in that unit. A response with more
//!   than [`MAX_OUTSIDE`] of its area outside the simulated range is an error (the channel
//!   sees light the simulation does not have).
//!
//! For photopic and melanopic quantities of a *measured* reading, [`ChannelMap::weights`]
//! gives per-channel weights `w_c` (the mean band integral of ybar or s_mel over the
//! channel's footprint); the measured quantity is the simulated one times
//! `Σ w_c m_c / Σ w_c sim_c` (a ratio estimator, exact when the channels are the bands).

use super::readings::SpectralReadings;
use crate::colour::bands::band_integrals;
use crate::colour::cie::tables;
use crate::csv::{self, shorten};
use crate::error::{Error, Location, Result};
use crate::radiometry::Channels;

/// Largest share of a response curve's area allowed outside the simulated range.
pub const MAX_OUTSIDE: f64 = 0.01;

/// Radiance's span: band values are spectral irradiance times this (nm).
const SPAN_NM: f64 = crate::metrics::melanopic::RADIANCE_SPAN_NM;

/// The linear map from simulated bands to channels.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelMap {
    pub names: Vec<String>,
    pub centres: Vec<f64>,
    /// `[c][b]`.
    pub matrix: Vec<Vec<f64>>,
    pub ch: Channels,
    /// Unit of a channel reading.
    pub unit: &'static str,
}

/// A response-curve table: wavelengths and one column per channel name.
#[derive(Debug, Clone, PartialEq)]
pub struct Responses {
    pub file: String,
    pub header_line: usize,
    pub names: Vec<String>,
    pub wavelengths: Vec<f64>,
    /// `[channel][row]`.
    pub values: Vec<Vec<f64>>,
}

impl Responses {
    pub fn read_path(path: &str) -> Result<Responses> {
        Responses::parse(&csv::read_text(path)?, path)
    }

    /// Parse `wavelength,<name>,...` rows of numbers.
    pub fn parse(text: &str, file: &str) -> Result<Responses> {
        let header = |l: &csv::Line| {
            let f = &l.fields;
            let ok = f.len() >= 2
                && f.first().is_some_and(|w| {
                    w.eq_ignore_ascii_case("wavelength") || w.eq_ignore_ascii_case("nm")
                })
                && f[1..].iter().all(|n| !n.is_empty());
            if !ok {
                return Err(l.error(format!(
                    "expected the header 'wavelength,<channel>,...' (channel names as \
                     in the measurements), found '{}'",
                    shorten(l.text)
                )));
            }
            Ok(Responses {
                file: file.to_string(),
                header_line: l.no,
                names: f[1..].iter().map(|s| s.to_string()).collect(),
                wavelengths: Vec::new(),
                values: vec![Vec::new(); f.len() - 1],
            })
        };
        let (r, _, _) = csv::read(text, file, "wavelength,<channel>,...", header, row)?;
        if r.wavelengths.len() >= 2 {
            Ok(r)
        } else {
            Err(Error::parse(
                Location::file(file),
                "expected at least two rows of responses after the header",
            ))
        }
    }
}

/// A row of responses, appended to `r`.
fn row(r: &mut Responses, l: &csv::Line) -> Result<()> {
    let f = &l.fields;
    if f.len() != r.names.len() + 1 {
        return Err(l.error(format!(
            "expected {} fields (wavelength and {} responses), found {}",
            r.names.len() + 1,
            r.names.len(),
            f.len()
        )));
    }
    let mut nums = Vec::with_capacity(f.len());
    for k in 0..f.len() {
        let v = l.number(k, &format!("in column {}", k + 1))?;
        if k > 0 && v < 0.0 {
            return Err(l.error(format!("negative response {v} in column {}", k + 1)));
        }
        nums.push(v);
    }
    if r.wavelengths.last().is_some_and(|&w| nums[0] <= w) {
        return Err(l.error(format!(
            "wavelength {} nm: expected wavelengths increasing down the file",
            nums[0]
        )));
    }
    r.wavelengths.push(nums[0]);
    for (col, v) in r.values.iter_mut().zip(&nums[1..]) {
        col.push(*v);
    }
    Ok(())
}

/// Integral over `[lo, hi]` of the piecewise-linear `(x, y)` (zero outside its range).
fn integral(x: &[f64], y: &[f64], lo: f64, hi: f64) -> f64 {
    let at = |t: f64| -> f64 {
        match x.iter().position(|&a| a >= t) {
            Some(0) if t < x[0] => 0.0,
            Some(0) => y[0],
            Some(k) => {
                let (x0, x1) = (x[k - 1], x[k]);
                y[k - 1] + (y[k] - y[k - 1]) * (t - x0) / (x1 - x0)
            }
            None => 0.0,
        }
    };
    let (Some(&first), Some(&last)) = (x.first(), x.last()) else {
        return 0.0;
    };
    let (a, b) = (lo.max(first), hi.min(last));
    if b <= a {
        return 0.0;
    }
    let mut pts = vec![a];
    pts.extend(x.iter().copied().filter(|&t| t > a && t < b));
    pts.push(b);
    pts.windows(2)
        .map(|p| 0.5 * (at(p[0]) + at(p[1])) * (p[1] - p[0]))
        .sum()
}

impl ChannelMap {
    /// Channels of `r` as bands of `ch` (no response curves).
    pub fn bands(r: &SpectralReadings, ch: &Channels) -> Result<ChannelMap> {
        let (lo, hi) = (ch.splits[3], ch.splits[0]);
        let mut matrix = Vec::new();
        for (name, &c) in r.names.iter().zip(&r.centres) {
            if c < lo || c > hi {
                return Err(Error::parse(
                    Location::line(&r.file, r.header_line),
                    format!(
                        "channel {name}: centre wavelength {c} nm is outside the simulated \
                         {lo}-{hi} nm; simulate a wider range (-cw) or drop the channel"
                    ),
                ));
            }
            let b = (0..ch.ncomp)
                .find(|&b| {
                    let (u, l) = ch.band(b);
                    c >= l && (c < u || (b == 0 && c <= u))
                })
                .unwrap_or(0);
            let mut row = vec![0.0; ch.ncomp];
            row[b] = 1.0 / SPAN_NM;
            matrix.push(row);
        }
        Ok(ChannelMap {
            names: r.names.clone(),
            centres: r.centres.clone(),
            matrix,
            ch: *ch,
            unit: "W m-2 nm-1",
        })
    }

    /// Channels of `r` through the response curves `resp` (matched by channel name).
    pub fn with_responses(
        r: &SpectralReadings,
        resp: &Responses,
        ch: &Channels,
    ) -> Result<ChannelMap> {
        let (lo, hi) = (ch.splits[3], ch.splits[0]);
        let at = Location::line(&resp.file, resp.header_line);
        let mut matrix = Vec::new();
        for name in &r.names {
            let k = resp.names.iter().position(|n| n == name).ok_or_else(|| {
                Error::parse(
                    at.clone(),
                    format!(
                        "no response curve for channel '{name}' of {} (columns here: {})",
                        r.file,
                        resp.names.join(",")
                    ),
                )
            })?;
            let (x, y) = (&resp.wavelengths, &resp.values[k]);
            let total = integral(x, y, f64::NEG_INFINITY, f64::INFINITY);
            if total <= 0.0 {
                return Err(Error::parse(
                    at.clone(),
                    format!("channel '{name}': the response curve is zero everywhere"),
                ));
            }
            let inside = integral(x, y, lo, hi);
            if inside < (1.0 - MAX_OUTSIDE) * total {
                return Err(Error::parse(
                    at.clone(),
                    format!(
                        "channel '{name}': {:.0} % of its response lies outside the simulated \
                         {lo}-{hi} nm; simulate a wider range (-cw) or drop the channel",
                        100.0 * (1.0 - inside / total)
                    ),
                ));
            }
            let row: Vec<f64> = (0..ch.ncomp)
                .map(|b| {
                    let (u, l) = ch.band(b);
                    integral(x, y, l, u) / SPAN_NM
                })
                .collect();
            matrix.push(row);
        }
        Ok(ChannelMap {
            names: r.names.clone(),
            centres: r.centres.clone(),
            matrix,
            ch: *ch,
            unit: "W m-2 (response-weighted)",
        })
    }

    pub fn len(&self) -> usize {
        self.names.len()
    }
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Channel readings of simulated band values.
    pub fn apply(&self, bands: &[f64]) -> Vec<f64> {
        self.matrix
            .iter()
            .map(|row| row.iter().zip(bands).map(|(m, v)| m * v).sum())
            .collect()
    }

    /// Per-channel weights for photopic (`melanopic = false`) or melanopic quantities: the
    /// mean band integral of ybar or s_mel over the channel's footprint.
    pub fn weights(&self, melanopic: bool) -> Vec<f64> {
        let t = tables();
        let curve = if melanopic { &t.melanopic } else { &t.cmf[1] };
        let w = band_integrals(curve, &self.ch);
        self.matrix
            .iter()
            .map(|row| {
                let s: f64 = row.iter().sum();
                if s > 0.0 {
                    row.iter().zip(&w).map(|(m, x)| m * x).sum::<f64>() / s
                } else {
                    0.0
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn readings(header: &str) -> SpectralReadings {
        let text = format!(
            "{header}\n1,1,12,a{}\n",
            ",1".repeat(header.split(',').count() - 4)
        );
        SpectralReadings::parse(&text, "m.csv").unwrap()
    }

    #[test]
    fn channels_are_bands_and_range_is_checked() {
        let ch = Channels::spectral(18, 380.0, 780.0).unwrap();
        let r = readings("month,day,hour,sensor,391nm,770nm");
        let m = ChannelMap::bands(&r, &ch).unwrap();
        // 391 nm is in the last (shortest) band, 770 nm in the first.
        assert!(m.matrix[0][17] > 0.0 && m.matrix[1][0] > 0.0);
        let bands: Vec<f64> = (0..18).map(|b| b as f64 * 400.0).collect();
        assert_eq!(m.apply(&bands), vec![17.0, 0.0]);
        let r = readings("month,day,hour,sensor,410nm,810nm");
        let e = ChannelMap::bands(&r, &ch).unwrap_err().to_string();
        assert!(
            e.starts_with("m.csv:1: channel 810nm: centre wavelength 810 nm is outside"),
            "{e}"
        );
    }

    #[test]
    fn responses_integrate_and_check() {
        let ch = Channels::spectral(4, 380.0, 780.0).unwrap();
        let r = readings("month,day,hour,sensor,450nm,650nm");
        let resp = Responses::parse(
            "wavelength,450nm,650nm\n380,1,0\n580,1,0\n581,0,0\n780,0,0\n",
            "r.csv",
        )
        .unwrap();
        let m = ChannelMap::with_responses(&r, &resp, &ch);
        // Channel b has a zero response.
        assert!(
            m.unwrap_err()
                .to_string()
                .contains("'650nm': the response curve is zero")
        );
        let resp = Responses::parse(
            "wavelength,450nm,650nm\n380,1,0\n580,1,1\n780,1,1\n",
            "r.csv",
        )
        .unwrap();
        let m = ChannelMap::with_responses(&r, &resp, &ch).unwrap();
        // Flat E = 1 W m-2 nm-1 (v = 400 in every band): a sees 400 nm, b 300 nm.
        let v = m.apply(&[400.0; 4]);
        assert!(
            (v[0] - 400.0).abs() < 1e-9 && (v[1] - 300.0).abs() < 1e-9,
            "{v:?}"
        );
        let resp = Responses::parse("wavelength,450nm,650nm\n700,1,1\n900,1,1\n", "r.csv").unwrap();
        let e = ChannelMap::with_responses(&r, &resp, &ch)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("r.csv:1: channel '450nm': 60 % of its response"),
            "{e}"
        );
        let e = Responses::parse("wavelength,a\n500,1\n400,1\n", "r.csv").unwrap_err();
        assert!(
            e.to_string().starts_with("r.csv:3: wavelength 400 nm"),
            "{e}"
        );
        let good = "wavelength,450nm,650nm\n380,1,0\n580,1,1\n780,1,1\n";
        for n in 0..=good.len() {
            let _ = Responses::parse(&good[..n], "r.csv");
        }
    }
}
