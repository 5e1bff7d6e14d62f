"""The Python package gives the command-line tools' numbers for the same settings.

Small inputs (three sensors, -ad 64) keep this to seconds; the full pipeline of `make` is
examples/python/annual.py.
"""

import json

import numpy as np
import pytest

import rdaylight as rd
from conftest import EPW, REPO, ROOM, read_matrix, write_matrix

SENSORS = np.array(
    [[1.0, 1.0, 0.8, 0, 0, 1], [3.0, 1.5, 0.8, 0, 0, 1], [5.0, 2.0, 0.8, 0, 0, 1]]
)
SENSOR_TEXT = "".join(" ".join(f"{v:g}" for v in r) + "\n" for r in SENSORS).encode()
SCENE = [str(ROOM / "room.rad"), str(ROOM / "skydome.rad")]


@pytest.fixture(scope="module")
def dc(tool):
    """rdc's sky coefficients and ours, same seed."""
    out = tool("rdc", "-I", "-ab", "2", "-ad", "64", "-m", "1", "-s", "7", "-fad", *SCENE,
               stdin=SENSOR_TEXT).stdout
    ours = rd.daylight_coefficients(SCENE, SENSORS, mf=1, ab=2, ad=64, seed=7)
    return read_matrix(out), ours


def test_daylight_coefficients_equal_rdc(dc):
    theirs, ours = dc
    assert ours.shape == (3, 146, 3)
    assert ours.sum() > 0
    # The same engine, the same per-record seeds: the same bytes.
    np.testing.assert_array_equal(ours, theirs)


def test_thread_count_does_not_change_coefficients():
    one = rd.daylight_coefficients(SCENE, SENSORS, ab=1, ad=32, seed=3, threads=1)
    two = rd.daylight_coefficients(SCENE, SENSORS, ab=1, ad=32, seed=3, threads=2)
    np.testing.assert_array_equal(one, two)


def test_sun_coefficients_equal_rdc(tool):
    out = tool("rdc", "-I", "--suns", "1", "-ad", "4", "-fad", *SCENE, stdin=SENSOR_TEXT).stdout
    ours = rd.sun_coefficients(SCENE, SENSORS, suns=1, ad=4)
    np.testing.assert_array_equal(ours, read_matrix(out))


@pytest.fixture(scope="module")
def skies(tool):
    total = tool("rspecsky", "-m", "1", "-od", EPW).stdout
    sun = tool("rspecsky", "-m", "1", "-5", "0.533", "-d", "-od", EPW).stdout
    return read_matrix(total), read_matrix(sun)


def test_sky_matrix_equals_rspecsky(skies):
    ours = rd.sky_matrix(EPW, mf=1)
    assert ours.shape == (146, 8760, 3)
    np.testing.assert_array_equal(ours, skies[0])
    sun = rd.sky_matrix(EPW, mf=1, sun_only=True, five_phase_sun=0.533)
    np.testing.assert_array_equal(sun, skies[1])
    # The sun-only sky is dark except at the sun's patch: fewer non-zeros per step.
    assert (sun > 0).sum() < (ours > 0).sum()


def test_product_and_metrics_equal_rmtx_and_rmetrics(tool, dc, skies, tmp_path):
    theirs_dc, ours_dc = dc
    write_matrix(tmp_path / "dc.mtx", theirs_dc)
    write_matrix(tmp_path / "sky.smx", skies[0])
    write_matrix(tmp_path / "sun.smx", skies[1])
    ill = read_matrix(tool("rmtx", "-fd", "-c", "47.4", "119.9", "11.6",
                           tmp_path / "dc.mtx", tmp_path / "sky.smx").stdout)[:, :, 0]
    lux = rd.illuminance(ours_dc, skies[0])
    assert lux.shape == (3, 8760)
    np.testing.assert_array_equal(lux, ill)
    # A sun-only product stands in for the direct-sun matrix (ASE's input).
    direct = rd.illuminance(ours_dc, skies[1])
    write_matrix(tmp_path / "ill.mtx", lux)
    write_matrix(tmp_path / "direct.mtx", direct)
    pts = tmp_path / "s.pts"
    pts.write_bytes(SENSOR_TEXT)
    tsv = tool("rmetrics", "-w", EPW, "--pts", pts, "--direct-sun", tmp_path / "direct.mtx",
               tmp_path / "ill.mtx").stdout.decode()
    m = rd.annual_metrics(lux, weather=EPW, direct_sun=direct, positions=SENSORS)
    rows = lambda t: [line for line in t.splitlines() if not line.startswith("#")]
    assert rows(m["table"]) == rows(tsv)
    assert m["columns"] == rows(tsv)[0].split("\t")[4:]
    room = rows(tsv)[-1].split("\t")
    for k, name in enumerate(m["columns"]):
        assert m[name].shape == (3,)
        assert m["room"][name] == pytest.approx(float(room[4 + k]), abs=1e-6)
    assert m["occupied_steps"] == 3650


def test_multiply_with_transform_and_spectral_shapes():
    a = np.arange(2 * 4 * 3, dtype=float).reshape(2, 4, 3)
    b = np.arange(4 * 5 * 3, dtype=float).reshape(4, 5, 3)
    # Per-channel product, the definition dctimestep uses.
    want = np.einsum("npc,ptc->ntc", a, b)
    np.testing.assert_allclose(rd.multiply(a, b), want, rtol=1e-15)
    np.testing.assert_allclose(rd.multiply(a, b, [1, 2, 3])[:, :, 0], want @ [1, 2, 3], rtol=1e-15)


