//! # `rdaylight._rdaylight`: the typed library API for Python (PyO3, NumPy arrays)
//!
//! Each function builds the same typed config the command-line tool builds from its
//! options and calls the same library function, so a Python result equals the tool's
//! output for the same settings and seed (python/tests check this against the binaries):
//!
//! | function | tool | library call |
//! |---|---|---|
//! | `daylight_coefficients`, `sun_coefficients`, `point_values` | `rdc -I -m MF`, `rdc -I --suns`, `rdc -I` | `rdc::Tracer::compute` |
//! | `sky_matrix` | `rspecsky` (gendaymtx) | `sky::config::SkyMatrixConfig::write` |
//! | `multiply` | `rmtx a b -c ...` (dctimestep, rmtxop) | `matrix::RowOps` |
//! | `annual_metrics` | `rmetrics` | `metrics::compute`, `metrics::report::write_tsv` |
//! | `glare` | `rglare` (evalglare) | `glare::evaluate_pixels` |
//! | `glod_objects` | `rglod objects --json` | `glod::analyse` |
//! | `mcop_study` | `rmcop study` | `mcop::study` |
//!
//! The Python package `rdaylight` (python/rdaylight/__init__.py) wraps these with
//! docstrings and converts array-likes to contiguous float64 first, so the functions here
//! take contiguous `f64` arrays only. Long computations release the GIL. Errors: the
//! library's one-line messages, as `ValueError` for the user's input (bad values, malformed
//! or mismatched files) and `OSError` for files that cannot be read.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use rdaylight_base::error::Error;
use rdaylight_base::radiometry::Channels;
use rdaylight_formats::header::Header;
use rdaylight_formats::matrix::{
    ChannelTransform, DataFormat, Matrix, MatrixReader, Operand, ReadOptions, RowOps, WriteOptions,
};
use rdaylight_formats::scene::{self, LoadOptions, Scene};
use rdaylight_formats::sensors::SensorRay;
use rdaylight_physics::sky::config::{Bands, ColourEdit, Messages, SkyMatrixConfig, SkyModel};
use rdaylight_trace::rdc::{Config, Sampling, SunSource, Target, Tracer};
use std::sync::Mutex;

/// The library's error as a Python exception with the same one-line message.
fn py_err(e: Error) -> PyErr {
    let msg = e.to_string();
    match &e {
        Error::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(msg)
        }
        Error::Io { .. } => PyOSError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}

fn usage(msg: impl Into<String>) -> PyErr {
    py_err(Error::Usage(msg.into()))
}

