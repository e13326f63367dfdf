"""The VTK algorithms behind the ParaView plugin, on pip's vtk (vtkmodules only)."""

import json

import numpy as np
import pytest

import toposmooth
from conftest import grid_neighbours, strict_extrema

vtk = pytest.importorskip("vtkmodules.vtkCommonDataModel")
from vtkmodules.util import numpy_support  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402

from toposmooth.vtk_algorithms import PersistenceDiagram, TopologyControlledSmoothing  # noqa: E402


def piv_image(datasets):
    h = np.genfromtxt(datasets / "soapfilm_piv_vorticity_63x63.csv", delimiter=",")
    h = toposmooth._toposmooth.fill_missing(toposmooth.Domain.grid(63, 63, [1.0, 1.0], [0.0, 0.0]), h.ravel())[0]
    img = vtkImageData()
    img.SetDimensions(63, 63, 1)
    img.SetSpacing(0.5, 0.5, 1)
    img.SetOrigin(2.0, -1.0, 0)
    a = numpy_support.numpy_to_vtk(h, deep=1)
    a.SetName("vorticity")
    img.GetPointData().SetScalars(a)
    other = numpy_support.numpy_to_vtk(np.arange(63 * 63, dtype=np.int32), deep=1)
    other.SetName("id")
    img.GetPointData().AddArray(other)
    return img, h


def test_the_filter_smooths_image_data_like_the_package(datasets):
    img, h = piv_image(datasets)
    f = TopologyControlledSmoothing()
    f.SetInputDataObject(0, img)
    f.SetInputArrayToProcess(0, 0, 0, 0, "vorticity")
    f.SetMinima(9)
    f.SetMaxima(4)
    f.Update()
    out = f.GetOutputDataObject(0)
    assert out.GetClassName() == "vtkImageData" and out.GetDimensions() == (63, 63, 1)
    pd = out.GetPointData()
    assert pd.GetScalars().GetName() == "vorticity", "the smoothed field under the input's name, active"
    assert pd.GetArray("id") is not None, "other arrays pass through"
    smoothed = numpy_support.vtk_to_numpy(pd.GetArray("vorticity"))
    roles = numpy_support.vtk_to_numpy(pd.GetArray("role"))
    ref = toposmooth.smooth(h.reshape(63, 63), spacing=(0.5, 0.5), origin=(2.0, -1.0), minima=9, maxima=4)
    assert np.array_equal(smoothed, ref.smoothed.ravel())
    mins, maxs = strict_extrema(smoothed, grid_neighbours(63, 63))
    assert (len(mins), len(maxs)) == (9, 4)
    assert mins == set(np.flatnonzero(roles == -1)) and maxs == set(np.flatnonzero(roles == 1))
    report = json.loads(out.GetFieldData().GetAbstractArray("toposmooth_report").GetValue(0))
    assert report["certificate"]["passed"]
    # the input is untouched
    assert np.array_equal(numpy_support.vtk_to_numpy(img.GetPointData().GetArray("vorticity")), h)


def test_the_filter_smooths_a_triangle_mesh():
    from vtkmodules.vtkFiltersSources import vtkSphereSource

    sphere = vtkSphereSource()
    sphere.SetThetaResolution(40)
    sphere.SetPhiResolution(30)
    sphere.Update()
    mesh = sphere.GetOutput()
    p = numpy_support.vtk_to_numpy(mesh.GetPoints().GetData()).astype(float)
    h = np.sin(3 * p[:, 0]) * np.cos(2 * p[:, 1]) + 0.05 * np.random.default_rng(4).standard_normal(len(p))
    a = numpy_support.numpy_to_vtk(h, deep=1)
    a.SetName("h")
    mesh.GetPointData().SetScalars(a)
    f = TopologyControlledSmoothing()
    f.SetInputDataObject(0, mesh)
    f.SetPersistence(20.0)
    f.Update()
    out = f.GetOutputDataObject(0)
    assert out.GetClassName() == "vtkPolyData"
    roles = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("role"))
    smoothed = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("h"))
    faces = numpy_support.vtk_to_numpy(mesh.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    nb = {v: set() for v in range(len(p))}
    for t in faces:
        for i in range(3):
            nb[t[i]].update(t[j] for j in range(3) if j != i)
    mins, maxs = strict_extrema(smoothed, lambda v: nb[v])
    assert mins == set(np.flatnonzero(roles == -1)) and maxs == set(np.flatnonzero(roles == 1))


def test_the_diagram_thresholded_on_persistence_selects_the_kept_pairs(datasets):
    from vtkmodules.vtkFiltersCore import vtkThreshold

    img, h = piv_image(datasets)
    d = PersistenceDiagram()
    d.SetInputDataObject(0, img)
    d.SetInputArrayToProcess(0, 0, 0, 0, "vorticity")
    d.SetPersistence(5.0)
    d.Update()
    diagram = d.GetOutputDataObject(0)
    cd = diagram.GetCellData()
    for name in ["PairIdentifier", "PairType", "Persistence", "Birth", "IsFinite", "Kept"]:
        assert cd.GetArray(name) is not None, name
    ids = numpy_support.vtk_to_numpy(cd.GetArray("PairIdentifier"))
    assert ids[-1] == -1 and numpy_support.vtk_to_numpy(cd.GetArray("IsFinite"))[0] == 0
    th = vtkThreshold()
    th.SetInputData(diagram)
    th.SetInputArrayToProcess(0, 0, 0, 1, "Persistence")
    th.SetThresholdFunction(vtkThreshold.THRESHOLD_UPPER)
    th.SetUpperThreshold(0.05 * (h.max() - h.min()))
    th.Update()
    kept_ids = numpy_support.vtk_to_numpy(th.GetOutput().GetCellData().GetArray("PairIdentifier"))
    e = toposmooth.extrema(h.reshape(63, 63), persistence="5%")
    # every kept extremum is a pair's, the essential pair keeps two
    assert int((kept_ids >= 0).sum()) + 1 == int(e["kept"].sum())


def test_the_filters_parameters_are_the_schema_s_settings_with_its_defaults():
    schema = {s["name"]: s for s in toposmooth.SETTINGS}
    default_selection = {"persistence": "5.0%"}
    for algorithm in (TopologyControlledSmoothing(), PersistenceDiagram()):
        given = algorithm.settings()
        assert set(given) <= set(schema), set(given) - set(schema)
        for name, value in given.items():
            if name in default_selection:
                assert value == default_selection[name]
                continue
            default = schema[name]["default"]
            assert value is None or str(value) == default or float(value) == float(default), (name, value, default)
        # every setter changes exactly one setting of the schema (or the selection's rule)
        setters = [m for m in dir(algorithm) if m.startswith("Set") and m[3:] in ALGORITHM_PARAMETERS]
        extra = [m for m in dir(type(algorithm)) if m.startswith("Set") and m not in dir(VTK_BASE)]
        assert sorted(extra) == sorted(setters), "a parameter the schema does not know: " + str(set(extra) - set(setters))
        for setter in setters:
            a = type(algorithm)()
            before = a.settings()
            getattr(a, setter)(ALGORITHM_PARAMETERS[setter[3:]])
            after = a.settings()
            changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
            assert changed and changed <= set(schema), (setter, changed)


#: A value other than the default for each parameter of the VTK algorithms.
ALGORITHM_PARAMETERS = {
    "Persistence": 2.5,
    "Minima": 3,
    "Maxima": 2,
    "Order": 3,
    "DataWeight": 0.5,
    "SmoothLength": 0.02,
    "Edges": "all",
    "Threads": 1,
}

from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase as VTK_BASE  # noqa: E402
