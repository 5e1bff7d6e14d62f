//! `rspecsky`: Perez all-weather sky matrices from a weather file (the `gendaymtx`
//! counterpart), physically based spectral matrices (`--model atmosphere`, the
//! `gensdaymtx` counterpart) and point-in-time skies as scene text (the `gendaylit` and
//! `genssky` counterparts).
//! The models are in `rdaylight::sky::{matrix, pointsky}`; this file parses options, reads
//! the weather, writes the output and reports.

use clap::{CommandFactory, FromArgMatches, Parser};
use rdaylight::Error;
use rdaylight::formats::header::Header;
use rdaylight::formats::matrix::writer::{DOUBLE_DIGITS, FLOAT_DIGITS};
use rdaylight::formats::matrix::{DataFormat, MatrixWriter, WriteOptions};
use rdaylight::formats::weather::Weather;
use rdaylight::radiometry::Channels;
use rdaylight::sky::gendaylit::{GendaylitInput, GendaylitOptions, GendaylitOutput, GendaylitSky};
use rdaylight::sky::matrix::{
    Colours, MatrixOptions, average_column, latlong, radiance_site, sky_matrix, time_steps,
};
use rdaylight::sky::pointsky::{
    PointSkyColours, point_sky_text, record_input, split_ground_reflectance,
};
use rdaylight::sky::spectral::spectral_sky_matrix;
use rdaylight::sky::{PerezOptions, SkyPatches, solar};
use std::io::Write;

const EXAMPLES: &str = "\
Examples:
  Annual sky matrix at MF 4 (like gendaymtx -m 4 -of), then illuminance with a DC matrix:
    rspecsky -m 4 -of london.epw > sky.smx
    rmtx dc.mtx sky.smx -c 47.4 119.9 11.6 -fa > ill.txt
  Sun-only and sky-only matrices for a 5-phase calculation:
    rspecsky -5 0.533 -d -m 6 -of site.wea > suns.smx
    rspecsky -s -m 1 -of site.wea > skies.smx
  An 18-band spectral sky matrix (rdc -cs 18 coefficients multiply it with rmtx):
    rspecsky -cs 18 -m 1 -of london.epw > sky18.smx
  A gendaylit-style sky for 2 March 12:30, from the weather file or given irradiances:
    rspecsky --at \"3 2 12.5\" london.epw > sky.rad
    rspecsky --at \"3 2 12.5\" -W 838 79 -a 51.15 -o 0.18 -m 0 > sky.rad
  A physically based 20-band sky matrix as Radiance 6's gensdaymtx (tables cached):
    rspecsky --model atmosphere -u -m 1 -of london.epw > sky20.smx
  A physically based spectral sky and sun as Radiance 6's genssky (same options):
    rspecsky genssky 3 2 15.25 -a 42 -o 108 -m 110 -c 0.5 > sky.rad
    oconv sky.rad room.rad > room.oct";

/// Perez all-weather sky matrices (gendaymtx) and point-in-time skies (gendaylit).
///
/// Matrix mode: `rspecsky [options] weather.wea|weather.epw > sky.smx`. Rows are the ground
/// (row 0) and the Tregenza/Reinhart patches in gendaymtx's order, columns the time steps,
/// NCOMP=3 radiances (W/sr/m2). The weather file is recognised by content (.wea or EPW);
/// with an EPW, the site comes from its LOCATION line and the dew point is the 3-hour
/// running mean gendaymtx uses. -d, -s, -g and -c apply in command-line order, as in
/// gendaymtx (-d then -g keeps the given ground).
///
/// Point-in-time mode: `rspecsky --at "month day hour" [weather | -W dni dhi -a lat -o lon
/// -m meridian] > sky.rad` writes gendaylit's description (sun, perezlum.cal sky) plus the
/// sky and ground glow sources, ready for oconv/rtrace. Here -m, -o and -a are gendaylit's
/// meridian, longitude and latitude (degrees, west positive).
#[derive(Parser, Debug)]
#[command(name = "rspecsky", disable_help_flag = true, after_help = EXAMPLES)]
struct Cli {
    /// Reinhart multiplication factor MF (gendaymtx -m; default 1 = Tregenza's 145 patches
    /// + ground). With --at: standard meridian in degrees west (gendaylit -m).
    #[arg(short = 'm', value_name = "MF", allow_negative_numbers = true)]
    m: Option<String>,