/// Rows of an `(N, 6)` array (`x y z dx dy dz`) as sensor rays.
fn sensor_rays(sensors: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<SensorRay>> {
    let a = sensors.as_array();
    if a.ncols() != 6 {
        return Err(usage(format!(
            "sensors: expected an (N, 6) array of x y z dx dy dz, found {} columns",
            a.ncols()
        )));
    }
    Ok(a.rows()
        .into_iter()
        .map(|r| SensorRay::new([r[0], r[1], r[2]], [r[3], r[4], r[5]]))
        .collect())
}

fn load_scene(files: &[String]) -> Result<Scene, Error> {
    if files.is_empty() {
        return Err(Error::Usage(
            "no scene given: expected one or more .rad files".into(),
        ));
    }
    // As rdc: RAYPATH and RDAYLIGHT_NO_EXEC from the environment.
    scene::load(files, &LoadOptions::from_env())
}

/// Trace `rays` through `files` with `config`: columns, channels and the `(N, columns,
/// ncomp)` values in row order.
fn trace_rows(
    py: Python<'_>,
    files: Vec<String>,
    rays: &[SensorRay],
    config: Config,
) -> PyResult<(usize, usize, Vec<f64>)> {
    py.detach(|| -> Result<_, Error> {
        let scene = load_scene(&files)?;
        let tracer = Tracer::new(&config, &scene)?;
        let rows = tracer.compute(rays)?;
        let data: Vec<f64> = rows.into_iter().flat_map(|r| r.values).collect();
        Ok((tracer.ncols(), tracer.channels.ncomp, data))
    })
    .map_err(py_err)
}

/// [`trace_rows`] as an `(N, columns, ncomp)` array.
fn trace<'py>(
    py: Python<'py>,
    files: Vec<String>,
    rays: Vec<SensorRay>,
    config: Config,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (ncols, ncomp, data) = trace_rows(py, files, &rays, config)?;
    let a = Array3::from_shape_vec((rays.len(), ncols, ncomp), data)
        .map_err(|e| usage(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// The sampling of `rdc`: rcontrib's defaults where an option is not given.
fn sampling(ab: Option<u32>, ad: Option<usize>, lw: Option<f64>, lr: Option<i32>) -> Sampling {
    let d = Sampling::default();
    Sampling {
        ab: ab.unwrap_or(d.ab),
        ad: ad.unwrap_or(d.ad),
        lw: lw.unwrap_or(d.lw),
        lr: lr.unwrap_or(d.lr),
        ..d
    }
}

/// `rdc -I -m MF`: sky-patch daylight coefficients, `(N, 144 MF^2 + 2, 3)`.
#[pyfunction]
#[pyo3(signature = (scene, sensors, mf=1, ab=None, ad=None, lw=None, lr=None, seed=0, threads=None, direct=false, irradiance=true))]
#[allow(clippy::too_many_arguments)]
fn daylight_coefficients<'py>(
    py: Python<'py>,
    scene: Vec<String>,
    sensors: PyReadonlyArray2<'py, f64>,
    mf: usize,
    ab: Option<u32>,
    ad: Option<usize>,
    lw: Option<f64>,
    lr: Option<i32>,
    seed: u64,
    threads: Option<usize>,
    direct: bool,
    irradiance: bool,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let config = Config {
        sampling: sampling(ab, ad, lw, lr),
        target: Target::Sky {
            mf,
            direct_only: direct,
            below_horizon: false,
        },
        irradiance,
        seed,
        threads,
        ..Config::default()
    };
    trace(py, scene, sensor_rays(&sensors)?, config)
}

/// `rdc -I --suns MF|weather`: sun coefficients, `(N, suns, 3)`.
#[pyfunction]
#[pyo3(signature = (scene, sensors, suns=None, weather=None, angle=rdaylight_trace::rdc::config::SUN_ANGLE_DEG, bounces=false, ab=None, ad=None, lw=None, lr=None, seed=0, threads=None, irradiance=true))]
#[allow(clippy::too_many_arguments)]
fn sun_coefficients<'py>(
    py: Python<'py>,
    scene: Vec<String>,
    sensors: PyReadonlyArray2<'py, f64>,
    suns: Option<usize>,
    weather: Option<String>,
    angle: f64,
    bounces: bool,
    ab: Option<u32>,
    ad: Option<usize>,
    lw: Option<f64>,
    lr: Option<i32>,
    seed: u64,
    threads: Option<usize>,
    irradiance: bool,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let source = match (suns, weather) {
        (Some(mf), None) => SunSource::Patches(mf),
        (None, Some(w)) => SunSource::Weather(w),
        _ => {
            return Err(usage(
                "sun_coefficients: give suns=MF (suns at the Reinhart patch centres) or \
                 weather=FILE (one sun per time step), not both",
            ));
        }
    };
    let config = Config {
        sampling: sampling(ab, ad, lw, lr),
        target: Target::Suns {
            suns: source,
            angle_deg: angle,
            bounces,
        },
        irradiance,
        seed,
        threads,
        ..Config::default()
    };
    trace(py, scene, sensor_rays(&sensors)?, config)
}

/// `rdc -I` (or without `-I`, radiance along the rays): point-in-time values under the
/// scene's own sky, `(N, 3)`.
#[pyfunction]
#[pyo3(signature = (scene, sensors, ab=None, ad=None, lw=None, lr=None, seed=0, threads=None, irradiance=true))]
#[allow(clippy::too_many_arguments)]
fn point_values<'py>(
    py: Python<'py>,
    scene: Vec<String>,
    sensors: PyReadonlyArray2<'py, f64>,
    ab: Option<u32>,
    ad: Option<usize>,
    lw: Option<f64>,
    lr: Option<i32>,
    seed: u64,
    threads: Option<usize>,
    irradiance: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let config = Config {
        sampling: sampling(ab, ad, lw, lr),
        target: Target::Values,
        irradiance,
        seed,
        threads,
        ..Config::default()
    };
    let rays = sensor_rays(&sensors)?;
    let (_, ncomp, data) = trace_rows(py, scene, &rays, config)?;
    Ok(Array2::from_shape_vec((rays.len(), ncomp), data)
        .map_err(|e| usage(format!("internal shape error: {e}")))?
        .into_pyarray(py))
}

