"""Many fields: xarray over time, files on a Dask LocalCluster (2 worker processes of one
thread each), each bit-identical to a serial loop of toposmooth.smooth."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

import toposmooth

xr = pytest.importorskip("xarray")
distributed = pytest.importorskip("distributed")

STEPS, NY, NX = 24, 40, 96
SETTINGS = dict(persistence="8%")


def vortex_street(steps=STEPS, ny=NY, nx=NX, seed=0):
    """Vorticity of two rows of opposite vortices advected downstream, with seeded noise."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    frames = []
    for t in range(steps):
        w = np.zeros((ny, nx))
        for k in range(-1, 6):
            cx = (k * 18.0 + 1.5 * t) % (nx + 18) - 9
            for cy, sign, shift in [(ny * 0.33, 1.0, 0.0), (ny * 0.67, -1.0, 9.0)]:
                w += sign * np.exp(-((x - cx - shift) ** 2 + (y - cy) ** 2) / 18.0)
        frames.append(w + 0.04 * rng.standard_normal((ny, nx)))
    return np.array(frames)


@pytest.fixture(scope="module")
def cluster():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        with Client(c) as client:
            yield client


def serial(frames, threads=2):
    return np.array([toposmooth.smooth(f, spacing=(0.5, 0.5), threads=threads, **SETTINGS).smoothed for f in frames])


def test_xarray_over_time_on_the_cluster_is_the_serial_loop(cluster):
    frames = vortex_street()
    da = xr.DataArray(
        frames,
        dims=("time", "y", "x"),
        coords={"time": np.arange(STEPS), "y": np.arange(NY) * 0.5, "x": np.arange(NX) * 0.5},
        attrs={"units": "1/s"},
        name="vorticity",
    ).chunk({"time": 4})
    out = toposmooth.xarray.smooth(da, dims=("y", "x"), threads=1, **SETTINGS)
    assert out.chunks is not None, "stays lazy"
    got = out.compute()
    assert got.dims == ("time", "y", "x") and got.attrs["units"] == "1/s" and got.name == "vorticity"
    one, two = serial(frames, threads=1), serial(frames, threads=2)
    assert np.array_equal(one, two), "the thread count changes nothing"
    assert np.array_equal(got.values, one)
    roles = toposmooth.xarray.smooth(da, dims=("y", "x"), output="roles", **SETTINGS).compute()
    assert roles.dtype == np.int8 and (roles.values == 1).any()


def test_files_on_the_cluster_are_the_serial_loop(cluster, tmp_path):
    frames = vortex_street(seed=1)
    src = tmp_path / "in"
    src.mkdir()
    paths = []
    for t, f in enumerate(frames):
        p = src / f"step_{t:03d}.npy"
        np.save(p, f)
        paths.append(p)
    out = tmp_path / "out"
    out.mkdir()
    written = toposmooth.dask.smooth_files(paths, out, client=cluster, spacing="0.5,0.5", **SETTINGS)
    assert [w.name for w in written] == [p.name for p in paths]
    assert np.array_equal(np.array([np.load(w) for w in written]), serial(frames))
    # VTK outputs get a ParaView collection in input order
    vti = tmp_path / "vti"
    vti.mkdir()
    npz_paths = paths[:3]
    renamed = []
    for p in npz_paths:
        q = src / (p.stem + ".vti")
        toposmooth.cli("smooth", p, "-o", q, "--persistence", "50%")
        renamed.append(q)
    toposmooth.dask.smooth_files(renamed, vti, client=cluster, array="smoothed", **SETTINGS)
    pvd = ET.parse(vti / "collection.pvd").getroot()
    files = [d.get("file") for d in pvd.iter("DataSet")]
    assert files == [q.name for q in renamed]
    with pytest.raises(toposmooth.UsageError):
        toposmooth.dask.smooth_files([paths[0], src / ".." / "in" / paths[0].name], out)


def test_cli_in_process_raises_the_package_errors(tmp_path):
    with pytest.raises(toposmooth.UsageError):
        toposmooth.cli("smooth", "--no-such-flag")
    with pytest.raises(toposmooth.IoError) as e:
        toposmooth.cli("extrema", tmp_path / "missing.csv")
    assert "missing.csv" in str(e.value) and e.value.exit_code == 3


def test_xarray_fills_missing_samples_in_every_chunk():
    frames = vortex_street(steps=6, seed=3)
    frames[:, 5, 7] = np.nan
    da = xr.DataArray(frames, dims=("time", "y", "x")).chunk({"time": 2})
    out = toposmooth.xarray.smooth(da, fill_missing=True, **SETTINGS).compute(scheduler="synchronous")
    assert not np.isnan(out.values).any()
    ref = [toposmooth.smooth(f, fill_missing=True, **SETTINGS).smoothed for f in frames]
    assert np.array_equal(out.values, np.array(ref))
