//! `rmetrics`: annual daylight metrics (TAI, UDI, DA, sDA, ASE) from an illuminance matrix,
//! falsecolor maps, and Appendix-A errors between model variants. The physics lives in
//! `rdaylight::metrics`; this file parses options and opens files.

use clap::{Args, Parser, Subcommand};
use rdaylight::Error;
use rdaylight::formats::sensors::{RayFormat, read_rays};
use rdaylight::metrics::{
    self, LuxRows, Thresholds,
    annual::column_names,
    compare, map, report,
    schedule::{ScheduleSpec, parse_range},
};
use std::io::Write;
use std::path::Path;

const EXAMPLE: &str = "\
Example pipeline (two-phase, with Radiance or rdaylight tools):
  gendaymtx -m 1 weather.wea > sky.smx             # one column per weather step (no -u)
  dctimestep dc.mtx sky.smx | rmtxop -fa -c 47.4 119.9 11.6 - > illum.mtx
  rmetrics -w weather.wea --pts sensors.pts --json metrics.json illum.mtx > metrics.tsv
  rmetrics -w weather.wea --pts sensors.pts --map DA --png da.png illum.mtx > /dev/null
  # ASE needs direct sun only: sun coefficients (-ab 0) times a sun-only sky (gendaymtx -d)
  rmetrics -w weather.wea --direct-sun sun.mtx illum.mtx
  rmetrics compare benchmark.tsv variant.tsv      # PE, MAPE, RMSE (seed Appendix A)

Time steps: the matrix must have one column per step of the weather file (gendaymtx
without -u); a step at decimal hour h is occupied when START <= h < END (8-18 counts the
hourly stamps 8.5 ... 17.5). Per-sensor TAI is seed Eq. 4.1 in klx.h; the `room` row
(mean of each column) is Eq. 2.2. UDI-n < 100 <= UDI-s < 300 <= UDI-a <= 3000 < UDI-e;
DA counts E >= 300 lx; sDA: share of sensors with DA >= 50 %; ASE: share of sensors with
direct sun > 1000 lx for > 250 h.";

#[derive(Parser)]
#[command(
    name = "rmetrics",
    version,
    about = "Annual daylight metrics (TAI, UDI, DA, sDA, ASE) from an illuminance matrix \
             (sensors x time steps), maps and model-variant errors",
    after_help = EXAMPLE,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
    /// Illuminance matrix: rows = sensors, columns = time steps; NCOMP=1 lux (rmtxop -c
    /// 47.4 119.9 11.6) or NCOMP=3 RGB irradiance (converted, noted in the output); `-` =
    /// standard input.
    #[arg(default_value = "-")]
    illum: String,
    #[command(flatten)]
    sched: SchedArgs,
    /// UDI thresholds LOW,MID,HIGH in lux (UDI-n < LOW <= UDI-s < MID <= UDI-a <= HIGH <
    /// UDI-e). The seed's three-bin UDI (300/3000) is UDI-n + UDI-s, UDI-a, UDI-e.
    #[arg(long, value_name = "LOW,MID,HIGH", default_value = "100,300,3000")]
    udi: String,
    /// Daylight Autonomy threshold in lux (E >= DA counts).
    #[arg(long, value_name = "LUX", default_value_t = 300.0)]
    da: f64,
    /// sDA: a sensor passes when its DA is at least this percentage.
    #[arg(long, value_name = "PERCENT", default_value_t = 50.0)]
    sda: f64,
    /// ASE thresholds LUX,HOURS: direct sun above LUX for more than HOURS occupied hours.
    #[arg(long, value_name = "LUX,HOURS", default_value = "1000,250")]
    ase: String,
    /// Direct-sun-only illuminance matrix (same sensors and steps) for ASE. Without it ASE
    /// is not computed (and asking for it is an error), never reported as zero.
    #[arg(long, value_name = "FILE")]
    direct_sun: Option<String>,
    /// Sensor points (rtrace ascii `x y z dx dy dz`, one per matrix row): adds x y z
    /// columns and is required by --map.
    #[arg(long, value_name = "FILE")]
    pts: Option<String>,
    /// Write the TSV table here instead of standard output.
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<String>,
    /// Also write the results as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<String>,
    /// Metric to map (a column name: TAI_klxh, UDI_n, UDI_s, UDI_a, UDI_e, DA, sDA, ASE_h,
    /// ASE); needs --pts and --png.
    #[arg(long, value_name = "METRIC", requires = "png")]
    map: Option<String>,
    /// PNG file for --map: one 16-px cell per sensor over the plan (x right, y up), blue =
    /// minimum to red = maximum, legend bar with min/max labels.
    #[arg(long, value_name = "FILE", requires = "map")]
    png: Option<String>,
}

