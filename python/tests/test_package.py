"""The Python package against the CLI and against SPEC.md's definitions, counted here."""

import csv
import doctest
import sys
import threading
import time

import numpy as np
import pytest

import toposmooth
from conftest import grid_neighbours, series_neighbours, strict_extrema


def piv(datasets):
    return np.genfromtxt(datasets / "soapfilm_piv_vorticity_63x63.csv", delimiter=",")


def test_grid_is_bit_identical_to_the_cli(datasets, cli, tmp_path):
    h = piv(datasets)
    assert h.shape == (63, 63) and np.isnan(h).sum() == 774
    out = tmp_path / "piv.npz"
    cli(
        "smooth",
        datasets / "soapfilm_piv_vorticity_63x63.csv",
        "--fill-missing",
        "--spacing",
        "0.31248,-0.31248",
        "--minima",
        "9",
        "--maxima",
        "4",
        "-o",
        out,
    )
    ref = np.load(out)
    r = toposmooth.smooth(h, spacing=(0.31248, -0.31248), minima=9, maxima=4, fill_missing=True)
    assert r.smoothed.shape == (63, 63)
    assert np.array_equal(r.smoothed, ref["smoothed"].reshape(63, 63))
    assert np.array_equal(r.representative, ref["representative"].reshape(63, 63))
    assert np.array_equal(r.roles, ref["role"].reshape(63, 63).astype(np.int8))
    assert r.filled.sum() == 774 and not np.isnan(r.smoothed).any()
    # the certificate, counted here on the six-neighbour grid
    mins, maxs = strict_extrema(r.smoothed.reshape(-1), grid_neighbours(63, 63))
    assert (len(mins), len(maxs)) == (9, 4)
    assert mins == set(r.kept_minima) and maxs == set(r.kept_maxima)
    # kept extrema keep their (filled) input values
    filled_input = ref["input"].reshape(-1)
    kept = np.concatenate([r.kept_minima, r.kept_maxima])
    assert np.array_equal(r.smoothed.reshape(-1)[kept], filled_input[kept])
    assert r.report["certificate"]["passed"] and r.certified


def read_series_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def test_series_from_pandas_dates_is_bit_identical_to_the_cli(datasets, cli, tmp_path):
    pd = pytest.importorskip("pandas")
    src = datasets / "fx_eur_per_usd_daily_1999_2017.csv"
    out = tmp_path / "fx.csv"
    cli("smooth", src, "--persistence", "8%", "-o", out)
    rows = read_series_csv(out)
    ref = np.array([float(r["output"]) for r in rows])
    df = pd.read_csv(src, parse_dates=["date"], index_col="date")
    series = df["eur_per_usd"]
    assert isinstance(series.index, pd.DatetimeIndex)
    r = toposmooth.smooth(series, persistence="8%")
    assert np.array_equal(r.smoothed, ref)
    # counted here: the strict extrema are the kept ones, besides free ends (role 3)
    mins, maxs = strict_extrema(r.smoothed, series_neighbours(len(ref)))
    ends = set(np.flatnonzero(r.roles == toposmooth.ROLE_END))
    assert mins - ends == set(r.kept_minima) and maxs - ends == set(r.kept_maxima)
    assert r.kept_minima.size + r.kept_maxima.size == 43 and r.certified
    # the same dates at another resolution (pandas 2+ parses to s, ms, us or ns) give x in days
    x = toposmooth._days_since_epoch(series.index)
    assert x[0] == 10595.0 and np.array_equal(toposmooth._days_since_epoch(series.index.as_unit("s")), x)


def test_float32_and_integer_inputs_are_accepted(datasets):
    h = piv(datasets)
    h = np.where(np.isnan(h), 0.0, h)
    r64 = toposmooth.smooth(h.astype(np.float32).astype(np.float64), minima=5, maxima=3)
    r32 = toposmooth.smooth(h.astype(np.float32), minima=5, maxima=3)
    assert np.array_equal(r32.smoothed, r64.smoothed)
    ints = (np.add.outer(np.arange(30), np.arange(40)) % 17).astype(np.int32)
    ri = toposmooth.smooth(ints, persistence=5)
    assert ri.smoothed.dtype == np.float64 and ri.certified


def test_a_contiguous_float64_input_is_not_copied():
    # the values reach the library as a view: np.ascontiguousarray returns the array itself
    h = np.random.default_rng(1).standard_normal((20, 30))
    assert toposmooth._float64("values", h) is h
    assert toposmooth._float64("values", h.T) is not h  # a transposed view is copied once