    /// Output unit (gendaymtx/gendaylit -O): 0 visible radiance (default), 1 solar radiance.
    #[arg(short = 'O', value_name = "0|1")]
    output: Option<u8>,

    /// Sun only: zero sky and ground (gendaymtx -d).
    #[arg(short = 'd')]
    sun_only: bool,

    /// Sky only: no sun (gendaymtx -s; gendaylit -s).
    #[arg(short = 's')]
    sky_only: bool,

    /// Five-phase sun: each sun in one patch, with the solid angle of a disc of this
    /// diameter in degrees (gendaymtx -5, usually 0.533).
    #[arg(short = '5', value_name = "DEG")]
    five: Option<f64>,

    /// Ground reflectance r g b (gendaymtx -g; default 0.2 0.2 0.2; gendaylit -g takes the
    /// mean, the colour goes to the ground glow).
    #[arg(short = 'g', num_args = 3, value_names = ["R", "G", "B"])]
    ground: Option<Vec<f64>>,

    /// Sky colour r g b (gendaymtx -c; default .960 1.004 1.118; with --at the sky glow
    /// colour, default 1 1 1).
    #[arg(short = 'c', num_args = 3, value_names = ["R", "G", "B"])]
    colour: Option<Vec<f64>>,

    /// Rotate the sky counter-clockwise about the zenith by DEG degrees (gendaymtx -r).
    #[arg(short = 'r', value_name = "DEG", allow_negative_numbers = true)]
    rotation: Option<f64>,

    /// Output format: -oa ascii (default, full precision, not gendaymtx's 3 digits), -of
    /// float, -od double (gendaymtx -of/-od). With --at: longitude in degrees west
    /// (gendaylit -o).
    #[arg(short = 'o', value_name = "a|f|d", allow_negative_numbers = true)]
    o: Option<String>,

    /// Write no header (gendaymtx -h).
    #[arg(short = 'h')]
    no_header: bool,

    /// Leave out time steps with the sun below the horizon (gendaymtx -u).
    #[arg(short = 'u')]
    skip_night: bool,

    /// One column, the average of all (kept) time steps, with NAVERAGED= (gendaymtx -A).
    #[arg(short = 'A')]
    average: bool,

    /// Sunrise/sunset interval correction for data averaged over MIN minutes
    /// (gendaymtx -i).
    #[arg(short = 'i', value_name = "MIN")]
    interval: Option<f64>,

    /// Point-in-time sky for "month day hour" (local standard time, as gendaylit's
    /// `month day hour`; with a weather file, a record's own hour, e.g. 12.5). The sky is
    /// gendaylit's model with its defaults (dew point 10.97 C, i.e. 2 cm precipitable
    /// water, also for EPW records); -s drops the sun, -d blackens sky and ground glows.
    #[arg(long = "at", value_name = "\"M D H\"")]
    at: Option<String>,

    /// With --at: direct normal and diffuse horizontal irradiance, W/m2 (gendaylit -W).
    #[arg(short = 'W', num_args = 2, value_names = ["DNI", "DHI"])]
    irradiance: Option<Vec<f64>>,

    /// With --at -W: latitude in degrees north (gendaylit -a).
    #[arg(short = 'a', value_name = "LAT", allow_negative_numbers = true)]
    latitude: Option<f64>,

    /// Spectral matrix with N bands (Radiance's -cs N; also written -cs N): the same Perez
    /// sky with a CIE daylight spectrum per part and time step, NCOMP=N and
    /// WAVELENGTH_SPLITS= in the header, photopically equal to the RGB matrix
    /// (rdaylight::sky::spectral documents the spectra).
    #[arg(long = "cs", value_name = "N")]
    cs: Option<usize>,

    /// Wavelength range of the -cs bands in nm (Radiance's -cw; default 380 780).
    #[arg(long = "cw", num_args = 2, value_names = ["MIN", "MAX"])]
    cw: Option<Vec<f64>>,

