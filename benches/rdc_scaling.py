#!/usr/bin/env python3
"""How rdc's time grows with triangle count and sensor count (issue 3, "Speed").

Scenes: the fixture office (radiance-fixtures/scenes/office.rad + sky_glow360.rad) with
furniture made of triangles added: tessellated spheres (grey plastic, 0.4) on a grid over
the floor, written as plain `polygon`s with 3 vertices to a temporary .rad, so rdc reads,
triangulates and builds its BVH from text as it would a scanned mesh. For each size:

- load + compile (BVH build) time, from `rdc --stats` with no sensors;
- trace time for the 165 office sensors at -ab 3 -ad 1000 -lw 1e-4 (2 threads), with the
  rays cast by paths and rays per second (`--stats`);
- peak resident memory of the run (os.wait4's ru_maxrss).

Then sensor count: 10, 100, 1000 sensors (random points at desk height) in the plain office.

Usage: python3 benches/rdc_scaling.py [--sizes 10000,100000,1000000] [--ad 1000]
Needs: cargo build --release. Prints two tables.
"""
import argparse
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIX = os.path.join(ROOT, "radiance-fixtures")
RDC = os.path.join(ROOT, "target", "release", "rdc")
STATS = re.compile(
    r"load ([\d.]+) s, compile ([\d.]+) s \(BVH build ([\d.]+) s; (\d+) surfaces, (\d+) "
    r"primitives\), trace ([\d.]+) s, (\d+) path rays"
)


def sphere_triangles(c, r, nlat, nlon):
    """A UV sphere as triangles (outward winding), 2 nlon (nlat - 1) triangles."""
    def p(i, j):
        th = math.pi * i / nlat
        ph = 2 * math.pi * j / nlon
        return (c[0] + r * math.sin(th) * math.cos(ph),
                c[1] + r * math.sin(th) * math.sin(ph),
                c[2] + r * math.cos(th))
    for i in range(nlat):
        for j in range(nlon):
            a, b, cc, d = p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)
            if i > 0:
                yield (a, b, d)
            if i < nlat - 1:
                yield (b, cc, d)


