"""toposmooth as VTK algorithms (Python, ``VTKPythonAlgorithmBase``), for VTK pipelines and
for the ParaView plugin ``paraview/toposmooth_filters.py``, which registers them. This module
imports only ``vtkmodules`` (pip's ``vtk`` and ParaView's both have them), numpy and
toposmooth.

``TopologyControlledSmoothing``
    Image data (2D: one point along z), poly data or an unstructured grid of triangles with a
    point scalar in; out: the input with the smoothed field under the scalar's name (the active
    scalars), the tool's ``role`` array (-1 kept minimum, 1 kept maximum) and the JSON report
    as the field data string ``toposmooth_report``.
``PersistenceDiagram``
    The input scalar's persistence diagram in TTK's layout (an unstructured grid of one line
    cell per pair, from (birth, birth) to (birth, death), then the diagonal).
"""

from __future__ import annotations

import json
from typing import Any, Dict, Optional, Tuple

import numpy as np
from vtkmodules.util import numpy_support
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
from vtkmodules.vtkCommonCore import (
    VTK_DOUBLE,
    VTK_FLOAT,
    VTK_INT,
    VTK_UNSIGNED_CHAR,
    vtkPoints,
    vtkStringArray,
)
from vtkmodules.vtkCommonDataModel import (
    VTK_LINE,
    vtkDataObject,
    vtkDataSet,
    vtkImageData,
    vtkPolyData,
    vtkUnstructuredGrid,
)

import toposmooth

__all__ = ["TopologyControlledSmoothing", "PersistenceDiagram", "domain_of"]


def _scalars(algorithm: VTKPythonAlgorithmBase, inInfo: Any, data: Any) -> Tuple[str, np.ndarray]:
    # the array chosen with SetInputArrayToProcess (ParaView's "Scalars"), else the active one
    info = algorithm.GetInputArrayInformation(0)
    name = info.Get(vtkDataObject.FIELD_NAME()) if info is not None and info.Has(vtkDataObject.FIELD_NAME()) else None
    array = data.GetPointData().GetArray(name) if name else data.GetPointData().GetScalars()
    if name and array is None:
        raise toposmooth.UsageError(f"the input has no point array `{name}`")
    if array is None:
        raise toposmooth.UsageError("choose a point scalar to smooth (the input has no active scalars)")
    if array.GetNumberOfComponents() != 1:
        raise toposmooth.UsageError(f"`{array.GetName()}` has {array.GetNumberOfComponents()} components: choose a scalar")
    return array.GetName() or "scalars", numpy_support.vtk_to_numpy(array).astype(np.float64)


def _triangles(data: Any) -> np.ndarray:
    """The (m, 3) triangles of poly data or an unstructured grid (every cell a triangle)."""
    cells = data.GetPolys() if isinstance(data, vtkPolyData) else data.GetCells()
    if isinstance(data, vtkPolyData) and (
        data.GetNumberOfVerts() or data.GetNumberOfLines() or data.GetNumberOfStrips()
    ):
        raise toposmooth.InputError("poly data with vertices, lines or strips: triangulate it first")
    offsets = numpy_support.vtk_to_numpy(cells.GetOffsetsArray())
    conn = numpy_support.vtk_to_numpy(cells.GetConnectivityArray())
    sizes = np.diff(offsets)
    if sizes.size == 0 or np.any(sizes != 3):
        raise toposmooth.InputError("every cell must be a triangle (apply Triangulate first)")
    return conn.reshape(-1, 3).astype(np.int64)


def domain_of(data: Any) -> Dict[str, Any]:
    """The domain arguments of :func:`toposmooth.smooth` for a VTK data set, and the shape of
    its point values."""
    if isinstance(data, vtkImageData):
        nx, ny, nz = data.GetDimensions()
        if nz != 1:
            raise toposmooth.InputError(f"a {nx} × {ny} × {nz} volume: only 2D images (one point along z) for now")
        sx, sy, _ = data.GetSpacing()
        # the first point, not the origin: an extent need not start at 0 (Extract Subset)
        ox, oy, _ = data.GetPoint(0)
        return {"spacing": (sx, sy), "origin": (ox, oy), "shape": (ny, nx)}
    if isinstance(data, (vtkPolyData, vtkUnstructuredGrid)):
        points = numpy_support.vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)
        return {"vertices": points, "faces": _triangles(data), "shape": (points.shape[0],)}
    raise toposmooth.InputError(f"{data.GetClassName()}: image data, poly data or an unstructured grid is needed")