    /// Sky model of the matrix: perez (default; gendaymtx's Perez sky, with -cs a CIE
    /// daylight spectrum per part) or atmosphere (gensdaymtx's physically based spectral
    /// sky: precomputed clear-sky scattering blended with an overcast sky by cloud cover and
    /// scaled to the measured light; 20 bands 380-780 nm unless -cs/-cw; see
    /// rdaylight::sky::atmosphere_matrix). With atmosphere, -g takes the mean of its three
    /// values (one reflectance), -c, -5, -O 1 and -i are refused.
    #[arg(long = "model", value_name = "perez|atmosphere")]
    model: Option<String>,

    /// With --model atmosphere: one aerosol optical depth for every record (default: the
    /// weather file's AOD column, else 0.115, as gensdaymtx).
    #[arg(long = "aod", value_name = "AOD", allow_negative_numbers = true)]
    aod: Option<f64>,

    /// With --model atmosphere: folder of the cached atmosphere tables (gensdaymtx -p;
    /// default $XDG_CACHE_HOME/rdaylight or ~/.cache/rdaylight).
    #[arg(short = 'p', value_name = "DIR")]
    table_dir: Option<String>,

    /// With --model atmosphere: aerosol profile file (default mie_ca.dat on RAYPATH, else
    /// the documented fallback profile).
    #[arg(short = 'l', value_name = "FILE")]
    mie: Option<String>,

    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    help: Option<bool>,

    /// Weather file (.wea or .epw, recognised by content).
    #[arg(value_name = "WEATHER")]
    weather: Option<String>,
}

fn main() {
    rdaylight::cli::run("rspecsky", real_main)
}

/// Apply -d, -s, -g, -c in command-line order, as gendaymtx's option loop does.
fn colours(m: &clap::ArgMatches, cli: &Cli, mut c: Colours) -> Colours {
    let mut events: Vec<(usize, &str)> = Vec::new();
    for id in ["sun_only", "sky_only", "ground", "colour"] {
        // Flags have default values (with indices): only count what the user typed.
        if m.value_source(id) != Some(clap::parser::ValueSource::CommandLine) {
            continue;
        }
        if let Some(ix) = m.indices_of(id) {
            if let Some(first) = ix.into_iter().next() {
                events.push((first, id));
            }
        }
    }
    events.sort();
    for (_, id) in events {
        match id {
            "sun_only" => {
                c.sky = vec![0.0; 3];
                c.ground = vec![0.0; 3];
            }
            "sky_only" => c.sun = vec![0.0; 3],
            "ground" => c.ground = cli.ground.clone().unwrap_or_default(),
            _ => c.sky = cli.colour.clone().unwrap_or_default(),
        }
    }
    c
}

