#!/usr/bin/env python3
"""rdc against real rcontrib at equal noise (docs/benchmarking.md rules 2-4).

Same scene bytes (radiance-fixtures/scenes/SCENE.rad + sky_glow360.rad; SCENE = furnished by
default, the issue's target, or office), same 165 sensors,
same -ab 5 -lw 1e-5. Noise = per-sensor coefficient of variation of annual photopic totals
(DC x the full-year average London sky) over 3 independent runs; rcontrib's runs are
independent because its default -u+ seeds from the clock (runs are spaced over seconds),
ours use -s 1, 2, 3. rdc runs at several -ad; the time at rcontrib's noise is interpolated
on a log-log line through the measured points (noise is not assumed to fall as t^-0.5).

Usage: python3 benches/rdc_vs_rcontrib.py [--scene furnished|office] [--ad 10000]
       [--ours 2500,5000,10000,20000]
Needs: cargo build --release; pyradiance (make radiance). Prints a table and the ratio.
"""
import argparse
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from radiance_env import radiance_env  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIX = os.path.join(ROOT, "radiance-fixtures")
BIN = os.path.join(ROOT, "target", "release")
Y = (47.45394, 119.94894, 11.59712)




def run(cmd, stdin_path, out_path, env=None, cwd=FIX):
    """Run, return (wall s, cpu s of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    with open(stdin_path, "rb") as i, open(out_path, "wb") as o:
        subprocess.run(cmd, stdin=i, stdout=o, check=True, env=env, cwd=cwd)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def totals(mtx):
    """Annual photopic totals per sensor via our rmtx (DC x average sky)."""
    sky = os.path.join(FIX, "sky", "london_year_m1_A.smx")
    out = subprocess.run(
        [os.path.join(BIN, "rmtx"), "-h", "-fa", "-c", *map(str, Y), mtx, sky],
        check=True, capture_output=True, text=True,
    ).stdout.split()
    return [float(v) for v in out]


def noise(runs):
    """Median and p95 over sensors of the coefficient of variation across runs."""
    cvs = []
    for vals in zip(*runs):
        m = statistics.mean(vals)
        cvs.append(statistics.stdev(vals) / m if m > 0 else 0.0)
    cvs.sort()
    return statistics.median(cvs), cvs[int(math.ceil(0.95 * len(cvs))) - 1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ad", type=int, default=10000, help="rcontrib -ad (default 10000)")
    ap.add_argument("--ours", default="2500,5000,10000,20000", help="rdc -ad values")
    ap.add_argument("--scene", default="furnished", choices=["furnished", "office"])
    ap.add_argument("--json", action="store_true",
                    help="also print one JSON line with the figures (for benches/bench.py)")
    args = ap.parse_args()
    scene = f"scenes/{args.scene}.rad"
    pts = os.path.join(FIX, "sensors", "office.pts")
    nsens = sum(1 for l in open(pts) if l.strip())
    tmp = tempfile.mkdtemp()
    env = radiance_env()
    oct_path = os.path.join(tmp, "office.oct")
    with open(oct_path, "wb") as o:
        subprocess.run(["oconv", scene, "scenes/sky_glow360.rad"],
                       stdout=o, check=True, env=env, cwd=FIX)
    rows = []
    rc_runs, rc_wall, rc_cpu = [], [], []
    for k in range(3):
        out = os.path.join(tmp, f"rc{k}.mtx")
        w, c = run(["rcontrib", "-n", "2", "-I+", "-ab", "5", "-ad", str(args.ad), "-lw", "1e-5",
                    "-faf", "-y", str(nsens), "-e", "MF:1", "-f", "reinhart.cal", "-b", "rbin",
                    "-bn", "Nrbins", "-m", "skyglow", oct_path], pts, out, env=env)
        rc_runs.append(totals(out))
        rc_wall.append(w)
        rc_cpu.append(c)
        time.sleep(1.1)  # a new clock second: a new rcontrib seed
    rc_noise = noise(rc_runs)
    rows.append(("rcontrib -n 2", args.ad, statistics.median(rc_wall), statistics.median(rc_cpu), *rc_noise))
    ours = []
    for ad in [int(a) for a in args.ours.split(",")]:
        runs, walls, cpus = [], [], []
        for seed in (1, 2, 3):
            out = os.path.join(tmp, f"rdc{ad}_{seed}.mtx")
            w, c = run([os.path.join(BIN, "rdc"), "-I", "-ab", "5", "-ad", str(ad), "-lw", "1e-5",
                        "-m", "1", "-faf", "-s", str(seed), "-n", "2", scene,
                        "scenes/sky_glow360.rad"], pts, out)
            runs.append(totals(out))
            walls.append(w)
            cpus.append(c)
        n = noise(runs)
        ours.append((statistics.median(walls), statistics.median(cpus), n[0]))
        rows.append(("rdc (2 threads)", ad, statistics.median(walls), statistics.median(cpus), *n))
    print(f"{args.scene}, {nsens} sensors, -ab 5 -lw 1e-5; noise = per-sensor CV of annual totals over 3 runs")
    print(f"{'program':<16} {'-ad':>6} {'wall s':>8} {'CPU s':>8} {'CV med %':>9} {'CV p95 %':>9}")
    for name, ad, w, c, m, p in rows:
        print(f"{name:<16} {ad:>6} {w:>8.2f} {c:>8.2f} {100*m:>9.2f} {100*p:>9.2f}")
    # Interpolate our wall time at rcontrib's median noise on a log-log line.
    target = rc_noise[0]
    pts_ = sorted((math.log(n), math.log(w)) for w, _, n in ours if n > 0)
    best = None
    for (n0, w0), (n1, w1) in zip(pts_, pts_[1:]):
        lo, hi = min(n0, n1), max(n0, n1)
        if lo <= math.log(target) <= hi and n1 != n0:
            best = math.exp(w0 + (w1 - w0) * (math.log(target) - n0) / (n1 - n0))
    if best is None and len(pts_) >= 2:  # extrapolate with the two noisiest... or quietest
        (n0, w0), (n1, w1) = (pts_[0], pts_[1]) if math.log(target) < pts_[0][0] else (pts_[-2], pts_[-1])
        best = math.exp(w0 + (w1 - w0) * (math.log(target) - n0) / (n1 - n0))
    if best:
        rc = statistics.median(rc_wall)
        print(f"rdc wall time at rcontrib's median noise ({100*target:.2f} %): {best:.2f} s; "
              f"rcontrib -n 2: {rc:.2f} s; ratio {rc/best:.2f}x")
    # The same on CPU time (robust when other jobs share the machine).
    cpts = sorted((math.log(n), math.log(c)) for _, c, n in ours if n > 0)
    cbest = None
    for (n0, c0), (n1, c1) in zip(cpts, cpts[1:]):
        lo, hi = min(n0, n1), max(n0, n1)
        if lo <= math.log(target) <= hi and n1 != n0:
            cbest = math.exp(c0 + (c1 - c0) * (math.log(target) - n0) / (n1 - n0))
    if cbest is None and len(cpts) >= 2:
        (n0, c0), (n1, c1) = (cpts[0], cpts[1]) if math.log(target) < cpts[0][0] else (cpts[-2], cpts[-1])
        cbest = math.exp(c0 + (c1 - c0) * (math.log(target) - n0) / (n1 - n0))
    if cbest:
        rcc = statistics.median(rc_cpu)
        print(f"rdc CPU time at that noise: {cbest:.2f} s; rcontrib: {rcc:.2f} CPU s; "
              f"CPU ratio {rcc/cbest:.2f}x")
    print(f"load average during the run: {os.getloadavg()[0]:.1f} (quote ratios from an idle machine)")
    if args.json:
        import json
        print(json.dumps({"scene": args.scene, "noise": target, "rcontrib_cpu": statistics.median(rc_cpu),
                          "rcontrib_wall": statistics.median(rc_wall), "rdc_cpu": cbest, "rdc_wall": best}))


if __name__ == "__main__":
    sys.exit(main())
