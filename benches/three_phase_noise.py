#!/usr/bin/env python3
"""rdc --flux against real rfluxmtx at equal noise: the shading example's view matrix V and
daylight matrix D (docs/benchmarking.md rules 2-4; figures in docs/performance.md and
docs/three-phase.md).

Same scene bytes (examples/shading/: materials.rad, geometry.rad, the Klems sender/receiver
window.rad; examples/room/skydome.rad for D), the same 165 sensors, the same -ab and -lw.
Noise is per matrix entry: the coefficient of variation (sample std / mean) of each entry's
photopic value (0.265 R + 0.670 G + 0.065 B) over 3 independent runs, median over the entries
that matter (the largest entries of the runs' mean that together carry 90 % of its total; the
many near-empty Klems patches would otherwise decide the figure). Radiance has no seed option:
V run k prepends 7k copies of the first sensor (rows dropped), D run k uses -c C+k (C, C+1,
C+2 rays per patch), which reshuffles every sample; ours use -s 1, 2, 3. Ours runs at several
sample counts (-ad for V, -c for D); our CPU time at Radiance's noise is interpolated on a
log-log line through the two bracketing points (no assumed t^-1/2). Times are CPU seconds
(user + sys of the whole process tree: rfluxmtx's rcontrib and oconv included), median of the
3 runs, both single-process (rfluxmtx's default -n 1, rdc -n 1).

Usage: python3 benches/three_phase_noise.py [--which V,D] [--rad-c 250] [--ours-ad ...]
       [--ours-c ...]
Needs: cargo build --release (or RDAYLIGHT_BIN=dir with rdc); pyradiance (make radiance).
"""
import argparse
import math
import os
import resource
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from radiance_env import radiance_env  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = os.path.join(ROOT, "examples", "shading")
BIN = os.environ.get("RDAYLIGHT_BIN") or os.path.join(
    os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target"), "release")
LIT = [os.path.join(EX, "materials.rad"), os.path.join(EX, "geometry.rad")]
WINDOW = os.path.join(EX, "window.rad")
SKY = os.path.join(ROOT, "examples", "room", "skydome.rad")
SENSORS = os.path.join(ROOT, "examples", "room", "sensors.pts")
# The Makefile's shading-example settings (D's -c is an option: -c 1000 costs Radiance
# about 2 CPU minutes per run).
V_OPTS = ["-ab", "5", "-lw", "1e-5"]
D_OPTS = ["-ab", "2", "-ad", "1000", "-lw", "1e-4"]




def run(cmd, stdin_bytes, env=None):
    """Run from the repository root; return (stdout bytes, CPU seconds of the process tree)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, input=stdin_bytes, capture_output=True, check=True, env=env,
                         cwd=ROOT).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return out, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def photopic(mtx, skip_rows=0):
    """A Radiance float matrix (header, NROWS/NCOLS/NCOMP=3) as photopic entries, the first
    skip_rows rows dropped: a flat list, row-major."""
    import array

    head, _, body = mtx.partition(b"\n\n")
    info = dict(l.split("=", 1) for l in head.decode().splitlines() if "=" in l)
    assert info["FORMAT"].strip() == "float" and info["NCOMP"].strip() == "3", info
    ncols = int(info["NCOLS"])
    a = array.array("f")
    a.frombytes(body)
    if info.get("BigEndian", "0").strip() == "1" and sys.byteorder == "little":
        a.byteswap()
    y = [0.265 * a[i] + 0.670 * a[i + 1] + 0.065 * a[i + 2] for i in range(0, len(a), 3)]
    return y[skip_rows * ncols:]


def noise(runs):
    """Median CV over the entries carrying 90 % of the mean matrix's total."""
    means = [statistics.mean(v) for v in zip(*runs)]
    order = sorted(range(len(means)), key=lambda i: -means[i])
    total, acc, keep = sum(means), 0.0, []
    for i in order:
        if acc >= 0.9 * total or means[i] <= 0:
            break
        keep.append(i)
        acc += means[i]
    cvs = [statistics.stdev([r[i] for r in runs]) / means[i] for i in keep]
    return statistics.median(cvs), len(keep)


def interpolate(points, target):
    """CPU time at noise `target` on a log-log line through the two bracketing (cpu, noise)
    points, or the two nearest if none bracket it (then flagged)."""
    pts = sorted((math.log(n), math.log(c)) for c, n in points if n > 0)
    t = math.log(target)
    for (n0, c0), (n1, c1) in zip(pts, pts[1:]):
        if min(n0, n1) <= t <= max(n0, n1) and n0 != n1:
            return math.exp(c0 + (c1 - c0) * (t - n0) / (n1 - n0)), True
    (n0, c0), (n1, c1) = (pts[0], pts[1]) if t < pts[0][0] else (pts[-2], pts[-1])
    return math.exp(c0 + (c1 - c0) * (t - n0) / (n1 - n0)), False


def measure(name, rad_cmds, ours_cmds, skips):
    """rad_cmds: 3 (cmd, stdin, setting) for Radiance, ours_cmds: {setting: 3 (cmd, stdin)};
    skips: rows to drop from Radiance run k."""
    env = radiance_env()
    rows = []
    runs, cpus = [], []
    for k, (cmd, stdin, _) in enumerate(rad_cmds):
        out, cpu = run(cmd, stdin, env)
        runs.append(photopic(out, skips[k]))
        cpus.append(cpu)
    rad_noise, n = noise(runs)
    rad_cpu = statistics.median(cpus)
    rows.append(("rfluxmtx", rad_cmds[0][2], rad_cpu, rad_noise, n))
    ours = []
    for setting, cmds in ours_cmds.items():
        runs, cpus = [], []
        for cmd, stdin in cmds:
            out, cpu = run(cmd, stdin)
            runs.append(photopic(out))
            cpus.append(cpu)
        nz, n = noise(runs)
        ours.append((statistics.median(cpus), nz))
        rows.append(("rdc --flux", setting, statistics.median(cpus), nz, n))
    print(f"\n{name}")
    print(f"{'program':<12} {'setting':>14} {'CPU s':>9} {'noise %':>8} {'entries':>8}")
    for prog, setting, cpu, nz, n in rows:
        print(f"{prog:<12} {setting:>14} {cpu:>9.2f} {100 * nz:>8.2f} {n:>8}")
    at, bracketed = interpolate(ours, rad_noise)
    print(f"{name}: rdc --flux CPU at rfluxmtx's noise ({100 * rad_noise:.2f} %): {at:.2f} s"
          f"{'' if bracketed else ' (extrapolated)'}; rfluxmtx {rad_cpu:.2f} s; "
          f"ratio {rad_cpu / at:.1f}x")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--which", default="V,D", help="V, D or V,D")
    ap.add_argument("--rad-ad", type=int, default=10000, help="rfluxmtx -ad for V (10000)")
    ap.add_argument("--rad-c", type=int, default=250, help="rfluxmtx -c for D (250)")
    ap.add_argument("--ours-ad", default="2500,10000,40000", help="rdc --flux -ad values for V")
    ap.add_argument("--ours-c", default="1000,4000,16000", help="rdc --flux -c values for D")
    args = ap.parse_args()
    rdc = os.path.join(BIN, "rdc")
    pts = open(SENSORS, "rb").read()
    first = pts.splitlines(keepends=True)[0]
    nsens = pts.count(b"\n")
    print(f"examples/shading, {nsens} sensors; load average {os.getloadavg()[0]:.1f}"
          " (CPU seconds are robust to other jobs, wall seconds are not quoted)")
    if "V" in args.which:
        rad = [(["rfluxmtx", "-I+", *V_OPTS, "-ad", str(args.rad_ad), "-faf", "-", WINDOW, *LIT],
                first * (7 * k) + pts, f"-ad {args.rad_ad}") for k in range(3)]
        ours = {f"-ad {ad}": [([rdc, "--flux", "-n", "1", "-I+", *V_OPTS, "-ad", str(ad), "-s",
                                str(s), "-faf", "-", WINDOW, *LIT], pts) for s in (1, 2, 3)]
                for ad in map(int, args.ours_ad.split(","))}
        measure("V (165 sensors x 145 Klems patches)", rad, ours, [7 * k for k in range(3)])
    if "D" in args.which:
        rad = [(["rfluxmtx", *D_OPTS, "-c", str(args.rad_c + k), "-faf", WINDOW, SKY, *LIT], b"",
                f"-c {args.rad_c}") for k in range(3)]
        ours = {f"-c {c}": [([rdc, "--flux", "-n", "1", *D_OPTS, "-c", str(c), "-s", str(s),
                              "-faf", WINDOW, SKY, *LIT], b"") for s in (1, 2, 3)]
                for c in map(int, args.ours_c.split(","))}
        measure("D (145 Klems patches x 146 sky patches)", rad, ours, [0, 0, 0])


if __name__ == "__main__":
    sys.exit(main())