fn real_main() -> Result<(), Error> {
    if std::env::args().nth(1).as_deref() == Some("genssky") {
        return genssky_mode();
    }
    // Radiance spells the spectral options -cs/-cw; clap's short -c is the sky colour.
    let args = std::env::args().map(|a| match a.as_str() {
        "-cs" => "--cs".to_string(),
        "-cw" => "--cw".to_string(),
        _ => a,
    });
    let m = Cli::command().get_matches_from(args);
    let cli = Cli::from_arg_matches(&m).unwrap_or_else(|e| e.exit());
    if let Some(out) = cli.output {
        if out > 1 {
            return Err(Error::Usage(format!(
                "-O{out}: expected -O0 (visible) or -O1 (solar)"
            )));
        }
    }
    if cli.at.is_some() {
        return point_sky(&m, &cli);
    }
    for (set, what) in [
        (cli.irradiance.is_some(), "-W"),
        (cli.latitude.is_some(), "-a"),
    ] {
        if set {
            return Err(Error::Usage(format!("{what} is only used with --at")));
        }
    }
    let mf = match cli.m.as_deref() {
        None => 1,
        Some(s) => match s.parse::<usize>() {
            Ok(n) if (1..=100).contains(&n) => n,
            _ => {
                return Err(Error::Usage(format!(
                    "-m {s}: expected a multiplication factor from 1 to 100"
                )));
            }
        },
    };
    let format = match cli.o.as_deref() {
        None | Some("a") => DataFormat::Ascii,
        Some("f") => DataFormat::Float,
        Some("d") => DataFormat::Double,
        Some(o) => return Err(Error::Usage(format!("-o{o}: expected -oa, -of or -od"))),
    };
    if let Some(d) = cli.five {
        if !(d > 0.0 && d < 180.0) {
            return Err(Error::Usage(format!(
                "-5 {d}: expected a sun diameter in degrees (e.g. 0.533)"
            )));
        }
    }
    let Some(path) = cli.weather.as_deref() else {
        return Err(Error::Usage(
            "expected a weather file (.wea or .epw); see --help".into(),
        ));
    };
    let weather = Weather::read_path(path)?;
    match cli.model.as_deref() {
        None | Some("perez") => {}
        Some("atmosphere") => {
            return atmosphere_mode(&cli, &weather, path, mf, format);
        }
        Some(o) => {
            return Err(Error::Usage(format!(
                "--model {o}: expected perez or atmosphere"
            )));
        }
    }
    for (set, what) in [
        (cli.aod.is_some(), "--aod"),
        (cli.table_dir.is_some(), "-p"),
        (cli.mie.is_some(), "-l"),
    ] {
        if set {
            return Err(Error::Usage(format!(
                "{what} is only used with --model atmosphere"
            )));
        }
    }
    let site = radiance_site(&weather);
    let steps = time_steps(&weather);
    let opts = MatrixOptions {
        perez: PerezOptions {
            rotation_deg: cli.rotation.unwrap_or(0.0),
            five_phase_sun_deg: cli.five,
            solar_radiance: cli.output == Some(1),
            interval_minutes: cli.interval.unwrap_or(0.0),
        },
        colours: colours(&m, &cli, Colours::gendaymtx()),
        skip_night: cli.skip_night,
    };
    let patches = SkyPatches::new(mf);
    let show = rdaylight::io::show_progress();
    let progress = move |done: usize, total: usize| {
        if show {
            eprint!("\rrspecsky: {done}/{total} time steps");
            if done == total {
                eprintln!();
            }
        }
    };

    let spectral = match (cli.cs, &cli.cw) {
        (None, None) => None,
        (n, cw) => {
            let (lo, hi) = match cw.as_deref() {
                Some([a, b]) => (*a, *b),
                _ => (380.0, 780.0),
            };
            Some(Channels::spectral(n.unwrap_or(18), lo, hi)?)
        }
    };
    let mut header = Header::new();
    header.push_command(std::env::args());
    header.set("LATLONG", format!(" {}", latlong(&weather)));
    let mut wopts = WriteOptions::new(format);
    wopts.header = !cli.no_header;
    wopts.seekable = rdaylight::io::stdout_is_file();
    wopts.ascii_digits = if format == DataFormat::Double {
        DOUBLE_DIGITS
    } else {
        FLOAT_DIGITS
    };
    let out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    if let Some(ch) = spectral {
        let mtx = spectral_sky_matrix(&patches, &steps, &site, &opts, &ch, &progress);
        let ncols = if cli.average { 1 } else { mtx.ncols() };
        if cli.average {
            header.set("NAVERAGED", mtx.ncols());
        }
        let mut w =
            MatrixWriter::new(out, "<stdout>", header, Some(mtx.nrows()), ncols, ch, wopts)?;
        let mut row = Vec::new();
        for p in 0..mtx.nrows() {
            mtx.row(p, &mut row);
            if cli.average {
                row = average_columns(&row, ch.ncomp, mtx.ncols());
            }
            w.write_row(&row)?;
        }
        w.finish()?.flush().map_err(|e| Error::io("<stdout>", e))?;
    } else if cli.average {
        let (col, n) = average_column(&patches, &steps, &site, &opts, &progress);
        header.set("NAVERAGED", n);
        let mut w = MatrixWriter::new(
            out,
            "<stdout>",
            header,
            Some(patches.len()),
            1,
            Channels::rgb(),
            wopts,
        )?;
        for row in col.chunks_exact(3) {
            w.write_row(row)?;
        }
        w.finish()?.flush().map_err(|e| Error::io("<stdout>", e))?;
    } else {
        let mtx = sky_matrix(&patches, &steps, &site, &opts, &progress);
        let mut w = MatrixWriter::new(
            out,
            "<stdout>",
            header,
            Some(mtx.nrows()),
            mtx.ncols(),
            Channels::rgb(),
            wopts,
        )?;
        let mut row = Vec::new();
        for p in 0..mtx.nrows() {
            mtx.row(p, &mut row);
            w.write_row(&row)?;
        }
        w.finish()?.flush().map_err(|e| Error::io("<stdout>", e))?;
    }
    Ok(())
}

