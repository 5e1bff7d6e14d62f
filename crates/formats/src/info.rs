//! Summaries of any file our tools read: what `rinfo` prints (the `getinfo` counterpart).
//!
//! `getinfo` shows a Radiance header; users of a daylight pipeline also want to know, before
//! a long run, whether a scene parses and what it holds, what site and period a weather file
//! covers, how many sensors a grid has, and the range of the numbers in a matrix. Each
//! summary is computed by streaming the file, so it works on matrices of any size.
//! [`describe`] picks the summary for one file by its content.

use crate::error::{Error, Location, Result};
use crate::header::Header;
use crate::matrix::reader::{MatrixReader, ReadOptions};
use crate::picture::PictureReader;
use crate::picture::resolution::Resolution;

use crate::scene::Scene;
use crate::sensors::{RayFormat, RayReader};
use crate::weather::{WeaUnits, Weather};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::BufRead;

/// What kind of file a stream holds, judged by its first bytes (never by its name).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Starts with `#?`: a picture or matrix (or other Radiance data) with a header.
    Radiance,
    /// An EPW (`LOCATION,`) or `.wea` (`place`) weather file.
    Weather,
    /// Lines of six numbers: sensor rays.
    Sensors,
    /// Nothing at all (0 bytes).
    Empty,
    /// A PNG, JPEG or OpenEXR picture (by its magic bytes).
    Photo(PhotoFormat),
    /// Binary data without a Radiance header (a headerless `-ff`/`-fd` matrix or ray file).
    Binary,
    /// Lines of `month day hour direct diffuse`: a `.wea` body without its header.
    WeaBody,
    /// Anything else is taken as a scene description.
    Scene,
}

/// Picture formats [`Kind::Photo`] recognises by their first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotoFormat {
    Png,
    Jpeg,
    Exr,
}

impl PhotoFormat {
    fn name(self) -> &'static str {
        match self {
            PhotoFormat::Png => "PNG",
            PhotoFormat::Jpeg => "JPEG",
            PhotoFormat::Exr => "OpenEXR",
        }
    }
}

/// True for bytes no text file holds: NUL, or more than 1 % other control characters
/// (binary floats always have some; a Latin-1 comment has none).
fn is_binary(head: &[u8]) -> bool {
    let control = head
        .iter()
        .filter(|&&b| (b < 0x20 && !b"\t\n\r\x0b\x0c".contains(&b)) || b == 0x7f)
        .count();
    head.contains(&0) || control * 100 > head.len()
}

/// Classify by content.
pub fn detect(head: &[u8]) -> Kind {
    if head.is_empty() {
        return Kind::Empty;
    }
    if head.starts_with(b"#?") {
        return Kind::Radiance;
    }
    if head.starts_with(b"\x89PNG\r\n\x1a\n") {
        return Kind::Photo(PhotoFormat::Png);
    }
    if head.starts_with(&[0xff, 0xd8, 0xff]) {
        return Kind::Photo(PhotoFormat::Jpeg);
    }
    if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return Kind::Photo(PhotoFormat::Exr);
    }
    let text = String::from_utf8_lossy(&head[..head.len().min(4096)]);
    if crate::weather::detect(&text).is_some() {
        return Kind::Weather;
    }
    if is_binary(&head[..head.len().min(4096)]) {
        return Kind::Binary;
    }
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    let words: Vec<&str> = first.split_whitespace().collect();
    let numbers = words.iter().all(|w| w.parse::<f64>().is_ok());
    let int = |w: &str, max: u32| w.parse::<u32>().is_ok_and(|v| (1..=max).contains(&v));
    if words.len() == 6 && numbers {
        Kind::Sensors
    } else if (words.len() == 5 || words.len() == 7)
        && numbers
        && int(words[0], 12)
        && int(words[1], 31)
    {
        Kind::WeaBody
    } else {
        Kind::Scene
    }
}

/// [`detect`], with the file's extension deciding what content that reads as a scene was
/// meant to be (issue #19: a `.pts` with a comment line, an `.epw` without its LOCATION
/// record or a `.mtx` without its header were summarised as scenes of "0 objects"), so the
/// reader of that format reports the problem with its line.
pub fn detect_file(head: &[u8], path: &str) -> Kind {
    let kind = detect(head);
    if kind != Kind::Scene {
        return kind;
    }
    let ext = std::path::Path::new(path)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "pts" => Kind::Sensors,
        "wea" | "epw" => Kind::Weather,
        "mtx" | "smx" | "dmx" | "vmx" | "xml" | "hdr" | "pic" | "unf" | "dat" => Kind::Radiance,
        _ => Kind::Scene,
    }
}

