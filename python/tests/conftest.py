"""Shared fixtures: the repository's datasets and the CLI binary the package is compared with."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATASETS = ROOT / "datasets"


@pytest.fixture(scope="session")
def datasets() -> pathlib.Path:
    return DATASETS


@pytest.fixture(scope="session")
def cli() -> "callable":
    """Runs the CLI (``TOPOSMOOTH_BIN``, default target/release/toposmooth) and returns the
    completed process; fails the test with the CLI's output when it exits non-zero."""
    binary = os.environ.get("TOPOSMOOTH_BIN", str(ROOT / "target" / "release" / "toposmooth"))
    if not os.access(binary, os.X_OK):
        pytest.fail(f"no toposmooth binary at {binary}: build it (cargo build --release) or set TOPOSMOOTH_BIN")

    def run(*args: str) -> subprocess.CompletedProcess:
        p = subprocess.run([binary, "-q", *map(str, args)], capture_output=True, text=True)
        assert p.returncode == 0, f"toposmooth {' '.join(map(str, args))}: exit {p.returncode}\n{p.stdout}\n{p.stderr}"
        return p

    return run


def strict_extrema(values: np.ndarray, neighbours) -> "tuple[set, set]":
    """Strict minima and maxima counted directly (every neighbour higher, resp. lower): an
    independent check of the certificate, written from SPEC.md's definition."""
    mins, maxs = set(), set()
    for v in range(values.size):
        nb = neighbours(v)
        if all(values[w] > values[v] for w in nb):
            mins.add(v)
        if all(values[w] < values[v] for w in nb):
            maxs.add(v)
    return mins, maxs


def grid_neighbours(nx: int, ny: int):
    """SPEC.md's grid: each cell split by the diagonal from (c, r) to (c+1, r+1), six
    neighbours inside: left, right, up, down and the two along that diagonal."""

    def nb(v: int):
        r, c = divmod(v, nx)
        out = []
        for dr, dc in [(0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1)]:
            rr, cc = r + dr, c + dc
            if 0 <= rr < ny and 0 <= cc < nx:
                out.append(rr * nx + cc)
        return out

    return nb


def series_neighbours(n: int):
    return lambda v: [w for w in (v - 1, v + 1) if 0 <= w < n]