#[derive(Args, Clone)]
struct SchedArgs {
    /// Weather file (.wea or .epw) the sky matrix was made from: one column per step.
    #[arg(short = 'w', long, value_name = "FILE")]
    weather: Option<String>,
    /// Time stamps instead: one `month day hour` line per column (e.g. with gendaymtx -u).
    #[arg(long, value_name = "FILE", conflicts_with = "weather")]
    hours: Option<String>,
    /// Occupied hours START-END in decimal local standard time: START <= hour < END. LEED
    /// and IES LM-83 use 8-18; the seed used 9-17 for TAI (ch. 2) and 8-17 for RMSE (App. A).
    #[arg(long, value_name = "START-END", default_value = "8-18")]
    occupied: String,
    /// Count Monday to Friday only (weekday from an EPW's DATA PERIODS, or --jan1).
    #[arg(long)]
    weekdays: bool,
    /// Weekday of 1 January (e.g. Monday) for --weekdays.
    #[arg(long, value_name = "DAY")]
    jan1: Option<String>,
    /// Occupancy flags instead of --occupied: one 0 or 1 per column, one per line.
    #[arg(long, value_name = "FILE")]
    schedule: Option<String>,
    /// Without time stamps: count every column as an occupied one-hour step.
    #[arg(long)]
    all_steps: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// Melanopic quantities from a spectral irradiance matrix (NCOMP > 3, Radiance band
    /// convention, e.g. `rmtx dc18.mtx sky18.smx`): writes one quantity per sensor and
    /// step as an NCOMP=1 matrix (CIE S 026 m-EDI by default; Ev, M/P, melanopic
    /// irradiance, or Radiance's `M`, where m-EDI = 0.9233 M), and optionally a per-sensor
    /// summary and a PNG map of the mean m-EDI (rdaylight::metrics::melanopic).
    Melanopic {
        /// Spectral irradiance matrix; `-` = standard input.
        #[arg(default_value = "-")]
        input: String,
        /// Quantity per sensor and step: medi, ev, mp, emel or radiance-m.
        #[arg(long, default_value = "medi")]
        quantity: metrics::melanopic::Quantity,
        /// Write the matrix here instead of standard output.
        #[arg(short = 'o', long, value_name = "FILE")]
        output: Option<String>,
        /// Per-sensor summary TSV (mean m-EDI, Ev and M/P over lit steps, steps with m-EDI
        /// at or above --threshold).
        #[arg(long, value_name = "FILE")]
        summary: Option<String>,
        /// m-EDI threshold in lx for the summary (Brown et al. 2022 daytime: 250).
        #[arg(long, value_name = "LUX", default_value_t = metrics::melanopic::DAYTIME_MEDI_LX)]
        threshold: f64,
        /// Sensor points (one per row) for the summary's x y z and for --png.
        #[arg(long, value_name = "FILE")]
        pts: Option<String>,
        /// PNG map of the mean m-EDI per sensor over the plan (needs --pts); with
        /// --weather, of the share of days passing the daily rule instead.
        #[arg(long, value_name = "FILE", requires = "pts")]
        png: Option<String>,
        /// Weather file the sky matrix was made from (one column per step): enables the
        /// daily rule (Brown et al. 2022) in the summary and map.
        #[arg(short = 'w', long, value_name = "FILE")]
        weather: Option<String>,
        /// Daily rule: the morning window START-END (decimal hours) and the hours inside
        /// it that must reach --threshold.
        #[arg(long, value_name = "START-END", default_value = "8-12")]
        morning: String,
        #[arg(long, value_name = "HOURS", default_value_t = 4.0)]
        min_hours: f64,
    },
    /// PE, MAPE, RMSE (seed Appendix A) of variants against a benchmark: two or more
    /// rmetrics TSV tables, or two or more illuminance matrices (then with the same time
    /// stamp options as the main command).
    Compare {
        /// Benchmark (TSV table or matrix).
        benchmark: String,
        /// One or more variants of the same kind.
        #[arg(required = true)]
        variants: Vec<String>,
        #[command(flatten)]
        sched: SchedArgs,
    },
}

fn pair(s: &str, what: &str, n: usize) -> Result<Vec<f64>, Error> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            Error::Usage(format!(
                "{what}: expected {n} comma-separated numbers, found '{s}'"
            ))
        })?;
    if v.len() != n {
        return Err(Error::Usage(format!(
            "{what}: expected {n} comma-separated numbers, found '{s}'"
        )));
    }
    Ok(v)
}

impl SchedArgs {
    fn spec(&self) -> Result<ScheduleSpec, Error> {
        Ok(ScheduleSpec {
            weather: self.weather.clone(),
            hours: self.hours.clone(),
            occupied: Some(parse_range(&self.occupied)?),
            weekdays: self.weekdays,
            jan1: self.jan1.clone(),
            flags: self.schedule.clone(),
            all_steps: self.all_steps,
        })
    }
}

