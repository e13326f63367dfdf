#!/usr/bin/env python3
"""Writes spot_tets.vtu: a tetrahedral mesh of the solid Spot cow with a noisy scalar field.

Steps (all deterministic; Gmsh runs on one thread):
1. read datasets/spot.obj (11,533 vertices, 23,062 triangles, closed, genus 0) and check it;
2. hand it to Gmsh (PyPI `gmsh`) as a discrete surface, classify it (feature angle 40 deg,
   split into patches that can be parametrized) and build a geometry on it
   (classifySurfaces + createGeometry), close it into a volume, and mesh it in 3D with one
   target edge length H = 0.06 everywhere (Mesh.MeshSizeMin = Mesh.MeshSizeMax = H, no size
   from curvature, none extended from the boundary), Delaunay 2D/3D with Gmsh's default
   optimizer and Netgen's (Mesh.OptimizeNetgen = 1). The boundary is a new, roughly uniform
   triangulation whose vertices lie on Spot's surface;
3. keep the linear tetrahedra (Gmsh element type 4) and the nodes they use;
4. check the mesh (every cell a tetrahedron with 4 distinct corners and nonzero signed volume,
   every vertex used, no two vertices at one position, each triangle on at most 2 tetrahedra,
   the boundary a closed connected genus-0 surface, one connected component, V - E + F - T
   = 1, 1,500 ... 5,000 vertices) and print its statistics, how many tetrahedra are
   negatively oriented, its dihedral angles and how far its boundary is from spot.obj;
5. attach the point array `f` = sin(3x) + cos(2y) + z + 0.05 * (max - min of that smooth part)
   * u, u uniform in [-1, 1) from numpy.random.default_rng(20260), one per vertex in order;
6. write it with vtkXMLUnstructuredGridWriter at its default settings (appended, base64,
   zlib), only VTK_TETRA (10) cells, Float64 points, Float64 `f`, check the file's size
   (< 1.5 MB) and read it back with vtkXMLUnstructuredGridReader (same points, cells, `f`).

(TetGen 1.6 through PyPI `tetgen` 0.8.4, on spot.obj simplified by vtkQuadricDecimation, was
tried first: `-pq1.4` gave 3,175 vertices but dihedral angles down to 0.28 deg, 2.5 deg at
best with `-o/150`; Gmsh's mesh has none below 15 deg.)

Needs a venv outside the repository with exact versions (numpy 2.4.6 is what pip resolved
beside vtk 9.7.2 on CPython 3.11; other versions may give another mesh):

    python3 -m venv /tmp/tetfix-venv
    /tmp/tetfix-venv/bin/pip install gmsh==4.15.2 numpy==2.4.6 vtk==9.7.2
    /tmp/tetfix-venv/bin/python datasets/tools/make_spot_tets.py

Optional arguments: input .obj and output .vtu (defaults: datasets/spot.obj, datasets/spot_tets.vtu).
"""
import math
import sys
from pathlib import Path

import gmsh
import numpy as np
import vtk
from vtk.util import numpy_support as ns

H = 0.06
FEATURE_ANGLE = 40.0
SEED = 20260
NOISE = 0.05

here = Path(__file__).resolve().parent.parent


def read_obj(path):
    V, F = [], []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            V.append([float(t) for t in p[1:4]])
        elif p and p[0] == "f":
            assert len(p) == 4, "triangles only"
            F.append([int(t.split("/")[0]) - 1 for t in p[1:4]])
    return np.array(V, dtype=np.float64), np.array(F, dtype=np.int64)


def id_array(a):
    return ns.numpy_to_vtkIdTypeArray(np.ascontiguousarray(a, dtype=np.int64), deep=1)


def cell_array(cells):
    k = cells.shape[1]
    ca = vtk.vtkCellArray()
    ca.SetData(id_array(np.arange(0, k * len(cells) + 1, k)), id_array(cells.ravel()))
    return ca


def polydata(V, F):
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(V), deep=1))
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    pd.SetPolys(cell_array(F))
    return pd


