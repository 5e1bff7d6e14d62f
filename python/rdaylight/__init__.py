"""rdaylight: Radiance-compatible daylight tools for existing rooms, from Python.

The typed library behind the ``r*`` command-line tools, with NumPy arrays in and out.
Each function takes the options of one tool under the same names and gives the numbers
that tool writes for the same settings and seed:

==========================  ===============================  =============================
function                    tool                             Radiance counterpart
==========================  ===============================  =============================
``daylight_coefficients``   ``rdc -I -m MF``                 rcontrib ... -f reinhart.cal
``sun_coefficients``        ``rdc -I --suns MF``             rcontrib (five-phase suns)
``point_values``            ``rdc -I`` (scene with a sky)    rtrace -I
``sky_matrix``              ``rspecsky``                     gendaymtx
``multiply``                ``rmtx a b -c ...``              dctimestep, rmtxop
``illuminance``             ``rmtx -c 47.4 119.9 11.6``      dctimestep | rmtxop -c ...
``annual_metrics``          ``rmetrics``                     (TAI, UDI, DA, sDA, ASE)
``glare``                   ``rglare``                       evalglare
``glod_objects``            ``rglod objects --json``
``mcop_study``              ``rmcop study``
==========================  ===============================  =============================

A two-phase annual study (``examples/python/annual.py`` is the whole of ``make``)::

    import rdaylight as rd
    sensors = rd.read_sensors("examples/room/sensors.pts")          # (N, 6)
    dc = rd.daylight_coefficients(["examples/room/room.rad"], sensors,
                                  mf=1, ab=5, ad=10000, lw=1e-5, seed=1)  # (N, 146, 3)
    sky = rd.sky_matrix("site.epw", mf=1)                            # (146, 8760, 3)
    lux = rd.illuminance(dc, sky)                                    # (N, 8760)
    m = rd.annual_metrics(lux, weather="site.epw")
    print(m["room"]["DA"], m["DA"])                                  # room value, per sensor

Errors in the input raise ``ValueError`` (``FileNotFoundError``/``OSError`` for files)
with the tools' one-line messages. Long computations release the GIL, so they may run
in threads.
"""

from __future__ import annotations

import json as _json
import os as _os
from typing import Optional, Sequence, Union

import numpy as _np

from . import _rdaylight

__version__ = _rdaylight.__version__

PathLike = Union[str, "_os.PathLike[str]"]

#: Radiance's RGB to lux weights, 179 lm/W x (0.265, 0.670, 0.065) rounded as in
#: ``rmtxop -c 47.4 119.9 11.6`` (the weights of ``make``'s pipeline).
LUX_WEIGHTS = (47.4, 119.9, 11.6)

__all__ = [
    "LUX_WEIGHTS",
    "annual_metrics",
    "daylight_coefficients",
    "glare",
    "glod_objects",
    "mcop_study",
    "illuminance",
    "multiply",
    "point_values",
    "read_sensors",
    "sky_matrix",
    "sun_coefficients",
]


def _scene(scene) -> list:
    if isinstance(scene, (str, _os.PathLike)):
        return [_os.fspath(scene)]
    return [_os.fspath(s) for s in scene]


def _f64(a, ndim: int, what: str) -> _np.ndarray:
    a = _np.ascontiguousarray(a, dtype=_np.float64)
    if a.ndim != ndim:
        raise ValueError(f"{what}: expected a {ndim}-dimensional array, found shape {a.shape}")
    return a


def _sensors(sensors) -> _np.ndarray:
    if isinstance(sensors, (str, _os.PathLike)):
        return _rdaylight.read_sensors(_os.fspath(sensors))
    a = _f64(sensors, 2, "sensors")
    if a.shape[1] != 6:
        raise ValueError(
            f"sensors: expected an (N, 6) array of x y z dx dy dz, found shape {a.shape}"
        )
    return a


def _path(p) -> Optional[str]:
    return None if p is None else _os.fspath(p)


def read_sensors(path: PathLike) -> _np.ndarray:
    """Sensor rays of a ``.pts`` file (``x y z dx dy dz`` per line) as an ``(N, 6)`` array."""
    return _rdaylight.read_sensors(_os.fspath(path))