/// Sensor rays of a `.pts` file (`x y z dx dy dz` lines) as `(N, 6)`.
#[pyfunction]
fn read_sensors<'py>(py: Python<'py>, path: String) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rays = rdaylight_formats::sensors::read_sensor_path(&path).map_err(py_err)?;
    let data: Vec<f64> = rays
        .iter()
        .flat_map(|r| r.org.into_iter().chain(r.dir))
        .collect();
    Ok(Array2::from_shape_vec((rays.len(), 6), data)
        .map_err(|e| usage(format!("internal shape error: {e}")))?
        .into_pyarray(py))
}

/// Warnings a sky matrix run reports, handed to Python's `warnings` afterwards.
#[derive(Default)]
struct Collected(Mutex<Vec<String>>);

impl Messages for Collected {
    fn warn(&self, msg: &str) {
        self.0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(msg.to_string());
    }
}

/// A matrix written by the library into memory (double precision: no rounding), read back
/// into storage of the header's size (an annual MF 6 sky is 1 GB: no doubling growth).
fn matrix_from_bytes(bytes: &[u8], name: &str) -> Result<Matrix, Error> {
    let mut r = MatrixReader::new(bytes, name, &ReadOptions::default())?;
    let n = r.row_len();
    let mut data = Vec::with_capacity(r.nrows().unwrap_or(0) * n);
    let mut row = vec![0.0; n];
    let mut nrows = 0;
    while r.read_row(&mut row)? {
        data.extend_from_slice(&row);
        nrows += 1;
    }
    Ok(Matrix {
        nrows,
        ncols: r.ncols(),
        channels: r.info().channels,
        data,
    })
}

fn matrix_to_array<'py>(py: Python<'py>, m: Matrix) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let shape = (m.nrows, m.ncols, m.ncomp());
    Ok(Array3::from_shape_vec(shape, m.data)
        .map_err(|e| usage(format!("internal shape error: {e}")))?
        .into_pyarray(py))
}