fn write_out(
    path: Option<&str>,
    f: impl FnOnce(&mut dyn Write) -> Result<(), Error>,
) -> Result<(), Error> {
    match path {
        Some(p) if p != "-" => rdaylight::io::write_atomically(Path::new(p), f),
        _ => {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            f(&mut out)?;
            out.flush().map_err(|e| Error::io("<stdout>", e))
        }
    }
}

fn run_compare(bench: &str, variants: &[String], sched: &SchedArgs) -> Result<(), Error> {
    use std::io::Read;
    let text = |p: &str| std::fs::read(p).map_err(|e| Error::io(p, e));
    // Only the start decides (a matrix is then streamed, never loaded whole).
    let mut first = Vec::new();
    std::fs::File::open(bench)
        .and_then(|f| f.take(4096).read_to_end(&mut first))
        .map_err(|e| Error::io(bench, e))?;
    let is_table = String::from_utf8_lossy(&first)
        .lines()
        .find(|l| !l.starts_with('#') && !l.trim().is_empty())
        .is_some_and(|l| l.starts_with("sensor\t"));
    let rows = if is_table {
        let b = report::read_tsv(&String::from_utf8_lossy(&text(bench)?), bench)?;
        let mut vs = Vec::new();
        for v in variants {
            vs.push((
                v.clone(),
                report::read_tsv(&String::from_utf8_lossy(&text(v)?), v)?,
            ));
        }
        compare::compare_tables(&b, bench, &vs)?
    } else {
        let mut b = LuxRows::open(bench)?;
        let schedule = sched.spec()?.build(b.ncols(), bench)?;
        let mut vs = variants
            .iter()
            .map(|v| LuxRows::open(v))
            .collect::<Result<Vec<_>, _>>()?;
        compare::compare_matrices(&mut b, &mut vs, &schedule)?
    };
    write_out(None, |w| {
        compare::write_comparison(w, bench, variants, &rows)
    })
}

#[allow(clippy::too_many_arguments)]
fn run_melanopic(
    input: &str,
    quantity: metrics::melanopic::Quantity,
    output: Option<&str>,
    summary: Option<&str>,
    pts: Option<&str>,
    png: Option<&str>,
    weather: Option<&str>,
    rule: &metrics::melanopic::DailyRule,
) -> Result<(), Error> {
    let threshold = rule.threshold;
    use rdaylight::formats::header::Header;
    use rdaylight::formats::matrix::{DataFormat, MatrixReader, MatrixWriter, WriteOptions};
    let positions = match pts {
        Some(p) => {
            let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
            let rays = read_rays(std::io::BufReader::new(f), p, RayFormat::Ascii)?;
            Some(rays.iter().map(|r| r.org).collect::<Vec<[f64; 3]>>())
        }
        None => None,
    };
    let mut reader = MatrixReader::open(input, &metrics::melanopic::read_options())?;
    let stamps = match weather {
        Some(w) => {
            let st = metrics::schedule::stamps_from_weather(
                &rdaylight::formats::weather::Weather::read_path(w)?,
            );
            if st.len() != reader.ncols() {
                return Err(Error::Mismatch(format!(
                    "{w}: {} weather steps but {input} has {} columns (make the sky matrix \
                     without -u)",
                    st.len(),
                    reader.ncols()
                )));
            }
            Some(st)
        }
        None => None,
    };
    let step = stamps.as_deref().map_or(1.0, metrics::schedule::step_hours);
    let daily = stamps.as_deref().map(|s| (s, step, rule));
    let mut header = Header::new();
    header.push_command(std::env::args());
    let mut sums = Vec::new();
    write_out(output, |w| {
        let mut mw = MatrixWriter::new(
            w,
            output.unwrap_or("<stdout>"),
            header,
            reader.nrows(),
            reader.ncols(),
            rdaylight::radiometry::Channels::mono(),
            WriteOptions::new(DataFormat::Ascii),
        )?;
        let mut row = Vec::new();
        sums = metrics::melanopic::reduce(&mut reader, threshold, daily, |_, vals| {
            row.clear();
            row.extend(vals.iter().map(|m| quantity.of(m)));
            mw.write_row(&row)
        })?;
        mw.finish()?;
        Ok(())
    })?;
    if let Some(p) = &positions {
        if p.len() != sums.len() {
            return Err(Error::Mismatch(format!(
                "{}: {} sensor points but {input} has {} rows",
                pts.unwrap_or(""),
                p.len(),
                sums.len()
            )));
        }
    }
    if let Some(s) = summary {
        rdaylight::io::write_atomically(Path::new(s), |w| {
            metrics::melanopic::write_summary(w, s, &sums, threshold, positions.as_deref())
        })?;
    }
    if let (Some(png), Some(p)) = (png, &positions) {
        let xy: Vec<[f64; 2]> = p.iter().map(|q| [q[0], q[1]]).collect();
        let vals: Vec<f64> = if stamps.is_some() {
            sums.iter().map(|s| s.days_share()).collect()
        } else {
            sums.iter().map(|s| s.mean_medi).collect()
        };
        let bytes = map::png_bytes(&map::render(&xy, &vals)?)?;
        rdaylight::io::write_atomically(Path::new(png), |w| {
            w.write_all(&bytes).map_err(|e| Error::io(png, e))
        })?;
    }
    Ok(())
}