def daylight_coefficients(
    scene,
    sensors,
    mf: int = 1,
    ab: Optional[int] = None,
    ad: Optional[int] = None,
    lw: Optional[float] = None,
    lr: Optional[int] = None,
    seed: int = 0,
    threads: Optional[int] = None,
    direct: bool = False,
    irradiance: bool = True,
) -> _np.ndarray:
    """Sky-patch daylight coefficients, as ``rdc -I -m MF scene... < sensors``.

    scene: a ``.rad`` file or a list of them (no sky needed: every path that leaves the
    scene is binned by its direction). sensors: an ``(N, 6)`` array (``x y z dx dy dz``)
    or a ``.pts`` file. ``ab``, ``ad``, ``lw``, ``lr``: rcontrib's options and defaults
    (1, 350, 2e-3, -10). ``seed``: rdc's ``-s``; the numbers do not depend on
    ``threads`` (None: all cores). ``direct``: direct-only coefficients (``--direct``).
    ``irradiance``: sensors measure irradiance (``-I``).

    Returns ``(N, 144 mf^2 + 2, 3)`` float64: RGB coefficients per sensor and Reinhart
    patch, ground first (gendaymtx's row order), equal to rdc's output.
    """
    return _rdaylight.daylight_coefficients(
        _scene(scene), _sensors(sensors), mf, ab, ad, lw, lr, seed, threads, direct, irradiance
    )


def sun_coefficients(
    scene,
    sensors,
    suns: Optional[int] = None,
    weather: Optional[PathLike] = None,
    angle: float = 0.533,
    bounces: bool = False,
    ab: Optional[int] = None,
    ad: Optional[int] = None,
    lw: Optional[float] = None,
    lr: Optional[int] = None,
    seed: int = 0,
    threads: Optional[int] = None,
    irradiance: bool = True,
) -> _np.ndarray:
    """Sun coefficients, as ``rdc -I --suns MF|weather``.

    ``suns=MF``: one unit-radiance sun at each Reinhart MF patch centre (columns as
    ``gendaymtx -5 0.533 -d -m MF``; the ground column is 0); ``weather=FILE``: one sun per
    time step of a ``.wea``/``.epw`` file. ``angle``: the discs' apex angle in degrees;
    ``bounces``: with inter-reflection (``--suns-ab``). Returns ``(N, suns, 3)``.
    """
    return _rdaylight.sun_coefficients(
        _scene(scene), _sensors(sensors), suns, _path(weather), angle, bounces,
        ab, ad, lw, lr, seed, threads, irradiance,
    )


def point_values(
    scene,
    sensors,
    ab: Optional[int] = None,
    ad: Optional[int] = None,
    lw: Optional[float] = None,
    lr: Optional[int] = None,
    seed: int = 0,
    threads: Optional[int] = None,
    irradiance: bool = True,
) -> _np.ndarray:
    """Point-in-time RGB values under the scene's own sky (a gensky sky plus skyglow.rad),
    as ``rdc -I`` (``rtrace -I``): irradiance in W/m2, or radiance along the rays with
    ``irradiance=False``. Returns ``(N, 3)``; lux = ``values @ LUX_WEIGHTS``."""
    return _rdaylight.point_values(
        _scene(scene), _sensors(sensors), ab, ad, lw, lr, seed, threads, irradiance
    )


def sky_matrix(
    weather: PathLike,
    mf: int = 1,
    sun_only: bool = False,
    sky_only: bool = False,
    five_phase_sun: Optional[float] = None,
    ground: Optional[Sequence[float]] = None,
    sky_colour: Optional[Sequence[float]] = None,
    rotation: float = 0.0,
    solar_radiance: bool = False,
    interval: Optional[float] = None,
    skip_night: bool = False,
    average: bool = False,
    bands: Optional[int] = None,
    band_range: Optional[tuple] = None,
    model: str = "perez",
    aod: Optional[float] = None,
) -> _np.ndarray:
    """The annual sky matrix of a weather file (``.epw`` or ``.wea``), as ``rspecsky``
    (gendaymtx's letters: ``-m mf -d -s -5 deg -g r g b -c r g b -r deg -O 1 -i min -u
    -A -cs n -cw lo hi``; ``model="atmosphere"`` is gensdaymtx with ``--aod``).

    Returns ``(patches, steps, ncomp)`` float64: rows are the ground and the Reinhart
    patches (as the coefficients' columns), columns the time steps, RGB (ncomp 3) or
    ``bands`` spectral channels. Colours are applied before ``sun_only``/``sky_only``.
    """
    return _rdaylight.sky_matrix(
        _os.fspath(weather), mf, sun_only, sky_only, five_phase_sun,
        None if ground is None else [float(g) for g in ground],
        None if sky_colour is None else [float(c) for c in sky_colour],
        rotation, solar_radiance, interval, skip_night, average, bands,
        None if band_range is None else (float(band_range[0]), float(band_range[1])),
        model, aod,
    )