/// `rspecsky` / gendaymtx: the sky matrix of a weather file, `(patches, steps, ncomp)`.
#[pyfunction]
#[pyo3(signature = (weather, mf=1, sun_only=false, sky_only=false, five_phase_sun=None, ground=None, sky_colour=None, rotation=0.0, solar_radiance=false, interval=None, skip_night=false, average=false, bands=None, band_range=None, model="perez", aod=None))]
#[allow(clippy::too_many_arguments)]
fn sky_matrix<'py>(
    py: Python<'py>,
    weather: String,
    mf: usize,
    sun_only: bool,
    sky_only: bool,
    five_phase_sun: Option<f64>,
    ground: Option<Vec<f64>>,
    sky_colour: Option<Vec<f64>>,
    rotation: f64,
    solar_radiance: bool,
    interval: Option<f64>,
    skip_night: bool,
    average: bool,
    bands: Option<usize>,
    band_range: Option<(f64, f64)>,
    model: &str,
    aod: Option<f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let model = match model {
        "perez" => SkyModel::Perez,
        "atmosphere" => SkyModel::Atmosphere,
        o => return Err(usage(format!("model={o}: expected perez or atmosphere"))),
    };
    // gendaymtx applies its colour options in command-line order; here the colours come
    // first and -d/-s last, so sun_only always means a black sky and ground.
    let mut colours = Vec::new();
    colours.extend(sky_colour.map(ColourEdit::Sky));
    colours.extend(ground.map(ColourEdit::Ground));
    if sun_only {
        colours.push(ColourEdit::SunOnly);
    }
    if sky_only {
        colours.push(ColourEdit::SkyOnly);
    }
    let config = SkyMatrixConfig {
        mf,
        format: DataFormat::Double,
        model,
        colours,
        rotation_deg: rotation,
        five_phase_sun_deg: five_phase_sun,
        solar_radiance,
        interval_minutes: interval,
        skip_night,
        average,
        bands: (bands.is_some() || band_range.is_some()).then_some(Bands {
            n: bands,
            range: band_range,
        }),
        aod,
        ..SkyMatrixConfig::new(weather.clone())
    };
    let msgs = Collected::default();
    let m = py
        .detach(|| {
            let mut bytes = Vec::new();
            config.write(&mut bytes, "<sky matrix>", &msgs)?;
            matrix_from_bytes(&bytes, "<sky matrix>")
        })
        .map_err(py_err)?;
    for w in msgs.0.into_inner().unwrap_or_else(|e| e.into_inner()) {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        let msg = std::ffi::CString::new(w).unwrap_or_default();
        PyErr::warn(py, category.as_any(), &msg, 1)?;
    }
    matrix_to_array(py, m)
}

/// `rmtx a b [-c ...]`: the per-channel product `a . b` (dctimestep), then the channel
/// transform `coefficients` (rmtxop -c: nout x ncomp numbers), `(N, T, nout)`.
#[pyfunction]
#[pyo3(signature = (a, b, coefficients=None))]
fn multiply<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<'py, f64>,
    b: PyReadonlyArray3<'py, f64>,
    coefficients: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (na, pa, ca) = a.as_array().dim();
    let (pb, nt, cb) = b.as_array().dim();
    let shape = |r, c, n| rdaylight_formats::matrix::Shape {
        nrows: Some(r),
        ncols: c,
        ncomp: n,
    };
    rdaylight_formats::matrix::ops::check_multiply("a", shape(na, pa, ca), "b", shape(pb, nt, cb))
        .map_err(py_err)?;
    let channels = |n: usize| if n == 3 { Channels::rgb() } else { layout(n) };
    let right = Operand::from_values(pb, nt, channels(cb), b.as_slice()?);
    let transform = coefficients
        .map(|c| ChannelTransform::new(c, ca, "coefficients"))
        .transpose()
        .map_err(py_err)?;
    let ops = RowOps::new(ca, vec![right], transform, None);
    let nout = ops.out_ncomp();
    let left = a.as_slice()?;
    let out = py.detach(|| {
        let row_out = nt * nout;
        let mut out = vec![0.0; na * row_out];
        out.par_chunks_mut(row_out.max(1))
            .zip(left.par_chunks(pa * ca).take(na))
            .for_each_init(
                || ops.clone(),
                |ops, (o, row)| o.copy_from_slice(ops.apply(row)),
            );
        out
    });
    Ok(Array3::from_shape_vec((na, nt, nout), out)
        .map_err(|e| usage(format!("internal shape error: {e}")))?
        .into_pyarray(py))
}

/// Channel layout of `n` components as matrix headers without WAVELENGTH_SPLITS have it.
fn layout(n: usize) -> Channels {
    Channels {
        ncomp: n,
        ..Channels::rgb()
    }
}