/// Running minimum, mean and maximum per component.
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    pub count: u64,
    pub min: Vec<f64>,
    pub max: Vec<f64>,
    pub sum: Vec<f64>,
}

impl Stats {
    pub fn new(ncomp: usize) -> Self {
        Stats {
            count: 0,
            min: vec![f64::INFINITY; ncomp],
            max: vec![f64::NEG_INFINITY; ncomp],
            sum: vec![0.0; ncomp],
        }
    }

    /// Add values laid out as elements of `ncomp` components.
    pub fn add(&mut self, values: &[f64]) {
        let nc = self.sum.len();
        for e in values.chunks_exact(nc) {
            for (k, &v) in e.iter().enumerate() {
                self.min[k] = self.min[k].min(v);
                self.max[k] = self.max[k].max(v);
                self.sum[k] += v;
            }
            self.count += 1;
        }
    }

    pub fn mean(&self) -> Vec<f64> {
        let n = self.count.max(1) as f64;
        self.sum.iter().map(|s| s / n).collect()
    }
}

/// Dimensions line for `-d`, like `getinfo -d`: the resolution of a picture, or the size
/// variables of a matrix.
pub fn dimensions<R: BufRead>(r: R, name: &str) -> Result<String> {
    let mut r = r;
    let header = Header::read(&mut r, name)?;
    let is_picture = matches!(
        header.format(),
        None | Some("32-bit_rle_rgbe") | Some("32-bit_rle_xyze")
    ) && header.get("NCOLS").is_none();
    if is_picture || header.format() == Some("Radiance_spectra") {
        let res = Resolution::read(&mut r, name, header.nlines + 1)?;
        return Ok(res.to_line().trim_end().to_string());
    }
    let info = crate::matrix::MatrixInfo::from_header(header, name, &ReadOptions::default())?;
    let rows = info
        .nrows
        .map(|n| n.to_string())
        .unwrap_or_else(|| "?".into());
    Ok(format!(
        "NROWS={rows} NCOLS={} NCOMP={} FORMAT={}",
        info.ncols,
        info.channels.ncomp,
        info.format.name()
    ))
}

/// Statistics of a matrix (per component) or a picture (luminance), streamed.
pub fn stats<R: BufRead>(mut r: R, name: &str) -> Result<String> {
    // Peek at the header to decide, then hand the whole stream to the right reader.
    let head = r.fill_buf().map_err(|e| Error::io(name, e))?;
    let text = String::from_utf8_lossy(&head[..head.len().min(8192)]);
    let header_end = text.find("\n\n").map(|i| &text[..i]).unwrap_or(&text);
    let is_matrix = header_end
        .lines()
        .any(|l| l.starts_with("NCOLS=") || l.starts_with("NROWS="))
        || header_end.lines().any(|l| {
            l.starts_with("FORMAT=") && matches!(l[7..].trim(), "ascii" | "float" | "double")
        });
    if is_matrix {
        matrix_stats(r, name)
    } else {
        picture_stats(r, name)
    }
}

/// Luminance statistics of a picture (cd/m2 for radiance pictures, after EXPOSURE), read
/// scanline by scanline; decoding errors (corrupt RLE, early end) surface here.
pub fn picture_stats<R: BufRead>(r: R, name: &str) -> Result<String> {
    let mut p = PictureReader::new(r, name)?;
    let nc = p.ncomp();
    let (w, h) = (p.resolution.scan_len(), p.resolution.num_scans());
    let mut line = vec![0f32; w * nc];
    let exposure = p.header.exposure();
    let mut st = Stats::new(1);
    let splits = p.channels.splits;
    while p.read_scanline(&mut line)? {
        for px in line.chunks_exact(nc) {
            let rgb = if nc == 3 {
                [px[0], px[1], px[2]]
            } else {
                crate::picture::spectral::to_rgb(px, splits)
            };
            let lum = match p.format {
                // XYZE: Y is already luminance (179 applied), notes §3.1.
                crate::picture::PixelFormat::Xyze => rgb[1] as f64,
                _ => crate::radiometry::luminance(rgb.map(f64::from)),
            };
            st.add(&[lum / exposure]);
        }
    }
    Ok(format!(
        "{name}: {w} x {h} pixels, {nc} components ({}); luminance min {:.6e}  mean {:.6e}  max {:.6e} cd/m2\n",
        p.format.name(),
        st.min[0],
        st.mean()[0],
        st.max[0]
    ))
}

