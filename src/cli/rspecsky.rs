//! # `rspecsky`'s command line: gendaymtx's, gendaylit's and genssky's letters
//!
//! The tools layer's half of `rspecsky`: the clap structs, Radiance's spellings, and the
//! conversion into the library's typed configs (`rdaylight::sky::config`), which hold the
//! models, the defaults and the rules about values. `rspecsky` has three modes:
//!
//! | mode | command line | config | Radiance |
//! |---|---|---|---|
//! | sky matrix | `rspecsky [options] weather` | [`SkyMatrixConfig`] | `gendaymtx`, `gensdaymtx` (`--model atmosphere`) |
//! | point-in-time sky | `rspecsky --at "M D H" ...` | [`PointSkyConfig`] | `gendaylit` |
//! | genssky | `rspecsky genssky M D H ...` | [`GensskyConfig`] | `genssky` |
//!
//! Radiance spells the spectral options `-cs`/`-cw` while clap's short `-c` is the sky colour,
//! so they are rewritten to `--cs`/`--cw` before parsing. `-m` and `-o` are strings because
//! their meaning depends on the mode (gendaymtx's MF and format, gendaylit's meridian and
//! longitude). gendaymtx applies `-d -s -g -c` in command-line order: [`colour_edits`]
//! recovers that order from clap's indices. A clap error prints clap's block and exits 2, as
//! `rspecsky` always has.

use crate::error::{Error, Result};
use crate::formats::matrix::DataFormat;
use crate::formats::weather::Site;
use crate::sky::config::point::parse_date;
use crate::sky::config::{
    Bands, ColourEdit, GensskyConfig, Messages, PointSkyConfig, PointSkyInput, SkyMatrixConfig,
    SkyModel,
};
use crate::sky::genssky::{GensskyOptions, Hour};
use clap::{CommandFactory, FromArgMatches, Parser};

pub const EXAMPLES: &str = "\
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

/// Perez all-weather sky matrices (gendaymtx), point-in-time skies (gendaylit) and
/// physically based spectral skies (gensdaymtx with --model atmosphere; genssky).
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
///
/// Spectral point-in-time mode: `rspecsky genssky month day hour [options] > sky.rad` is
/// Radiance 6's genssky with the same options (`rspecsky genssky --help` lists them).
#[derive(Parser, Debug)]
#[command(
    name = "rspecsky",
    version,
    disable_help_flag = true,
    after_help = EXAMPLES,
    override_usage = "rspecsky [OPTIONS] [WEATHER]\n       rspecsky --at \"MONTH DAY HOUR\" [OPTIONS] [WEATHER]\n       rspecsky genssky MONTH DAY HOUR [OPTIONS]"
)]
pub struct Options {
    /// Reinhart multiplication factor MF (gendaymtx -m; default 1 = Tregenza's 145 patches
    /// + ground). With --at: standard meridian in degrees west (gendaylit -m).
    #[arg(short = 'm', value_name = "MF", allow_negative_numbers = true)]
    pub m: Option<String>,

    /// Output unit (gendaymtx/gendaylit -O): 0 visible radiance (default), 1 solar radiance.
    #[arg(short = 'O', value_name = "0|1")]
    pub output: Option<u8>,

    /// Sun only: zero sky and ground (gendaymtx -d).
    #[arg(short = 'd')]
    pub sun_only: bool,

    /// Sky only: no sun (gendaymtx -s; gendaylit -s).
    #[arg(short = 's')]
    pub sky_only: bool,

    /// Five-phase sun: each sun in one patch, with the solid angle of a disc of this
    /// diameter in degrees (gendaymtx -5, usually 0.533).
    #[arg(value_parser = super::finite, short = '5', value_name = "DEG")]
    pub five: Option<f64>,

    /// Ground reflectance r g b (gendaymtx -g; default 0.2 0.2 0.2; gendaylit -g takes the
    /// mean, the colour goes to the ground glow).
    #[arg(value_parser = super::finite, short = 'g', num_args = 3, value_names = ["R", "G", "B"])]
    pub ground: Option<Vec<f64>>,

    /// Sky colour r g b (gendaymtx -c; default .960 1.004 1.118; with --at the sky glow
    /// colour, default 1 1 1).
    #[arg(value_parser = super::finite, short = 'c', num_args = 3, value_names = ["R", "G", "B"])]
    pub colour: Option<Vec<f64>>,

