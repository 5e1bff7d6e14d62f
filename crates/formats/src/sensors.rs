//! Sensor rays: the `x y z dx dy dz` records `rtrace` and `rcontrib` read on their input.
//!
//! Formats (`src/rt/rtrace.c`: `getvec`, `nextray`; man `rtrace.1` option `-f`):
//! - **ascii** (`-fa?`): six numbers per ray, origin then direction, separated by white
//!   space. Radiance reads them word by word (`fgetword` + `isflt`), so line breaks are not
//!   significant to it; we require one ray per line so that errors can name a line, and we
//!   skip blank lines.
//! - **float** / **double** (`-ff?` / `-fd?`): six IEEE-754 values per ray in native byte
//!   order, no header and no separators (24 or 48 bytes a record).
//!
//! Comments: rtrace does **not** accept them. The first word that is not a number ends its
//! input as if the file had ended there (`getvec` returns -1, `nextray` reports EOF), so a
//! `# comment` line silently truncates a sensor file. We report such a word as an error
//! instead of silently dropping the rest.
//!
//! A zero direction `(0, 0, 0)` is rtrace's "flush" request: it prints an empty record
//! (zeros) and flushes its output (`rtrace()`, `bogusray()`). We keep such records as ordinary
//! [`SensorRay`]s with [`SensorRay::is_flush`] true, so a consumer can emit its own empty record and keep
//! output records aligned one-to-one with input rays, as rtrace does. That is right for a ray
//! stream (`rdc` reads one, as rtrace and rcontrib do), but in a *sensor file* read for
//! coefficients or metrics (`rcalib`, `rglod study --pts`, `rmcop --pts`) a zero direction
//! is a typo whose all-zero row would pass as a dark sensor (rcalib showed a -100 % error):
//! [`read_sensor_file`] refuses it with file:line, and refuses a file with no sensors.
//!
//! Also here: [`work_plane_grid`] (a regular grid of upward sensors over a rectangle) and the
//! CSV form with sensor ids (`id,x,y,z,dx,dy,dz` with a header line), [`read_csv`] and
//! [`write_csv`].

use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    bytes::complete::{take_while, take_while1},
    character::complete::{char, space0},
    multi::{many0, separated_list1},
    sequence::delimited,
};
use std::io::{BufRead, Read, Write};

/// One sensor (a ray record): origin and direction (not necessarily normalised; rtrace normalises).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorRay {
    pub org: [f64; 3],
    pub dir: [f64; 3],
}

impl SensorRay {
    pub fn new(org: [f64; 3], dir: [f64; 3]) -> SensorRay {
        SensorRay { org, dir }
    }

    /// A zero direction: rtrace's flush request, answered with an empty record.
    pub fn is_flush(&self) -> bool {
        self.dir == [0.0; 3]
    }

    fn values(&self) -> [f64; 6] {
        let [x, y, z] = self.org;
        let [dx, dy, dz] = self.dir;
        [x, y, z, dx, dy, dz]
    }

    fn from_values(v: [f64; 6]) -> SensorRay {
        SensorRay {
            org: [v[0], v[1], v[2]],
            dir: [v[3], v[4], v[5]],
        }
    }
}

/// Input encoding of a ray stream, the first letter of rtrace's `-f` pair (`-faa`, `-ffa`,
/// `-fda`; note a single letter `-ff` sets input AND output).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RayFormat {
    Ascii,
    Float,
    Double,
}

impl RayFormat {
    /// From rtrace's letter `a`, `f` or `d`.
    pub fn from_letter(c: char) -> Option<RayFormat> {
        match c {
            'a' => Some(RayFormat::Ascii),
            'f' => Some(RayFormat::Float),
            'd' => Some(RayFormat::Double),
            _ => None,
        }
    }

    /// Bytes per binary record (`None` for ascii).
    pub fn record_bytes(self) -> Option<usize> {
        match self {
            RayFormat::Ascii => None,
            RayFormat::Float => Some(24),
            RayFormat::Double => Some(48),
        }
    }
}

/// Longest ascii line we accept: far beyond any real sensor line, it only stops a binary
/// file read as ascii from being buffered whole.
const MAX_LINE: u64 = 1 << 16;

/// Streaming reader: an iterator of rays with file:line (ascii) or record/byte (binary)
/// locations in its errors. After the first error it ends.
pub struct RayReader<R> {
    inner: R,
    file: String,
    format: RayFormat,
    line: usize,
    record: usize,
    done: bool,
    buf: Vec<u8>,
}