/// An `(N, T)` array as a double-precision matrix in memory (exact), for the readers the
/// tools use.
fn lux_bytes(a: &[f64], nrows: usize, ncols: usize, name: &str) -> Result<Vec<u8>, Error> {
    let m = Matrix {
        nrows,
        ncols,
        channels: Channels::mono(),
        data: a.to_vec(),
    };
    m.write(
        Vec::new(),
        name,
        Header::new(),
        WriteOptions::new(DataFormat::Double),
    )
}

/// `rmetrics`: TAI, UDI, DA, sDA (and ASE with `direct_sun`) per sensor and for the room.
#[pyfunction]
#[pyo3(signature = (illuminance, weather=None, direct_sun=None, hours=None, occupied="8-18".to_string(), weekdays=false, jan1=None, schedule=None, all_steps=false, udi=(100.0, 300.0, 3000.0), da=300.0, sda=50.0, ase=(1000.0, 250.0), positions=None))]
#[allow(clippy::too_many_arguments)]
fn annual_metrics<'py>(
    py: Python<'py>,
    illuminance: PyReadonlyArray2<'py, f64>,
    weather: Option<String>,
    direct_sun: Option<PyReadonlyArray2<'py, f64>>,
    hours: Option<String>,
    occupied: String,
    weekdays: bool,
    jan1: Option<String>,
    schedule: Option<String>,
    all_steps: bool,
    udi: (f64, f64, f64),
    da: f64,
    sda: f64,
    ase: (f64, f64),
    positions: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    use rdaylight_metrics::config::ScheduleOptions;
    use rdaylight_metrics::{LuxRows, Thresholds, annual::column_names, read_options};
    let (n, t) = illuminance.as_array().dim();
    let illum = illuminance.as_slice()?;
    let direct = match &direct_sun {
        Some(d) => {
            let (dn, dt) = d.as_array().dim();
            Some((d.as_slice()?, dn, dt))
        }
        None => None,
    };
    let pos: Option<Vec<SensorRay>> = match &positions {
        Some(p) => {
            let a = p.as_array();
            if a.ncols() < 3 {
                return Err(usage("positions: expected an (N, 3) or (N, 6) array"));
            }
            Some(
                a.rows()
                    .into_iter()
                    .map(|r| SensorRay::new([r[0], r[1], r[2]], [0.0, 0.0, 1.0]))
                    .collect(),
            )
        }
        None => None,
    };
    let sched = ScheduleOptions {
        weather,
        hours,
        occupied,
        weekdays,
        jan1,
        flags: schedule,
        all_steps,
    };
    let thresholds = Thresholds {
        udi_low: udi.0,
        udi_mid: udi.1,
        udi_high: udi.2,
        da,
        sda_percent: sda,
        ase_lux: ase.0,
        ase_hours: ase.1,
    };
    const ILLUM: &str = "<illuminance>";
    const DIRECT: &str = "<direct_sun>";
    let (res, table) = py
        .detach(|| -> Result<_, Error> {
            thresholds.check()?;
            let bytes = lux_bytes(illum, n, t, ILLUM)?;
            let mut rows = LuxRows::new(MatrixReader::new(&bytes[..], ILLUM, &read_options())?)?;
            let schedule = sched.spec()?.build(t, ILLUM)?;
            let dbytes = direct
                .map(|(d, dn, dt)| lux_bytes(d, dn, dt, DIRECT))
                .transpose()?;
            let mut drows = match &dbytes {
                Some(b) => Some(LuxRows::new(MatrixReader::new(
                    &b[..],
                    DIRECT,
                    &read_options(),
                )?)?),
                None => None,
            };
            let res =
                rdaylight_metrics::compute(&mut rows, drows.as_mut(), &schedule, &thresholds)?;
            if let Some(p) = &pos {
                if p.len() != res.sensors.len() {
                    return Err(Error::Mismatch(format!(
                        "positions: {} sensor points but the illuminance has {} rows",
                        p.len(),
                        res.sensors.len()
                    )));
                }
            }
            let mut table = Vec::new();
            rdaylight_metrics::report::write_tsv(
                &mut table,
                ILLUM,
                &res,
                &thresholds,
                pos.as_deref(),
            )?;
            Ok((res, String::from_utf8_lossy(&table).into_owned()))
        })
        .map_err(py_err)?;
    let d = PyDict::new(py);
    let room = PyDict::new(py);
    let names = column_names(res.with_ase);
    for (k, name) in names.iter().enumerate() {
        let v: Array1<f64> = res.sensors.iter().map(|s| s.values()[k]).collect();
        d.set_item(*name, v.into_pyarray(py))?;
        room.set_item(*name, res.room[k])?;
    }
    d.set_item("room", room)?;
    d.set_item("columns", PyList::new(py, &names)?)?;
    d.set_item("notes", PyList::new(py, &res.notes)?)?;
    d.set_item("occupied_steps", res.occupied_steps)?;
    d.set_item("occupied_hours", res.occupied_hours)?;
    d.set_item("table", table)?;
    Ok(d)
}

