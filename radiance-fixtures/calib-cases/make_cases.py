#!/usr/bin/env python3
"""Independent hidden-effect cases for rcalib, simulated by REAL Radiance (issue 22).

rcalib's own cases (`rcalib synth`, crates/calib/src/cases.rs) are made by rcalib's own
simulator, so its errors cancel. These are not: the rooms, effects, sites and sensors are
written here, in Python, with nothing taken from rcalib; every reading comes from real
Radiance, `gendaylit M D H -W dni dhi` + `rtrace -I` per measured time step, at converged
settings, run twice (independent random sequences) so that each truth's own Monte Carlo
error is measured, not assumed.

Per case, in CASE/ (the user-side files first):
  model.rad     the room as the user modelled it (no hidden effect)
  sensors.csv   id,x,y,z,dx,dy,dz
  weather.wea   the measured time steps (gendaylit/.wea convention: longitude and time
                zone meridian in degrees WEST)
  readings.csv  month,day,hour,sensor,lux: the truth times a fixed calibration factor per
                sensor exp(N(0, 0.03)) and a factor per reading exp(N(0, 0.02)) (seeded),
                times the hidden sensor fault where there is one
  truth.rad     model.rad plus the hidden effect, as simulated
  truth.tsv     month, day, hour, sensor, lux of run 1 and run 2 (lux = 179 (0.265 R +
                0.670 G + 0.065 B))
  case.json     the hidden effects with their true parameters, the room, the site
Top level: cases.tsv (one line per case) and VERSION (rtrace -version).

Usage: radiance-fixtures/calib-cases/make_cases.py [CASE ...]   (all cases by default)
  SCENES_ONLY=1  rewrite model.rad, truth.rad and sensors.csv only (same geometry)
  OUT=DIR        write the cases there instead of beside this script
  AD=65536 AB=10 JOBS=2  sampling and parallel rtrace processes
  REFINE_DIFF=0.01 MAX_REFINE=64 REFINE_ROUNDS=2  sensors whose two runs differ by more
                (RMS over the steps) are traced again at up to 64 x AD, measured again, up
                to twice (per-sensor -ad and run difference in case.json)
  RADIANCE_BIN=/path/to/radiance/bin  optional; otherwise pip's pyradiance.
About 4 CPU-minutes per case at the defaults.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FIXTURES = HERE.parent
# Where the cases go (OUT=DIR for a trial run that leaves the committed ones alone).
DEST = Path(os.environ.get("OUT", HERE))
EPW = FIXTURES.parent / "examples" / "weather" / "GBR_London.Gatwick.037760_IWEC.epw"
SKYGLOW = FIXTURES / "skies" / "skyglow.rad"
AD = int(os.environ.get("AD", "65536"))
AB = int(os.environ.get("AB", "10"))
JOBS = int(os.environ.get("JOBS", "2"))
# Per-sensor refinement (see make_case): target RMS difference of the two runs, and the
# largest factor on -ad it may use.
REFINE_DIFF = float(os.environ.get("REFINE_DIFF", "0.01"))
MAX_REFINE = int(os.environ.get("MAX_REFINE", "64"))
REFINE_ROUNDS = int(os.environ.get("REFINE_ROUNDS", "2"))
# -aa 0: pure Monte Carlo, no irradiance cache (its interpolation error is not random);
# -lw below 1/AD so that roulette, not a weight cut, ends the paths.
RTRACE = ["rtrace", "-h", "-I", "-ab", str(AB), "-ad", str(AD), "-aa", "0", "-as", "0", "-lw", "1e-6"]
# One cheap ray first moves Radiance's random sequence on: run 2 is independent of run 1
# (rtrace has no seed option). Its result is dropped.
DUMMY = "0 0 200 0 0 1\n"
SENSOR_SIGMA = 0.03
READING_SIGMA = 0.02
# Photopic lux of Radiance RGB radiometry (rmtxop -c 47.4 119.9 11.6): 179 lm/W times
# Radiance's luminance coefficients 0.265, 0.670, 0.065 (radiance-notes, `bright()`).
LUX = (47.4, 119.9, 11.6)


def radiance_bin():
    if os.environ.get("RADIANCE_BIN"):
        b = Path(os.environ["RADIANCE_BIN"])
        lib = Path(os.environ.get("RAYPATH", b.parent / "lib"))
    else:
        import pyradiance

        root = Path(pyradiance.__file__).parent
        b, lib = root / "bin", root / "lib"
    if not (b / "rtrace").exists():
        sys.exit(f"make_cases.py: no rtrace in {b}")
    env = dict(os.environ)
    env["PATH"] = f"{b}:{env['PATH']}"
    env["RAYPATH"] = f".:{lib}"
    return env


# ---------------------------------------------------------------------------------------
# Geometry. Rooms are built in local coordinates: the main facade is the wall y = 0 with
# the outside at y < 0, x along it (0..W), y into the room (0..D), z up (0..H). The whole
# scene is then rotated about z so that the facade faces `facing` degrees east of north.
# ---------------------------------------------------------------------------------------


def rotate(p, facing):
    # The local facade normal (0, -1) faces 180 deg (south); rotating counter-clockwise by
    # phi = 180 - facing turns it to (sin facing, cos facing).
    phi = math.radians(180.0 - facing)
    c, s = math.cos(phi), math.sin(phi)
    return (p[0] * c - p[1] * s, p[0] * s + p[1] * c, p[2])


def normal(vs):
    v = np.array(vs, dtype=float)
    n = np.zeros(3)
    for i in range(len(v)):
        n += np.cross(v[i], v[(i + 1) % len(v)])
    return n


class Scene:
    def __init__(self, facing):
        self.facing = facing
        self.lines = []
        self.count = 0

    def comment(self, text):
        self.lines.append(f"\n# {text}")

    def raw(self, text):
        self.lines.append(text)

    def polygon(self, mat, verts, towards=None, name=None):
        """A polygon whose normal points along `towards` (local coordinates) if given."""
        if towards is not None and np.dot(normal(verts), towards) < 0:
            verts = verts[::-1]
        self.count += 1
        pts = [rotate(v, self.facing) for v in verts]
        body = "\n".join("\t" + " ".join(f"{c:.6g}" for c in p) for p in pts)
        name = name or f"surface{self.count}"
        self.lines.append(f"{mat} polygon {name} 0 0 {3 * len(pts)}\n{body}")

    def box(self, mat, lo, hi, name="box"):
        """An axis-aligned box (local axes), faces pointing outwards."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        c = ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)
        faces = [
            [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)],
            [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
            [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
            [(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)],
            [(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)],
            [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
        ]
        for k, f in enumerate(faces):
            centre = np.mean(np.array(f), axis=0)
            self.polygon(mat, f, towards=centre - np.array(c), name=f"{name}_{k}")

    def text(self):
        return "\n".join(self.lines) + "\n"


def wall_frame(w, d, h, wall):
    """Origin, along-wall unit vector, length and inward normal of wall `wall` (0 facade
    y=0, 1 x=W, 2 back y=D, 3 x=0)."""
    return {
        0: ((0, 0, 0), (1, 0, 0), w, (0, 1, 0)),
        1: ((w, 0, 0), (0, 1, 0), d, (-1, 0, 0)),
        2: ((w, d, 0), (-1, 0, 0), w, (0, -1, 0)),
        3: ((0, d, 0), (0, -1, 0), d, (1, 0, 0)),
    }[wall]


def build_room(room, mats, facing, extras=()):
    """The room's .rad text: materials, shell with glazed openings, optional exterior
    ground, then `extras` (callables adding hidden-effect geometry)."""
    w, d, h = room["w"], room["d"], room["h"]
    sc = Scene(facing)
    sc.raw(f"# {room['name']}: {w} x {d} x {h} m, facade facing {facing} deg east of north")
    sc.raw("# written by radiance-fixtures/calib-cases/make_cases.py")
    for name, rho in (("wall_mat", mats["wall"]), ("ceiling_mat", mats["ceiling"]),
                      ("floor_mat", mats["floor"]), ("ground_mat", mats["ground"])):
        sc.raw(f"void plastic {name} 0 0 5 {rho:.4g} {rho:.4g} {rho:.4g} 0 0")
    tn = mats["glass_tn"]
    sc.raw(f"# glass: normal-incidence transmittance {tn:.4g}")
    sc.raw(f"void glass glazing 0 0 3 {tn_to_tau(tn):.5g} {tn_to_tau(tn):.5g} {tn_to_tau(tn):.5g}")
    sc.raw("void plastic obstacle_mat 0 0 5 0.3 0.3 0.3 0 0")
    sc.raw("void plastic furniture_mat 0 0 5 0.45 0.4 0.35 0 0")
    sc.comment("floor and ceiling")
    sc.polygon("floor_mat", [(0, 0, 0), (w, 0, 0), (w, d, 0), (0, d, 0)], towards=(0, 0, 1),
               name="floor")
    sc.polygon("ceiling_mat", [(0, 0, h), (w, 0, h), (w, d, h), (0, d, h)], towards=(0, 0, -1),
               name="ceiling")
    for wall in range(4):
        org, along, length, inward = wall_frame(w, d, h, wall)
        ops = [o for o in room["windows"] if o["wall"] == wall]
        us = sorted({0.0, length} | {o["u"][k] for o in ops for k in (0, 1)})
        zs = sorted({0.0, h} | {o["z"][k] for o in ops for k in (0, 1)})
        sc.comment(f"wall {wall}")

        def at(u, z):
            return tuple(org[i] + u * along[i] + (z if i == 2 else 0.0) for i in range(3))

        piece = 0
        for u0, u1 in zip(us, us[1:]):
            for z0, z1 in zip(zs, zs[1:]):
                um, zm = (u0 + u1) / 2, (z0 + z1) / 2
                if any(o["u"][0] < um < o["u"][1] and o["z"][0] < zm < o["z"][1] for o in ops):
                    continue
                piece += 1
                sc.polygon("wall_mat", [at(u0, z0), at(u1, z0), at(u1, z1), at(u0, z1)],
                           towards=inward, name=f"wall{wall}_{piece}")
        for o in ops:
            (u0, u1), (z0, z1) = o["u"], o["z"]
            sc.polygon("glazing", [at(u0, z0), at(u1, z0), at(u1, z1), at(u0, z1)], towards=inward,
                       name=f"window{room['windows'].index(o)}")
    if room.get("ground", True):
        sc.comment("exterior ground, 60 x 60 m around the room, just below the floor")
        g = 30.0
        cx, cy = w / 2, d / 2
        sc.polygon("ground_mat", [(cx - g, cy - g, -0.01), (cx + g, cy - g, -0.01),
                                  (cx + g, cy + g, -0.01), (cx - g, cy + g, -0.01)],
                   towards=(0, 0, 1), name="ground")
    for extra in extras:
        extra(sc, room)
    return sc.text()


def tn_to_tau(tn):
    """Radiance glass transmissivity for a normal-incidence transmittance: the closed form
    given with the `glass` material in the Radiance Reference Manual (refractive index
    1.52)."""
    return (math.sqrt(0.8402528435 + 0.0072522239 * tn * tn) - 0.9166530661) / 0.0036261119 / tn


# ---------------------------------------------------------------------------------------
# Hidden effects, as geometry or materials (what a real site has), with true parameters.
# ---------------------------------------------------------------------------------------


def overhang(window, above, depth, overrun=0.5, thick=0.08):
    def add(sc, room):
        o = room["windows"][window]
        z = o["z"][1] + above
        sc.comment(f"hidden: overhang {depth} m deep, {above} m above window {window}'s head")
        sc.box("obstacle_mat", (o["u"][0] - overrun, -depth, z), (o["u"][1] + overrun, 0.0, z + thick),
               name="overhang")

    return add


def building(x0, x1, dist, height, depth=10.0):
    """A block across the street: x0..x1 along the facade, from `dist` to `dist + depth`
    metres in front of it, `height` metres high (ends and top as real buildings have)."""

    def add(sc, room):
        sc.comment(f"hidden: building x {x0}..{x1}, {dist} m away, {height} m high")
        sc.box("obstacle_mat", (x0, -dist - depth, 0.0), (x1, -dist, height), name="building")

    return add


def furniture(lo, hi, what):
    def add(sc, room):
        sc.comment(f"hidden: {what}")
        sc.box("furniture_mat", lo, hi, name="furniture")

    return add


# ---------------------------------------------------------------------------------------
# Rooms, sites, sensors
# ---------------------------------------------------------------------------------------

ROOMS = {
    # A small single office, one window, exterior ground.
    "studio": dict(name="studio", w=5.0, d=6.5, h=2.8,
                   windows=[dict(wall=0, u=(0.7, 4.3), z=(0.9, 2.3))]),
    # 11 m deep, narrow, a tall window, no exterior ground (the sensors see gendaylit's
    # ground glow).
    "deep": dict(name="deep", w=4.2, d=11.0, h=3.0, ground=False,
                 windows=[dict(wall=0, u=(0.5, 3.7), z=(0.8, 2.7))]),
    # A high room with a view window and a clerestory band on the same facade.
    "clerestory": dict(name="clerestory", w=7.0, d=7.5, h=3.8,
                       windows=[dict(wall=0, u=(2.0, 5.0), z=(0.9, 2.1)),
                                dict(wall=0, u=(0.5, 6.5), z=(2.9, 3.5))]),
    # A corner room, windows on the facade and on the side wall x = W.
    "corner": dict(name="corner", w=6.0, d=5.5, h=2.9,
                   windows=[dict(wall=0, u=(1.0, 4.6), z=(0.85, 2.4)),
                            dict(wall=1, u=(1.2, 3.8), z=(0.85, 2.4))]),
}

BASE_MATS = dict(wall=0.55, ceiling=0.8, floor=0.25, ground=0.2, glass_tn=0.8)


def sensors_for(room, vertical):
    """Work-plane sensors (0.8 m, up) on a grid away from the walls, plus eye-level
    vertical ones (1.2 m) facing the facade and facing away if `vertical`."""
    w, d = room["w"], room["d"]
    nx = 3 if w >= 5 else 2
    ny = 4 if d < 9 else 5
    out = []
    for j in range(ny):
        y = 0.9 + (d - 1.8) * j / (ny - 1)
        for i in range(nx):
            x = w * (i + 1) / (nx + 1)
            out.append((x, y, 0.8, 0.0, 0.0, 1.0))
    if vertical:
        out.append((w / 2, d * 0.45, 1.2, 0.0, -1.0, 0.0))
        out.append((w / 2, d * 0.7, 1.2, 0.0, -1.0, 0.0))
        out.append((w / 2 + 0.3, d * 0.45, 1.2, 0.0, 1.0, 0.0))
    return out


SITES = {
    # The IWEC file's own site (gendaylit: longitude and meridian in degrees west).
    "london": dict(place="London_Gatwick_GBR", lat=51.15, lon=0.18, tz=0.0, elev=62, shift=0),
    # Southern hemisphere: Melbourne, the London file's irradiance moved by six months
    # (same season, same day and clock hour): a plausible measured record for a site where
    # the sun passes to the north; sun positions are Melbourne's.
    "melbourne": dict(place="Melbourne_AUS", lat=-37.81, lon=-144.96, tz=-150.0, elev=31, shift=6),
}


def solar_altitude(lat, lon_w, tz_w, month, day, hour):
    """Sun altitude (deg), Spencer (1971) declination and equation of time, as a filter
    of usable steps only (gendaylit computes its own position)."""
    doy = (date_ordinal(month, day))
    g = 2 * math.pi * (doy - 1) / 365.0
    decl = (0.006918 - 0.399912 * math.cos(g) + 0.070257 * math.sin(g) - 0.006758 * math.cos(2 * g)
            + 0.000907 * math.sin(2 * g) - 0.002697 * math.cos(3 * g) + 0.00148 * math.sin(3 * g))
    eot = 229.18 * (0.000075 + 0.001868 * math.cos(g) - 0.032077 * math.sin(g)
                    - 0.014615 * math.cos(2 * g) - 0.040849 * math.sin(2 * g))
    solar_time = hour + eot / 60.0 + (tz_w - lon_w) / 15.0
    ha = math.radians(15.0 * (solar_time - 12.0))
    la = math.radians(lat)
    s = math.sin(la) * math.sin(decl) + math.cos(la) * math.cos(decl) * math.cos(ha)
    return math.degrees(math.asin(max(-1.0, min(1.0, s))))


DAYS = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]


def date_ordinal(month, day):
    return sum(DAYS[: month - 1]) + day


def read_epw():
    rows = []
    with open(EPW) as f:
        for line in f.readlines()[8:]:
            c = line.split(",")
            month, day, hour = int(c[1]), int(c[2]), int(c[3])
            rows.append((month, day, hour - 0.5, float(c[14]), float(c[15])))
    return rows


def pick_steps(site, seed, n=18):
    """`n` daylit measured hours: about 40 % sunny (DNI >= 400 W/m2), 30 % intermediate,
    30 % overcast or faint sun (DNI < 50), between 8 and 17 h, sun above 8 degrees, at most
    one per day, chosen with `seed`."""
    rng = np.random.default_rng(seed)
    pools = {"sun": [], "mid": [], "dull": []}
    for (m, d, h, dn, df) in read_epw():
        if not 8 <= h <= 17 or df < 20:
            continue
        m2 = (m - 1 + site["shift"]) % 12 + 1
        d2 = min(d, DAYS[m2 - 1])
        if solar_altitude(site["lat"], site["lon"], site["tz"], m2, d2, h) < 8.0:
            continue
        kind = "sun" if dn >= 400 else "mid" if dn >= 50 else "dull"
        pools[kind].append((m2, d2, h, dn, df))
    want = {"sun": round(0.4 * n), "mid": round(0.3 * n)}
    want["dull"] = n - want["sun"] - want["mid"]
    out, days = [], set()
    for kind in ("sun", "mid", "dull"):
        pool = pools[kind]
        for i in rng.permutation(len(pool)):
            if want[kind] == 0:
                break
            s = pool[i]
            if (s[0], s[1]) in days:
                continue
            days.add((s[0], s[1]))
            out.append(s)
            want[kind] -= 1
    return sorted(out)


# ---------------------------------------------------------------------------------------
# Cases: (room, site, facing, vertical sensors, hidden effects, true parameters)
# ---------------------------------------------------------------------------------------


def mats_with(**kw):
    m = dict(BASE_MATS)
    m.update(kw)
    return m


CASES = [
    dict(name="control-studio", room="studio", site="london", facing=180, vertical=False,
         truth=[], seed=11),
    dict(name="control-deep-north", room="deep", site="melbourne", facing=0, vertical=True,
         truth=[], seed=12),
    dict(name="control-clerestory", room="clerestory", site="london", facing=200, vertical=False,
         truth=[], seed=13),
    dict(name="glazing-clerestory", room="clerestory", site="london", facing=160, vertical=False,
         truth=[dict(effect="transmittance", scale=0.75)], mats=mats_with(glass_tn=0.6), seed=21),
    dict(name="glazing-corner-south", room="corner", site="melbourne", facing=10, vertical=True,
         truth=[dict(effect="transmittance", scale=0.8)], mats=mats_with(glass_tn=0.64), seed=22),
    dict(name="surfaces-deep", room="deep", site="london", facing=170, vertical=True,
         truth=[dict(effect="walls", scale=0.6), dict(effect="ceiling", scale=0.75)],
         mats=mats_with(wall=0.33, ceiling=0.6), seed=31),
    dict(name="overhang-high-studio", room="studio", site="london", facing=185, vertical=False,
         truth=[dict(effect="overhang", window=0, above=0.4, depth=1.4)],
         extras=[overhang(0, 0.4, 1.4)], seed=41),
    dict(name="overhang-north-deep", room="deep", site="melbourne", facing=355, vertical=False,
         truth=[dict(effect="overhang", window=0, above=0.15, depth=1.0)],
         extras=[overhang(0, 0.15, 1.0)], seed=42),
    dict(name="skyline-studio", room="studio", site="london", facing=175, vertical=False,
         truth=[dict(effect="obstruction", x=(-8.0, 14.0), dist=14.0, height=13.0)],
         extras=[building(-8.0, 14.0, 14.0, 13.0)], seed=51),
    dict(name="skyline-corner-south", room="corner", site="melbourne", facing=350, vertical=True,
         truth=[dict(effect="obstruction", x=(-20.0, 2.0), dist=9.0, height=10.0)],
         extras=[building(-20.0, 2.0, 9.0, 10.0)], seed=52),
    dict(name="shelf-clerestory", room="clerestory", site="london", facing=180, vertical=False,
         truth=[dict(effect="local-obstruction", what="shelf 1.6 x 0.4 x 2.0 m")],
         extras=[furniture((1.0, 3.4, 0.0), (2.6, 3.8, 2.0), "shelf 1.6 x 0.4 x 2.0 m")], seed=61),
    dict(name="partition-studio", room="studio", site="london", facing=180, vertical=False,
         truth=[dict(effect="local-obstruction", what="partition 2.0 x 0.05 x 1.6 m")],
         extras=[furniture((2.9, 2.2, 0.0), (4.9, 2.25, 1.6), "partition 2.0 x 0.05 x 1.6 m")],
         seed=62),
    dict(name="fault-corner", room="corner", site="london", facing=180, vertical=False,
         truth=[dict(effect="sensor-fault", sensor=4, factor=0.8)], fault=(4, 0.8), seed=71),
    dict(name="combined-skyline-glazing", room="studio", site="melbourne", facing=5,
         vertical=False,
         truth=[dict(effect="obstruction", x=(-10.0, 12.0), dist=12.0, height=11.0),
                dict(effect="transmittance", scale=0.8)],
         mats=mats_with(glass_tn=0.64), extras=[building(-10.0, 12.0, 12.0, 11.0)], seed=81),
]


def run(cmd, env, stdin=None, out=None):
    r = subprocess.run(cmd, input=stdin, env=env, capture_output=True, text=True, shell=isinstance(cmd, str))
    if r.returncode != 0:
        sys.exit(f"make_cases.py: {cmd if isinstance(cmd, str) else ' '.join(cmd)} failed: {r.stderr}")
    if out:
        Path(out).write_text(r.stdout)
    return r.stdout


def lux(line):
    r, g, b = (float(v) for v in line.split()[:3])
    return LUX[0] * r + LUX[1] * g + LUX[2] * b


def make_case(case, env, work):
    room = ROOMS[case["room"]]
    site = SITES[case["site"]]
    out = DEST / case["name"]
    out.mkdir(parents=True, exist_ok=True)
    model = build_room(room, BASE_MATS, case["facing"])
    truth = build_room(room, case.get("mats", BASE_MATS), case["facing"], case.get("extras", ()))
    (out / "model.rad").write_text(model)
    (out / "truth.rad").write_text(truth)
    sens = sensors_for(room, case["vertical"])
    ids = [f"p{i + 1:02d}" for i in range(len(sens))]
    rows = []
    for sid, s in zip(ids, sens):
        o = rotate(s[:3], case["facing"])
        dvec = rotate(s[3:], case["facing"])
        rows.append(f"{sid}," + ",".join(f"{v:.6g}" for v in (*o, *dvec)))
    (out / "sensors.csv").write_text("id,x,y,z,dx,dy,dz\n" + "\n".join(rows) + "\n")
    pts = "".join(
        " ".join(f"{v:.6g}" for v in (*rotate(s[:3], case["facing"]), *rotate(s[3:], case["facing"]))) + "\n"
        for s in sens
    )
    if os.environ.get("SCENES_ONLY"):
        # Rewrite the scene and sensor files only (names, comments): the truths stand.
        return None
    steps = pick_steps(site, case["seed"])
    wea = (f"place {site['place']}\nlatitude {site['lat']}\nlongitude {site['lon']}\n"
           f"time_zone {site['tz']}\nsite_elevation {site['elev']}\nweather_data_file_units 1\n")
    wea += "".join(f"{m} {d} {h:.3f} {dn:.0f} {df:.0f}\n" for (m, d, h, dn, df) in steps)
    (out / "weather.wea").write_text(wea)
    wdir = Path(work) / case["name"]
    wdir.mkdir()
    (wdir / "truth.rad").write_text(truth)

    def one(k):
        m, d, h, dn, df = steps[k]
        sky = run(["gendaylit", str(m), str(d), f"{h:.3f}", "-a", str(site["lat"]), "-o",
                   str(site["lon"]), "-m", str(site["tz"]), "-W", f"{dn:.0f}", f"{df:.0f}"], env)
        (wdir / f"s{k}.sky").write_text(sky + SKYGLOW.read_text())
        subprocess.run(["oconv", "truth.rad", f"s{k}.sky"], cwd=wdir, env=env, check=True,
                       stdout=open(wdir / f"s{k}.oct", "wb"))
        r1 = subprocess.run(RTRACE + [f"s{k}.oct"], cwd=wdir, env=env, input=pts, text=True,
                            capture_output=True, check=True).stdout.splitlines()
        r2 = subprocess.run(RTRACE + [f"s{k}.oct"], cwd=wdir, env=env, input=DUMMY + pts, text=True,
                            capture_output=True, check=True).stdout.splitlines()[1:]
        print(f"{case['name']}: step {k + 1}/{len(steps)} done", file=sys.stderr)
        return [(lux(a), lux(b)) for a, b in zip(r1, r2)]

    with ThreadPoolExecutor(JOBS) as pool:
        res = list(pool.map(one, range(len(steps))))
    # Sensors whose two runs differ by more than REFINE_DIFF (RMS over the steps) are traced
    # again, both runs, at the -ad that brings the expected difference under it (Monte
    # Carlo error ~ 1/sqrt(samples); a multiple of AD, at most MAX_REFINE x AD, with a
    # margin for the difference's own estimate from 18 steps), and measured again, for up
    # to REFINE_ROUNDS rounds: the back of a deep room needs far more samples than the
    # window row, and Radiance has no per-ray -ad.
    ad_of = [AD] * len(sens)

    def differences():
        out = []
        for i in range(len(sens)):
            r = [(a - b) / (0.5 * (a + b)) for a, b in (res[k][i] for k in range(len(steps)))
                 if a + b > 0]
            out.append(math.sqrt(sum(x * x for x in r) / max(len(r), 1)))
        return out

    for rnd in range(REFINE_ROUNDS):
        diffs = differences()
        redo = []
        for i, dv in enumerate(diffs):
            if dv > REFINE_DIFF and ad_of[i] < AD * MAX_REFINE:
                want = ad_of[i] * 1.2 * (dv / REFINE_DIFF) ** 2
                ad_of[i] = min(AD * MAX_REFINE, AD * math.ceil(want / AD))
                redo.append(i)
        if not redo:
            break

        def again(k):
            found = {}
            for i in redo:
                cmd = RTRACE[:]
                cmd[cmd.index("-ad") + 1] = str(ad_of[i])
                line = pts.splitlines()[i] + "\n"
                a = subprocess.run(cmd + [f"s{k}.oct"], cwd=wdir, env=env, input=line, text=True,
                                   capture_output=True, check=True).stdout.splitlines()[0]
                b = subprocess.run(cmd + [f"s{k}.oct"], cwd=wdir, env=env, input=DUMMY + line,
                                   text=True, capture_output=True, check=True).stdout.splitlines()[1]
                found[i] = (lux(a), lux(b))
            print(f"{case['name']}: step {k + 1}/{len(steps)} refined, round {rnd + 1} "
                  f"({len(redo)} sensors)", file=sys.stderr)
            return found

        with ThreadPoolExecutor(JOBS) as pool:
            for k, found in enumerate(pool.map(again, range(len(steps)))):
                for i, v in found.items():
                    res[k][i] = v
    diffs = differences()
    every = [(a - b) / (0.5 * (a + b)) for row in res for a, b in row if a + b > 0]
    rms_all = math.sqrt(sum(x * x for x in every) / max(len(every), 1))
    print(f"{case['name']}: runs differ {100 * rms_all:.2f} % RMS, worst sensor "
          f"{100 * max(diffs):.2f} %", file=sys.stderr)
    rng = np.random.default_rng(1000 + case["seed"])
    cal = np.exp(rng.normal(0.0, SENSOR_SIGMA, len(sens)))
    tsv = ["month\tday\thour\tsensor\tlux_run1\tlux_run2"]
    csv = ["month,day,hour,sensor,lux"]
    for k, (m, d, h, _, _) in enumerate(steps):
        noise = np.exp(rng.normal(0.0, READING_SIGMA, len(sens)))
        for i, sid in enumerate(ids):
            a, b = res[k][i]
            tsv.append(f"{m}\t{d}\t{h:.3f}\t{sid}\t{a:.6g}\t{b:.6g}")
            value = 0.5 * (a + b) * cal[i] * noise[i]
            if case.get("fault") and case["fault"][0] == i:
                value *= case["fault"][1]
            csv.append(f"{m},{d},{h:.3f},{sid},{value:.2f}")
    (out / "truth.tsv").write_text("\n".join(tsv) + "\n")
    (out / "readings.csv").write_text("\n".join(csv) + "\n")
    meta = dict(name=case["name"], room=room, site=site, facing=case["facing"],
                hidden=case["truth"], sensors=len(sens), steps=len(steps),
                sampling=" ".join(RTRACE[1:]), ad_per_sensor=ad_of, sensor_sigma=SENSOR_SIGMA,
                reading_sigma=READING_SIGMA, noise_seed=1000 + case["seed"],
                runs_differ_rms_per_sensor=[round(v, 5) for v in diffs],
                runs_differ_rms_all=round(rms_all, 5))
    (out / "case.json").write_text(json.dumps(meta, indent=1) + "\n")
    fam = "+".join(t["effect"] for t in case["truth"]) or "nothing"
    return f"{case['name']}\t{case['room']}\t{case['site']}\t{case['facing']}\t{len(sens)}\t{len(steps)}\t{fam}"


def write_index(line):
    """Add or replace one case's line of cases.tsv (kept in CASES order)."""
    index = DEST / "cases.tsv"
    old = {}
    if index.exists():
        for row in index.read_text().splitlines()[1:]:
            old[row.split("\t")[0]] = row
    old[line.split("\t")[0]] = line
    order = [c["name"] for c in CASES if c["name"] in old]
    index.write_text("case\troom\tsite\tfacing\tsensors\tsteps\thidden\n"
                     + "".join(old[n] + "\n" for n in order))


def main():
    env = radiance_bin()
    names = sys.argv[1:] or [c["name"] for c in CASES]
    unknown = set(names) - {c["name"] for c in CASES}
    if unknown:
        sys.exit(f"make_cases.py: unknown case(s) {sorted(unknown)}")
    work = tempfile.mkdtemp()
    try:
        for c in CASES:
            if c["name"] in names:
                line = make_case(c, env, work)
                if line:
                    write_index(line)
    finally:
        shutil.rmtree(work)
    (DEST / "VERSION").write_text(run(["rtrace", "-version"], env))


if __name__ == "__main__":
    main()
