"""Opens every VTK output of toposmooth with VTK's own readers (pip's vtk) and checks that it
reads without an error or a warning, carries every point and cell array of the input in its
type with its values, and marks the smoothed field as the active scalars under the input
array's name. Usage: check_outputs.py TOPOSMOOTH_BINARY FIXTURE_DIR DATASETS_DIR WORK_DIR.
Exits 1 on the first failure, naming the file."""

import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

LOG = vtk.vtkStringOutputWindow()
vtk.vtkOutputWindow.SetInstance(LOG)

BIN, FIXTURES, DATASETS, WORK = sys.argv[1:5]
failures = []


def fail(path, message):
    failures.append(f"{path}: {message}")
    print(f"FAIL {path}: {message}", file=sys.stderr)


def read(path):
    """The data set as VTK reads it, and what VTK printed while reading."""
    LOG.SetOutput("") if hasattr(LOG, "SetOutput") else None
    before = LOG.GetOutput()
    if path.endswith(".vtk"):
        reader = vtk.vtkDataSetReader()
        reader.ReadAllScalarsOn()
        reader.ReadAllVectorsOn()
        reader.ReadAllFieldsOn()
    else:
        reader = {
            ".vti": vtk.vtkXMLImageDataReader,
            ".vtu": vtk.vtkXMLUnstructuredGridReader,
            ".vtp": vtk.vtkXMLPolyDataReader,
        }[os.path.splitext(path)[1]]()
    reader.SetFileName(path)
    reader.Update()
    said = LOG.GetOutput()[len(before):]
    return reader.GetOutput(), said


def arrays(data):
    """name -> (VTK type name, components, numpy values)."""
    out = {}
    for k in range(data.GetNumberOfArrays()):
        a = data.GetArray(k)
        if a is None:
            continue
        out[a.GetName()] = (a.GetDataTypeAsString(), a.GetNumberOfComponents(), vtk_to_numpy(a).copy())
    return out


def run(*args):
    p = subprocess.run([BIN, "-q", *args], capture_output=True, text=True)
    if p.returncode != 0:
        fail(" ".join(args), f"exit {p.returncode}: {p.stderr.strip()}")
    return p.returncode == 0


def same_type(a, b, legacy=False):
    # VTK's own legacy reader reads `signed_char` (what its writer writes for Int8) as char
    alias = {"signed char": "char"} if legacy else {}
    return alias.get(a, a) == alias.get(b, b)


def check_smoothed(inp, out, array):
    src, said = read(inp)
    if said.strip():
        fail(inp, f"VTK said while reading the input: {said.strip()}")
    res, said = read(out)
    if "ERROR" in said or "Warning" in said or "WARNING" in said or said.strip():
        fail(out, f"VTK said: {said.strip()}")
        return
    if res is None or res.GetNumberOfPoints() != src.GetNumberOfPoints():
        fail(out, "another number of points than the input")
        return
    pd, ipd = res.GetPointData(), src.GetPointData()
    got, had = arrays(pd), arrays(ipd)
    scalars = pd.GetScalars()
    if scalars is None or scalars.GetName() != array:
        fail(out, f"active scalars {scalars.GetName() if scalars else None}, not `{array}`")
    for own in ["input", "smoothed", "representative", "role"]:
        if own not in got:
            fail(out, f"no `{own}` array")
    if array in got and "smoothed" in got and not np.array_equal(got[array][2], got["smoothed"][2]):
        fail(out, f"`{array}` is not the smoothed field")
    if "input" in got and array in had and not np.array_equal(got["input"][2], had[array][2]):
        fail(out, "`input` differs from the input's array")
    for name, (ty, comps, values) in had.items():
        if name == array:
            continue
        if name not in got:
            fail(out, f"input point array `{name}` not carried")
        elif got[name][1] != comps or not np.array_equal(got[name][2], values) or not same_type(got[name][0], ty, out.endswith(".vtk")):
            fail(out, f"point array `{name}` changed: {got[name][0]}x{got[name][1]} for {ty}x{comps}")
    got_c, had_c = arrays(res.GetCellData()), arrays(src.GetCellData())
    for name, (ty, comps, values) in had_c.items():
        if name not in got_c:
            fail(out, f"input cell array `{name}` not carried")
        elif not np.array_equal(got_c[name][2], values) or not same_type(got_c[name][0], ty, out.endswith(".vtk")):
            fail(out, f"cell array `{name}` changed")
    if res.GetNumberOfCells() != src.GetNumberOfCells():
        fail(out, f"{res.GetNumberOfCells()} cells, the input {src.GetNumberOfCells()}")
    print(f"ok {os.path.basename(out)}: {len(got)} point arrays, {len(got_c)} cell arrays")