/// `rglare` / evalglare: glare metrics of one picture.
#[pyfunction]
#[pyo3(signature = (picture, threshold=None, radius=0.2, peaks=true, peak_limit=50000.0, smooth=false, task=None, low_light=false))]
#[allow(clippy::too_many_arguments)]
fn glare<'py>(
    py: Python<'py>,
    picture: String,
    threshold: Option<f64>,
    radius: f64,
    peaks: bool,
    peak_limit: f64,
    smooth: bool,
    task: Option<(usize, usize, f64)>,
    low_light: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use rdaylight_glare::{Options, Pixels, evaluate_pixels, picture_view, report};
    let mut opts = Options::default();
    opts.detect.threshold = threshold;
    opts.detect.radius = radius;
    opts.detect.peaks = peaks;
    opts.detect.peak_limit = peak_limit;
    opts.detect.smooth = smooth;
    opts.detect.task = task;
    opts.low_light = low_light;
    let e = py
        .detach(|| -> Result<_, Error> {
            let f = std::fs::File::open(&picture).map_err(|e| Error::io(&picture, e))?;
            let pic =
                rdaylight_formats::picture::Picture::read(std::io::BufReader::new(f), &picture)?;
            let view = picture_view(&pic, &picture, None)?;
            let p = Pixels::new(&pic, view.setup()?);
            if let Some((x, y, _)) = task {
                if x >= p.xres || y >= p.yres {
                    return Err(Error::Usage(format!(
                        "{picture}: task position {x} {y} outside the {}x{} picture",
                        p.xres, p.yres
                    )));
                }
            }
            Ok(evaluate_pixels(&p, &opts))
        })
        .map_err(py_err)?;
    let m = &e.metrics;
    let d = PyDict::new(py);
    for (k, v) in [
        ("dgp", m.dgp),
        ("dgi", m.dgi),
        ("ugr", m.ugr),
        ("vcp", m.vcp),
        ("cgi", m.cgi),
        ("lveil", m.lveil),
        ("dgr", m.dgr),
        ("ugp", m.ugp),
        ("ev", e.e_v),
        ("e_dir", e.e_dir),
        ("avlum", e.avlum),
        ("lum_backg", e.lum_backg),
        ("lum_task", e.lum_task),
        ("lum_sources", e.lum_sources),
        ("omega_sources", e.omega_sources),
        ("threshold", e.threshold),
    ] {
        d.set_item(k, v)?;
    }
    let sources = PyList::empty(py);
    for s in &e.sources {
        let sd = PyDict::new(py);
        sd.set_item("npix", s.npix)?;
        sd.set_item("x", s.x)?;
        sd.set_item("y", s.y)?;
        sd.set_item("lum", s.lum)?;
        sd.set_item("omega", s.omega)?;
        sd.set_item("pos", s.pos)?;
        sd.set_item("dir", s.dir.to_vec())?;
        sources.append(sd)?;
    }
    d.set_item("sources", sources)?;
    d.set_item("notices", PyList::new(py, &e.notices)?)?;
    d.set_item("line", report::default_line(&e))?;
    d.set_item("detailed", report::detailed(&e))?;
    Ok(d)
}