class _Settings:
    """The parameters both filters share: the selection. :meth:`settings` gives the filter's
    parameters as the library's settings (``toposmooth.SETTINGS``' names and values), which
    the tests check against the schema: every parameter is a setting, every default the
    schema's."""

    def _init_settings(self) -> None:
        self._persistence = 5.0
        self._minima = 0
        self._maxima = 0

    def SetPersistence(self, percent: float) -> None:
        """Keep the extrema of persistence at least this percentage of the range (used when
        Minima and Maxima are both 0)."""
        if percent != self._persistence:
            self._persistence = float(percent)
            self.Modified()

    def SetMinima(self, n: int) -> None:
        """Keep the N most persistent minima (0: by persistence)."""
        if n != self._minima:
            self._minima = int(n)
            self.Modified()

    def SetMaxima(self, n: int) -> None:
        """Keep the M most persistent maxima (0: by persistence)."""
        if n != self._maxima:
            self._maxima = int(n)
            self.Modified()

    def _selection(self) -> Dict[str, Any]:
        if self._minima > 0 or self._maxima > 0:
            return {"minima": max(self._minima, 1), "maxima": max(self._maxima, 1)}
        return {"persistence": f"{self._persistence}%"}

    def settings(self) -> Dict[str, Any]:
        """The filter's parameters as the settings of :func:`toposmooth.smooth`."""
        return self._selection()