impl<R: BufRead> RayReader<R> {
    /// The line of the ray returned last (ascii; 0 before the first).
    pub fn line(&self) -> usize {
        self.line
    }

    pub fn new(inner: R, file: impl Into<String>, format: RayFormat) -> Self {
        RayReader {
            inner,
            file: file.into(),
            format,
            line: 0,
            record: 0,
            done: false,
            buf: Vec::new(),
        }
    }

    fn next_ascii(&mut self) -> Option<Result<SensorRay>> {
        loop {
            self.buf.clear();
            let n = match (&mut self.inner)
                .take(MAX_LINE)
                .read_until(b'\n', &mut self.buf)
            {
                Ok(n) => n,
                Err(e) => return Some(Err(Error::io(&self.file, e))),
            };
            if n == 0 {
                return None;
            }
            self.line += 1;
            let at = Location::line(&self.file, self.line);
            if self.buf.last() != Some(&b'\n') && n as u64 == MAX_LINE {
                return Some(Err(Error::parse(
                    at,
                    format!("line longer than {MAX_LINE} bytes: is this a binary ray file?"),
                )));
            }
            let Ok(text) = std::str::from_utf8(&self.buf) else {
                return Some(Err(Error::parse(
                    at,
                    "expected 6 numbers (x y z dx dy dz), found non-text bytes \
                     (binary input needs the float or double format)",
                )));
            };
            match parse_ascii_line(text) {
                Ok(None) => continue,
                Ok(Some(ray)) => return Some(Ok(ray)),
                Err(msg) => return Some(Err(Error::parse(at, msg))),
            }
        }
    }

    fn next_binary(&mut self, size: usize) -> Option<Result<SensorRay>> {
        let mut rec = [0u8; 48];
        let rec = &mut rec[..size];
        let mut got = 0;
        while got < size {
            match self.inner.read(&mut rec[got..]) {
                Ok(0) => break,
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Some(Err(Error::io(&self.file, e))),
            }
        }
        if got == 0 {
            return None;
        }
        self.record += 1;
        let byte = (self.record - 1) * size;
        let at = Location::file(&self.file);
        if got < size {
            return Some(Err(Error::parse(
                at,
                format!(
                    "record {} at byte {byte} is truncated: expected {size} bytes \
                     (6 values x y z dx dy dz), found {got}",
                    self.record
                ),
            )));
        }
        let mut v = [0.0; 6];
        for (i, x) in v.iter_mut().enumerate() {
            *x = if size == 24 {
                let mut b = [0u8; 4];
                b.copy_from_slice(&rec[4 * i..4 * i + 4]);
                f64::from(f32::from_ne_bytes(b))
            } else {
                let mut b = [0u8; 8];
                b.copy_from_slice(&rec[8 * i..8 * i + 8]);
                f64::from_ne_bytes(b)
            };
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Some(Err(Error::parse(
                at,
                format!(
                    "record {} at byte {byte}: non-finite value in {v:?} (wrong format or byte order?)",
                    self.record
                ),
            )));
        }
        Some(Ok(SensorRay::from_values(v)))
    }
}

impl<R: BufRead> Iterator for RayReader<R> {
    type Item = Result<SensorRay>;

    fn next(&mut self) -> Option<Result<SensorRay>> {
        if self.done {
            return None;
        }
        let item = match self.format.record_bytes() {
            None => self.next_ascii(),
            Some(size) => self.next_binary(size),
        };
        if !matches!(item, Some(Ok(_))) {
            self.done = true;
        }
        item
    }
}

/// White-space separated words of a line (`\r` of CRLF files included as white space).
fn words(line: &str) -> IResult<&str, Vec<&str>> {
    let ws = |c: char| c.is_ascii_whitespace();
    many0(delimited(
        take_while(ws),
        take_while1(move |c: char| !ws(c)),
        take_while(ws),
    ))
    .parse(line)
}

/// A finite number filling the whole word.
fn number(word: &str) -> Option<f64> {
    let r: IResult<&str, f64> =
        nom::combinator::all_consuming(nom::number::complete::double).parse(word);
    match r {
        Ok((_, v)) if v.is_finite() => Some(v),
        _ => None,
    }
}