fn real_main() -> Result<(), Error> {
    let cli = Cli::parse();
    if let Some(Cmd::Compare {
        benchmark,
        variants,
        sched,
    }) = &cli.cmd
    {
        return run_compare(benchmark, variants, sched);
    }
    if let Some(Cmd::Melanopic {
        input,
        quantity,
        output,
        summary,
        threshold,
        pts,
        png,
        weather,
        morning,
        min_hours,
    }) = &cli.cmd
    {
        let (start, end) = parse_range(morning).map_err(|_| {
            Error::Usage(format!(
                "--morning: expected START-END in decimal hours such as 8-12, found '{morning}'"
            ))
        })?;
        let rule = metrics::melanopic::DailyRule {
            threshold: *threshold,
            start,
            end,
            min_hours: *min_hours,
        };
        return run_melanopic(
            input,
            *quantity,
            output.as_deref(),
            summary.as_deref(),
            pts.as_deref(),
            png.as_deref(),
            weather.as_deref(),
            &rule,
        );
    }
    let udi = pair(&cli.udi, "--udi", 3)?;
    let ase = pair(&cli.ase, "--ase", 2)?;
    let t = Thresholds {
        udi_low: udi[0],
        udi_mid: udi[1],
        udi_high: udi[2],
        da: cli.da,
        sda_percent: cli.sda,
        ase_lux: ase[0],
        ase_hours: ase[1],
    };
    t.check()?;
    if let Some(m) = &cli.map {
        if !column_names(true).contains(&m.as_str()) {
            return Err(Error::Usage(format!(
                "--map: unknown metric '{m}'; one of {}",
                column_names(true).join(", ")
            )));
        }
        if m.starts_with("ASE") && cli.direct_sun.is_none() {
            return Err(Error::Usage(metrics::ASE_REFUSAL.into()));
        }
        if cli.pts.is_none() {
            return Err(Error::Usage(
                "--map needs the sensor positions (--pts FILE)".into(),
            ));
        }
    }
    let positions = match &cli.pts {
        Some(p) => {
            let f = std::fs::File::open(p).map_err(|e| Error::io(p, e))?;
            Some(read_rays(std::io::BufReader::new(f), p, RayFormat::Ascii)?)
        }
        None => None,
    };
    let mut illum = LuxRows::open(&cli.illum)?;
    let schedule = cli.sched.spec()?.build(illum.ncols(), illum.name())?;
    let mut direct = cli.direct_sun.as_deref().map(LuxRows::open).transpose()?;
    let res = metrics::compute(&mut illum, direct.as_mut(), &schedule, &t)?;
    if let Some(p) = &positions {
        if p.len() != res.sensors.len() {
            return Err(Error::Mismatch(format!(
                "{}: {} sensor points but {} has {} rows",
                cli.pts.as_deref().unwrap_or(""),
                p.len(),
                illum.name(),
                res.sensors.len()
            )));
        }
    }
    for n in &res.notes {
        if n.starts_with("input was RGB") {
            eprintln!("rmetrics: note: {n}");
        }
    }
    let pos = positions.as_deref();
    if let (Some(m), Some(png)) = (&cli.map, &cli.png) {
        let k = column_names(res.with_ase)
            .iter()
            .position(|c| c == m)
            .ok_or_else(|| Error::Usage(metrics::ASE_REFUSAL.into()))?;
        let pts: Vec<[f64; 2]> = pos
            .unwrap_or(&[])
            .iter()
            .map(|r| [r.org[0], r.org[1]])
            .collect();
        let vals: Vec<f64> = res.sensors.iter().map(|s| s.values()[k]).collect();
        let bytes = map::png_bytes(&map::render(&pts, &vals)?)?;
        rdaylight::io::write_atomically(Path::new(png), |w| {
            w.write_all(&bytes).map_err(|e| Error::io(png, e))
        })?;
    }
    if let Some(j) = &cli.json {
        rdaylight::io::write_atomically(Path::new(j), |w| {
            report::write_json(w, &cli.illum, &res, &t, pos)
        })?;
    }
    write_out(cli.output.as_deref(), |w| {
        report::write_tsv(w, &cli.illum, &res, &t, pos)
    })
}

fn main() {
    rdaylight::cli::run("rmetrics", real_main)
}
