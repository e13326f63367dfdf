"""Run by paraview/run_test.sh under pvpython: loads the plugin, applies "Topology-Controlled
Smoothing" to a bundled .vti (the speed |Vectors_| of TTK's Kármán vortex street, made with
ParaView's Calculator) and checks the output with a counter written here from SPEC.md's
definitions: exactly the kept extrema (role -1 and 1) are strict extrema of the smoothed field.
Then the diagram filter: Threshold on Persistence keeps one pair per kept extremum but the
essential pair's two. Exits non-zero on the first failure.
Usage: pvpython paraview/test_plugin.py PLUGIN DATASET"""

import sys

import numpy as np
from paraview import servermanager
from paraview.simple import Calculator, LoadPlugin, Threshold, XMLImageDataReader
from vtkmodules.util import numpy_support

plugin, dataset = sys.argv[1], sys.argv[2]
LoadPlugin(plugin, ns=globals())

reader = XMLImageDataReader(FileName=[dataset])
speed = Calculator(Input=reader, Function="mag(Vectors_)", ResultArrayName="speed")
smooth = TopologyControlledSmoothing(Input=speed)  # noqa: F821 (registered by LoadPlugin from its label)
smooth.Scalars = ["POINTS", "speed"]
smooth.Minima = 6
smooth.Maxima = 6
smooth.UpdatePipeline()
out = servermanager.Fetch(smooth)
nx, ny, nz = out.GetDimensions()
f = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("speed"))
roles = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("role"))
assert out.GetPointData().GetScalars().GetName() == "speed", "the smoothed field is the active scalars"
assert out.GetPointData().GetArray("Vectors_") is not None, "the input's arrays pass through"


def neighbours(v):
    r, c = divmod(v, nx)
    for dr, dc in [(0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1)]:
        rr, cc = r + dr, c + dc
        if 0 <= rr < ny and 0 <= cc < nx:
            yield rr * nx + cc


mins = {v for v in range(f.size) if all(f[w] > f[v] for w in neighbours(v))}
maxs = {v for v in range(f.size) if all(f[w] < f[v] for w in neighbours(v))}
kept_min, kept_max = set(np.flatnonzero(roles == -1)), set(np.flatnonzero(roles == 1))
assert (len(kept_min), len(kept_max)) == (6, 6), (len(kept_min), len(kept_max))
assert mins == kept_min and maxs == kept_max, (sorted(mins), sorted(kept_min), sorted(maxs), sorted(kept_max))
print(f"ok Topology-Controlled Smoothing: {nx} x {ny} image, strict extrema = the kept 6 minima and 6 maxima")

diagram = PersistenceDiagramtoposmooth(Input=speed)  # noqa: F821
diagram.Scalars = ["POINTS", "speed"]
diagram.PersistencePercent = 5.0
s = numpy_support.vtk_to_numpy(servermanager.Fetch(speed).GetPointData().GetArray("speed"))
kept = Threshold(Input=diagram, Scalars=["CELLS", "Persistence"])
kept.LowerThreshold = 0.05 * (s.max() - s.min())
kept.UpperThreshold = 1e300
kept.UpdatePipeline()
ids = numpy_support.vtk_to_numpy(servermanager.Fetch(kept).GetCellData().GetArray("PairIdentifier"))
full = servermanager.Fetch(diagram)
kept_flags = numpy_support.vtk_to_numpy(full.GetCellData().GetArray("Kept"))
assert int((ids >= 0).sum()) == int(kept_flags[:-1].sum()), (int((ids >= 0).sum()), int(kept_flags.sum()))
print(f"ok Persistence Diagram: Threshold on Persistence keeps the {int((ids >= 0).sum())} kept pairs")

# every property of the filters is a setting of the library's schema (toposmooth.SETTINGS, from
# which the CLI's flags are made), with the schema's default: a property added to the plugin
# alone fails here
import toposmooth  # noqa: E402

schema = {s["name"]: s for s in toposmooth.SETTINGS}
for proxy, algorithm in ((TopologyControlledSmoothing(Input=speed), "smoothing"), (PersistenceDiagramtoposmooth(Input=speed), "diagram")):  # noqa: F821
    proxy.UpdateVTKObjects()
    defaults = proxy.GetClientSideObject().settings()
    assert set(defaults) <= set(schema), (algorithm, set(defaults) - set(schema))
    fresh = type(proxy.GetClientSideObject())().settings()
    assert defaults == fresh, (algorithm, "the properties' defaults are the algorithm's", defaults, fresh)
    for name in proxy.ListProperties():
        if name in ("Input", "Scalars", "ReloadPythonModule"):  # the last: ParaView's own button
            continue
        before = proxy.GetClientSideObject().settings()
        prop = proxy.GetProperty(name)
        if hasattr(prop, "Available"):  # an enumeration: its entries' texts
            value = prop.GetData()
            other = [v for v in prop.Available if v != value][0]
        else:
            value = prop.GetData()
            other = value + 1 if isinstance(value, int) else value / 2 + 0.01
        setattr(proxy, name, other)
        proxy.UpdateVTKObjects()
        after = proxy.GetClientSideObject().settings()
        changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
        assert changed and changed <= set(schema), (algorithm, name, "changes no setting of the schema", changed)
        setattr(proxy, name, value)
        proxy.UpdateVTKObjects()
    print(f"ok {algorithm}: {len(proxy.ListProperties()) - 3} properties, each a setting of toposmooth.SETTINGS")