class TopologyControlledSmoothing(_Settings, VTKPythonAlgorithmBase):
    """Smooths a point scalar keeping exactly the chosen extrema (certified)."""

    def __init__(self) -> None:
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkDataSet")
        self._init_settings()
        self._order = 2
        self._data_weight = 1.0
        self._smooth_length = 0.0
        self._edges = "minimal"
        self._threads: Optional[int] = None
        self.report: Optional[Dict[str, Any]] = None

    def FillInputPortInformation(self, port: int, info: Any) -> int:
        info.Set(self.INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet")
        return 1

    def SetOrder(self, k: int) -> None:
        """Polyharmonic order k (1-4)."""
        if k != self._order:
            self._order = int(k)
            self.Modified()

    def SetDataWeight(self, w: float) -> None:
        """Weight of the data term (0: no data, u harmonic)."""
        if w != self._data_weight:
            self._data_weight = float(w)
            self.Modified()

    def SetSmoothLength(self, length: float) -> None:
        """Smoothing length as a fraction of the diameter (0: the automatic rule)."""
        if length != self._smooth_length:
            self._smooth_length = float(length)
            self.Modified()

    def SetEdges(self, edges: Any) -> None:
        """Constraint set: "minimal" (or 0) or "all" (or 1)."""
        e = {0: "minimal", 1: "all"}.get(edges, edges)
        if e != self._edges:
            self._edges = str(e)
            self.Modified()

    def SetThreads(self, n: Optional[int]) -> None:
        """At most n threads (None or 0: the library's default, 2)."""
        n = int(n) if n else None
        if n != self._threads:
            self._threads = n
            self.Modified()

    def RequestDataObject(self, request: Any, inInfo: Any, outInfo: Any) -> int:
        inp = vtkDataSet.GetData(inInfo[0])
        out = outInfo.GetInformationObject(0).Get(vtkDataObject.DATA_OBJECT())
        if inp is not None and (out is None or out.GetClassName() != inp.GetClassName()):
            outInfo.GetInformationObject(0).Set(vtkDataObject.DATA_OBJECT(), inp.NewInstance())
        return 1

    def settings(self) -> Dict[str, Any]:
        return dict(
            self._selection(),
            order=self._order,
            data_weight=self._data_weight,
            smooth_length=self._smooth_length or None,
            edges=self._edges,
            threads=self._threads,
        )

    def RequestData(self, request: Any, inInfo: Any, outInfo: Any) -> int:
        inp = vtkDataSet.GetData(inInfo[0])
        out = vtkDataSet.GetData(outInfo)
        name, values = _scalars(self, inInfo[0], inp)
        geometry = domain_of(inp)
        shape = geometry.pop("shape")
        r = toposmooth.smooth(values.reshape(shape), **geometry, **self.settings())
        self.report = r.report
        out.ShallowCopy(inp)
        smoothed = numpy_support.numpy_to_vtk(np.ascontiguousarray(r.smoothed.ravel()), deep=1)
        smoothed.SetName(name)
        pd = out.GetPointData()
        pd.RemoveArray(name)
        pd.AddArray(smoothed)
        pd.SetActiveScalars(name)
        role = numpy_support.numpy_to_vtk(np.ascontiguousarray(r.roles.ravel()), deep=1)
        role.SetName("role")
        pd.RemoveArray("role")
        pd.AddArray(role)
        report = vtkStringArray()
        report.SetName("toposmooth_report")
        report.InsertNextValue(json.dumps(r.report))
        out.GetFieldData().RemoveArray("toposmooth_report")
        out.GetFieldData().AddArray(report)
        return 1


class PersistenceDiagram(_Settings, VTKPythonAlgorithmBase):
    """The persistence diagram of a point scalar in TTK's layout: point data
    ``ttkVertexScalarField``, ``CriticalType``, ``Coordinates``; cell data ``PairIdentifier``,
    ``PairType`` (0 minimum-saddle, 1 saddle-maximum, -1 the diagonal), ``Persistence``,
    ``Birth``, ``IsFinite`` and ``Kept`` (by this filter's selection); the essential pair
    (global minimum, global maximum) first with ``IsFinite`` 0."""

    def __init__(self) -> None:
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkUnstructuredGrid")
        self._init_settings()

    def FillInputPortInformation(self, port: int, info: Any) -> int:
        info.Set(self.INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet")
        return 1

    def RequestData(self, request: Any, inInfo: Any, outInfo: Any) -> int:
        inp = vtkDataSet.GetData(inInfo[0])
        out = vtkUnstructuredGrid.GetData(outInfo)
        _, values = _scalars(self, inInfo[0], inp)
        geometry = domain_of(inp)
        shape = geometry.pop("shape")
        domain, flat, _ = toposmooth._domain(values.reshape(shape), **geometry)
        d = toposmooth._toposmooth.diagram(domain, flat, self.settings())
        k = len(d["pair_type"])
        b, dv = d["values"][:, 0], d["values"][:, 1]
        xy = np.zeros((2 * k, 3))
        xy[0::2, 0], xy[0::2, 1] = b, b
        xy[1::2, 0], xy[1::2, 1] = b, dv
        points = vtkPoints()
        points.SetData(numpy_support.numpy_to_vtk(xy, deep=1))
        out.SetPoints(points)
        out.Allocate(k + 1)
        for i in range(k):
            out.InsertNextCell(VTK_LINE, 2, [2 * i, 2 * i + 1])
        persistence, birth = list(dv - b), list(b)
        ids, pair_type = list(range(k)), [int(t) for t in d["pair_type"]]
        finite, kept = [int(f) for f in d["finite"]], [int(x) for x in d["kept"]]
        if k:
            # the diagonal, as TTK draws it: from the first point to the highest birth
            out.InsertNextCell(VTK_LINE, 2, [0, 2 * int(np.argmax(b))])
            ids.append(-1)
            pair_type.append(-1)
            persistence.append(2.0 * persistence[0])
            birth.append(0.0)
            finite.append(0)
            kept.append(0)
        vertices = d["vertices"].reshape(-1)
        coords = np.array([geometry_point(geometry, shape, int(v)) for v in vertices]).reshape(-1, 3)

        def add(target: Any, name: str, data: Any, vtk_type: int) -> None:
            a = numpy_support.numpy_to_vtk(np.ascontiguousarray(data), deep=1, array_type=vtk_type)
            a.SetName(name)
            target.AddArray(a)

        pd, cd = out.GetPointData(), out.GetCellData()
        add(pd, "ttkVertexScalarField", vertices.astype(np.int32), VTK_INT)
        add(pd, "CriticalType", d["types"].reshape(-1).astype(np.int32), VTK_INT)
        add(pd, "Coordinates", coords.astype(np.float32), VTK_FLOAT)
        add(cd, "PairIdentifier", np.array(ids, dtype=np.int32), VTK_INT)
        add(cd, "PairType", np.array(pair_type, dtype=np.int32), VTK_INT)
        add(cd, "Persistence", np.array(persistence, dtype=np.float64), VTK_DOUBLE)
        add(cd, "Birth", np.array(birth, dtype=np.float64), VTK_DOUBLE)
        add(cd, "IsFinite", np.array(finite, dtype=np.uint8), VTK_UNSIGNED_CHAR)
        add(cd, "Kept", np.array(kept, dtype=np.uint8), VTK_UNSIGNED_CHAR)
        return 1


def geometry_point(geometry: Dict[str, Any], shape: Tuple[int, ...], v: int) -> Tuple[float, float, float]:
    """The position of vertex ``v``."""
    if "vertices" in geometry:
        p = geometry["vertices"][v]
        return (float(p[0]), float(p[1]), float(p[2]) if len(p) > 2 else 0.0)
    ny, nx = shape
    r, c = divmod(int(v), nx)
    (dx, dy), (ox, oy) = geometry["spacing"], geometry["origin"]
    return (ox + c * dx, oy + r * dy, 0.0)