def test_errors_are_typed_and_carry_the_cli_exit_status(datasets):
    h = piv(datasets)
    with pytest.raises(toposmooth.InputError) as e:
        toposmooth.smooth(h)
    assert isinstance(e.value, ValueError) and isinstance(e.value, toposmooth.Error)
    assert (e.value.exit_code, e.value.kind) == (3, "input")
    assert "NaN" in str(e.value) or "missing" in str(e.value), str(e.value)
    with pytest.raises(toposmooth.UsageError) as e:
        toposmooth.smooth(np.zeros((4, 4)) + np.arange(4), persistence="5%", minima=2)
    assert "one selection rule" in str(e.value) and e.value.exit_code == 2
    with pytest.raises(toposmooth.UsageError):
        toposmooth.smooth(np.arange(10.0), edges="some")
    with pytest.raises(toposmooth.UsageError):
        toposmooth.smooth(np.arange(10.0), persistence="five")
    with pytest.raises(toposmooth.UsageError):
        toposmooth.Smoother((10,), colour="red")
    # an explicit list no strict function realizes: two adjacent maxima
    t = np.array([0.0, 2.0, 1.0, 3.0, 0.5, 4.0, 0.0])
    with pytest.raises(toposmooth.InfeasibleError) as e:
        toposmooth.smooth(t, keep_min=[0, 6], keep_max=[3, 4])
    assert e.value.exit_code == 3
    # a degenerate mesh: a triangle with a repeated corner
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    with pytest.raises(toposmooth.InputError):
        toposmooth.smooth(np.arange(4.0), vertices=v, faces=[[0, 1, 1], [1, 3, 2]])
    with pytest.raises(toposmooth.InputError):
        toposmooth.smooth(np.arange(4.0), vertices=v, faces=[[0, 1, 7]])
    with pytest.raises(toposmooth.InputError):
        toposmooth.smooth(np.zeros((2, 3, 4)))


def test_a_mesh_field_keeps_exactly_the_chosen_extrema():
    # a 30 x 20 triangulated sheet in 3D with a bumpy field
    nx, ny = 30, 20
    y, x = np.mgrid[0:ny, 0:nx]
    vertices = np.column_stack([x.ravel() * 0.1, y.ravel() * 0.1, 0.05 * np.sin(x.ravel())])
    faces = []
    for r in range(ny - 1):
        for c in range(nx - 1):
            a, b, d, e = r * nx + c, r * nx + c + 1, (r + 1) * nx + c, (r + 1) * nx + c + 1
            faces += [[a, b, e], [a, e, d]]
    rng = np.random.default_rng(3)
    h = np.sin(x.ravel() / 4.0) * np.cos(y.ravel() / 5.0) + 0.1 * rng.standard_normal(nx * ny)
    r = toposmooth.smooth(h, vertices=vertices, faces=faces, minima=3, maxima=3)
    assert r.kept_minima.size == 3 and r.kept_maxima.size == 3
    nb = {v: set() for v in range(nx * ny)}
    for t in faces:
        for i in range(3):
            for j in range(3):
                if i != j:
                    nb[t[i]].add(t[j])
    mins, maxs = strict_extrema(r.smoothed, lambda v: nb[v])
    assert mins == set(r.kept_minima) and maxs == set(r.kept_maxima)
    # verify: the certificate holds, and fails once a free vertex becomes a spurious minimum
    assert toposmooth.verify(r.smoothed, r.roles, h, vertices=vertices, faces=faces)["passed"]
    bad = r.smoothed.copy()
    free = next(v for v in range(nx * ny) if r.roles[v] == 0 and v not in mins)
    bad[free] = bad[list(nb[free])].min() - 1.0
    checked = toposmooth.verify(bad, r.roles, vertices=vertices, faces=faces)
    assert not checked["passed"] and checked["failures"]


def test_a_smoother_reused_over_time_steps_gives_the_separate_calls_results():
    y, x = np.mgrid[0:48, 0:64]
    rng = np.random.default_rng(7)
    frames = [
        np.sin((x - 3 * t) / 8.0) * np.cos(y / 6.0) + 0.05 * rng.standard_normal(x.shape) for t in range(4)
    ]
    s = toposmooth.Smoother((48, 64), spacing=(0.5, 0.5), persistence="10%")
    for h in frames:
        a = s.smooth(h)
        b = toposmooth.smooth(h, spacing=(0.5, 0.5), persistence="10%")
        assert np.array_equal(a.smoothed, b.smoothed) and np.array_equal(a.roles, b.roles)
    with pytest.raises(toposmooth.InputError):
        s.smooth(np.zeros((48, 63)))