def write_vti(data, path):
    """Writes image data with VTK's XML writer and its defaults."""
    w = vtk.vtkXMLImageDataWriter()
    w.SetInputData(data)
    w.SetFileName(path)
    w.Write()


def check_opens(path, want_arrays):
    data, said = read(path)
    if said.strip():
        fail(path, f"VTK said: {said.strip()}")
        return
    names = set(arrays(data.GetPointData())) | set(arrays(data.GetCellData()))
    missing = [n for n in want_arrays if n not in names]
    if data.GetNumberOfPoints() == 0 or missing:
        fail(path, f"{data.GetNumberOfPoints()} points; missing arrays {missing}")
    else:
        print(f"ok {os.path.basename(path)}: {data.GetNumberOfPoints()} points, arrays {sorted(names)}")


os.makedirs(WORK, exist_ok=True)
cases = [
    ("types.appended-raw-zlib-u64.vti", ["vti", "vtk"]),
    ("img.pyvista-default.vti", ["vti", "vtk"]),
    ("img_flipy.ascii.vti", ["vti"]),
    ("types.ascii.vtp", ["vtp", "vtu", "vtk"]),
    ("surf.binary-zlib-u64.vtu", ["vtu", "vtp", "vtk"]),
    ("surf.legacy-ugrid-binary-v51.vtk", ["vtu", "vtk"]),
    # tetrahedral meshes: the tetra cells and their arrays go through
    ("tets.ascii.vtu", ["vtu", "vtk"]),
    ("tets.legacy-ugrid-binary-v51.vtk", ["vtu", "vtk"]),
]
for name, outputs in cases:
    inp = os.path.join(FIXTURES, name)
    if not os.path.exists(inp):
        fail(inp, "fixture missing")
        continue
    for ext in outputs:
        out = os.path.join(WORK, f"{name}.out.{ext}")
        if run("smooth", inp, "--array", "f", "--persistence", "20%", "-o", out):
            check_smoothed(inp, out, "f")
            run("verify", out)
            if name.startswith("tets"):
                res, _ = read(out)
                types = {res.GetCellType(c) for c in range(res.GetNumberOfCells())}
                if types != {vtk.VTK_TETRA}:
                    fail(out, f"cell types {types}, not tetrahedra only")

# the other writers: the complex, geodesic distance, weights
karman = os.path.join(DATASETS, "karman_vortex_street_ttk_example1.vti")
out, cx = os.path.join(WORK, "karman.vti"), os.path.join(WORK, "karman_complex.vtp")
if run("smooth", karman, "--derive", "vorticity", "--persistence", "5%", "-o", out, "--complex", cx):
    check_opens(out, ["smoothed", "input", "representative", "role", "Vectors_"])
    # a derived field has no input array's name: `smoothed` is the active scalars
    k, _ = read(out)
    if k.GetPointData().GetScalars() is None or k.GetPointData().GetScalars().GetName() != "smoothed":
        fail(out, "the active scalars are not `smoothed`")
    check_opens(cx, ["input"])
bunny = os.path.join(DATASETS, "bunny.obj")
geo = os.path.join(WORK, "bunny_geodesic.vtu")
if run("geodesic", bunny, "--source", "0", "-o", geo):
    check_opens(geo, [])
penguin = os.path.join(DATASETS, "penguin.obj")
w = os.path.join(WORK, "penguin_weights.vtu")
if run("weights", penguin, "--handles", os.path.join(DATASETS, "penguin_handles.json"), "-o", w):
    check_opens(w, [])

