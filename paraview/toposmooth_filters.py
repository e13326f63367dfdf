"""ParaView plugin: "Topology-Controlled Smoothing" and "Persistence Diagram (toposmooth)".

Load it in the GUI with Tools > Manage Plugins > Load New (this file), or in pvpython/pvbatch
with ``LoadPlugin("paraview/toposmooth_filters.py", ns=globals())``, then
``TopologyControlledSmoothing(Input=src, Scalars=["POINTS", "h"], Minima=6, Maxima=6)``
(properties: Scalars, PersistencePercent, Minima, Maxima — 0 and 0 select by persistence —,
Order, DataWeight, SmoothLength — 0 is automatic —, Edges) and
``PersistenceDiagramtoposmooth(Input=src, Scalars=[...], PersistencePercent=5)``. The toposmooth package
must be importable by ParaView's Python (for Debian's ParaView:
``pip install --no-deps --target DIR .`` and DIR on PYTHONPATH). The algorithms themselves are
``toposmooth.vtk_algorithms`` (plain VTK); this file only registers them with ParaView.
"""

import inspect

# ParaView 5.11's pythonalgorithm module imports inspect.getargspec, which Python 3.11 removed
# (Debian bookworm's python3-paraview); it uses only `.args`, which getfullargspec has
if not hasattr(inspect, "getargspec"):
    inspect.getargspec = inspect.getfullargspec

from paraview.util.vtkAlgorithm import smdomain, smhint, smproperty, smproxy  # noqa: E402

from toposmooth import vtk_algorithms  # noqa: E402

_SCALARS = """
<StringVectorProperty name="SelectInputScalars" label="Scalars" command="SetInputArrayToProcess"
    number_of_elements="5" element_types="0 0 0 0 2" animateable="0">
  <ArrayListDomain name="array_list" attribute_type="Scalars" input_domain_name="inputs_array">
    <RequiredProperties><Property name="Input" function="Input"/></RequiredProperties>
  </ArrayListDomain>
  <Documentation>The point scalar to smooth.</Documentation>
</StringVectorProperty>
"""


@smproxy.filter(name="ToposmoothSmoothing", label="Topology-Controlled Smoothing")
@smhint.xml('<ShowInMenu category="toposmooth"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData", "vtkPolyData", "vtkUnstructuredGrid"], composite_data_supported=False)
class TopologyControlledSmoothing(vtk_algorithms.TopologyControlledSmoothing):
    @smproperty.xml(_SCALARS)
    def SetInputArrayToProcess(self, idx, port, connection, field, name):
        return super().SetInputArrayToProcess(idx, port, connection, field, name)

    @smproperty.doublevector(name="PersistencePercent", default_values=5.0)
    @smdomain.doublerange(min=0.0, max=100.0)
    def SetPersistence(self, percent):
        super().SetPersistence(percent)

    @smproperty.intvector(name="Minima", default_values=0)
    def SetMinima(self, n):
        super().SetMinima(n)

    @smproperty.intvector(name="Maxima", default_values=0)
    def SetMaxima(self, n):
        super().SetMaxima(n)

    @smproperty.intvector(name="Order", default_values=2)
    @smdomain.intrange(min=1, max=4)
    def SetOrder(self, k):
        super().SetOrder(k)

    @smproperty.doublevector(name="DataWeight", default_values=1.0)
    def SetDataWeight(self, w):
        super().SetDataWeight(w)

    @smproperty.doublevector(name="SmoothLength", default_values=0.0)
    def SetSmoothLength(self, length):
        super().SetSmoothLength(length)

    @smproperty.xml(
        """<IntVectorProperty name="Edges" command="SetEdges"
            number_of_elements="1" default_values="0">
          <EnumerationDomain name="enum"><Entry value="0" text="minimal"/><Entry value="1" text="all"/></EnumerationDomain>
        </IntVectorProperty>"""
    )
    def SetEdges(self, e):
        super().SetEdges(e)


@smproxy.filter(name="ToposmoothPersistenceDiagram", label="Persistence Diagram (toposmooth)")
@smhint.xml('<ShowInMenu category="toposmooth"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData", "vtkPolyData", "vtkUnstructuredGrid"], composite_data_supported=False)
class PersistenceDiagram(vtk_algorithms.PersistenceDiagram):
    @smproperty.xml(_SCALARS)
    def SetInputArrayToProcess(self, idx, port, connection, field, name):
        return super().SetInputArrayToProcess(idx, port, connection, field, name)

    @smproperty.doublevector(name="PersistencePercent", default_values=5.0)
    @smdomain.doublerange(min=0.0, max=100.0)
    def SetPersistence(self, percent):
        super().SetPersistence(percent)