/// The mean over `ncols` columns of a row of `ncomp`-channel values (gendaymtx -A).
fn average_columns(row: &[f64], ncomp: usize, ncols: usize) -> Vec<f64> {
    let mut out = vec![0.0; ncomp];
    for c in row.chunks_exact(ncomp) {
        for (o, v) in out.iter_mut().zip(c) {
            *o += v;
        }
    }
    out.iter().map(|s| s / ncols.max(1) as f64).collect()
}

/// `--at`: one gendaylit sky as scene text.
fn point_sky(m: &clap::ArgMatches, cli: &Cli) -> Result<(), Error> {
    let at = cli.at.as_deref().unwrap_or_default();
    let v: Vec<f64> = at
        .split_whitespace()
        .map(|w| w.parse::<f64>())
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    let (month, day, hour) = match v[..] {
        [mo, d, h] if mo.fract() == 0.0 && d.fract() == 0.0 => (mo, d, h),
        _ => {
            return Err(Error::Usage(format!(
                "--at \"{at}\": expected \"month day hour\" (e.g. \"3 2 12.5\")"
            )));
        }
    };
    if !(1.0..=12.0).contains(&month)
        || !(1.0..=31.0).contains(&day)
        || !(0.0..=24.0).contains(&hour)
    {
        return Err(Error::Usage(format!(
            "--at \"{at}\": month 1..12, day 1..31 and hour 0..24 expected"
        )));
    }
    let (month, day) = (month as u32, day as u32);
    for (set, what) in [
        (cli.skip_night, "-u"),
        (cli.average, "-A"),
        (cli.five.is_some(), "-5"),
        (cli.interval.is_some(), "-i"),
        (cli.rotation.is_some(), "-r"),
        (cli.no_header, "-h"),
        (cli.cs.is_some() || cli.cw.is_some(), "-cs/-cw"),
    ] {
        if set {
            return Err(Error::Usage(format!("{what} is not used with --at")));
        }
    }
    let num = |s: &Option<String>, what: &str| -> Result<Option<f64>, Error> {
        s.as_deref()
            .map(|t| {
                t.parse::<f64>()
                    .map_err(|_| Error::Usage(format!("{what} {t}: expected degrees")))
            })
            .transpose()
    };
    let (site, input) = match (&cli.weather, &cli.irradiance) {
        (Some(_), Some(_)) => {
            return Err(Error::Usage(
                "--at takes a weather file or -W, not both".into(),
            ));
        }
        (None, None) => {
            return Err(Error::Usage(
                "--at needs a weather file or -W dni dhi with -a, -o, -m".into(),
            ));
        }
        (Some(path), None) => {
            if cli.latitude.is_some() || cli.o.is_some() || cli.m.is_some() {
                return Err(Error::Usage(
                    "-a, -o and -m are not used with a weather file: its site applies".into(),
                ));
            }
            let w = Weather::read_path(path)?;
            let Some(input) = record_input(&w, month, day, hour) else {
                return Err(Error::Usage(format!(
                    "{path}: no record at month {month} day {day} hour {hour}"
                )));
            };
            (radiance_site(&w), input)
        }
        (None, Some(wv)) => {
            let (Some(lat), Some(lon), Some(mer)) =
                (cli.latitude, num(&cli.o, "-o")?, num(&cli.m, "-m")?)
            else {
                return Err(Error::Usage("-W needs -a lat -o lon -m meridian".into()));
            };
            let site = solar::Site {
                latitude: lat,
                longitude_west: lon,
                meridian_west: mer,
            };
            let (direct, diffuse) = (wv[0], wv[1]);
            (
                site,
                GendaylitInput::DirectNormalIrradiance { direct, diffuse },
            )
        }
    };
    let c = colours(
        m,
        cli,
        Colours {
            sky: vec![1.0; 3],
            ground: vec![0.2; 3],
            sun: vec![1.0; 3],
        },
    );
    let (grey, ground_colour) = split_ground_reflectance([c.ground[0], c.ground[1], c.ground[2]]);
    let mut o = GendaylitOptions::new(input);
    o.ground_reflectance = grey;
    o.sun = c.sun[0] != 0.0;
    if cli.output == Some(1) {
        o.output = GendaylitOutput::Solar;
    }
    let (pos, sky) = GendaylitSky::for_date(&site, month, day, hour, false, None, &o);
    let mut words: Vec<String> = std::env::args().collect();
    if let Some(w) = words.first_mut() {
        *w = "rspecsky".into();
    }
    let comments = vec![words.join(" ")];
    let text = point_sky_text(
        &comments,
        &pos,
        &sky,
        &PointSkyColours {
            sky: [c.sky[0], c.sky[1], c.sky[2]],
            ground: ground_colour,
        },
    );
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .map_err(|e| Error::io("<stdout>", e))
}