/// Per-component statistics of a matrix, streamed row by row.
pub fn matrix_stats<R: BufRead>(r: R, name: &str) -> Result<String> {
    let mut m = MatrixReader::new(r, name, &ReadOptions::default())?;
    let nc = m.ncomp();
    let mut row = vec![0.0; m.row_len()];
    let mut stats = Stats::new(nc);
    let mut rows = 0usize;
    while m.read_row(&mut row)? {
        stats.add(&row);
        rows += 1;
    }
    let mut s = format!(
        "{name}: {rows} rows x {} columns x {nc} components ({})\n",
        m.ncols(),
        m.info().format.name()
    );
    let mean = stats.mean();
    for (k, ((lo, hi), avg)) in stats.min.iter().zip(&stats.max).zip(&mean).enumerate() {
        let _ = writeln!(
            s,
            "  component {k}: min {lo:.6e}  mean {avg:.6e}  max {hi:.6e}"
        );
    }
    Ok(s)
}

/// Object counts by type, surfaces' bounding box, and the types a tracer would refuse.
pub fn describe_scene(scene: &Scene, name: &str) -> String {
    let mut by_type: BTreeMap<&str, usize> = BTreeMap::new();
    for o in &scene.objects {
        *by_type.entry(o.type_name()).or_default() += 1;
    }
    let nsurf = scene.surfaces().count();
    let mut s = format!(
        "{name}: {} objects ({} surfaces, {} modifiers)\n",
        scene.objects.len(),
        nsurf,
        scene.objects.len() - nsurf
    );
    let list: Vec<String> = by_type.iter().map(|(t, n)| format!("{n} {t}")).collect();
    let _ = writeln!(s, "  types: {}", list.join(", "));
    if let Some(b) = scene.bounding_box() {
        let _ = writeln!(
            s,
            "  bounding box: ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4}); size {:.4} x {:.4} x {:.4}",
            b.min[0],
            b.min[1],
            b.min[2],
            b.max[0],
            b.max[1],
            b.max[2],
            b.max[0] - b.min[0],
            b.max[1] - b.min[1],
            b.max[2] - b.min[2]
        );
    }
    s
}

/// Site, period and irradiation totals of a weather file.
pub fn describe_weather(w: &Weather, name: &str) -> String {
    let site = &w.site;
    let mut s = format!(
        "{name}: {} ({}) at {:.3} N {:.3} E, UTC{:+} h, {} m\n",
        site.name,
        site.country,
        site.latitude_deg_n,
        site.longitude_deg_e,
        site.time_zone_hours_e(),
        site.elevation_m
    );
    let (Some(first), Some(last)) = (w.steps.first(), w.steps.last()) else {
        let _ = writeln!(s, "  no time steps");
        return s;
    };
    let _ = writeln!(
        s,
        "  {} time steps from {:02}-{:02} {:.2} h to {:02}-{:02} {:.2} h",
        w.steps.len(),
        first.month,
        first.day,
        first.hour,
        last.month,
        last.day,
        last.hour
    );
    // Totals assume hourly steps (what EPW and typical .wea files hold); values at or above
    // EPW's missing code 9999 are skipped and counted.
    let hourly = w.steps.len() >= 2 && (w.steps[1].hour - w.steps[0].hour - 1.0).abs() < 1e-9;
    let valid = |v: f64| (0.0..9999.0).contains(&v);
    let missing = w
        .steps
        .iter()
        .filter(|st| !valid(st.direct) || !valid(st.diffuse))
        .count();
    let dir: f64 = w
        .steps
        .iter()
        .map(|st| st.direct)
        .filter(|&v| valid(v))
        .sum();
    let dif: f64 = w
        .steps
        .iter()
        .map(|st| st.diffuse)
        .filter(|&v| valid(v))
        .sum();
    let (what, unit, scale) = match w.units {
        WeaUnits::NormalIlluminance => ("illuminance", "klx h", 1e-3),
        WeaUnits::HorizontalIrradiance => {
            ("direct horizontal / diffuse horizontal", "kWh/m2", 1e-3)
        }
        WeaUnits::NormalIrradiance => ("direct normal / diffuse horizontal", "kWh/m2", 1e-3),
    };
    if hourly {
        let _ = writeln!(
            s,
            "  {what}: {:.1} / {:.1} {unit} in total{}",
            dir * scale,
            dif * scale,
            if missing > 0 {
                format!(" ({missing} steps with missing values skipped)")
            } else {
                String::new()
            }
        );
    }
    s
}