    /// Rotate the sky counter-clockwise about the zenith by DEG degrees (gendaymtx -r).
    #[arg(value_parser = super::finite, short = 'r', value_name = "DEG", allow_negative_numbers = true)]
    pub rotation: Option<f64>,

    /// Output format: -oa ascii (default, full precision, not gendaymtx's 3 digits), -of
    /// float, -od double (gendaymtx -of/-od). With --at: longitude in degrees west
    /// (gendaylit -o).
    #[arg(short = 'o', value_name = "a|f|d", allow_negative_numbers = true)]
    pub o: Option<String>,

    /// Write no header (gendaymtx -h).
    #[arg(short = 'h')]
    pub no_header: bool,

    /// Leave out time steps with the sun below the horizon (gendaymtx -u).
    #[arg(short = 'u')]
    pub skip_night: bool,

    /// One column, the average of all (kept) time steps, with NAVERAGED= (gendaymtx -A).
    #[arg(short = 'A')]
    pub average: bool,

    /// Sunrise/sunset interval correction for data averaged over MIN minutes
    /// (gendaymtx -i).
    #[arg(value_parser = super::finite, short = 'i', value_name = "MIN")]
    pub interval: Option<f64>,

    /// Point-in-time sky for "month day hour" (local standard time, as gendaylit's
    /// `month day hour`; with a weather file, a record's own hour, e.g. 12.5). The sky is
    /// gendaylit's model with its defaults (dew point 10.97 C, i.e. 2 cm precipitable
    /// water, also for EPW records); -s drops the sun, -d blackens sky and ground glows.
    #[arg(long = "at", value_name = "\"M D H\"")]
    pub at: Option<String>,

    /// With --at: direct normal and diffuse horizontal irradiance, W/m2 (gendaylit -W).
    #[arg(value_parser = super::finite, short = 'W', num_args = 2, value_names = ["DNI", "DHI"])]
    pub irradiance: Option<Vec<f64>>,

    /// With --at -W: latitude in degrees north (gendaylit -a).
    #[arg(value_parser = super::finite, short = 'a', value_name = "LAT", allow_negative_numbers = true)]
    pub latitude: Option<f64>,

    /// Spectral matrix with N bands (Radiance's -cs N; also written -cs N): the same Perez
    /// sky with a CIE daylight spectrum per part and time step, NCOMP=N and
    /// WAVELENGTH_SPLITS= in the header, photopically equal to the RGB matrix
    /// (rdaylight::sky::spectral documents the spectra).
    #[arg(long = "cs", value_name = "N")]
    pub cs: Option<usize>,

    /// Wavelength range of the -cs bands in nm (Radiance's -cw; default 380 780).
    #[arg(value_parser = super::finite, long = "cw", num_args = 2, value_names = ["MIN", "MAX"])]
    pub cw: Option<Vec<f64>>,

    /// Sky model of the matrix: perez (default; gendaymtx's Perez sky, with -cs a CIE
    /// daylight spectrum per part) or atmosphere (gensdaymtx's physically based spectral
    /// sky: precomputed clear-sky scattering blended with an overcast sky by cloud cover and
    /// scaled to the measured light; 20 bands 380-780 nm unless -cs/-cw; see
    /// rdaylight::sky::atmosphere_matrix). With atmosphere, -g takes the mean of its three
    /// values (one reflectance), -c, -5, -O 1 and -i are refused.
    #[arg(long = "model", value_name = "perez|atmosphere")]
    pub model: Option<String>,

    /// With --model atmosphere: one aerosol optical depth for every record (default: the
    /// weather file's AOD column, else 0.115, as gensdaymtx).
    #[arg(value_parser = super::finite, long = "aod", value_name = "AOD", allow_negative_numbers = true)]
    pub aod: Option<f64>,

    /// With --model atmosphere: folder of the cached atmosphere tables (gensdaymtx -p;
    /// default $XDG_CACHE_HOME/rdaylight or ~/.cache/rdaylight).
    #[arg(short = 'p', value_name = "DIR")]
    pub table_dir: Option<String>,

    /// With --model atmosphere: aerosol profile file (default mie_ca.dat on RAYPATH, else
    /// the documented fallback profile).
    #[arg(short = 'l', value_name = "FILE")]
    pub mie: Option<String>,

    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    pub help: Option<bool>,