def mesh_volume(V, F):
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        s = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, s, list(range(1, len(V) + 1)), V.ravel().tolist())
        gmsh.model.mesh.addElementsByType(s, 2, [], (F + 1).ravel().tolist())
        gmsh.model.mesh.classifySurfaces(FEATURE_ANGLE * math.pi / 180.0, True, True, math.pi)
        gmsh.model.mesh.createGeometry()
        loop = gmsh.model.geo.addSurfaceLoop([t for _, t in gmsh.model.getEntities(2)])
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        for name, value in (("Mesh.MeshSizeMin", H), ("Mesh.MeshSizeMax", H), ("Mesh.MeshSizeFromCurvature", 0),
                            ("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.Algorithm", 6), ("Mesh.Algorithm3D", 1),
                            ("Mesh.Optimize", 1), ("Mesh.OptimizeNetgen", 1)):
            gmsh.option.setNumber(name, value)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, tet_nodes = gmsh.model.mesh.getElementsByType(4)
    finally:
        gmsh.finalize()
    tags = tags.astype(np.int64)
    P = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    index = np.full(tags.max() + 1, -1, dtype=np.int64)
    index[tags] = np.arange(len(tags))
    T = index[np.asarray(tet_nodes, dtype=np.int64)].reshape(-1, 4)
    assert T.min() >= 0
    used = np.unique(T)
    print(f"Gmsh: {len(P)} nodes, {len(T)} tetrahedra; {len(P) - len(used)} nodes on no tetrahedron dropped")
    remap = np.full(len(P), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return P[used], remap[T]


def surface_distance(V, F, P, B):
    """Largest distance from the boundary's vertices to spot.obj's surface and back."""
    def largest(points, surface):
        d = vtk.vtkImplicitPolyDataDistance()
        d.SetInput(surface)
        return max(abs(d.EvaluateFunction(*p)) for p in points.tolist())
    return largest(P[np.unique(B)], polydata(V, F)), largest(V, polydata(P, B))


def components(n, pairs):
    """Number of connected components of n nodes joined by the (m, 2) array pairs."""
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in pairs.tolist():
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[ra] = rb
    return len({find(a) for a in range(n)})


def check_closed_surface(nv, tris, what):
    """Closed (every edge on exactly 2 triangles), one component, Euler characteristic 2."""
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    ue, c = np.unique(e, axis=0, return_counts=True)
    used = np.unique(tris)
    assert np.all(c == 2), f"{what}: an edge is not on exactly 2 triangles"
    assert components(nv, ue) - (nv - len(used)) == 1, f"{what}: not connected"
    chi = len(used) - len(ue) + len(tris)
    assert chi == 2, f"{what}: Euler characteristic {chi}, not 2"
    return len(used), len(ue)


def dihedral_angles(P, T):
    """All 6 dihedral angles (degrees) of every tetrahedron, shape (#T, 6)."""
    out = []
    for a, b, c, d in ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2), (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1)):
        pa, pb, pc, pd = (P[T[:, i]] for i in (a, b, c, d))
        e = pb - pa
        e /= np.linalg.norm(e, axis=1, keepdims=True)
        u = (pc - pa) - np.sum((pc - pa) * e, axis=1, keepdims=True) * e
        w = (pd - pa) - np.sum((pd - pa) * e, axis=1, keepdims=True) * e
        cos = np.sum(u * w, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1))
        out.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return np.stack(out, axis=1)


