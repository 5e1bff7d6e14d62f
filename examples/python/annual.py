"""make's main job from Python: the example room's annual daylight metrics.

The same pipeline as the Makefile's `example` target, step by step (each call names the
tool it stands for), printing the same room line as `make`:

    python examples/python/annual.py            # under a minute; 2.8 GB at its peak

    rdc -I -ab 5 -ad 10000 -lw 1e-5 -s 1 -m 1 room.rad skydome.rad < sensors.pts  (sky)
    rdc -I --suns 6 -ad 1 room.rad skydome.rad < sensors.pts                       (suns)
    rspecsky -m 1 weather.epw ; rspecsky -m 6 -5 0.533 -d weather.epw             (skies)
    rmtx -c 47.4 119.9 11.6 ...                                                    (lux)
    rmetrics -w weather.epw --pts sensors.pts --direct-sun direct_sun.mtx ill.mtx
"""

import pathlib
import sys
import time

import numpy as np

import rdaylight as rd

REPO = pathlib.Path(__file__).resolve().parents[2]
ROOM = REPO / "examples" / "room"
EPW = REPO / "examples" / "weather" / "GBR_London.Gatwick.037760_IWEC.epw"
SCENE = [ROOM / "room.rad", ROOM / "skydome.rad"]


def as_float_file(a):
    """`make` keeps its matrices in float files (rdc -faf, rspecsky -of, rmtx -ff); rounding
    to float32 at the same steps makes the room line equal to make's digit for digit
    (without it the metrics agree to about 1e-6)."""
    return a.astype(np.float32).astype(np.float64)


def main():
    t0 = time.time()
    sensors = rd.read_sensors(ROOM / "sensors.pts")
    dc = as_float_file(rd.daylight_coefficients(SCENE, sensors, mf=1, ab=5, ad=10000,
                                                lw=1e-5, seed=1))
    suns = as_float_file(rd.sun_coefficients(SCENE, sensors, suns=6, ad=1))
    print(f"coefficients: sky {dc.shape}, suns {suns.shape} ({time.time() - t0:.0f} s)",
          file=sys.stderr)
    sky = as_float_file(rd.sky_matrix(EPW, mf=1))
    illuminance = as_float_file(rd.illuminance(dc, sky))
    del sky
    sun_sky = as_float_file(rd.sky_matrix(EPW, mf=6, five_phase_sun=0.533, sun_only=True))
    direct_sun = as_float_file(rd.illuminance(suns, sun_sky))
    del sun_sky
    m = rd.annual_metrics(illuminance, weather=EPW, direct_sun=direct_sun, positions=sensors)
    print(f"metrics of {illuminance.shape[0]} sensors x {illuminance.shape[1]} hours "
          f"({time.time() - t0:.0f} s)", file=sys.stderr)
    # The two lines `make` prints from rmetrics' table.
    rows = [line for line in m["table"].splitlines() if not line.startswith("#")]
    print("Room means (occupied 8-18 h, every day):")
    print(rows[0])
    print(rows[-1])
    r = m["room"]
    print(f"TAI {r['TAI_klxh']:.3f} klx.h, UDI-a {r['UDI_a']:.2f} %, DA {r['DA']:.2f} %, "
          f"sDA {r['sDA']:.0f} %, ASE {r['ASE']:.2f} %")


if __name__ == "__main__":
    main()