def multiply(a, b, coefficients: Optional[Sequence[float]] = None) -> _np.ndarray:
    """The per-channel matrix product ``a . b`` of ``(N, P, ncomp)`` and
    ``(P, T, ncomp)`` arrays (dctimestep), then with ``coefficients`` the channel transform
    of ``rmtxop -c`` (``nout x ncomp`` numbers). Returns ``(N, T, nout)``, as ``rmtx``."""
    a = _f64(a, 3, "a")
    b = _f64(b, 3, "b")
    c = None if coefficients is None else [float(x) for x in coefficients]
    return _rdaylight.multiply(a, b, c)


def illuminance(coefficients, sky, weights: Sequence[float] = LUX_WEIGHTS) -> _np.ndarray:
    """Illuminance in lux, ``(N, T)``: coefficients ``(N, P, 3)`` times a sky matrix
    ``(P, T, 3)``, weighted by ``weights`` (``rmtx -c 47.4 119.9 11.6 dc.mtx sky.smx``)."""
    return multiply(coefficients, sky, weights)[:, :, 0]


def annual_metrics(
    illuminance,
    weather: Optional[PathLike] = None,
    direct_sun=None,
    hours: Optional[PathLike] = None,
    occupied: str = "8-18",
    weekdays: bool = False,
    jan1: Optional[str] = None,
    schedule: Optional[PathLike] = None,
    all_steps: bool = False,
    udi: Sequence[float] = (100.0, 300.0, 3000.0),
    da: float = 300.0,
    sda: float = 50.0,
    ase: Sequence[float] = (1000.0, 250.0),
    positions=None,
) -> dict:
    """Annual daylight metrics of an ``(N, T)`` illuminance array in lux, as ``rmetrics``.

    The time stamps come from ``weather`` (the file the sky matrix was made from) or
    ``hours``; ``occupied``, ``weekdays``, ``jan1``, ``schedule``, ``all_steps``, ``udi``,
    ``da``, ``sda``, ``ase`` are rmetrics' options. ``direct_sun``: the ``(N, T)``
    direct-sun illuminance for ASE (``--direct-sun``). ``positions``: ``(N, 3)`` or
    ``(N, 6)`` sensor positions or a ``.pts`` file, written into the table.

    Returns a dict: per-sensor arrays under the metric names (``TAI_klxh``, ``UDI_n``,
    ``UDI_s``, ``UDI_a``, ``UDI_e``, ``DA``, ``sDA``, and ``ASE_h``, ``ASE`` with
    ``direct_sun``), ``room`` (the room values, a dict), ``columns`` (the names in order),
    ``notes``, ``occupied_steps``, ``occupied_hours`` and ``table`` (rmetrics' TSV text).
    """
    lux = _f64(illuminance, 2, "illuminance")
    d = None if direct_sun is None else _f64(direct_sun, 2, "direct_sun")
    if isinstance(positions, (str, _os.PathLike)):
        positions = read_sensors(positions)
    p = None if positions is None else _f64(positions, 2, "positions")
    return _rdaylight.annual_metrics(
        lux, _path(weather), d, _path(hours), occupied, weekdays, jan1, _path(schedule),
        all_steps, tuple(float(u) for u in udi), float(da), float(sda),
        tuple(float(a) for a in ase), p,
    )