def check(P, T):
    nv, nt = len(P), len(T)
    assert T.ndim == 2 and T.shape[1] == 4 and T.min() >= 0 and T.max() < nv
    assert np.all(np.sort(T, axis=1)[:, 1:] != np.sort(T, axis=1)[:, :-1]), "a tetrahedron repeats a corner"
    assert len(np.unique(T)) == nv, f"{nv - len(np.unique(T))} unused vertices"
    assert len(np.unique(P, axis=0)) == nv, "two vertices at one position"
    e1, e2, e3 = (P[T[:, k]] - P[T[:, 0]] for k in (1, 2, 3))
    vol6 = np.einsum("ij,ij->i", e1, np.cross(e2, e3))
    assert np.all(vol6 != 0.0), f"{np.sum(vol6 == 0.0)} zero-volume tetrahedra"
    neg = int(np.sum(vol6 < 0))
    faces = np.sort(np.concatenate([T[:, [1, 2, 3]], T[:, [0, 2, 3]], T[:, [0, 1, 3]], T[:, [0, 1, 2]]]), axis=1)
    uf, inv, fc = np.unique(faces, axis=0, return_inverse=True, return_counts=True)
    assert fc.max() <= 2, "a triangle is on more than 2 tetrahedra"
    boundary = uf[fc == 1]
    nbv, _ = check_closed_surface(nv, boundary, "boundary")
    edges = np.sort(np.concatenate([T[:, [i, j]] for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))]), axis=1)
    ue = np.unique(edges, axis=0)
    assert components(nv, ue) == 1, "the mesh is not connected"
    # Tetrahedra joined through shared triangles: one component too (no pinched pieces).
    order = np.argsort(inv.ravel(), kind="stable")
    fi, tet = inv.ravel()[order], np.tile(np.arange(nt), 4)[order]
    same = fi[1:] == fi[:-1]
    assert components(nt, np.stack([tet[:-1][same], tet[1:][same]], axis=1)) == 1, "tetrahedra not face-connected"
    chi = nv - len(ue) + len(uf) - nt
    assert chi == 1, f"Euler characteristic V - E + F - T = {chi}, not 1"
    dih = dihedral_angles(P, T)
    vol = np.abs(vol6) / 6.0
    print(f"vertices {nv} ({nbv} on the boundary), edges {len(ue)}, triangles {len(uf)}, tetrahedra {nt}")
    print(f"boundary triangles {len(boundary)}, Euler characteristic V - E + F - T = {chi}")
    print(f"signed volumes: {nt - neg} positive, {neg} negative, none zero; "
          f"|volume| {vol.min():.3g} ... {vol.max():.3g}, total {vol.sum():.6g}")
    print(f"dihedral angles {dih.min():.2f} ... {dih.max():.2f} degrees")
    return boundary


def field(P):
    x, y, z = P[:, 0], P[:, 1], P[:, 2]
    smooth = np.sin(3.0 * x) + np.cos(2.0 * y) + z
    rng = np.random.default_rng(SEED)
    return smooth + NOISE * (smooth.max() - smooth.min()) * rng.uniform(-1.0, 1.0, len(P))


def write_vtu(path, P, T, f):
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(P), deep=1))
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(pts)
    grid.SetCells(vtk.VTK_TETRA, cell_array(T))
    arr = ns.numpy_to_vtk(np.ascontiguousarray(f, dtype=np.float64), deep=1)
    arr.SetName("f")
    grid.GetPointData().AddArray(arr)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(str(path))
    w.SetInputData(grid)
    assert w.Write() == 1, f"could not write {path}"


def read_back(path, P, T, f):
    """Reads the file with vtkXMLUnstructuredGridReader and compares it with what was written."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    g = r.GetOutput()
    types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}
    arr = g.GetPointData().GetArray("f")
    assert g.GetNumberOfPoints() == len(P) and g.GetNumberOfCells() == len(T) and types == {vtk.VTK_TETRA}
    assert np.array_equal(ns.vtk_to_numpy(g.GetPoints().GetData()), P)
    assert np.array_equal(ns.vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 4), T)
    assert arr is not None and np.array_equal(ns.vtk_to_numpy(arr), f)
    lo, hi = arr.GetRange()
    print(f"read back: {g.GetNumberOfPoints()} points, {g.GetNumberOfCells()} cells, types {sorted(types)}, "
          f"f {lo:.6g} ... {hi:.6g}")


def main(src, dst):
    V, F = read_obj(src)
    check_closed_surface(len(V), F, "input surface")
    P, T = mesh_volume(V, F)
    assert 1500 <= len(P) <= 5000, f"{len(P)} vertices, outside 1,500 ... 5,000"
    boundary = check(P, T)
    there, back = surface_distance(V, F, P, boundary)
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    print(f"boundary vertices to spot.obj <= {there:.3g}, spot.obj vertices to boundary <= {back:.3g} "
          f"(bounding-box diagonal {diag:.3g})")
    f = field(P)
    print(f"f: {f.min():.6g} ... {f.max():.6g}")
    write_vtu(dst, P, T, f)
    size = Path(dst).stat().st_size
    print(f"wrote {dst} ({size} bytes)")
    assert size < 1_500_000, "file too large"
    read_back(dst, P, T, f)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else here / "spot.obj",
         sys.argv[2] if len(sys.argv) > 2 else here / "spot_tets.vtu")