# TTK's diagram: VTK's Threshold on `Persistence` (diagonal excluded, as TTK's filters do)
# selects exactly the pairs the selection keeps
volcano = os.path.join(DATASETS, "volcano_maunga_whau_61x87.csv")
vo, vd, vc = (os.path.join(WORK, n) for n in ["volcano.vti", "volcano_diagram.vtu", "volcano_complex.vtp"])
if run("smooth", volcano, "--persistence", "5%", "-o", vo, "--diagram", vd, "--complex", vc):
    check_opens(vd, ["PairIdentifier", "PairType", "Persistence", "Birth", "IsFinite", "CriticalType", "Coordinates"])
    check_opens(vc, ["CriticalType", "ttkVertexScalarField", "Persistence", "PairIdentifier", "Kept", "SeparatrixType"])
    diagram, _ = read(vd)
    lo, hi = float("inf"), float("-inf")
    field, _ = read(vo)
    values = vtk_to_numpy(field.GetPointData().GetArray("input"))
    roles = vtk_to_numpy(field.GetPointData().GetArray("role"))
    t = 0.05 * (values.max() - values.min())
    th = vtk.vtkThreshold()
    th.SetInputData(diagram)
    th.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_CELLS, "Persistence")
    th.SetThresholdFunction(vtk.vtkThreshold.THRESHOLD_UPPER)
    th.SetUpperThreshold(t)
    th.Update()
    ids = vtk_to_numpy(th.GetOutput().GetCellData().GetArray("PairIdentifier"))
    pairs = int((ids >= 0).sum())
    kept = int((abs(roles) == 1).sum())
    # the essential pair keeps two extrema, every other pair one
    if pairs + 1 != kept:
        fail(vd, f"Threshold Persistence >= {t} keeps {pairs} pairs; the output keeps {kept} extrema")
    else:
        print(f"ok Threshold on Persistence: {pairs} pairs for {kept} kept extrema")

# a raster: our .vti puts every pixel where ParaView's PNG reader puts it (top row at the top)
png = os.path.join(WORK, "ramp.png")
rows, cols = np.mgrid[0:5, 0:7]
pixels = (rows * 40 + cols * 3 + ((rows * 7 + cols * 5) % 4)).astype(np.uint8)
writer = vtk.vtkPNGWriter()
image = vtk.vtkImageData()
image.SetDimensions(7, 5, 1)
# vtkPNGWriter writes VTK's row y = 0 as the file's bottom row: hand it the rows reversed so
# that the file's top row is pixels[0]
from vtk.util.numpy_support import numpy_to_vtk
image.GetPointData().SetScalars(numpy_to_vtk(pixels[::-1].ravel(), array_type=vtk.VTK_UNSIGNED_CHAR))
writer.SetInputData(image)
writer.SetFileName(png)
writer.Write()
ramp = os.path.join(WORK, "ramp.vti")
if run("smooth", png, "--minima", "1", "--maxima", "1", "-o", ramp):
    ours, _ = read(ramp)
    theirs = vtk.vtkPNGReader()
    theirs.SetFileName(png)
    theirs.Update()
    ref = theirs.GetOutput()
    ref_values = vtk_to_numpy(ref.GetPointData().GetScalars()).astype(float)
    our_values = vtk_to_numpy(ours.GetPointData().GetArray("input"))
    ref_at = {tuple(np.round(ref.GetPoint(i), 9)): ref_values[i] for i in range(ref.GetNumberOfPoints())}
    our_at = {tuple(np.round(ours.GetPoint(i), 9)): our_values[i] for i in range(ours.GetNumberOfPoints())}
    if ref_at != our_at:
        fail(ramp, "pixels are not where vtkPNGReader puts them (the image is flipped)")
    elif ours.GetPoint(0)[1] != 4.0 or our_values[0] != pixels[0, 0]:
        fail(ramp, f"the file's top-left pixel is at {ours.GetPoint(0)}, expected y = 4")
    else:
        print("ok raster .vti: every pixel where vtkPNGReader puts it")