    /// Weather file (.wea or .epw, recognised by content).
    #[arg(value_name = "WEATHER")]
    pub weather: Option<String>,
}

/// `rspecsky genssky month day hour [options]`: Radiance 6 genssky's point-in-time
/// spectral sky (Bruneton's precomputed atmosphere, rdaylight::sky::genssky).
#[derive(Parser, Debug)]
#[command(name = "rspecsky genssky", version, disable_help_flag = true)]
pub struct GensskyArgs {
    /// Month (1-12).
    pub month: String,
    /// Day of the month.
    pub day: String,
    /// Local standard time in hours (15.25 or 15:15), +H for solar time, or with a zone
    /// name (10PST).
    pub hour: String,
    /// Latitude, degrees north.
    #[arg(value_parser = super::finite, short = 'a', allow_negative_numbers = true)]
    pub latitude: Option<f64>,
    /// Longitude, degrees west.
    #[arg(value_parser = super::finite, short = 'o', allow_negative_numbers = true)]
    pub longitude: Option<f64>,
    /// Standard meridian, degrees west (UTC-8 = 120).
    #[arg(value_parser = super::finite, short = 'm', allow_negative_numbers = true)]
    pub meridian: Option<f64>,
    /// Year: use the Michalsky solar position.
    #[arg(short = 'y')]
    pub year: Option<i32>,
    /// Broadband aerosol optical depth (default 0.115).
    #[arg(value_parser = super::finite, short = 'd', default_value_t = crate::sky::atmosphere::AOD_CONTINENTAL)]
    pub aod: f64,
    /// Cloud cover, 0 clear to 1 overcast (default 0).
    #[arg(value_parser = super::finite, short = 'c', default_value_t = 0.0)]
    pub cloud: f64,
    /// Ground reflectance (default 0.2).
    #[arg(value_parser = super::finite, short = 'g', default_value_t = 0.2)]
    pub ground: f64,
    /// Aerosol profile (Radiance data file; default mie_ca.dat on RAYPATH, else an
    /// exponential profile, named in the output header).
    #[arg(short = 'l')]
    pub mie: Option<String>,
    /// Folder for the sky picture and atmos_data/ (default: picture in the current
    /// folder, tables in the user cache folder).
    #[arg(short = 'p')]
    pub dir: Option<String>,
    /// Sky picture width (height is half; default 64).
    #[arg(short = 'r', default_value_t = 64)]
    pub res: usize,
    /// Sky picture name prefix (default "out": out_sky.hsr).
    #[arg(short = 'f', default_value = "out")]
    pub prefix: String,
    /// Direct normal and diffuse horizontal illuminance, lux.
    #[arg(value_parser = super::finite, short = 'L', num_args = 2, value_names = ["DIRNORM", "DIFHOR"])]
    pub illuminance: Option<Vec<f64>>,
    /// Threads for the precomputation (results do not depend on it).
    #[arg(short = 'n', default_value_t = 0)]
    pub threads: usize,
    /// Highest scattering order (default 4).
    #[arg(short = 'i', default_value_t = 4)]
    pub order: usize,
    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    pub help: Option<bool>,
}

/// What the command line asks for: one of the three modes, as the library's config.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    Matrix(SkyMatrixConfig),
    Point(PointSkyConfig),
    Genssky(GensskyConfig),
}

/// Parse `args` (program name first) into the config of its mode.
pub fn command(args: Vec<String>) -> Result<Command> {
    if args.get(1).map(String::as_str) == Some("genssky") {
        return genssky_config(args).map(Command::Genssky);
    }
    // Radiance spells the spectral options -cs/-cw; clap's short -c is the sky colour.
    let clap_args = super::long_spellings(&args, &["cs", "cw"]);
    let m = Options::command()
        .try_get_matches_from(clap_args)
        .map_err(super::usage_error)?;
    let opts = Options::from_arg_matches(&m).map_err(super::usage_error)?;
    if let Some(out) = opts.output {
        if out > 1 {
            return Err(Error::Usage(format!(
                "-O{out}: expected -O0 (visible) or -O1 (solar)"
            )));
        }
    }
    let edits = colour_edits(&m, &opts);
    if opts.at.is_some() {
        let mut words = args;
        if let Some(w) = words.first_mut() {
            *w = "rspecsky".into();
        }
        return opts.to_point(edits, words).map(Command::Point);
    }
    opts.to_matrix(edits, args).map(Command::Matrix)
}