def glare(
    picture: PathLike,
    threshold: Optional[float] = None,
    radius: float = 0.2,
    peaks: bool = True,
    peak_limit: float = 50000.0,
    smooth: bool = False,
    task: Optional[tuple] = None,
    low_light: bool = False,
) -> dict:
    """Glare of a fisheye or perspective HDR picture with a view in its header, as
    ``rglare`` (evalglare 3.x): ``threshold`` (``-b``), ``radius`` (``-r``), ``peaks``
    and ``peak_limit`` (``-y``/``-x``/``-Y``), ``smooth`` (``-s``), ``task`` = (x, y,
    opening rad) (``-t``), ``low_light`` (``-C l+``).

    Returns a dict: ``dgp``, ``dgi``, ``ugr``, ``vcp``, ``cgi``, ``lveil``, ``dgr``,
    ``ugp``, ``ev`` (vertical illuminance, lux), ``e_dir``, ``avlum``, ``lum_backg``,
    ``lum_task``, ``lum_sources``, ``omega_sources``, ``threshold``, ``sources`` (a dict
    per glare source), ``notices``, ``line`` (rglare's output line) and ``detailed``
    (``rglare -d``'s output).
    """
    t = None if task is None else (int(task[0]), int(task[1]), float(task[2]))
    return _rdaylight.glare(
        _os.fspath(picture), threshold, radius, peaks, peak_limit, smooth, t, low_light
    )


def glod_objects(
    scene,
    by: str = "prefix",
    separator: str = ".",
    connect_tolerance: float = 1e-3,
    frame: str = "axes",
    tolerance: float = 0.01,
    permanent: Sequence[str] = (),
    thresholds: Optional[Sequence[float]] = None,
    percentiles: bool = False,
) -> dict:
    """Geometrical Levels of Detail (seed chapter 2) of a scene, as ``rglod objects
    --json``: ``{"shell": [primitive indices], "objects": [{"id", "members", "obb",
    "area", "level"}]}``. ``by``: prefix, modifier, connectivity or source grouping;
    ``thresholds``: the minimum box areas (m2) of GLoD1, GLoD2 and GLoD3 (default 3.0,
    2.4, 0.5, the seed's); ``percentiles``: the scene's own 75th/50th/25th percentiles
    instead. ``frame``: axes or walls; ``permanent``: identifier patterns always kept."""
    t = None if thresholds is None else tuple(float(x) for x in thresholds)
    text = _rdaylight.glod_objects(
        _scene(scene), by, separator, connect_tolerance, frame, tolerance, list(permanent),
        t, percentiles,
    )
    return _json.loads(text)


def mcop_study(
    scene,
    weather: PathLike,
    sensors,
    sigmas: Sequence[float] = (0.05, 0.10, 0.15, 0.20),
    draws: int = 500,
    levels: Sequence[int] = (0, 1, 2, 3, 4),
    by: str = "material",
    classes: Optional[dict] = None,
    truncate: str = "redraw",
    materials: Optional[Sequence[str]] = None,
    hourly: bool = False,
    occupied: str = "8-18",
    ab: int = 5,
    ad: int = 10000,
    lw: float = 1e-5,
    seed: int = 1,
    threads: Optional[int] = None,
    objects: str = "prefix",
    separator: str = ".",
    permanent: Sequence[str] = (),
    thresholds: Optional[Sequence[float]] = None,
) -> dict:
    """Material Classes of Precision (seed chapter 3), as ``rmcop study``: every GLoD of
    ``levels`` traced once with path re-weighting records, ``draws`` material draws per
    (GLoD, sigma) cell, reduced to the room TAI's statistics.

    ``classes``: ``{class: glob}`` for ``by="class"`` (``--class CLASS=GLOB``);
    ``objects``, ``separator``, ``permanent``, ``thresholds``: the GLoD options (as
    ``glod_objects``). Returns ``{"table": rmcop's cell table (TSV text), "cells": [a dict
    per cell: level, sigma, room_tai (median, quartiles, p5, p95), free_room_tai, pe, mape,
    mape_vs_top, normality, ks, ...]}``.
    """
    t = None if thresholds is None else tuple(float(x) for x in thresholds)
    table, cells = _rdaylight.mcop_study(
        _scene(scene), _os.fspath(weather), _sensors(sensors),
        [float(x) for x in sigmas], draws, [int(v) for v in levels], by,
        list((classes or {}).items()), truncate,
        None if materials is None else list(materials), hourly, occupied, ab, ad, lw, seed,
        threads, objects, separator, list(permanent), t,
    )
    return {"table": table, "cells": _json.loads(cells)}