/// One ascii line: `Ok(None)` for a blank line.
fn parse_ascii_line(line: &str) -> std::result::Result<Option<SensorRay>, String> {
    let (rest, w) = words(line).map_err(|_| "unreadable line".to_string())?;
    if !rest.trim().is_empty() {
        return Err("unreadable line".to_string());
    }
    if w.is_empty() {
        return Ok(None);
    }
    let mut v = [0.0; 6];
    for (i, word) in w.iter().enumerate().take(6) {
        v[i] = number(word).ok_or_else(|| {
            format!(
                "expected a number (x y z dx dy dz), found '{}' (rtrace allows no comments: \
                 it would stop reading here)",
                shorten(word)
            )
        })?;
    }
    if w.len() != 6 {
        return Err(format!(
            "expected 6 numbers (x y z dx dy dz), found {}",
            w.len()
        ));
    }
    Ok(Some(SensorRay::from_values(v)))
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 40 {
        let cut: String = s.chars().take(37).collect();
        format!("{cut}...")
    } else {
        s.to_string()
    }
}

/// The message for a zero sensor direction (one wording for the `.pts` and CSV forms).
const ZERO_DIRECTION: &str = "sensor direction is 0 0 0: give the direction the sensor faces \
     (e.g. 0 0 1 for an upward work-plane sensor); a zero direction is rtrace's flush request \
     and would give an all-zero row";

/// Read a sensor file for coefficients or metrics (ascii `x y z dx dy dz`): unlike a ray
/// stream ([`read_rays`]), a zero direction is an error naming the line (see the module
/// doc), and so is a file without sensors.
pub fn read_sensor_file<R: BufRead>(r: R, file: &str) -> Result<Vec<SensorRay>> {
    let mut reader = RayReader::new(r, file, RayFormat::Ascii);
    let mut rays = Vec::new();
    while let Some(ray) = reader.next() {
        let ray = ray?;
        if ray.is_flush() {
            return Err(Error::parse(
                Location::line(file, reader.line()),
                ZERO_DIRECTION,
            ));
        }
        rays.push(ray);
    }
    if rays.is_empty() {
        return Err(no_sensors(file));
    }
    Ok(rays)
}

/// [`read_sensor_file`] of the file at `path`.
pub fn read_sensor_path(path: &str) -> Result<Vec<SensorRay>> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    read_sensor_file(std::io::BufReader::new(f), path)
}

/// The error for an input that holds no sensors (an empty file or stream).
pub fn no_sensors(file: &str) -> Error {
    Error::Usage(format!(
        "no sensors in {file}: expected lines of 'x y z dx dy dz'"
    ))
}

/// Read every ray of a stream.
pub fn read_rays<R: BufRead>(r: R, file: &str, format: RayFormat) -> Result<Vec<SensorRay>> {
    RayReader::new(r, file, format).collect()
}

/// A number in the shortest text that reads back to the same f64, in a form rtrace can read:
/// its words are at most 31 characters (`fgetword` into a 32-byte buffer), so very large or
/// small magnitudes use exponent notation instead of Rust's long plain decimals.
pub fn format_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Write one ray: ascii `x y z dx dy dz\n` (exact shortest decimals), or 6 native-order
/// floats/doubles. Float output rounds to f32, as rtrace's `-ff` input would anyway.
pub fn write_ray<W: Write + ?Sized>(
    w: &mut W,
    ray: &SensorRay,
    format: RayFormat,
) -> std::io::Result<()> {
    let v = ray.values();
    match format {
        RayFormat::Ascii => {
            let s: Vec<String> = v.iter().map(|&x| format_number(x)).collect();
            writeln!(w, "{}", s.join(" "))
        }
        RayFormat::Float => {
            let mut b = [0u8; 24];
            for (i, x) in v.iter().enumerate() {
                b[4 * i..4 * i + 4].copy_from_slice(&(*x as f32).to_ne_bytes());
            }
            w.write_all(&b)
        }
        RayFormat::Double => {
            let mut b = [0u8; 48];
            for (i, x) in v.iter().enumerate() {
                b[8 * i..8 * i + 8].copy_from_slice(&x.to_ne_bytes());
            }
            w.write_all(&b)
        }
    }
}

/// Write all rays.
pub fn write_rays<W: Write + ?Sized>(
    w: &mut W,
    rays: &[SensorRay],
    format: RayFormat,
) -> std::io::Result<()> {
    rays.iter().try_for_each(|r| write_ray(w, r, format))
}

/// Most points [`work_plane_grid`] makes; a typo in the spacing should not fill memory.
pub const MAX_GRID_POINTS: usize = 10_000_000;

