"""toposmooth.read per format family: the values and the domain as the CLI reads them (no CLI
in between), and Dataset.smooth bit-identical to the CLI's smooth with the same options."""

import numpy as np
import pytest

import toposmooth


def test_a_csv_series_with_dates(datasets, cli, tmp_path):
    d = toposmooth.read(datasets / "fx_eur_per_usd_daily_1999_2017.csv")
    assert (d.kind, d.values.shape, d.description) == ("series", (4754,), "eur_per_usd")
    assert d.dates and d.x_name == "date" and d.x_text[0] == "1999-01-04"
    assert d.x[1] - d.x[0] == 1.0 and d.x[0] == 10595.0, "days since 1970-01-01"
    r = d.smooth(persistence="8%")
    out = tmp_path / "fx.csv"
    cli("smooth", datasets / "fx_eur_per_usd_daily_1999_2017.csv", "--persistence", "8%", "-o", out)
    ref = np.genfromtxt(out, delimiter=",", names=True)
    assert np.array_equal(r.smoothed, ref["output"])
    w = toposmooth.read(datasets / "seattle_weather_daily_2012_2015.csv", column="temp_max", x_column="none")
    assert w.values[0] == 12.8 and w.x[:3].tolist() == [0.0, 1.0, 2.0] and not w.dates


def test_a_csv_matrix_with_missing_cells_is_filled_as_the_cli_fills_it(datasets, cli, tmp_path):
    path = datasets / "soapfilm_piv_vorticity_63x63.csv"
    with pytest.raises(toposmooth.InputError, match="fill-missing"):
        toposmooth.read(path)
    d = toposmooth.read(path, fill_missing=True, spacing=(0.31248, -0.31248))
    assert (d.kind, d.values.shape, int(d.filled.sum())) == ("grid", (63, 63), 774)
    assert d.spacing == (0.31248, -0.31248) and d.origin == (0.0, 0.0)
    r = d.smooth(minima=9, maxima=4)
    out = tmp_path / "piv.npz"
    cli("smooth", path, "--fill-missing", "--spacing", "0.31248,-0.31248", "--minima", "9", "--maxima", "4", "-o", out)
    ref = np.load(out)
    assert np.array_equal(r.smoothed.ravel(), ref["smoothed"].ravel())
    assert np.array_equal(d.values.ravel(), ref["input"].ravel()), "the filled input, bit for bit"


def test_a_vtk_image_keeps_its_arrays_and_derives_a_scalar(datasets):
    path = datasets / "karman_vortex_street_ttk_example1.vti"
    with pytest.raises(toposmooth.InputError, match="components"):
        toposmooth.read(path)
    d = toposmooth.read(path, derive="magnitude")
    ny, nx = d.values.shape
    vectors = d.arrays["Vectors_"]
    assert vectors.shape == (nx * ny, 3)
    assert np.allclose(d.values.ravel(), np.linalg.norm(vectors, axis=1), rtol=1e-12, atol=0)
    with pytest.raises(toposmooth.UsageError):
        toposmooth.read(path, derive="curl")


def test_numpy_files_by_dimension(tmp_path):
    rng = np.random.default_rng(2)
    for shape, kind in [((50,), "series"), ((6, 9), "grid"), ((3, 4, 5), "volume")]:
        a = rng.standard_normal(shape)
        p = tmp_path / f"a{len(shape)}.npy"
        np.save(p, a)
        d = toposmooth.read(p)
        assert d.kind == kind and d.values.shape == shape and np.array_equal(d.values, a), kind


def test_volumes_meshes_and_masks(datasets):
    mri = toposmooth.read(datasets / "mri_anatomical_33x41x25.nii")
    assert (mri.kind, mri.values.shape) == ("volume", (25, 41, 33))
    masked = toposmooth.read(datasets / "mri_anatomical_33x41x25.nii", mask_below=50)
    assert masked.mask.sum() == (mri.values >= 50).sum()
    tets = toposmooth.read(datasets / "spot_tets.vtu")
    assert tets.kind == "tetrahedra" and tets.faces.shape[1] == 4 and tets.vertices.shape == (tets.values.size, 3)
    spot = toposmooth.read(datasets / "spot.obj", array="y")
    assert spot.kind == "mesh" and np.array_equal(spot.values, spot.vertices[:, 1])
    r = spot.smooth(minima=2, maxima=2)
    assert r.certified and r.kept_minima.size == 2


def test_bad_files_and_options_raise_the_package_errors(tmp_path, datasets):
    with pytest.raises(toposmooth.IoError):
        toposmooth.read(tmp_path / "absent.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(toposmooth.InputError, match="empty.csv"):
        toposmooth.read(tmp_path / "empty.csv")
    with pytest.raises(toposmooth.UsageError, match="spacing"):
        toposmooth.read(datasets / "volcano_maunga_whau_61x87.csv", spacing=(1.0,))
    with pytest.raises(toposmooth.UsageError, match="fill_missing: expected True or False"):
        toposmooth.read(datasets / "volcano_maunga_whau_61x87.csv", fill_missing="yes")
    with pytest.raises(TypeError):
        toposmooth.read(datasets / "volcano_maunga_whau_61x87.csv", colour="red")