/// `rglod`'s object options (shared by `rmcop`): grouping, frame, shell tolerance,
/// permanent patterns and level thresholds.
#[allow(clippy::too_many_arguments)]
fn glod_options(
    by: &str,
    separator: String,
    connect_tolerance: f64,
    frame: &str,
    tolerance: f64,
    permanent: Vec<String>,
    thresholds: Option<(f64, f64, f64)>,
) -> PyResult<rdaylight_glod::Options> {
    use rdaylight_glod::{Frame, Grouping, Options, Thresholds};
    let grouping = match by {
        "prefix" => Grouping::Prefix(separator),
        "modifier" => Grouping::Modifier,
        "connectivity" => Grouping::Connectivity(connect_tolerance),
        "source" => Grouping::Source,
        o => {
            return Err(usage(format!(
                "by={o}: expected prefix, modifier, connectivity or source"
            )));
        }
    };
    let frame = match frame {
        "axes" => Frame::Axes,
        "walls" => Frame::Walls,
        o => return Err(usage(format!("frame={o}: expected axes or walls"))),
    };
    let thresholds = match thresholds {
        Some((glod1, glod2, glod3)) => {
            let t = Thresholds {
                glod1,
                glod2,
                glod3,
            };
            t.validate().map_err(py_err)?;
            t
        }
        None => Thresholds::default(),
    };
    let opts = Options {
        grouping,
        frame,
        tolerance,
        permanent,
        thresholds,
    };
    opts.validate().map_err(py_err)?;
    Ok(opts)
}

/// `rglod objects --json`: the GLoD analysis of a scene (seed chapter 2) as JSON text.
#[pyfunction]
#[pyo3(signature = (scene, by="prefix", separator=".".to_string(), connect_tolerance=1e-3, frame="axes", tolerance=0.01, permanent=Vec::new(), thresholds=None, percentiles=false))]
#[allow(clippy::too_many_arguments)]
fn glod_objects(
    py: Python<'_>,
    scene: Vec<String>,
    by: &str,
    separator: String,
    connect_tolerance: f64,
    frame: &str,
    tolerance: f64,
    permanent: Vec<String>,
    thresholds: Option<(f64, f64, f64)>,
    percentiles: bool,
) -> PyResult<String> {
    let opts = glod_options(
        by,
        separator,
        connect_tolerance,
        frame,
        tolerance,
        permanent,
        thresholds,
    )?;
    py.detach(|| -> Result<String, Error> {
        let s = load_scene(&scene)?;
        let mut a = rdaylight_glod::analyse(&s, &opts)?;
        if percentiles {
            // As `rglod --percentiles`: the scene's own 75th/50th/25th area percentiles.
            let areas: Vec<f64> = a.objects.iter().map(|o| o.area).collect();
            let t = rdaylight_glod::percentiles(&areas).ok_or_else(|| {
                Error::Usage(format!(
                    "percentiles: {} has no non-permanent objects to take percentiles of; \
                     give thresholds instead",
                    scene.join(" ")
                ))
            })?;
            a.relevel(&t)?;
        }
        Ok(rdaylight_glod::report::json(&a))
    })
    .map_err(py_err)
}