/// `rspecsky genssky month day hour [options]`: Radiance 6 genssky's point-in-time
/// spectral sky (Bruneton's precomputed atmosphere, rdaylight::sky::genssky).
#[derive(Parser, Debug)]
#[command(name = "rspecsky genssky", disable_help_flag = true)]
struct GensskyCli {
    /// Month (1-12).
    month: String,
    /// Day of the month.
    day: String,
    /// Local standard time in hours (15.25 or 15:15), +H for solar time, or with a zone
    /// name (10PST).
    hour: String,
    /// Latitude, degrees north.
    #[arg(short = 'a', allow_negative_numbers = true)]
    latitude: Option<f64>,
    /// Longitude, degrees west.
    #[arg(short = 'o', allow_negative_numbers = true)]
    longitude: Option<f64>,
    /// Standard meridian, degrees west (UTC-8 = 120).
    #[arg(short = 'm', allow_negative_numbers = true)]
    meridian: Option<f64>,
    /// Year: use the Michalsky solar position.
    #[arg(short = 'y')]
    year: Option<i32>,
    /// Broadband aerosol optical depth (default 0.115).
    #[arg(short = 'd', default_value_t = rdaylight::sky::atmosphere::AOD_CONTINENTAL)]
    aod: f64,
    /// Cloud cover, 0 clear to 1 overcast (default 0).
    #[arg(short = 'c', default_value_t = 0.0)]
    cloud: f64,
    /// Ground reflectance (default 0.2).
    #[arg(short = 'g', default_value_t = 0.2)]
    ground: f64,
    /// Aerosol profile (Radiance data file; default mie_ca.dat on RAYPATH, else an
    /// exponential profile, named in the output header).
    #[arg(short = 'l')]
    mie: Option<String>,
    /// Folder for the sky picture and atmos_data/ (default: picture in the current
    /// folder, tables in the user cache folder).
    #[arg(short = 'p')]
    dir: Option<String>,
    /// Sky picture width (height is half; default 64).
    #[arg(short = 'r', default_value_t = 64)]
    res: usize,
    /// Sky picture name prefix (default "out": out_sky.hsr).
    #[arg(short = 'f', default_value = "out")]
    prefix: String,
    /// Direct normal and diffuse horizontal illuminance, lux.
    #[arg(short = 'L', num_args = 2, value_names = ["DIRNORM", "DIFHOR"])]
    illuminance: Option<Vec<f64>>,
    /// Threads for the precomputation (results do not depend on it).
    #[arg(short = 'n', default_value_t = 0)]
    threads: usize,
    /// Highest scattering order (default 4).
    #[arg(short = 'i', default_value_t = 4)]
    order: usize,
    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    help: Option<bool>,
}

