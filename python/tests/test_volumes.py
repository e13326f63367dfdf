"""Volumes and tetrahedral meshes from numpy: the package against the CLI on the bundled MRI
volume (whole and masked), and against SPEC.md's neighbours counted here on tetrahedra."""

import itertools

import numpy as np
import pytest

import toposmooth
from conftest import strict_extrema

T1 = "mri_anatomical_33x41x25.nii"


def test_the_mri_volume_is_bit_identical_to_the_cli(datasets, cli, tmp_path):
    out = tmp_path / "t1.npz"
    cli("smooth", datasets / T1, "--persistence", "10%", "-o", out)
    ref = np.load(out)
    h = ref["input"]
    assert h.shape == (25, 41, 33)
    r = toposmooth.smooth(h, spacing=(2.0, 2.0, 2.0), persistence="10%")
    assert r.smoothed.shape == (25, 41, 33) and r.certified
    assert np.array_equal(r.smoothed, ref["smoothed"])
    assert np.array_equal(r.representative, ref["representative"])
    assert np.array_equal(r.roles, ref["role"].astype(np.int8))
    assert r.kept_minima.size > 0 and r.kept_maxima.size > 0


def test_a_masked_volume_is_bit_identical_to_the_cli_and_leaves_the_outside(datasets, cli, tmp_path):
    out = tmp_path / "t1_masked.npz"
    cli("smooth", datasets / T1, "--mask-below", "3000", "-o", out)
    ref = np.load(out)
    h = ref["input"]
    inside = h >= 3000
    r = toposmooth.smooth(h, spacing=(2.0, 2.0, 2.0), mask=inside)
    assert r.certified
    assert np.array_equal(r.smoothed, ref["smoothed"])
    assert np.array_equal(r.roles, ref["role"].astype(np.int8))
    domain = ref["mask"] != 0
    assert np.array_equal(domain & ~inside, np.zeros_like(domain))
    assert np.array_equal(r.smoothed[~domain], h[~domain]) and np.all(r.roles[~domain] == 0)
    assert not np.array_equal(r.smoothed[domain], h[domain])
    # NaN outside a mask is background, not missing data
    hn = np.where(inside, h, np.nan)
    rn = toposmooth.smooth(hn, spacing=(2.0, 2.0, 2.0), mask=inside)
    assert np.array_equal(rn.smoothed[domain], r.smoothed[domain])
    with pytest.raises(toposmooth.InputError, match="mask has shape"):
        toposmooth.smooth(h, mask=inside[0])


def freudenthal_tets(n):
    """A jittered n×n×n point lattice cut into six tetrahedra per cube, numbered at random."""
    rng = np.random.default_rng(7)
    idx = lambda i, j, k: i + n * (j + n * k)
    pts = np.array([[i, j, k] for k in range(n) for j in range(n) for i in range(n)], float)
    pts += rng.uniform(-0.2, 0.2, pts.shape)
    tets = []
    for i, j, k in itertools.product(range(n - 1), repeat=3):
        c = [idx(i + a, j + b, k + d) for d in (0, 1) for b in (0, 1) for a in (0, 1)]
        # the six tetrahedra around the diagonal from corner 0 to corner 7
        for p in itertools.permutations((1, 2, 4)):
            a = p[0]
            b = a | p[1]
            tets.append([c[0], c[a], c[b], c[7]])
    perm = rng.permutation(len(pts))
    return pts[np.argsort(perm)], perm[np.array(tets)]


def test_tetrahedral_meshes_keep_exactly_the_chosen_extrema():
    v, t = freudenthal_tets(6)
    rng = np.random.default_rng(3)
    h = np.sin(v[:, 0]) * np.cos(v[:, 1]) + 0.3 * rng.standard_normal(len(v))
    h = np.round(h, 1)  # ties
    nbrs = [set() for _ in range(len(v))]
    for tet in t:
        for a in tet:
            nbrs[a].update(int(b) for b in tet if b != a)
    domain = toposmooth._toposmooth.Domain.tetrahedra(v, t)
    assert domain.kind == "tetrahedra" and domain.n_vertices == 216
    r = toposmooth.smooth(h, vertices=v, faces=t, persistence="20%")
    assert r.certified
    mins, maxs = strict_extrema(r.smoothed, lambda i: nbrs[i])
    assert mins == set(r.kept_minima) and maxs == set(r.kept_maxima)
    assert 0 < len(mins) + len(maxs) < 20
    kept = np.concatenate([r.kept_minima, r.kept_maxima])
    assert np.array_equal(r.smoothed[kept], h[kept])
    bad = t.copy()
    bad[0, 1] = bad[0, 0]
    with pytest.raises(toposmooth.InputError, match="repeat a corner"):
        toposmooth.smooth(h, vertices=v, faces=bad)


def test_the_synthetic_abc_flow_s_vorticity_magnitude_is_bit_identical_to_the_cli(datasets, cli, tmp_path):
    # the CLI derives |curl u| from the velocity; its .npz `input` is that field, which a
    # numpy user smooths with the file's spacing and gets the same output bit for bit
    out = tmp_path / "abc.npz"
    args = ["--persistence", "10%", "--smooth-length", "0.03", "--solver", "active-set"]
    cli("smooth", datasets / "abc_flow_noisy_32x32x32.vti", "--derive", "vorticity-magnitude", *args, "-o", out)
    ref = np.load(out)
    h = ref["input"]
    assert h.shape == (32, 32, 32)
    d = 2 * np.pi / 32
    r = toposmooth.smooth(h, spacing=(d, d, d), persistence="10%", smooth_length=0.03, solver="active-set")
    assert r.certified
    assert np.array_equal(r.smoothed, ref["smoothed"])
    assert np.array_equal(r.roles, ref["role"].astype(np.int8))
    assert r.kept_minima.size > 10 and r.kept_maxima.size > 10