/// `rmcop study`: material uncertainty (MCoP draws) at each GLoD, reduced to the cells'
/// statistics. Returns (cell table as rmcop prints it, the cells as JSON).
#[pyfunction]
#[pyo3(signature = (scene, weather, sensors, sigmas=vec![0.05, 0.10, 0.15, 0.20], draws=500, levels=vec![0, 1, 2, 3, 4], by="material", classes=Vec::new(), truncate="redraw", materials=None, hourly=false, occupied="8-18".to_string(), ab=5, ad=10000, lw=1e-5, seed=1, threads=None, objects="prefix", separator=".".to_string(), permanent=Vec::new(), thresholds=None))]
#[allow(clippy::too_many_arguments)]
fn mcop_study(
    py: Python<'_>,
    scene: Vec<String>,
    weather: String,
    sensors: PyReadonlyArray2<'_, f64>,
    sigmas: Vec<f64>,
    draws: usize,
    levels: Vec<u8>,
    by: &str,
    classes: Vec<(String, String)>,
    truncate: &str,
    materials: Option<Vec<String>>,
    hourly: bool,
    occupied: String,
    ab: u32,
    ad: usize,
    lw: f64,
    seed: u64,
    threads: Option<usize>,
    objects: &str,
    separator: String,
    permanent: Vec<String>,
    thresholds: Option<(f64, f64, f64)>,
) -> PyResult<(String, String)> {
    use rdaylight_mcop::{Grouping, StudyConfig, Truncation};
    let rays = sensor_rays(&sensors)?;
    // rmcop's object options: rglod's, connectivity within 1 mm, axes frame.
    let glod = glod_options(
        objects, separator, 1e-3, "axes", 0.01, permanent, thresholds,
    )?;
    let sigma_text: Vec<String> = sigmas.iter().map(|s| s.to_string()).collect();
    let cfg = StudyConfig {
        trace: rdaylight_glod::study::StudyConfig {
            sampling: Sampling {
                ab,
                ad,
                lw,
                ..Sampling::default()
            },
            mf: 1,
            seed,
            occupied: rdaylight_metrics::schedule::parse_range(&occupied).map_err(py_err)?,
            threads,
        },
        // Through rmcop's parser: the same checks and messages as --sigmas.
        sigmas: rdaylight_mcop::classes::parse_sigmas(&sigma_text.join(",")).map_err(py_err)?,
        draws,
        levels,
        truncation: match truncate {
            "redraw" => Truncation::Redraw,
            "clip" => Truncation::Clip,
            o => return Err(usage(format!("truncate={o}: expected redraw or clip"))),
        },
        grouping: match by {
            "material" => Grouping::Material,
            "class" => Grouping::Class,
            o => return Err(usage(format!("by={o}: expected material or class"))),
        },
        class_rules: classes,
        materials,
        hourly,
        ..StudyConfig::default()
    };
    cfg.validate().map_err(py_err)?;
    py.detach(|| -> Result<_, Error> {
        let w = rdaylight_formats::weather::Weather::read_path(&weather)?;
        let s = load_scene(&scene)?;
        let analysis = rdaylight_glod::analyse(&s, &glod)?;
        let quiet = &rdaylight_base::progress::QUIET;
        let prep = rdaylight_mcop::prepare(&s, &analysis, &w, &rays, &cfg, quiet)?;
        let recs = rdaylight_mcop::draws(&prep, &cfg, quiet);
        let results = rdaylight_mcop::reduce(&prep, &cfg, &recs)?;
        let cells = serde_json::to_string(&results.cells)
            .map_err(|e| Error::Usage(format!("mcop cells as JSON: {e}")))?;
        Ok((rdaylight_mcop::report::cells_tsv(&results), cells))
    })
    .map_err(py_err)
}

#[pymodule]
fn _rdaylight(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(daylight_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(sun_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(point_values, m)?)?;
    m.add_function(wrap_pyfunction!(read_sensors, m)?)?;
    m.add_function(wrap_pyfunction!(sky_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(multiply, m)?)?;
    m.add_function(wrap_pyfunction!(annual_metrics, m)?)?;
    m.add_function(wrap_pyfunction!(glare, m)?)?;
    m.add_function(wrap_pyfunction!(glod_objects, m)?)?;
    m.add_function(wrap_pyfunction!(mcop_study, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
