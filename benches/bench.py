#!/usr/bin/env python3
"""`make bench`: every pair of issue 18 in one table (ours against the Radiance program it
stands beside), run on the same machine and inputs, the two programs alternating, medians
of RUNS runs (short rows more, see `pair`) of whole-process CPU (user + sys), wall and
peak memory (/usr/bin/time), and the ratio Radiance / ours (above 1: ours is faster or
smaller). Not a test: the figures depend on the machine and its load, printed beside the
table (quote ratios from an idle machine). docs/performance.md keeps the latest table.

Rows (each needs pyradiance's Radiance 6 binaries, `make radiance`):
  sky MF 1 / MF 4      rspecsky -m N -of site.wea vs gendaymtx -m N -of site.wea (London IWEC year
                       through epw2wea: the same input for both)
  glare 1000 x 1000    rglare PIC                 vs evalglare PIC (an rpict fisheye of the
                       furnished office, sun in view; rendered once into the work folder)
  scene 1M triangles   rdc -ab 0 scene.rad (parse + BVH, one sensor)
                                                  vs oconv + rtrace -ab 0 (one ray)
  compiled scene       rdc -ab 0 scene.rdb (rdc --compile's file, made once)
                                                  vs rtrace -ab 0 on oconv's octree (made once)
  product MF 4         rmtx dc sky                vs dctimestep dc sky (165 x 2306 x 8760)
  equal noise         rdc at the -ad giving rcontrib -n 2 -ad 10000's per-sensor noise, both fixture
                       rooms (benches/rdc_vs_rcontrib.py, minutes per room)
  thread scaling      the same rdc job at -n 1 and -n 2 (CPU growth; same output bytes)
The main job's peak memory step by step is benches/memory.sh's. BENCH_QUICK=1 skips the
equal-noise and scaling rows.

Usage: python3 benches/bench.py [RUNS [ROW...]]   (BENCH_DIR keeps inputs between runs;
ROW: sky, glare, scene, product, to run only those rows and make only their inputs)
"""
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from radiance_env import radiance_env  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REL = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release")
EPW = os.path.join(ROOT, "examples", "weather", "GBR_London.Gatwick.037760_IWEC.epw")
FIX = os.path.join(ROOT, "radiance-fixtures")
ROOM = os.path.join(ROOT, "examples", "room")




ENV = radiance_env()


def sh(cmd, out=os.devnull, stdin=None, cwd=None):
    """Run a shell command, stdout to `out`; exit on failure."""
    with open(out, "wb") as f:
        r = subprocess.run(cmd, shell=True, stdout=f, stderr=subprocess.PIPE, env=ENV, cwd=cwd,
                           input=stdin)
    if r.returncode != 0:
        sys.exit(f"bench.py: `{cmd}` failed: {r.stderr.decode(errors='replace')[-400:]}")


def timed(cmd, work):
    """(cpu s, wall s, peak MiB) of one run of a shell command (a pipeline's peak is its
    largest process's; a `;` list is timed step by step, CPU and wall summed)."""
    cpu = wall = peak = 0.0
    for step in cmd.split(" ;; "):
        t = os.path.join(work, "time.txt")
        sh(f"/usr/bin/time -f '%U %S %e %M' -o {t} sh -c '{step}'")
        u, s, e, m = open(t).read().split()[-4:]
        cpu += float(u) + float(s)
        wall += float(e)
        peak = max(peak, float(m) / 1024)
    return cpu, wall, peak


def pair(name, ours, theirs, runs, work):
    a, b = [], []
    i = 0
    # Short rows get more runs (up to 7x RUNS, while the pair has taken under 3 s): a
    # median of 3 runs of a 0.1 s process moves by tens of percent with the machine.
    while i < runs or (i < 7 * runs and sum(x[1] + y[1] for x, y in zip(a, b)) < 3.0):
        a.append(timed(ours, work))
        b.append(timed(theirs, work))
        i += 1
    med = lambda v, k: statistics.median(x[k] for x in v)
    return [name] + [med(a, k) for k in range(3)] + [med(b, k) for k in range(3)]