# images in the x-z and y-z planes written by VTK itself, off the origin: the outputs
# (.vti, legacy .vtk) put every point where the input has it
for dims, name in [((6, 1, 5), "xz"), ((1, 6, 5), "yz")]:
    flat_img = vtk.vtkImageData()
    flat_img.SetDimensions(*dims)
    flat_img.SetSpacing(0.5, 2.0, 0.25)
    flat_img.SetOrigin(1.0, 3.0, -2.0)
    n_pts = flat_img.GetNumberOfPoints()
    vals = np.array([np.sin(0.9 * q) + 0.1 * ((q * 7) % 5) for q in range(n_pts)])
    arr = numpy_to_vtk(vals, deep=True, array_type=vtk.VTK_DOUBLE)
    arr.SetName("f")
    flat_img.GetPointData().SetScalars(arr)
    fin = os.path.join(WORK, f"plane_{name}.vti")
    write_vti(flat_img, fin)
    for ext in ["vti", "vtk"]:
        fout = os.path.join(WORK, f"plane_{name}.out.{ext}")
        if run("smooth", fin, "--minima", "1", "--maxima", "1", "-o", fout):
            check_smoothed(fin, fout, "f")
            res, _ = read(fout)
            moved = [q for q in range(n_pts) if res.GetPoint(q) != flat_img.GetPoint(q)]
            if res.GetNumberOfPoints() != n_pts or moved:
                fail(fout, f"{len(moved)} points are not where the input has them")
            else:
                print(f"ok {name} image .{ext}: every point where the input has it")

# a volume written by VTK itself (Int16 field plus a carried Float32 array), smoothed to
# .vti, legacy .vtk and .nii.gz; the NIfTI output read by VTK's own vtkNIFTIImageReader
vol = vtk.vtkImageData()
vol.SetDimensions(9, 8, 7)
vol.SetSpacing(1.0, 2.0, 0.5)
vol.SetOrigin(-3.0, 1.0, 2.0)
k, j, i = np.meshgrid(np.arange(7), np.arange(8), np.arange(9), indexing="ij")
field = (1000 * np.sin(i / 2.5) * np.cos(j / 3.0) + 300 * np.cos(k / 2.0) + 40 * ((i * 7 + j * 13 + k * 29) % 11)).astype(np.int16)
from vtk.util.numpy_support import numpy_to_vtk as _to_vtk
f_arr = _to_vtk(field.ravel(), deep=True, array_type=vtk.VTK_SHORT)
f_arr.SetName("density")
extra = _to_vtk((i + 0.5 * k).astype(np.float32).ravel(), deep=True, array_type=vtk.VTK_FLOAT)
extra.SetName("extra")
vol.GetPointData().SetScalars(f_arr)
vol.GetPointData().AddArray(extra)
vin = os.path.join(WORK, "volume_in.vti")
write_vti(vol, vin)
for ext in ["vti", "vtk"]:
    vout = os.path.join(WORK, f"volume_out.{ext}")
    if run("smooth", vin, "--array", "density", "--persistence", "10%", "-o", vout):
        check_smoothed(vin, vout, "density")
        res, _ = read(vout)
        if res.GetDimensions() != (9, 8, 7) or res.GetSpacing() != (1.0, 2.0, 0.5) or res.GetOrigin() != (-3.0, 1.0, 2.0):
            fail(vout, f"geometry {res.GetDimensions()} {res.GetSpacing()} {res.GetOrigin()}")
nout = os.path.join(WORK, "volume_out.nii.gz")
if run("smooth", vin, "--array", "density", "--persistence", "10%", "-o", nout):
    nr = vtk.vtkNIFTIImageReader()
    nr.SetFileName(nout)
    nr.Update()
    nimg = nr.GetOutput()
    ours, _ = read(os.path.join(WORK, "volume_out.vti"))
    nvals = vtk_to_numpy(nimg.GetPointData().GetScalars())
    svals = vtk_to_numpy(ours.GetPointData().GetArray("smoothed"))
    if nimg.GetDimensions() != (9, 8, 7) or nvals.dtype != np.float64 or not np.array_equal(nvals, svals):
        fail(nout, f"vtkNIFTIImageReader reads {nimg.GetDimensions()} {nvals.dtype}, not the smoothed field")
    elif nimg.GetSpacing() != (1.0, 2.0, 0.5):
        fail(nout, f"spacing {nimg.GetSpacing()}")
    else:
        print("ok volume .nii.gz: vtkNIFTIImageReader reads the smoothed field bit for bit")