def test_extrema_agree_with_the_cli(datasets, cli):
    import json

    src = datasets / "volcano_maunga_whau_61x87.csv"
    ref = json.loads(cli("extrema", src, "--json").stdout)
    h = np.genfromtxt(src, delimiter=",")
    e = toposmooth.extrema(h)
    rows = ref["extrema"]
    assert list(e["vertex"]) == [r["index"] for r in rows]
    assert list(e["is_max"]) == [r["kind"] != "min" for r in rows]
    assert list(e["kept"]) == [r["kept"] for r in rows]
    got = [None if np.isinf(p) else p for p in e["persistence"]]
    assert got == [r["persistence"] for r in rows]


def test_geodesic_and_weights_on_a_strip():
    n = 40
    vertices = np.array([[i * 0.1, j * 0.1, 0.0] for j in range(3) for i in range(n)])
    faces = []
    for j in range(2):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            faces += [[a, b, d], [a, d, c]]
    d = toposmooth.geodesic(vertices, faces, [0])
    assert d[0] == 0 and abs(d[n - 1] - 3.9) < 0.3 and np.all(np.diff(d[:n]) > 0)
    w = toposmooth.weights(vertices, faces, [[0, n, 2 * n], [n - 1, 2 * n - 1, 3 * n - 1]])
    assert w["certified"] and len(w["weights"]) == 2
    assert np.allclose(w["weights"][0] + w["weights"][1], 1.0)


def test_the_gil_is_released_while_a_field_is_smoothed():
    # With a switch interval of 1000 s the interpreter hands the GIL over only when a thread
    # releases it itself: the counting thread (which sleeps between counts, releasing it) can
    # count while the worker is inside `smooth` only if `smooth` released the GIL.
    y, x = np.mgrid[0:150, 0:150]
    h = np.sin(x / 9.0) * np.cos(y / 7.0) + 0.05 * np.random.default_rng(5).standard_normal(x.shape)
    counter = [0]
    seen = {}
    done = threading.Event()

    def worker():
        seen["before"] = counter[0]
        toposmooth.smooth(h, persistence="5%")
        seen["after"] = counter[0]
        done.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        while not done.is_set():
            counter[0] += 1
            time.sleep(0.0005)
        t.join()
    finally:
        sys.setswitchinterval(old)
    assert seen["after"] - seen["before"] > 0, seen


def test_help_reads_like_numpy():
    doc = toposmooth.smooth.__doc__
    for section in ["Parameters", "Returns", "Raises", "Examples", "values : array_like", "(ny, nx)"]:
        assert section in doc, section
    for f in [toposmooth.extrema, toposmooth.verify, toposmooth.geodesic, toposmooth.weights, toposmooth.Smoother]:
        assert f.__doc__ and ("Returns" in f.__doc__ or "Parameters" in f.__doc__), f