/// -d, -s, -g, -c in command-line order, as gendaymtx's option loop applies them.
pub fn colour_edits(m: &clap::ArgMatches, opts: &Options) -> Vec<ColourEdit> {
    let mut events: Vec<(usize, &str)> = Vec::new();
    for id in ["sun_only", "sky_only", "ground", "colour"] {
        // Flags have default values (with indices): only count what the user typed.
        if m.value_source(id) != Some(clap::parser::ValueSource::CommandLine) {
            continue;
        }
        if let Some(first) = m.indices_of(id).and_then(|mut ix| ix.next()) {
            events.push((first, id));
        }
    }
    events.sort();
    events
        .into_iter()
        .map(|(_, id)| match id {
            "sun_only" => ColourEdit::SunOnly,
            "sky_only" => ColourEdit::SkyOnly,
            "ground" => ColourEdit::Ground(opts.ground.clone().unwrap_or_default()),
            _ => ColourEdit::Sky(opts.colour.clone().unwrap_or_default()),
        })
        .collect()
}

impl Options {
    /// Matrix mode: gendaymtx's (and gensdaymtx's) reading of the letters.
    pub fn to_matrix(
        &self,
        colours: Vec<ColourEdit>,
        command: Vec<String>,
    ) -> Result<SkyMatrixConfig> {
        for (set, what) in [
            (self.irradiance.is_some(), "-W"),
            (self.latitude.is_some(), "-a"),
        ] {
            if set {
                return Err(Error::Usage(format!("{what} is only used with --at")));
            }
        }
        let mf = match self.m.as_deref() {
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
        let format = match self.o.as_deref() {
            None | Some("a") => DataFormat::Ascii,
            Some("f") => DataFormat::Float,
            Some("d") => DataFormat::Double,
            Some(o) => return Err(Error::Usage(format!("-o{o}: expected -oa, -of or -od"))),
        };
        let Some(path) = self.weather.as_deref() else {
            return Err(Error::Usage(
                "expected a weather file (.wea or .epw); see --help".into(),
            ));
        };
        let model = match self.model.as_deref() {
            None | Some("perez") => SkyModel::Perez,
            Some("atmosphere") => SkyModel::Atmosphere,
            Some(o) => {
                return Err(Error::Usage(format!(
                    "--model {o}: expected perez or atmosphere"
                )));
            }
        };
        let bands = match (self.cs, self.cw.as_deref()) {
            (None, None) => None,
            (n, cw) => Some(Bands {
                n,
                range: match cw {
                    Some([a, b]) => Some((*a, *b)),
                    _ => None,
                },
            }),
        };
        Ok(SkyMatrixConfig {
            mf,
            format,
            header: !self.no_header,
            command,
            seekable: crate::io::stdout_is_file(),
            model,
            colours,
            rotation_deg: self.rotation.unwrap_or(0.0),
            five_phase_sun_deg: self.five,
            solar_radiance: self.output == Some(1),
            interval_minutes: self.interval,
            skip_night: self.skip_night,
            average: self.average,
            bands,
            aod: self.aod,
            table_dir: self.table_dir.as_ref().map(Into::into),
            mie: self.mie.as_ref().map(Into::into),
            ..SkyMatrixConfig::new(path)
        })
    }

    /// `--at` mode: gendaylit's reading of the letters (-m, -o, -a in degrees).
    pub fn to_point(
        &self,
        colours: Vec<ColourEdit>,
        command: Vec<String>,
    ) -> Result<PointSkyConfig> {
        let (month, day, hour) = parse_date(self.at.as_deref().unwrap_or_default())?;
        for (set, what) in [
            (self.skip_night, "-u"),
            (self.average, "-A"),
            (self.five.is_some(), "-5"),
            (self.interval.is_some(), "-i"),
            (self.rotation.is_some(), "-r"),
            (self.no_header, "-h"),
            (self.cs.is_some() || self.cw.is_some(), "-cs/-cw"),
        ] {
            if set {
                return Err(Error::Usage(format!("{what} is not used with --at")));
            }
        }
        Ok(PointSkyConfig {
            month,
            day,
            hour,
            input: self.point_input()?,
            colours,
            solar_radiance: self.output == Some(1),
            command,
        })
    }

    /// A weather file (its site applies) or `-W dni dhi` with `-a -o -m`.
    fn point_input(&self) -> Result<PointSkyInput> {
        let num = |s: &Option<String>, what: &str| -> Result<Option<f64>> {
            s.as_deref()
                .map(|t| {
                    super::finite(t)
                        .map_err(|_| Error::Usage(format!("{what} {t}: expected degrees")))
                })
                .transpose()
        };
        match (&self.weather, &self.irradiance) {
            (Some(_), Some(_)) => Err(Error::Usage(
                "--at takes a weather file or -W, not both".into(),
            )),
            (None, None) => Err(Error::Usage(
                "--at needs a weather file or -W dni dhi with -a, -o, -m".into(),
            )),
            (Some(path), None) => {
                if self.latitude.is_some() || self.o.is_some() || self.m.is_some() {
                    return Err(Error::Usage(
                        "-a, -o and -m are not used with a weather file: its site applies".into(),
                    ));
                }
                Ok(PointSkyInput::Weather(path.into()))
            }
            (None, Some(wv)) => {
                let (Some(lat), Some(lon), Some(mer)) =
                    (self.latitude, num(&self.o, "-o")?, num(&self.m, "-m")?)
                else {
                    return Err(Error::Usage("-W needs -a lat -o lon -m meridian".into()));
                };
                // gendaylit's `-o`/`-m` are degrees west; the site is east positive.
                let site = Site {
                    latitude_deg_n: lat,
                    longitude_deg_e: -lon,
                    meridian_deg_e: -mer,
                    ..Site::default()
                };
                Ok(PointSkyInput::Irradiance {
                    direct: wv[0],
                    diffuse: wv[1],
                    site,
                })
            }
        }
    }
}

/// `rspecsky genssky month day hour [options]` (the word `genssky` is `args[1]`).
pub fn genssky_config(args: Vec<String>) -> Result<GensskyConfig> {
    let rest = args
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 1)
        .map(|(_, a)| a.clone());
    let g = GensskyArgs::try_parse_from(rest).map_err(super::usage_error)?;
    let whole = |s: &str, what: &str| -> Result<u32> {
        s.parse::<u32>()
            .map_err(|_| Error::Usage(format!("{what} \"{s}\": expected a whole number")))
    };
    let month = whole(&g.month, "month")?;
    let day = whole(&g.day, "day")?;
    let mut o = GensskyOptions::new(month, day, Hour::parse(&g.hour)?);
    // genssky's `-o`/`-m` are degrees west (gensky's convention); the site is east positive.
    if let Some(a) = g.latitude {
        o.site.latitude_deg_n = a;
    }
    if let Some(v) = g.longitude {
        o.site.longitude_deg_e = -v;
    }
    if let Some(v) = g.meridian {
        o.site.meridian_deg_e = -v;
    }
    o.year = g.year;
    o.aod = g.aod;
    o.cloud_cover = g.cloud;
    o.ground_reflectance = g.ground;
    o.resolution = g.res;
    o.illuminance = g.illuminance.as_ref().map(|v| (v[0], v[1]));
    let mut command = args;
    if let Some(w) = command.first_mut() {
        *w = "rspecsky".into();
    }
    Ok(GensskyConfig {
        options: o,
        mie: g.mie.map(Into::into),
        dir: g.dir,
        prefix: g.prefix,
        threads: g.threads,
        scattering_order: g.order,
        command,
    })
}

/// Progress (on a terminal, [`super::progress::Bars`]) and warnings on standard error, as
/// `rspecsky: ...` lines.
pub struct Stderr {
    /// Show progress and information ([`crate::io::show_progress`]).
    pub show: bool,
    bars: super::progress::Bars,
}

impl Stderr {
    pub fn new() -> Self {
        Stderr {
            show: crate::io::show_progress(),
            bars: super::progress::Bars::stderr("rspecsky"),
        }
    }
}

impl Default for Stderr {
    fn default() -> Self {
        Self::new()
    }
}

impl Messages for Stderr {
    fn progress(&self) -> &dyn crate::progress::Progress {
        &self.bars
    }

    fn info(&self, msg: &str) {
        if self.show {
            eprintln!("rspecsky: {msg}");
        }
    }

    fn warn(&self, msg: &str) {
        eprintln!("rspecsky: {msg}");
    }
}