# the same volume with a uint8 mask array (VTK's own writer): smoothed inside the mask only,
# the output read by vtkXMLImageDataReader with the outside unchanged and the domain's mask
brain = ((i - 4.0) ** 2 + (j - 3.5) ** 2 + ((k - 3.0) * 1.2) ** 2 < 12.0).astype(np.uint8)
m_arr = _to_vtk(brain.ravel(), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
m_arr.SetName("brain")
vol.GetPointData().AddArray(m_arr)
min_ = os.path.join(WORK, "volume_masked_in.vti")
write_vti(vol, min_)
mout = os.path.join(WORK, "volume_masked_out.vti")
if run("smooth", min_, "--array", "density", "--mask", "brain", "--persistence", "10%", "-o", mout):
    check_smoothed(min_, mout, "density")
    res, _ = read(mout)
    pd = res.GetPointData()
    dom = vtk_to_numpy(pd.GetArray("mask"))
    sm, inp = vtk_to_numpy(pd.GetArray("smoothed")), vtk_to_numpy(pd.GetArray("input"))
    roles = vtk_to_numpy(pd.GetArray("role"))
    inside = brain.ravel() != 0
    if dom is None or not np.all(dom[~inside] == 0) or dom.sum() < 0.5 * inside.sum():
        fail(mout, "the mask array is not the domain inside the brain mask")
    elif not (np.array_equal(sm[dom == 0], inp[dom == 0]) and np.all(roles[dom == 0] == 0)):
        fail(mout, "voxels outside the mask changed")
    elif np.array_equal(sm[dom == 1], inp[dom == 1]):
        fail(mout, "nothing inside the mask was smoothed")
    else:
        print(f"ok masked volume .vti: {int(dom.sum())} of {dom.size} voxels smoothed, the rest unchanged")
# the bundled real MRI volume (written by VTK's XML writer with its defaults)
t1 = os.path.join(DATASETS, "mri_anatomical_33x41x25.vti")
t1_out, t1_cx, t1_d = (os.path.join(WORK, n) for n in ["t1_out.vti", "t1_complex.vtp", "t1_diagram.vtu"])
if run("smooth", t1, "-o", t1_out, "--complex", t1_cx, "--diagram", t1_d):
    check_smoothed(t1, t1_out, "t1")
    # the volume's critical points (TTK's 3D codes) sit on the image's own points
    check_opens(t1_cx, ["CriticalType", "ttkVertexScalarField", "Kept"])
    check_opens(t1_d, ["PairIdentifier", "PairType", "Persistence", "CriticalType"])
    cx, _ = read(t1_cx)
    img, _ = read(t1_out)
    ids = vtk_to_numpy(cx.GetPointData().GetArray("ttkVertexScalarField"))
    codes = set(vtk_to_numpy(cx.GetPointData().GetArray("CriticalType")).tolist())
    off = [i for i in range(len(ids)) if max(abs(a - b) for a, b in zip(cx.GetPoint(i), img.GetPoint(int(ids[i])))) > 1e-9]
    if off or not {0, 1, 2, 3} <= codes:
        fail(t1_cx, f"{len(off)} critical points off their voxels; codes {sorted(codes)}")
    else:
        print(f"ok volume complex: {len(ids)} critical points on their voxels, codes {sorted(codes)}")

# the synthetic ABC flow: a derived field (|curl u|) from a 3-component velocity volume
abc = os.path.join(DATASETS, "abc_flow_noisy_32x32x32.vti")
abc_out = os.path.join(WORK, "abc_out.vti")
if run("smooth", abc, "--derive", "vorticity-magnitude", "--persistence", "10%", "-o", abc_out):
    check_opens(abc_out, ["smoothed", "input", "representative", "role"])
    a, _ = read(abc_out)
    if a.GetDimensions() != (32, 32, 32) or a.GetPointData().GetScalars().GetName() != "smoothed":
        fail(abc_out, f"dimensions {a.GetDimensions()}; the active scalars are not `smoothed`")

if failures:
    print(f"{len(failures)} failures", file=sys.stderr)
    sys.exit(1)
print("every output opens in VTK", vtk.vtkVersion.GetVTKVersion(), "without a message")
