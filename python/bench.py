"""Timings of the Python package (printed as a table; not a test): one call from Python vs
the CLI on the same file, a Smoother reused over 24 time steps vs 24 separate calls, and 24
files on a Dask LocalCluster of 2 one-thread worker processes vs a serial loop.
Usage: python python/bench.py [TOPOSMOOTH_BINARY]"""

import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import toposmooth

ROOT = pathlib.Path(__file__).resolve().parents[1]
BIN = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target" / "release" / "toposmooth")
sys.path.insert(0, str(ROOT / "python" / "tests"))
from test_many import vortex_street  # noqa: E402


def best(f, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    rows = []
    piv = ROOT / "datasets" / "soapfilm_piv_vorticity_63x63.csv"
    h = np.genfromtxt(piv, delimiter=",")
    args = dict(spacing=(0.31248, -0.31248), minima=9, maxima=4, fill_missing=True)
    with tempfile.TemporaryDirectory() as d:
        out = pathlib.Path(d) / "piv.npz"
        flags = ["--fill-missing", "--spacing", "0.31248,-0.31248", "--minima", "9", "--maxima", "4"]
        rows.append(("PIV 63x63, one call from Python", best(lambda: toposmooth.smooth(h, **args))))
        rows.append(("PIV 63x63, the CLI (a process, CSV in, NPZ out)",
                     best(lambda: subprocess.run([BIN, "-q", "smooth", str(piv), *flags, "-o", str(out)], check=True, capture_output=True))))
        rows.append(("PIV 63x63, toposmooth.cli in process", best(lambda: toposmooth.cli("smooth", piv, *flags, "-o", out))))
    for ny, nx in [(40, 96), (200, 300)]:
        frames = vortex_street(24, ny, nx)
        s = dict(persistence="8%", spacing=(0.5, 0.5))
        def reused():
            sm = toposmooth.Smoother(frames[0].shape, **s)
            for f in frames:
                sm.smooth(f)
        def separate():
            for f in frames:
                toposmooth.smooth(f, **s)
        rows.append((f"24 steps {ny}x{nx}, Smoother reused", best(reused, 2)))
        rows.append((f"24 steps {ny}x{nx}, 24 separate calls", best(separate, 2)))
        def serial1():
            for f in frames:
                toposmooth.smooth(f, threads=1, **s)
        rows.append((f"24 steps {ny}x{nx}, serial, threads=1", best(serial1, 2)))
        import xarray as xr
        from distributed import Client, LocalCluster
        da = xr.DataArray(frames, dims=("time", "y", "x")).chunk({"time": 2})
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c, Client(c):
            rows.append((f"24 steps {ny}x{nx}, xarray on LocalCluster(2x1)",
                         best(lambda: toposmooth.xarray.smooth(da, threads=1, persistence="8%").compute(), 2)))
    width = max(len(r[0]) for r in rows)
    for name, t in rows:
        print(f"{name:<{width}}  {t:8.3f} s")


if __name__ == "__main__":
    main()