/// `--model atmosphere`: the gensdaymtx counterpart.
fn atmosphere_mode(
    cli: &Cli,
    weather: &Weather,
    path: &str,
    mf: usize,
    format: DataFormat,
) -> Result<(), Error> {
    use rdaylight::formats::weather::epw::Epw;
    use rdaylight::sky::atmosphere::cache::CacheStatus;
    use rdaylight::sky::atmosphere_matrix::{
        AtmosphereMatrixOptions, atmosphere_matrix, atmosphere_steps, native_channels,
    };
    for (set, what) in [
        (cli.colour.is_some(), "-c (the model gives the sky colour)"),
        (cli.five.is_some(), "-5"),
        (cli.output == Some(1), "-O 1"),
        (cli.interval.is_some(), "-i"),
    ] {
        if set {
            return Err(Error::Usage(format!(
                "{what} is not supported with --model atmosphere"
            )));
        }
    }
    if let Some(a) = cli.aod {
        if !(0.0..10.0).contains(&a) {
            return Err(Error::Usage(format!(
                "--aod {a}: aerosol optical depth must be 0 to 10"
            )));
        }
    }
    let opts = AtmosphereMatrixOptions {
        ground_reflectance: cli
            .ground
            .as_ref()
            .map_or(0.2, |g| g.iter().sum::<f64>() / g.len().max(1) as f64),
        aod: cli.aod,
        rotation_deg: cli.rotation.unwrap_or(0.0),
        with_sun: !cli.sky_only,
        with_sky: !cli.sun_only,
        skip_night: cli.skip_night,
    };
    let ch = match (cli.cs, &cli.cw) {
        (None, None) => native_channels(),
        (n, cw) => {
            let (lo, hi) = match cw.as_deref() {
                Some([a, b]) => (*a, *b),
                _ => (380.0, 780.0),
            };
            Channels::spectral(n.unwrap_or(20), lo, hi)?
        }
    };
    // gensdaymtx reads the EPW's illuminance fields: parse it as EPW too when it is one.
    let epw = if weather.epw_text.is_some() {
        Some(Epw::read_path(path)?)
    } else {
        None
    };
    let patches = SkyPatches::new(mf);
    let steps = atmosphere_steps(weather, epw.as_ref(), &patches, &opts);
    let mie = rdaylight::sky::genssky::load_mie(cli.mie.as_deref().map(std::path::Path::new))?;
    let mie_source = mie.source.clone();
    let dir = cli
        .table_dir
        .as_ref()
        .map_or_else(default_cache_dir, std::path::PathBuf::from);
    if rdaylight::io::show_progress() {
        eprintln!(
            "rspecsky: {} time steps; atmosphere tables in {} (computed once per climate and AOD)",
            steps.len(),
            dir.display()
        );
    }
    let site = radiance_site(weather);
    let (mtx, used) = atmosphere_matrix(&patches, &steps, &site, &opts, &mie, &dir, &ch)?;
    let mut header = Header::new();
    header.push_command(std::env::args());
    header.set("LATLONG", format!(" {}", latlong(weather)));
    header.set(
        "SKYMODEL",
        " atmosphere (Bruneton precomputed scattering, gensdaymtx)",
    );
    header.set("AEROSOL", format!(" {mie_source}"));
    let tables: Vec<String> = used
        .iter()
        .map(|u| {
            let how = match &u.status {
                CacheStatus::Hit(_) => "cached",
                _ => "computed",
            };
            format!("{} AOD {} ({how})", u.climate.tag(), u.aod)
        })
        .collect();
    header.set("ATMOSPHERE", format!(" {}", tables.join(", ")));
    let mut wopts = WriteOptions::new(format);
    wopts.header = !cli.no_header;
    wopts.seekable = rdaylight::io::stdout_is_file();
    wopts.ascii_digits = if format == DataFormat::Double {
        DOUBLE_DIGITS
    } else {
        FLOAT_DIGITS
    };
    let out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    let ncols = if cli.average { 1 } else { mtx.ncols() };
    if cli.average {
        header.set("NAVERAGED", mtx.ncols());
    }
    let mut w = MatrixWriter::new(out, "<stdout>", header, Some(mtx.nrows()), ncols, ch, wopts)?;
    let mut row = Vec::new();
    for p in 0..mtx.nrows() {
        mtx.row(p, &mut row);
        if cli.average {
            row = average_columns(&row, ch.ncomp, mtx.ncols());
        }
        w.write_row(&row)?;
    }
    w.finish()?.flush().map_err(|e| Error::io("<stdout>", e))?;
    Ok(())
}

fn default_cache_dir() -> std::path::PathBuf {
    if let Some(x) = std::env::var_os("XDG_CACHE_HOME").filter(|x| !x.is_empty()) {
        return std::path::PathBuf::from(x).join("rdaylight");
    }
    if let Some(h) = std::env::var_os("HOME").filter(|x| !x.is_empty()) {
        return std::path::PathBuf::from(h).join(".cache").join("rdaylight");
    }
    std::path::PathBuf::from(".")
}