/// A regular grid of upward-facing sensors (`dir = (0, 0, 1)`) over the rectangle
/// `min..max` (x, y) at height `z`.
///
/// Each axis gets `n = floor(length / spacing)` points (at least one) `spacing` apart, and
/// the grid is centred in the rectangle, so when the spacing divides the length the points
/// are the centres of square cells (a 4 m side at 1 m spacing gives 0.5, 1.5, 2.5, 3.5).
/// Order: rows of increasing y, each of increasing x.
pub fn work_plane_grid(
    min: [f64; 2],
    max: [f64; 2],
    z: f64,
    spacing: f64,
) -> Result<Vec<SensorRay>> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(Error::Usage(format!(
            "grid spacing must be a positive number, found {spacing}"
        )));
    }
    let mut axes = [(0usize, 0.0f64); 2];
    for k in 0..2 {
        let len = max[k] - min[k];
        if !(len.is_finite() && len > 0.0 && z.is_finite()) {
            return Err(Error::Usage(format!(
                "grid rectangle needs min < max on every axis, found {:?} to {:?} at z {z}",
                min, max
            )));
        }
        // The epsilon keeps 4.0/0.2 (= 19.999999999999996) from losing a point.
        let n = ((len / spacing) * (1.0 + 1e-9)).floor().max(1.0);
        if n > MAX_GRID_POINTS as f64 {
            return Err(Error::Usage(format!(
                "grid of spacing {spacing} over {len} would need {n} points per row"
            )));
        }
        let n = n as usize;
        let first = min[k] + (len - (n - 1) as f64 * spacing) / 2.0;
        axes[k] = (n, first);
    }
    let (nx, x0) = axes[0];
    let (ny, y0) = axes[1];
    if nx.saturating_mul(ny) > MAX_GRID_POINTS {
        return Err(Error::Usage(format!(
            "grid of {nx} x {ny} points exceeds {MAX_GRID_POINTS}"
        )));
    }
    let mut rays = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            rays.push(SensorRay::new(
                [x0 + i as f64 * spacing, y0 + j as f64 * spacing, z],
                [0.0, 0.0, 1.0],
            ));
        }
    }
    Ok(rays)
}

/// A named sensor (CSV form).
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    pub id: String,
    pub ray: SensorRay,
}

/// The CSV header line, compared without regard to case or blanks around names.
pub const CSV_HEADER: [&str; 7] = ["id", "x", "y", "z", "dx", "dy", "dz"];

fn csv_fields(line: &str) -> IResult<&str, Vec<&str>> {
    separated_list1(
        char(','),
        delimited(space0, take_while(|c: char| c != ','), space0),
    )
    .parse(line)
}

/// Read `id,x,y,z,dx,dy,dz` sensors: a header line, then one sensor per line; blank lines
/// skipped; ids must be non-empty and unique (no quoting: an id cannot contain a comma).
pub fn read_csv(text: &str, file: &str) -> Result<Vec<Sensor>> {
    let mut sensors = Vec::new();
    let mut seen = std::collections::HashMap::new();
    let mut header_seen = false;
    for (i, raw) in text.split_inclusive('\n').enumerate() {
        let lno = i + 1;
        let at = || Location::line(file, lno);
        let line = raw.trim_end_matches(['\n', '\r']);
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = csv_fields(line)
            .map(|(_, f)| f.into_iter().map(str::trim).collect())
            .unwrap_or_default();
        if !header_seen {
            let ok = fields.len() == 7
                && fields
                    .iter()
                    .zip(CSV_HEADER)
                    .all(|(f, h)| f.eq_ignore_ascii_case(h));
            if !ok {
                return Err(Error::parse(
                    at(),
                    format!(
                        "expected the header 'id,x,y,z,dx,dy,dz', found '{}'",
                        shorten(line)
                    ),
                ));
            }
            header_seen = true;
            continue;
        }
        if fields.len() != 7 {
            return Err(Error::parse(
                at(),
                format!(
                    "expected 7 fields (id,x,y,z,dx,dy,dz), found {}",
                    fields.len()
                ),
            ));
        }
        let id = fields[0];
        if id.is_empty() {
            return Err(Error::parse(at(), "empty sensor id"));
        }
        let mut v = [0.0; 6];
        for (k, x) in v.iter_mut().enumerate() {
            *x = number(fields[k + 1]).ok_or_else(|| {
                Error::parse(
                    at(),
                    format!(
                        "expected a number for {}, found '{}'",
                        CSV_HEADER[k + 1],
                        shorten(fields[k + 1])
                    ),
                )
            })?;
        }
        if v[3..] == [0.0; 3] {
            return Err(Error::parse(at(), ZERO_DIRECTION));
        }
        if let Some(first) = seen.insert(id.to_string(), lno) {
            return Err(Error::parse(
                at(),
                format!(
                    "duplicate sensor id '{}' (first on line {first})",
                    shorten(id)
                ),
            ));
        }
        sensors.push(Sensor {
            id: id.to_string(),
            ray: SensorRay::from_values(v),
        });
    }
    if !header_seen {
        return Err(Error::parse(
            Location::line(file, 1),
            "expected the header 'id,x,y,z,dx,dy,dz', found an empty file",
        ));
    }
    if sensors.is_empty() {
        return Err(no_sensors(file));
    }
    Ok(sensors)
}