def test_the_docstring_examples_run():
    failures, tried = doctest.testmod(toposmooth, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried >= 4 and failures == 0
    pytest.importorskip("xarray")
    failures, tried = doctest.testmod(toposmooth.xarray, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried >= 4 and failures == 0


def test_the_readme_example_runs(datasets, capsys, monkeypatch):
    import re

    from conftest import ROOT

    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "the README has a Python example"
    monkeypatch.chdir(ROOT)
    exec(compile(blocks[0], "README.md", "exec"), {})
    lines = capsys.readouterr().out.split("\n")
    assert lines[0] == "9 4 True" and lines[1].startswith("0.02023"), lines


def test_results_do_not_depend_on_the_thread_count(datasets):
    h = piv(datasets)
    one = toposmooth.smooth(h, minima=9, maxima=4, fill_missing=True, threads=1)
    two = toposmooth.smooth(h, minima=9, maxima=4, fill_missing=True, threads=2)
    assert np.array_equal(one.smoothed, two.smoothed) and np.array_equal(one.roles, two.roles)
    y, x = np.mgrid[0:90, 0:120]
    g = np.sin(x / 11.0) * np.cos(y / 8.0) + 0.05 * np.random.default_rng(2).standard_normal(x.shape)
    s1, s2 = toposmooth.Smoother(g.shape, persistence="10%", threads=1), toposmooth.Smoother(g.shape, persistence="10%")
    assert np.array_equal(s1.smooth(g).smoothed, s2.smooth(g).smoothed)
    with pytest.raises(toposmooth.UsageError):
        toposmooth.smooth(g, threads=0)


def read_obj(path):
    v, f = [], []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            v.append([float(x) for x in p[1:4]])
        elif p and p[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
    return np.array(v), np.array(f)


def vtu_arrays(path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    pd = r.GetOutput().GetPointData()
    return {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}


def test_meshes_are_bit_identical_to_the_cli(datasets, cli, tmp_path):
    pytest.importorskip("vtkmodules")
    bunny = datasets / "bunny.obj"
    v, f = read_obj(bunny)
    g = tmp_path / "g.vtu"
    cli("geodesic", bunny, "--source", "0", "-o", g)
    d = toposmooth.geodesic(v, f, [0])
    assert np.array_equal(d, vtu_arrays(g)["distance"])
    # the distance smoothed keeping its maxima, as the paper's geodesic application does
    s = tmp_path / "s.vtu"
    cli("smooth", g, "--keep-all-maxima", "-o", s)
    r = toposmooth.smooth(d, vertices=v, faces=f, keep_all_maxima=True)
    out = vtu_arrays(s)
    assert np.array_equal(r.smoothed, out["smoothed"]) and np.array_equal(r.roles, out["role"].astype(np.int8))
    # weights for the bundled handles, given as the JSON format's dict
    import json

    penguin = datasets / "penguin.obj"
    pv, pf = read_obj(penguin)
    handles = json.loads((datasets / "penguin_handles.json").read_text())
    w = tmp_path / "w.vtu"
    cli("weights", penguin, "--handles", datasets / "penguin_handles.json", "-o", w)
    got = toposmooth.weights(pv, pf, handles)
    ref = vtu_arrays(w)
    assert got["certified"] and len(got["names"]) == len(handles["handles"])
    for name, raw, norm in zip(got["names"], got["raw"], got["weights"]):
        assert np.array_equal(raw, ref[f"weight_{name}_raw"]), name
        assert np.array_equal(norm, ref[f"weight_{name}"]), name


def test_extrema_pairs_as_birth_and_death():
    h = np.array([0.0, 3.0, 1.0, 2.0, -1.0])
    e = toposmooth.extrema(h, persistence=0.5)
    by_vertex = {int(v): (b, d) for v, b, d in zip(e["vertex"], e["birth"], e["death"])}
    assert by_vertex[2] == (1.0, 2.0), "the minimum 1 dies at the maximum 2"
    assert by_vertex[4][0] == -1.0 and np.isinf(by_vertex[4][1]), "the essential minimum never dies"


def test_review_findings_on_the_python_side(tmp_path):
    # a series' endpoint maximum has no persistence (not an essential extremum)
    e = toposmooth.extrema(np.array([5.0, 1.0, 3.0, 0.0]), persistence=0.1)
    end = list(e["vertex"]).index(0)
    assert e["endpoint"][end] and np.isnan(e["persistence"][end]) and np.isnan(e["birth"][end])
    # a kept extremum named explicitly may not be a filled sample, as in the CLI
    h = np.array([0.0, 2.0, np.nan, 3.0, 1.0, 4.0])
    with pytest.raises(toposmooth.InputError) as err:
        toposmooth.smooth(h, keep_min=[0, 2], keep_max=[5], fill_missing=True)
    assert "missing sample 2" in str(err.value)
    # dates as x for a Smoother, numpy values inside dict handles, negative indices
    pd = pytest.importorskip("pandas")
    days = pd.date_range("2020-01-01", periods=6, freq="D")
    s = toposmooth.Smoother(x=days, pairs=1)
    series = pd.Series([0.0, 2.0, 1.0, 3.0, 0.5, 4.0], index=days)
    assert np.array_equal(s.smooth(series.to_numpy()).smoothed, toposmooth.smooth(series, pairs=1).smoothed)
    with pytest.raises(toposmooth.UsageError):
        toposmooth.geodesic(np.eye(3), [[0, 1, 2]], [-1])
    # .pvd times from numpy are numbers, files relative to the collection
    files = [tmp_path / f"a{k}.vti" for k in range(2)]
    pvd = toposmooth.dask.write_pvd(tmp_path / "c.pvd", files, times=np.arange(2) * 0.5)
    text = pvd.read_text()
    assert 'timestep="0.5"' in text and 'file="a1.vti"' in text, text


def test_float32_coordinates_are_uniform_to_their_precision():
    xr = pytest.importorskip("xarray")
    lon = np.arange(0, 3.6, 0.1, dtype=np.float32)
    y = np.arange(20, dtype=np.float32)
    da = xr.DataArray(np.sin(lon[None, :] * 2) * np.cos(y[:, None] / 3), dims=("y", "lon"), coords={"y": y, "lon": lon})
    out = toposmooth.xarray.smooth(da, dims=("y", "lon"), persistence="20%")
    assert out.shape == da.shape
    over = toposmooth.xarray.smooth(da, dims=("y", "lon"), spacing=(0.5, 0.5), persistence="20%")
    assert over.shape == da.shape