fn genssky_mode() -> Result<(), Error> {
    use rdaylight::sky::atmosphere::cache::CacheStatus;
    use rdaylight::sky::genssky::{
        GensskyOptions, Hour, load_mie, rad_text, sky_path, spectral_sky,
    };
    let args: Vec<String> = std::env::args().collect();
    let rest = args
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 1)
        .map(|(_, a)| a.clone());
    let cli = GensskyCli::try_parse_from(rest).unwrap_or_else(|e| e.exit());
    let whole = |s: &str, what: &str| -> Result<u32, Error> {
        s.parse::<u32>()
            .map_err(|_| Error::Usage(format!("{what} \"{s}\": expected a whole number")))
    };
    let month = whole(&cli.month, "month")?;
    let day = whole(&cli.day, "day")?;
    let mut o = GensskyOptions::new(month, day, Hour::parse(&cli.hour)?);
    if let Some(a) = cli.latitude {
        o.site.latitude = a;
    }
    if let Some(v) = cli.longitude {
        o.site.longitude_west = v;
    }
    if let Some(v) = cli.meridian {
        o.site.meridian_west = v;
    }
    o.year = cli.year;
    o.aod = cli.aod;
    o.cloud_cover = cli.cloud;
    o.ground_reflectance = cli.ground;
    o.resolution = cli.res;
    o.illuminance = cli.illuminance.as_ref().map(|v| (v[0], v[1]));
    o.validate()?;
    if o.hour.zone_meridian.is_none()
        && !o.hour.solar
        && (o.site.meridian_west - o.site.longitude_west).abs() > 45.0
    {
        eprintln!(
            "rspecsky: warning - {:.1} hours btwn. standard meridian and longitude",
            (o.site.longitude_west - o.site.meridian_west) / 15.0
        );
    }
    let mie = load_mie(cli.mie.as_deref().map(std::path::Path::new))?;
    let mie_source = mie.source.clone();
    let mut atm = o.atmosphere(mie);
    atm.scattering_order = cli.order;
    let out_dir = cli.dir.clone().unwrap_or_else(|| ".".into());
    let out_dir = if out_dir.len() > 1 {
        out_dir.trim_end_matches('/').to_string()
    } else {
        out_dir
    };
    let cache_dir = match &cli.dir {
        Some(_) => std::path::PathBuf::from(&out_dir),
        None => default_cache_dir(),
    };
    let start = std::time::Instant::now();
    let work = || rdaylight::sky::atmosphere::cache::load_or_compute(&cache_dir, &atm);
    let (tables, status) = if cli.threads > 0 {
        rayon::ThreadPoolBuilder::new()
            .num_threads(cli.threads)
            .build()
            .map_err(|e| Error::Usage(format!("-n {}: {e}", cli.threads)))?
            .install(work)?
    } else {
        work()?
    };
    let secs = start.elapsed().as_secs_f64();
    let sky = spectral_sky(&tables, &o);
    let hsr = sky_path(std::path::Path::new(&out_dir), &cli.prefix);
    let sky_name = format!("{out_dir}/{}_sky.hsr", cli.prefix);
    sky.picture.save(&hsr, false)?;
    let mut words = args.clone();
    if let Some(w) = words.first_mut() {
        *w = "rspecsky".into();
    }
    let tables_note = match &status {
        CacheStatus::Hit(p) => format!("#Atmosphere tables: {} (cached)", p.display()),
        CacheStatus::Computed(p) => {
            format!(
                "#Atmosphere tables: {} (computed in {secs:.1} s)",
                p.display()
            )
        }
        CacheStatus::Recomputed(p, why) => format!(
            "#Atmosphere tables: {} (recomputed in {secs:.1} s: {why})",
            p.display()
        ),
    };
    if let CacheStatus::Recomputed(p, why) = &status {
        eprintln!("rspecsky: {}: {why}; recomputed", p.display());
    }
    let comments = vec![
        format!("# {} ", words.join(" ")),
        format!("#Cloud cover: {}", o.cloud_cover),
        format!("#Ground reflectance: {}", o.ground_reflectance),
        format!("#Sky map resolution: {}", o.resolution),
        format!("#Aerosol profile: {mie_source}"),
        tables_note,
    ];
    let text = rad_text(&sky, &comments, &sky_name);
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .map_err(|e| Error::io("<stdout>", e))
}