/// Sensor count, extent of origins, and how many point up.
pub fn describe_sensors<R: BufRead>(r: R, name: &str) -> Result<String> {
    let mut n = 0usize;
    let mut up = 0usize;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for ray in RayReader::new(r, name, RayFormat::Ascii) {
        let ray = ray?;
        n += 1;
        for k in 0..3 {
            lo[k] = lo[k].min(ray.org[k]);
            hi[k] = hi[k].max(ray.org[k]);
        }
        let len = (ray.dir[0].powi(2) + ray.dir[1].powi(2) + ray.dir[2].powi(2)).sqrt();
        if len > 0.0 && ray.dir[2] / len > 0.999_999 {
            up += 1;
        }
    }
    if n == 0 {
        return Err(Error::parse(
            Location::file(name),
            "no sensor rays: expected lines of 'x y z dx dy dz'",
        ));
    }
    Ok(format!(
        "{name}: {n} sensor rays ({up} facing up), origins from ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4})\n",
        lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
    ))
}

/// What `rinfo` prints for a picture or matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detail {
    /// The header, as getinfo prints it.
    #[default]
    Header,
    /// Dimensions only (getinfo -d).
    Dimensions,
    /// Per-component statistics of a matrix, luminance statistics of a picture.
    Stats,
}

/// Opens `-` as standard input (default buffer), anything else as a file (64 KiB buffer);
/// [`detect`] sees what the first fill of that buffer holds.
fn open_described(path: &str) -> Result<Box<dyn BufRead>> {
    use crate::error::IoContext;
    if path == "-" {
        return Ok(Box::new(std::io::BufReader::new(std::io::stdin().lock())));
    }
    Ok(Box::new(std::io::BufReader::with_capacity(
        1 << 16,
        std::fs::File::open(path).at_path(path)?,
    )))
}

/// A Radiance header as getinfo prints it: the name, then each line indented by a tab.
pub fn header_text(h: &Header, path: &str) -> String {
    let mut s = format!(
        "{path}:\n\t#?{}\n",
        h.magic.as_deref().unwrap_or("RADIANCE")
    );
    for l in &h.lines {
        s.push('\t');
        s.push_str(l);
        s.push('\n');
    }
    s.push('\n');
    s
}