def test_glare_equals_rglare_and_evalglare(tool):
    pic = REPO / "radiance-fixtures" / "pictures" / "office_clear_window.hdr"
    out = tool("rglare", pic).stdout.decode()
    g = rd.glare(pic)
    assert g["line"] == out
    values = [float(v) for v in out.split(":")[1].split()]
    assert [g[k] for k in ("dgp", "dgi", "ugr", "vcp", "cgi", "lveil")] == pytest.approx(
        values, abs=1e-6)
    # evalglare's own -d table lists 4 sources and E_v 75007.2 lx for this picture.
    assert len(g["sources"]) == 4
    assert g["ev"] == pytest.approx(75007.214806, rel=1e-6)
    assert g["detailed"] == tool("rglare", "-d", pic).stdout.decode()


def box(name, mat, x0, y0, z0, x1, y1, z1):
    """A closed box of six polygons named NAME.face (one GLoD object by prefix)."""
    faces = {
        "bottom": [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],
        "top": [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
        "south": [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
        "north": [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],
        "west": [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],
        "east": [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
    }
    return "".join(
        f"{mat} polygon {name}.{f} 0 0 12 " + " ".join(f"{c:g}" for v in vs for c in v) + "\n"
        for f, vs in faces.items()
    )


@pytest.fixture(scope="module")
def furnished(tmp_path_factory):
    """The example room with a desk (GLoD1) and a small box (GLoD3): the furnished example
    room takes 15 s to analyse in the test profile, this one a fraction of a second."""
    path = tmp_path_factory.mktemp("furnished") / "room.rad"
    path.write_text((ROOM / "room.rad").read_text() + "\n"
                    + box("desk_1", "wall_mat", 2, 3, 0.6, 4, 4.5, 0.75)
                    + box("bin_1", "wall_mat", 5, 1, 0, 5.3, 1.3, 0.4))
    return path


def test_glod_objects_equal_rglod(tool, furnished):
    scene = furnished
    theirs = json.loads(tool("rglod", "objects", "--json", scene).stdout)
    ours = rd.glod_objects(scene)
    assert ours == theirs
    assert sorted(o["level"] for o in ours["objects"]) == [1, 3]


def test_errors_are_the_tools_messages(tool):
    p = tool("rspecsky", "-m", "0", EPW, check=False)
    assert p.returncode == 1
    with pytest.raises(ValueError) as e:
        rd.sky_matrix(EPW, mf=0)
    assert str(e.value) in p.stderr.decode()
    assert "\n" not in str(e.value)
    with pytest.raises(FileNotFoundError, match="no-such.epw"):
        rd.sky_matrix("no-such.epw")
    with pytest.raises(ValueError, match="-ad 0"):
        rd.daylight_coefficients(SCENE, SENSORS, ad=0)
    with pytest.raises(ValueError, match=r"\(N, 6\)"):
        rd.daylight_coefficients(SCENE, SENSORS[:, :3])
    with pytest.raises(ValueError, match=r"10 columns \(time steps\), but .* gives 8760 steps"):
        rd.annual_metrics(np.ones((2, 10)), weather=EPW)


def test_read_sensors_matches_the_file():
    s = rd.read_sensors(ROOM / "sensors.pts")
    assert s.shape == (165, 6)
    np.testing.assert_array_equal(s[0], [0.5, 0.5, 0.8, 0, 0, 1])


def test_mcop_study_equals_rmcop(tool, furnished, tmp_path):
    pts = tmp_path / "s.pts"
    pts.write_text("2 2 0.8 0 0 1\n4 3 0.8 0 0 1\n")
    args = ["--draws", "30", "--levels", "0,4", "--sigmas", "0.1", "-ab", "1", "-ad", "16",
            "-lw", "1e-3", "-s", "5"]
    theirs = tool("rmcop", "study", "-w", EPW, "--pts", pts, *args, "-o", tmp_path / "mcop",
                  furnished).stdout.decode()
    ours = rd.mcop_study(furnished, EPW, pts, sigmas=[0.1], draws=30,
                         levels=[0, 4], ab=1, ad=16, lw=1e-3, seed=5)
    assert ours["table"] == theirs
    assert [c["level"] for c in ours["cells"]] == [0, 4]
    # Material draws spread the room TAI: the 5-95 % band is not a point.
    for c in ours["cells"]:
        assert c["room_tai"]["p5"] < c["room_tai"]["p95"]


def test_point_values_equal_rdc(tool):
    skies = REPO / "radiance-fixtures" / "skies"
    scene = [str(ROOM / "room.rad"), str(skies / "overcast_gensky.rad"), str(skies / "skyglow.rad")]
    out = tool("rdc", "-I", "-ab", "1", "-ad", "32", "-s", "3", "-fad", *scene,
               stdin=SENSOR_TEXT).stdout
    ours = rd.point_values(scene, SENSORS, ab=1, ad=32, seed=3)
    assert ours.shape == (3, 3)
    np.testing.assert_array_equal(ours, read_matrix(out)[:, 0, :])
    assert (ours > 0).all()
