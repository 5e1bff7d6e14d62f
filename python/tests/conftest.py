"""Shared helpers: where the command-line tools are, running them, reading their matrices.

The tests compare the Python package with the `r*` binaries of the same checkout. They are
found in $RDAYLIGHT_BIN, else in $CARGO_TARGET_DIR (or target/) under debug/ then
release/, else on PATH; `make test` sets RDAYLIGHT_BIN to the binaries `cargo test` built.
"""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
ROOM = REPO / "examples" / "room"
EPW = REPO / "examples" / "weather" / "GBR_London.Gatwick.037760_IWEC.epw"
TOOLS = ["rdc", "rspecsky", "rmtx", "rmetrics", "rglare", "rglod", "rmcop"]


def _bin_dir():
    env = os.environ.get("RDAYLIGHT_BIN")
    if env:
        return pathlib.Path(env)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for profile in ("debug", "release"):
        d = target / profile
        if all((d / t).is_file() for t in TOOLS):
            return d
    found = shutil.which("rdc")
    return pathlib.Path(found).parent if found else None


@pytest.fixture(scope="session")
def tool():
    d = _bin_dir()
    missing = [t for t in TOOLS if d is None or not (d / t).is_file()]
    if missing:
        pytest.fail(
            f"command-line tools not found ({', '.join(missing)}): build them with "
            "`cargo build --bins` or set RDAYLIGHT_BIN to their directory"
        )

    def run(name, *args, stdin=None, check=True):
        p = subprocess.run(
            [str(d / name), *map(str, args)], input=stdin, capture_output=True
        )
        if check and p.returncode != 0:
            raise AssertionError(f"{name} {' '.join(map(str, args))}: {p.stderr.decode()}")
        return p

    return run


def read_matrix(data: bytes) -> np.ndarray:
    """A Radiance matrix written with -fd/-od (binary float64) as (NROWS, NCOLS, NCOMP)."""
    end = data.index(b"\n\n")
    head = {}
    for line in data[:end].decode().splitlines():
        if "=" in line:
            k, v = line.split("=", 1)
            head[k.strip()] = v.strip()
    assert head["FORMAT"] == "double", head
    shape = (int(head["NROWS"]), int(head["NCOLS"]), int(head["NCOMP"]))
    order = "<" if head.get("BYTEORDER", "LittleEndian") == "LittleEndian" else ">"
    return np.frombuffer(data[end + 2 :], dtype=order + "f8").reshape(shape)


def write_matrix(path, a: np.ndarray):
    """(N, T) or (N, T, NCOMP) float64 as a Radiance binary double matrix."""
    a = np.ascontiguousarray(a, dtype="<f8")
    if a.ndim == 2:
        a = a[:, :, None]
    n, t, c = a.shape
    head = (
        f"#?RADIANCE\nNROWS={n}\nNCOLS={t}\nNCOMP={c}\nBYTEORDER=LittleEndian\n"
        "FORMAT=double\n\n"
    )
    pathlib.Path(path).write_bytes(head.encode() + a.tobytes())