/// The summary of one file (`-` = standard input) by its content: a picture's or matrix's
/// header, dimensions or statistics (`detail`), a weather file's site and period, a sensor
/// file's rays, or a scene (loaded with `load`, which says whether `!commands` run).
pub fn describe(path: &str, detail: Detail, load: &crate::scene::LoadOptions) -> Result<String> {
    use crate::error::IoContext;
    use std::io::Read as _;
    let mut r = open_described(path)?;
    let kind = detect_file(r.fill_buf().at_path(path)?, path);
    let scene_ext = |p: &str| {
        matches!(
            std::path::Path::new(p).extension().and_then(|e| e.to_str()),
            None | Some("rad" | "mat" | "sky" | "obj")
        )
    };
    let not = |what: &str| Err(Error::parse(Location::file(path), what.to_string()));
    Ok(match kind {
        // An empty scene is a scene; any other empty file is a mistake worth a line.
        Kind::Empty if !scene_ext(path) || path == "-" => {
            return not(
                "empty file (0 bytes): no header, data or scene (was it written by a run that failed?)",
            );
        }
        Kind::Radiance if !r.fill_buf().at_path(path)?.starts_with(b"#?") => {
            return not(
                "no Radiance header (expected '#?RADIANCE' on the first line): a headerless \
                 matrix or picture (written with -h?) cannot be described",
            );
        }
        Kind::Radiance
            if !matches!(detail, Detail::Header)
                && crate::scene::is_octree(r.fill_buf().at_path(path)?) =>
        {
            return Err(Error::Usage(format!(
                "{path} is a Radiance octree (oconv output): it has no dimensions or \
                 statistics; rinfo without -d/--stats shows its header"
            )));
        }
        Kind::Radiance => match detail {
            Detail::Dimensions => format!("{path}: {}\n", dimensions(r, path)?),
            Detail::Stats => stats(r, path)?,
            Detail::Header => header_text(&Header::read(&mut r, path)?, path),
        },
        Kind::Weather => {
            let mut bytes = Vec::new();
            r.read_to_end(&mut bytes).at_path(path)?;
            let w = Weather::parse(&crate::weather::decode_text(&bytes), path)?;
            describe_weather(&w, path)
        }
        Kind::Sensors => describe_sensors(r, path)?,
        Kind::Photo(f) => {
            let mut bytes = Vec::new();
            r.read_to_end(&mut bytes).at_path(path)?;
            let p = match f {
                PhotoFormat::Exr => {
                    crate::picture::exr::read_exr_from(std::io::Cursor::new(bytes), path)?
                }
                _ => crate::picture::preview::read_photo_bytes(&bytes, path)?,
            };
            let what = match f {
                PhotoFormat::Exr => "linear values",
                _ => "8-bit display values, not radiance: ruplift reads these",
            };
            format!(
                "{path}: {} picture, {} x {} pixels, {} components ({what})\n",
                f.name(),
                p.width,
                p.height,
                p.ncomp()
            )
        }
        Kind::Binary => {
            return not(
                "binary data without a Radiance header: a headerless float or double matrix \
                 or ray file (written with -h or -ff/-fd) cannot be described; keep its header",
            );
        }
        Kind::WeaBody => {
            return not(
                "lines of 'month day hour direct diffuse' without a header: a .wea file needs \
                 its six header lines (place, latitude, longitude, time_zone, site_elevation, \
                 weather_data_file_units) first",
            );
        }
        // Standard input was read into `r` to detect its kind: parse what `r` holds (loading
        // "-" again found nothing, so `... | rinfo -` said "0 objects").
        Kind::Scene | Kind::Empty if path == "-" => {
            let mut bytes = Vec::new();
            r.read_to_end(&mut bytes).at_path("<stdin>")?;
            let text = String::from_utf8_lossy(&bytes);
            let scene = crate::scene::parse_str(&text, "<stdin>", std::path::Path::new(""), load)?;
            describe_scene(&scene, path)
        }
        Kind::Scene | Kind::Empty => {
            drop(r);
            describe_scene(&crate::scene::load(&[path], load)?, path)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection_by_content() {
        assert_eq!(detect(b"#?RADIANCE\n"), Kind::Radiance);
        assert_eq!(detect(b"place London\nlatitude 51\n"), Kind::Weather);
        assert_eq!(detect(b"\n1 2 0.8 0 0 1\n"), Kind::Sensors);
        assert_eq!(detect(b""), Kind::Empty);
        assert_eq!(detect(b"1 1 0.5 0 0\n"), Kind::WeaBody);
        assert_eq!(
            detect(b"\x89PNG\r\n\x1a\n...."),
            Kind::Photo(PhotoFormat::Png)
        );
        assert_eq!(
            detect(&[0xff, 0xd8, 0xff, 0xe0]),
            Kind::Photo(PhotoFormat::Jpeg)
        );
        assert_eq!(
            detect(&[0x76, 0x2f, 0x31, 0x01, 2]),
            Kind::Photo(PhotoFormat::Exr)
        );
        assert_eq!(detect(&1.5f32.to_ne_bytes().repeat(12)), Kind::Binary);
        assert_eq!(
            detect_file(b"# my sensors\n1 2 3 0 0 1\n", "a.pts"),
            Kind::Sensors
        );
        assert_eq!(detect_file(b"junk\n", "a.epw"), Kind::Weather);
        assert_eq!(detect_file(b"NROWS=3\n", "a.mtx"), Kind::Radiance);
        assert_eq!(
            detect(b"void plastic white 0 0 5 .5 .5 .5 0 0\n"),
            Kind::Scene
        );
    }

    #[test]
    fn stats_per_component() {
        let mut s = Stats::new(3);
        s.add(&[1.0, 2.0, 3.0, 3.0, 0.0, 3.0]);
        assert_eq!(s.count, 2);
        assert_eq!(s.min, vec![1.0, 0.0, 3.0]);
        assert_eq!(s.max, vec![3.0, 2.0, 3.0]);
        assert_eq!(s.mean(), vec![2.0, 1.0, 3.0]);
    }
}