def inputs(work, rows):
    """Inputs made once, for the rows asked for: the sky file, the fisheye, the
    1M-triangle scene (and its octree and compiled scene), the MF 4 coefficients and sky."""
    wea = os.path.join(work, "site.wea")
    if not os.path.exists(wea) and ("sky" in rows or "product" in rows):
        sh(f"epw2wea {EPW} {wea}")
    pic = os.path.join(work, "fisheye.hdr")
    if not os.path.exists(pic) and "glare" in rows:
        sh(f"oconv {FIX}/scenes/furnished.rad {FIX}/skies/clear_gendaylit.rad {FIX}/skies/skyglow.rad",
           os.path.join(work, "glare.oct"))
        sh("rpict -vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180 -x 1000 -y 1000 "
           f"-ab 1 -ad 128 -aa 0.2 -ar 16 -as 0 -ps 2 {work}/glare.oct", pic)
    tri = os.path.join(work, "tri1m.rad")
    if not os.path.exists(tri) and "scene" in rows:
        # 1,000,000 random triangles of ~5 cm in a 10 m box: one material, plain polygons
        # (what a scanned or converted room becomes), seeded.
        import random

        rnd = random.Random(18)
        with open(tri, "w") as f:
            # A uniform glow sky: rdc's point-in-time values need a light source.
            f.write("void glow sky 0 0 4 1 1 1 0\nsky source skydome 0 0 4 0 0 1 360\n")
            f.write("void plastic m 0 0 5 .5 .5 .5 0 0\n")
            for i in range(1_000_000):
                x, y, z = (rnd.uniform(0, 10) for _ in range(3))
                v = [(x, y, z)] + [(x + rnd.uniform(-.05, .05), y + rnd.uniform(-.05, .05),
                                    z + rnd.uniform(-.05, .05)) for _ in range(2)]
                f.write(f"m polygon t{i} 0 0 9 " + " ".join(f"{c:.5f}" for p in v for c in p) + "\n")
        with open(os.path.join(work, "one.pts"), "w") as f:
            f.write("5 5 5 0 0 1\n")
    if "scene" in rows:
        # Made once, like an octree: the compiled rows time their use, not their making.
        sh(f"{REL}/rdc --compile {work}/tri1m.rdb {tri}")
        sh(f"oconv {tri}", os.path.join(work, "tri1m.oct"))
    dc = os.path.join(work, "dc4.mtx")
    if not os.path.exists(dc) and "product" in rows:
        # The main job's settings (benches/memory.sh): dense enough rows that the product
        # is not a sparse one (at -ad 512 most patches of a row are zero).
        sh(f"{REL}/rdc -I -ab 5 -ad 10000 -lw 1e-5 -s 1 -m 4 -faf {ROOM}/room.rad < {ROOM}/sensors.pts", dc)
        sh(f"gendaymtx -m 4 -of {wea}", os.path.join(work, "sky4.smx"))
    return wea, pic, tri


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    if runs < 1 or runs > 50:
        sys.exit("bench.py: RUNS must be 1..50")
    known = ["sky", "glare", "scene", "product"]
    wanted = sys.argv[2:] or known
    if any(r not in known for r in wanted):
        sys.exit(f"bench.py: rows are {', '.join(known)}")
    sh("cargo build --release --quiet --bins", cwd=ROOT)
    work = os.environ.get("BENCH_DIR") or tempfile.mkdtemp(prefix="rdaylight-bench-")
    os.makedirs(work, exist_ok=True)
    wea, pic, tri = inputs(work, wanted)
    one = os.path.join(work, "one.pts")
    todo = [
        # The same input for both: gendaymtx reads only .wea (rspecsky reads the EPW too).
        ("sky", "sky matrix MF 1", f"{REL}/rspecsky -m 1 -of {wea} > /dev/null",
         f"gendaymtx -m 1 -of {wea} > /dev/null"),
        ("sky", "sky matrix MF 4", f"{REL}/rspecsky -m 4 -of {wea} > /dev/null",
         f"gendaymtx -m 4 -of {wea} > /dev/null"),
        ("glare", "fisheye glare 1000 x 1000", f"{REL}/rglare {pic} > /dev/null 2>&1",
         f"evalglare {pic} > /dev/null 2>&1"),
        ("scene", "1M-triangle scene: load + BVH + 1 ray",
         f"{REL}/rdc -I -ab 0 {tri} < {one} > /dev/null",
         f"oconv {tri} > {work}/tri.oct ;; echo 5 5 5 0 0 1 | rtrace -I -ab 0 -h {work}/tri.oct > /dev/null"),
        ("scene", "1M-triangle scene from its compiled file + 1 ray (rdc scene.rdb vs rtrace scene.oct)",
         f"{REL}/rdc -I -ab 0 {work}/tri1m.rdb < {one} > /dev/null",
         f"echo 5 5 5 0 0 1 | rtrace -I -ab 0 -h {work}/tri1m.oct > /dev/null"),
        ("product", "matrix product MF 4 (165 x 2306 x 8760)",
         f"{REL}/rmtx {work}/dc4.mtx {work}/sky4.smx > /dev/null",
         f"dctimestep {work}/dc4.mtx {work}/sky4.smx > /dev/null"),
    ]
    rows = [pair(name, ours, theirs, runs, work)
            for key, name, ours, theirs in todo if key in wanted]
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"# make bench: medians of {runs} or more alternating runs (short rows until the "
          f"pair has taken 3 s, at most {7 * runs}); load average {load}; "
          f"{os.cpu_count()} cores")
    print("| workload | ours CPU s | ours wall s | ours peak MB | Radiance CPU s | Radiance wall s | "
          "Radiance peak MB | CPU ratio | memory ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, oc, ow, om, rc, rw, rm in rows:
        print(f"| {name} | {oc:.2f} | {ow:.2f} | {om:.1f} | {rc:.2f} | {rw:.2f} | {rm:.1f} | "
              f"{rc / max(oc, 1e-3):.2f}x | {rm / max(om, 1e-3):.2f}x |")
    if os.environ.get("BENCH_QUICK"):
        print("\n(BENCH_QUICK: the equal-noise and thread-scaling rows skipped)")
        return
    # Daylight coefficients at equal per-sensor noise (minutes per scene: three rcontrib runs
    # at -ad 10000 and rdc at four -ad, its time interpolated at rcontrib's noise).
    print("\n| daylight coefficients at equal noise (benches/rdc_vs_rcontrib.py) | per-sensor CV "
          "(rcontrib's median) | rdc CPU s | rdc wall s | rcontrib -n 2 CPU s | rcontrib wall s | "
          "CPU ratio | wall ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in ("furnished", "office"):
        r = subprocess.run([sys.executable, os.path.join(ROOT, "benches", "rdc_vs_rcontrib.py"),
                            "--scene", scene, "--ours", "500,1000,2000,4000", "--json"],
                           capture_output=True, text=True, env=ENV)
        if r.returncode != 0:
            sys.exit(f"bench.py: rdc_vs_rcontrib.py --scene {scene} failed: {r.stderr[-400:]}")
        import json
        j = json.loads(r.stdout.strip().splitlines()[-1])
        print(f"| {scene} room, 165 sensors, -ab 5 -lw 1e-5, 2 threads | {100 * j['noise']:.2f} % | "
              f"{j['rdc_cpu']:.2f} | {j['rdc_wall']:.2f} | {j['rcontrib_cpu']:.2f} | "
              f"{j['rcontrib_wall']:.2f} | {j['rcontrib_cpu'] / j['rdc_cpu']:.1f}x | "
              f"{j['rcontrib_wall'] / j['rdc_wall']:.1f}x |")
    # Thread scaling: the same job (same bytes) at -n 1 and -n 2, CPU seconds.
    job = (f"{REL}/rdc -I -ab 5 -ad 4000 -lw 1e-5 -s 1 -m 1 -faf {FIX}/scenes/furnished.rad "
           f"{FIX}/scenes/sky_glow360.rad < {FIX}/sensors/office.pts > /dev/null")
    one, two = [], []
    for _ in range(runs):
        one.append(timed(job.replace("-s 1", "-s 1 -n 1"), work))
        two.append(timed(job.replace("-s 1", "-s 1 -n 2"), work))
    c1 = statistics.median(x[0] for x in one)
    c2 = statistics.median(x[0] for x in two)
    w1 = statistics.median(x[1] for x in one)
    w2 = statistics.median(x[1] for x in two)
    print(f"\nthread scaling, furnished room -ad 4000 (same output bytes): -n 1 {c1:.2f} CPU s "
          f"{w1:.2f} wall s; -n 2 {c2:.2f} CPU s {w2:.2f} wall s; CPU growth {100 * (c2 / c1 - 1):+.1f} %"
          f" (goal within 10 %), wall speed-up {w1 / w2:.2f}x on {os.cpu_count()} cores")
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"load average at the end: {load}")

if __name__ == "__main__":
    main()