def furniture(path, ntri):
    """Write about `ntri` triangles of spheres on a grid over the office floor."""
    nspheres = 64
    per = max(ntri // nspheres, 8)
    # 2 nlon (nlat - 1) ~ per with nlon = 2 nlat.
    nlat = max(int(math.sqrt(per / 4)) + 1, 3)
    nlon = 2 * nlat
    n = 0
    with open(path, "w") as f:
        f.write("void plastic furniture 0 0 5 0.4 0.4 0.4 0 0\n")
        k = 0
        for gx in range(8):
            for gy in range(8):
                c = (0.5 + gx * 5.0 / 7, 1.5 + gy * 6.0 / 7, 0.35)
                for t in sphere_triangles(c, 0.25, nlat, nlon):
                    f.write(f"furniture polygon t{k} 0 0 9 "
                            + " ".join(f"{x:.6f} {y:.6f} {z:.6f}" for x, y, z in t) + "\n")
                    k += 1
                    n += 1
    return n


def run_ru(cmd, stdin_bytes):
    """Run with os.wait4 to get the child's own rusage."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as i, tempfile.TemporaryFile() as e:
        i.write(stdin_bytes)
        i.seek(0)
        pid = os.posix_spawn(cmd[0], cmd, dict(os.environ),
                             file_actions=[(os.POSIX_SPAWN_DUP2, i.fileno(), 0),
                                           (os.POSIX_SPAWN_OPEN, 1, "/dev/null", os.O_WRONLY, 0),
                                           (os.POSIX_SPAWN_DUP2, e.fileno(), 2)])
        _, status, ru = os.wait4(pid, 0)
        wall = time.perf_counter() - t0
        e.seek(0)
        err = e.read().decode()
    if status != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return wall, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0, err


def stats(err):
    m = STATS.search(err)
    if not m:
        sys.exit(f"no --stats line in: {err}")
    load, comp, bvh, surf, prims, trace, rays = m.groups()
    return float(load), float(comp), float(bvh), int(surf), int(prims), float(trace), int(rays)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="10000,100000,1000000")
    ap.add_argument("--ad", type=int, default=1000)
    ap.add_argument("--sensors", default="10,100,1000")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()
    office = os.path.join(FIX, "scenes", "office.rad")
    sky = os.path.join(FIX, "scenes", "sky_glow360.rad")
    pts = open(os.path.join(FIX, "sensors", "office.pts"), "rb").read()
    nsens = len([l for l in pts.splitlines() if l.strip()])
    common = ["-I", "-ab", "3", "-ad", str(args.ad), "-lw", "1e-4", "-m", "1", "-faf", "-n", "2",
              "--stats"]
    print(f"triangles: office + N triangles of spheres; {nsens} sensors, -ab 3 -ad {args.ad} "
          f"-lw 1e-4 -m 1, 2 threads")
    print(f"{'triangles':>10} {'file MB':>8} {'load s':>7} {'compile s':>9} {'BVH s':>6} "
          f"{'peak MiB (load)':>15} {'trace s':>8} {'CPU s':>7} {'Mrays':>7} {'Mrays/s':>8} "
          f"{'Mrays/CPU-s':>11} {'peak MiB':>9}")
    for size in [int(s) for s in args.sizes.split(",")]:
        rad = os.path.join(tmp, f"furniture{size}.rad")
        ntri = furniture(rad, size)
        mb = os.path.getsize(rad) / 1e6
        scene = [office, rad, sky]
        _, _, rss0, err0 = run_ru([RDC, *common, *scene], b"")
        load, comp, bvh, *_ = stats(err0)
        wall, cpu, rss, err = run_ru([RDC, *common, *scene], pts)
        _, _, _, _, prims, trace, rays = stats(err)
        # CPU of the tracing part: the run's CPU minus the (single-threaded) load + compile.
        # Trace CPU = run CPU - load/compile wall time; meaningless when the parallel BVH
        # build used more CPU than its wall time (then printed as nan).
        tcpu = cpu - load - comp
        print(f"{ntri:>10} {mb:>8.1f} {load:>7.2f} {comp:>9.2f} {bvh:>6.2f} {rss0:>15.0f} "
              f"{trace:>8.2f} {cpu:>7.2f} {rays/1e6:>7.2f} {rays/trace/1e6:>8.2f} "
              f"{(rays/tcpu/1e6 if tcpu > 0.5 * trace else float('nan')):>11.2f} {rss:>9.0f}")
        os.remove(rad)
    print()
    print(f"sensors: plain office, random desk-height points, -ab 3 -ad {args.ad}, 2 threads")
    print(f"{'sensors':>8} {'trace s':>8} {'CPU s':>7} {'s/sensor':>9} {'Mrays/s':>8} "
          f"{'Mrays/CPU-s':>11} {'peak MiB':>9}")
    rnd = random.Random(1)
    for n in [int(s) for s in args.sensors.split(",")]:
        lines = "".join(f"{rnd.uniform(0.2, 5.8):.4f} {rnd.uniform(0.2, 7.8):.4f} 0.8 0 0 1\n"
                        for _ in range(n))
        wall, cpu, rss, err = run_ru([RDC, *common, office, sky], lines.encode())
        load, comp, *_, trace, rays = stats(err)
        tcpu = cpu - load - comp
        print(f"{n:>8} {trace:>8.2f} {cpu:>7.2f} {trace/n:>9.4f} {rays/trace/1e6:>8.2f} "
              f"{(rays/tcpu/1e6 if tcpu > 0.5 * trace else float('nan')):>11.2f} {rss:>9.0f}")
    print(f"load average: {os.getloadavg()[0]:.1f} (2 cores; quote figures from an idle machine)")


if __name__ == "__main__":
    sys.exit(main())