/// Write sensors as CSV with the header line. Ids with a comma, a line break or surrounding
/// blanks could not be read back and are refused.
pub fn write_csv<W: Write + ?Sized>(w: &mut W, sensors: &[Sensor]) -> Result<()> {
    let io = |e| Error::io("<csv output>", e);
    writeln!(w, "{}", CSV_HEADER.join(",")).map_err(io)?;
    for s in sensors {
        if s.id.is_empty() || s.id.contains([',', '\n', '\r']) || s.id.trim() != s.id {
            return Err(Error::Usage(format!(
                "sensor id '{}' cannot be written to CSV (empty, comma, line break or blanks)",
                s.id
            )));
        }
        let v: Vec<String> = s.ray.values().iter().map(|&x| format_number(x)).collect();
        writeln!(w, "{},{}", s.id, v.join(",")).map_err(io)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_lines() {
        let r = parse_ascii_line("1 2 3\t0 0 1\r\n").unwrap().unwrap();
        assert_eq!(r, SensorRay::new([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]));
        assert_eq!(parse_ascii_line("  \r\n").unwrap(), None);
        assert_eq!(
            parse_ascii_line("1 2 3 0 0").unwrap_err(),
            "expected 6 numbers (x y z dx dy dz), found 5"
        );
        assert!(
            parse_ascii_line("# sensors")
                .unwrap_err()
                .contains("found '#'")
        );
    }

    #[test]
    fn sensor_files_refuse_zero_directions_and_emptiness() {
        let e = read_sensor_file(&b"1 1 1 0 0 1\n\n2 2 2 0 0 0\n"[..], "s.pts").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("s.pts:3: sensor direction is 0 0 0"),
            "{e}"
        );
        let e = read_sensor_file(&b"\n\n"[..], "s.pts").unwrap_err();
        assert_eq!(
            e.to_string(),
            "no sensors in s.pts: expected lines of 'x y z dx dy dz'"
        );
        // A ray stream keeps rtrace's flush records.
        let rays = read_rays(&b"1 1 1 0 0 0\n"[..], "-", RayFormat::Ascii).unwrap();
        assert!(rays[0].is_flush());
        let e = read_csv("id,x,y,z,dx,dy,dz\nA,1,1,1,0,0,0\n", "s.csv").unwrap_err();
        assert!(
            e.to_string().starts_with("s.csv:2: sensor direction"),
            "{e}"
        );
        let e = read_csv("id,x,y,z,dx,dy,dz\n", "s.csv").unwrap_err();
        assert!(e.to_string().starts_with("no sensors in s.csv"), "{e}");
    }

    #[test]
    fn numbers_stay_short_enough_for_rtrace() {
        for v in [
            1e-300,
            -1.2345678901234567e300,
            0.1,
            -0.0,
            123456.789,
            1e-5,
            9.99e15,
        ] {
            let s = format_number(v);
            assert!(s.len() <= 31, "{s}");
            assert_eq!(s.parse::<f64>().unwrap(), v);
        }
    }

    #[test]
    fn grid_is_centred() {
        let g = work_plane_grid([0.0, 0.0], [4.0, 2.0], 0.8, 1.0).unwrap();
        assert_eq!(g.len(), 8);
        assert_eq!(g[0].org, [0.5, 0.5, 0.8]);
        assert_eq!(g[7].org, [3.5, 1.5, 0.8]);
        let g = work_plane_grid([0.0, 0.0], [4.0, 4.0], 0.0, 0.2).unwrap();
        assert_eq!(g.len(), 400);
        assert!(work_plane_grid([0.0, 0.0], [1.0, 1.0], 0.0, 0.0).is_err());
        assert!(work_plane_grid([0.0, 0.0], [1.0, 1.0], 0.0, 1e-9).is_err());
        assert!(work_plane_grid([1.0, 0.0], [1.0, 1.0], 0.0, 0.5).is_err());
    }
}
