"""toposmooth: smooth scalar fields with certified control of their extrema.

The field keeps exactly the local minima and maxima you ask for (by persistence, by count or
by an explicit list), at their places and values, and every result carries a certificate
that proves it (Jacobson, Weinkauf & Sorkine, *Smooth Shape-Aware Functions with Controlled
Extrema*, SGP 2012).

Domains
-------
- a 1-D array or pandas Series: a series (x = 0, 1, ..., or ``x=``, or the Series' index;
  a DatetimeIndex gives x in days since 1970-01-01, as the CLI reads dates);
- a 2-D array: a regular grid, rows = y (``values[r, c]`` at ``origin + (c*dx, r*dy)``);
- ``vertices=V, faces=F``: a triangle mesh, one value per vertex.

Functions
---------
smooth     the field with exactly the kept extrema, certified
read       any file the CLI reads, with its input options: a Dataset (numpy values, domain)
extrema    every extremum with its persistence and whether a selection keeps it
verify     re-check a field's certificate
geodesic   geodesic distance on a mesh (heat method)
weights    smooth, certified weight functions for handles
Smoother   many fields on one domain, the domain's analysis reused

Long calls take ``progress=`` (a callable told each stage and how far it is) and
``cancel=`` (a :class:`CancelToken`); Ctrl-C stops them at their next check.

Example
-------
>>> import numpy as np, toposmooth
>>> rng = np.random.default_rng(0)
>>> y, x = np.mgrid[0:40, 0:60]
>>> h = np.sin(x / 9.0) * np.cos(y / 7.0) + 0.05 * rng.standard_normal(x.shape)
>>> r = toposmooth.smooth(h, persistence="20%")
>>> r.certified, r.smoothed.shape
(True, (40, 60))
"""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _toposmooth
from .errors import (
    Cancelled,
    CertificateError,
    Error,
    InfeasibleError,
    InputError,
    InternalError,
    IoError,
    MemoryLimitError,
    SolverError,
    UsageError,
)

__version__ = _toposmooth.version()

__all__ = [
    "smooth",
    "extrema",
    "verify",
    "geodesic",
    "weights",
    "Smoother",
    "SmoothResult",
    "Domain",
    "Error",
    "UsageError",
    "InputError",
    "IoError",
    "InfeasibleError",
    "CertificateError",
    "SolverError",
    "InternalError",
    "Cancelled",
    "MemoryLimitError",
    "CancelToken",
    "SETTINGS",
    "INPUT_OPTIONS",
    "read",
    "Dataset",
]

Domain = _toposmooth.Domain

#: A token to stop a long call from another thread: ``t = toposmooth.CancelToken()``, pass
#: ``cancel=t``, then ``t.cancel()``; the call raises :class:`Cancelled` at its next check
#: (between stages and solver iterations) and leaves no output or temporary file behind.
CancelToken = _toposmooth.CancelToken

#: The settings of a smoothing run, the library's schema (the CLI's flags are made from it;
#: :func:`smooth`'s keywords follow it): one dict per setting with ``name``, ``kind``
#: (``threshold``, ``count``, ``real``, ``switch``, ``choice``, ``indices``, ``orders``),
#: ``default`` (text, None where the run chooses), ``group``, ``help``, ``partner`` and, per
#: kind, ``choices``, ``min``, ``max``, ``inclusive``.
SETTINGS: tuple = tuple(_toposmooth.settings_schema())
_SETTING_NAMES = frozenset(s["name"] for s in SETTINGS)

#: The input options of :func:`read` (the CLI's input flags: ``x_column`` is ``--x``): one
#: dict each with ``name``, ``switch``, ``choices`` and ``help``.
INPUT_OPTIONS: tuple = tuple(_toposmooth.input_options())
_SELECTION_NAMES = tuple(s["name"] for s in SETTINGS if s["group"] == "selection")

#: Role codes of ``SmoothResult.roles`` (the ``role`` array of the CLI's outputs).
ROLE_MIN, ROLE_MAX, ROLE_OTHER, ROLE_FIXED, ROLE_END = -1, 1, 0, 2, 3


def _float64(name: str, a: Any, ndim: Optional[int] = None) -> np.ndarray:
    """A C-contiguous float64 view of ``a`` (no copy when it already is one)."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "fiub":
        raise UsageError(f"{name} must hold numbers, got dtype {arr.dtype}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if ndim is not None and arr.ndim != ndim:
        raise InputError(f"{name} must be {ndim}-D, got shape {arr.shape}")
    return arr


def _indices(name: str, values: Any) -> List[int]:
    """Vertex indices as Python ints; a negative or non-integer one is a usage error."""
    a = np.asarray(values)
    if a.size and (a.dtype.kind not in "iu" or a.min() < 0):
        raise UsageError(f"{name} must be non-negative vertex indices, got {values!r}")
    return [int(i) for i in a.reshape(-1)]


def _days_since_epoch(index: Any) -> np.ndarray:
    """Days since 1970-01-01 of a pandas DatetimeIndex, computed as the CLI computes them
    from the timestamps' text: (whole seconds + nanoseconds * 1e-9) / 86400, in UTC."""
    # pandas 2+ stores dates in s, ms, us or ns: asi8 is in the index's unit
    if hasattr(index, "as_unit"):
        index = index.as_unit("ns")
    ns = np.asarray(index.asi8, dtype=np.int64)
    seconds, nanos = np.divmod(ns, 1_000_000_000)
    return (seconds.astype(np.float64) + nanos.astype(np.float64) * 1e-9) / 86400.0


def _series_x(values: Any, x: Any) -> Optional[np.ndarray]:
    if x is not None:
        if np.asarray(x).dtype.kind == "M" or hasattr(x, "asi8"):
            import pandas as pd

            return _days_since_epoch(pd.DatetimeIndex(x))
        return _float64("x", x, 1)
    index = getattr(values, "index", None)
    if index is None:
        return None
    try:
        import pandas as pd
    except ImportError:  # pragma: no cover - a Series without pandas cannot exist
        return None
    if isinstance(index, pd.DatetimeIndex):
        return _days_since_epoch(index)
    if isinstance(index, pd.RangeIndex) and index.start == 0 and index.step == 1:
        return None
    if index.dtype.kind in "iuf":
        return _float64("x (the Series' index)", index.to_numpy(), 1)
    raise UsageError(f"a Series' index must be numbers or dates to serve as x, got dtype {index.dtype}")


def _domain(
    values: Any,
    x: Any = None,
    spacing: Optional[Sequence[float]] = None,
    origin: Optional[Sequence[float]] = None,
    vertices: Any = None,
    faces: Any = None,
) -> "tuple[Any, np.ndarray, tuple]":
    """The domain for ``values`` and the values as one contiguous float64 vector."""
    if (vertices is None) != (faces is None):
        raise UsageError("a mesh needs both vertices= and faces=")
    h = _float64("values", values)
    if vertices is not None:
        if x is not None or spacing is not None or origin is not None:
            raise UsageError("x=, spacing= and origin= are for series, grids and volumes, not meshes")
        v = _float64("vertices", vertices, 2)
        f = np.ascontiguousarray(np.asarray(faces), dtype=np.int64)
        if f.ndim != 2 or f.shape[1] not in (3, 4):
            raise InputError(f"faces must be 2-D (m, 3) triangles or (m, 4) tetrahedra, got shape {f.shape}")
        if h.ndim != 1:
            raise InputError(f"values on a mesh must be 1-D (one per vertex), got shape {h.shape}")
        if f.shape[1] == 4:
            return _toposmooth.Domain.tetrahedra(v, f), h, h.shape
        return _toposmooth.Domain.mesh(v, f), h, h.shape
    if h.ndim == 1:
        if spacing is not None or origin is not None:
            raise UsageError("spacing= and origin= are for grids and volumes (2-D, 3-D values); a series takes x=")
        return _toposmooth.Domain.series(h.shape[0], _series_x(values, x)), h, h.shape
    if x is not None:
        raise UsageError("x= is for series; a grid or volume takes spacing= and origin=")
    d = h.ndim
    if d not in (2, 3):
        raise InputError(
            f"values must be 1-D (a series or a mesh field), 2-D (ny, nx) a grid or 3-D (nz, ny, nx) a volume, got shape {h.shape}"
        )
    for name, given in (("spacing", spacing), ("origin", origin)):
        if given is not None and len(given) != d:
            raise UsageError(f"{name}= has {len(given)} entries; {d}-D values take {d} (x first)")
    step = [1.0] * d if spacing is None else [float(s) for s in spacing]
    at = [0.0] * d if origin is None else [float(o) for o in origin]
    if d == 2:
        ny, nx = h.shape
        return _toposmooth.Domain.grid(nx, ny, step, at), h.reshape(-1), h.shape
    nz, ny, nx = h.shape
    return _toposmooth.Domain.volume(nx, ny, nz, step, at), h.reshape(-1), h.shape


class SmoothResult:
    """What :func:`smooth` returns.

    Attributes
    ----------
    smoothed : ndarray of float64, the input's shape
        The output field, certified to have exactly the kept extrema.
    representative : ndarray of float64, the input's shape
        The representative function u whose order the output follows.
    roles : ndarray of int8, the input's shape
        -1 kept minimum, 1 kept maximum, 0 other, 2 fixed, 3 free end of a series.
    kept_minima, kept_maxima : ndarray of int64
        Flat vertex indices of the kept extrema (``r * nx + c`` on a grid).
    filled : ndarray of bool or None
        The samples ``fill_missing`` filled (None when nothing was missing).
    report : dict
        The JSON report (settings, selection, certificate, deviations, the fit's gap, seconds).
    certified : bool
        Always True: a result that cannot be certified raises :class:`CertificateError`.
    certificate : dict
        The report's certificate: the strict extrema counted and what was checked.
    """

    __slots__ = ("smoothed", "representative", "roles", "kept_minima", "kept_maxima", "filled", "report", "certified")

    def __init__(self, raw: Dict[str, Any], shape: tuple, filled: Optional[np.ndarray]) -> None:
        self.smoothed: np.ndarray = raw["smoothed"].reshape(shape)
        self.representative: np.ndarray = raw["representative"].reshape(shape)
        roles = raw["roles"]
        self.roles: np.ndarray = roles.reshape(shape)
        self.kept_minima: np.ndarray = np.flatnonzero(roles == ROLE_MIN).astype(np.int64)
        self.kept_maxima: np.ndarray = np.flatnonzero(roles == ROLE_MAX).astype(np.int64)
        self.filled: Optional[np.ndarray] = None if filled is None else filled.reshape(shape)
        self.report: Dict[str, Any] = json.loads(raw["report"])
        self.certified: bool = bool(raw["certified"])

    @property
    def certificate(self) -> Dict[str, Any]:
        return self.report["certificate"]

    def __repr__(self) -> str:
        c = self.certificate
        return (
            f"SmoothResult(shape={self.smoothed.shape}, kept {self.kept_minima.size} minima and "
            f"{self.kept_maxima.size} maxima, certified={self.certified}: "
            f"{c.get('strict_minima')} strict minima, {c.get('strict_maxima')} strict maxima)"
        )


class Smoother:
    """Many fields on one domain with one set of settings (time steps, ensemble members).

    Built once, it keeps the domain's operators (stiffness, mass, the fills' Laplacian) and
    the symbolic analyses of their factorisations; each :meth:`smooth` reuses them. Takes the
    same domain and settings arguments as :func:`smooth`, without the values::

        s = toposmooth.Smoother(shape=(ny, nx), spacing=(dx, dy), persistence="5%")
        results = [s.smooth(frame) for frame in frames]

    Parameters
    ----------
    shape : tuple, optional
        ``(n,)`` for a series, ``(ny, nx)`` for a grid, ``(nz, ny, nx)`` for a volume; not for a mesh.
    x, spacing, origin, vertices, faces
        As in :func:`smooth`.
    **settings
        Every setting of :func:`smooth` except ``fill_missing``, which is per field.
    """

    def __init__(
        self,
        shape: Optional[Sequence[int]] = None,
        *,
        x: Any = None,
        spacing: Optional[Sequence[float]] = None,
        origin: Optional[Sequence[float]] = None,
        vertices: Any = None,
        faces: Any = None,
        fill_missing: bool = False,
        **settings: Any,
    ) -> None:
        if vertices is not None:
            n = np.asarray(vertices).shape[0]
            self._shape: tuple = (n,)
        elif shape is not None:
            self._shape = tuple(int(s) for s in shape)
        elif x is not None:
            self._shape = (np.asarray(x).shape[0],)
        else:
            raise UsageError("Smoother needs shape= (series or grid), x= (series) or vertices=, faces= (mesh)")
        self._domain, _, _ = _domain(np.zeros(self._shape), x, spacing, origin, vertices, faces)
        self._fill_missing = bool(fill_missing)
        self._settings = _resolve(settings)
        self._inner = _toposmooth.Smoother(self._domain, self._settings)

    @property
    def domain(self) -> Any:
        """The domain (a ``toposmooth.Domain``)."""
        return self._domain

    def smooth(self, values: Any, *, progress: Any = None, cancel: Any = None) -> SmoothResult:
        """Smooths one field of the smoother's shape; see :func:`smooth` for the result and
        for ``progress`` and ``cancel``."""
        h = _float64("values", values)
        if h.shape != self._shape:
            raise InputError(f"values has shape {h.shape}, the smoother's domain {self._shape}")
        flat, filled = _fill(self._domain, h.reshape(-1), self._fill_missing, self._settings)
        return SmoothResult(self._inner.smooth(flat, progress, cancel), self._shape, filled)


def _resolve(settings: Dict[str, Any]) -> Dict[str, Any]:
    """The settings given (None is "not given"); their values are checked by the library,
    which reads them as it reads the CLI's flags."""
    unknown = sorted(set(settings) - _SETTING_NAMES)
    if unknown:
        raise UsageError(f"unknown setting(s): {', '.join(unknown)} (the settings are toposmooth.SETTINGS)")
    return {k: v for k, v in settings.items() if v is not None}


def _fill(
    domain: Any, flat: np.ndarray, fill_missing: bool, settings: Optional[Dict[str, Any]] = None
) -> "tuple[np.ndarray, Optional[np.ndarray]]":
    """The values with their NaN filled when asked, and the mask of filled samples. A kept
    extremum given explicitly may not be a filled sample (its value is not the input's), as in
    the CLI."""
    if not fill_missing or not np.isnan(flat).any():
        return flat, None
    filled, mask = _toposmooth.fill_missing(domain, flat)
    for key in ("keep_min", "keep_max"):
        given = (settings or {}).get(key)
        listed = [] if given is None or isinstance(given, str) else np.asarray(given).reshape(-1).tolist()
        bad = [i for i in listed if isinstance(i, int) and 0 <= i < mask.size and mask[i]]
        if bad:
            raise InputError(f"{key} names the missing sample {bad[0]}: a kept extremum must have an input value")
    return filled, mask


def smooth(
    values: Any,
    *,
    x: Any = None,
    spacing: Optional[Sequence[float]] = None,
    origin: Optional[Sequence[float]] = None,
    vertices: Any = None,
    faces: Any = None,
    persistence: Union[float, str, None] = None,
    minima: Optional[int] = None,
    maxima: Optional[int] = None,
    pairs: Optional[int] = None,
    keep_min: Optional[Sequence[int]] = None,
    keep_max: Optional[Sequence[int]] = None,
    keep_all_maxima: bool = False,
    keep_all_minima: bool = False,
    order: Union[int, str] = 2,
    data_weight: float = 1.0,
    smooth_length: Optional[float] = None,
    smooth_weight: Optional[float] = None,
    edges: str = "minimal",
    representative: Optional[str] = None,
    fill_missing: bool = False,
    mask: Any = None,
    max_iter: int = 200,
    solver: str = "auto",
    formulation: str = "auto",
    threads: Optional[int] = None,
    memory_limit: Union[str, int, None] = None,
    sharp: Optional[Sequence[int]] = None,
    progress: Any = None,
    cancel: Any = None,
) -> SmoothResult:
    """Smooth a field keeping exactly the chosen extrema, with a certificate.

    Parameters
    ----------
    values : array_like or pandas.Series
        Shape (n,): a series, or a field on a mesh's n vertices. Shape (ny, nx): a grid, row r
        at y = y0 + r*dy. Shape (nz, ny, nx): a volume, voxel [k, j, i] at
        origin + (i*dx, j*dy, k*dz) (a NIfTI or VTK image's x fastest). float64 is used
        without a copy when C-contiguous; float32 and integers are converted.
    x : array_like of shape (n,), optional
        Series coordinates, strictly increasing (default 0, 1, ...; a pandas Series' index:
        numbers, or dates as days since 1970-01-01).
    spacing : (dx, dy) or (dx, dy, dz), optional
        Grid or volume spacing (default 1); signs kept (dy < 0 for rows running downward).
    origin : (x0, y0) or (x0, y0, z0), optional
        Coordinates of ``values[0, 0]`` / ``values[0, 0, 0]`` (default 0).
    vertices : array_like of shape (n, 2) or (n, 3), optional
        Mesh vertex positions (with ``faces``).
    faces : array_like of int, shape (m, 3) or (m, 4), optional
        Mesh triangles, or tetrahedra (a tetrahedral mesh; ``vertices`` (n, 3)), as vertex
        indices.
    persistence : float or str, optional
        Keep the extrema of persistence >= this: a number in the field's units, or a
        percentage of the value range such as ``"5%"`` (the default rule, at 5 %).
    minima, maxima : int, optional
        Keep the N most persistent minima and M most persistent maxima (grids and meshes).
    pairs : int, optional
        Series: keep the N most persistent (minimum, maximum) pairs.
    keep_min, keep_max : sequence of int, optional
        Keep exactly these vertices (flat indices); checked for realizability.
    keep_all_maxima, keep_all_minima : bool
        Keep every maximum (resp. minimum) and only each part's global minimum (maximum).
    order : int or str
        Polyharmonic order k (1-4), or a blend such as ``"1:0.5,2:1"``.
    data_weight : float
        Weight of the data term (0: the no-data mode, u harmonic).
    smooth_length : float, optional
        Smoothing length as a fraction of the domain's diameter (default: chosen from the
        domain and the kept extrema; the report says which rule set it).
    smooth_weight : float, optional
        Energy weight for every order (default: smooth_length ** (2k)).
    edges : {"minimal", "all"}
        Constraint set: one lower and one higher neighbour per vertex, or every edge.
    representative : {"separatrix", "harmonic", "flooded"}, optional
        Representative function on grids and meshes (default: flooded, the data with its
        cancelled basins flooded, falling back to separatrix, then harmonic, each fallback
        reported).
    fill_missing : bool
        Fill NaN samples first (linearly on series, harmonically on grids and meshes), as
        the CLI's ``--fill-missing``; otherwise NaN is an :class:`InputError`.
    mask : array_like of bool, optional
        Grids and volumes: smooth only inside (True), as the CLI's ``--mask``: the domain is
        the triangles (tetrahedra) with every corner inside, the outside comes back unchanged
        with role 0, and NaN outside is background, not missing data.
    max_iter : int
        Largest number of solver iterations.
    solver : {"auto", "structured", "clarabel", "clarabel-auxiliary", "active-set"}
        ``auto``: the active-set iteration on volumes of 1,000 voxels or more, else the
        structured interior-point method.
    formulation : {"auto", "assembled", "factored"}
    threads : int, optional
        At most this many threads for the call (default: every core). Results are bit-identical for
        every thread count; 1 suits one process per core (Dask workers, pvbatch ranks).
    memory_limit : str or int, optional
        The memory the run may use: ``"6G"``, ``"512M"`` or bytes (default: the lowest of the
        cgroup's limit, ``ulimit -v`` and the machine's memory). A solver route predicted past
        it is refused before its work with :class:`MemoryLimitError` (a ``MemoryError``).
    sharp : sequence of int, optional
        Vertices where orders >= 2 are not penalised (a spike can stay C0).
    progress : callable, optional
        Called on this thread as the run goes, ``progress(stage, fraction, message)``: the
        stage (``"selection"``, ``"complex"``, ``"representative"``, ``"solve"``,
        ``"certificate"``), how far it is from 0 to 1 (None where not known; 1 when it ends)
        and what it does now (the iteration and its gap) or, at its end, its summary. An
        exception it raises stops the run and is raised.
    cancel : CancelToken, optional
        ``cancel.cancel()`` from another thread stops the run at its next check: the call
        raises :class:`Cancelled`. Ctrl-C stops it the same way and raises ``KeyboardInterrupt``.

    Returns
    -------
    SmoothResult
        ``smoothed``, ``representative``, ``roles``, ``kept_minima``, ``kept_maxima``,
        ``filled``, ``report`` (dict), ``certified`` and ``certificate``; arrays in the
        input's shape.

    Raises
    ------
    UsageError
        Contradictory or invalid settings (two selection rules, an unknown edge set).
    InputError
        NaN without ``fill_missing``, wrong sizes, a degenerate mesh.
    InfeasibleError
        An explicit list of extrema that no strict function realizes.
    CertificateError
        The output failed its certificate (a bug or a numerical failure).
    SolverError
        The solver returned no point.
    Cancelled
        The ``cancel`` token was cancelled.

    Notes
    -----
    The computation releases the GIL: other Python threads run meanwhile. Do not modify
    ``values`` from another thread during the call.

    Examples
    --------
    >>> import numpy as np, toposmooth
    >>> t = np.linspace(0, 6 * np.pi, 600)
    >>> h = np.sin(t) + 0.2 * np.sin(17 * t)
    >>> r = toposmooth.smooth(h, pairs=3)
    >>> r.kept_maxima.size, r.certified
    (3, True)
    """
    domain, flat, shape = _domain(values, x, spacing, origin, vertices, faces)
    settings = _resolve(
        dict(
            persistence=persistence,
            minima=minima,
            maxima=maxima,
            pairs=pairs,
            keep_min=keep_min,
            keep_max=keep_max,
            keep_all_maxima=keep_all_maxima,
            keep_all_minima=keep_all_minima,
            order=order,
            data_weight=data_weight,
            smooth_length=smooth_length,
            smooth_weight=smooth_weight,
            edges=edges,
            representative=representative,
            max_iter=max_iter,
            solver=solver,
            formulation=formulation,
            threads=threads,
            memory_limit=memory_limit,
            sharp=sharp,
        )
    )
    if mask is not None:
        inside = np.asarray(mask)
        if inside.shape != shape or len(shape) < 2:
            raise InputError(f"mask has shape {inside.shape}; it must be the values' shape {shape} (a grid or volume)")
        inside = np.ascontiguousarray(inside.reshape(-1) != 0)
        filled = None
        if fill_missing:
            # only the inside is filled: NaN outside the mask is background
            gaps = np.isnan(flat) & inside
            if gaps.any():
                raise UsageError("fill_missing= with mask=: give the mask without the NaN voxels, or fill first")
        raw = _toposmooth.smooth_masked(domain, settings, flat, inside, progress, cancel)
        return SmoothResult(raw, shape, filled)
    flat, filled = _fill(domain, flat, fill_missing, settings)
    raw = _toposmooth.Smoother(domain, settings).smooth(flat, progress, cancel)
    return SmoothResult(raw, shape, filled)


def extrema(
    values: Any,
    *,
    x: Any = None,
    spacing: Optional[Sequence[float]] = None,
    origin: Optional[Sequence[float]] = None,
    vertices: Any = None,
    faces: Any = None,
    persistence: Union[float, str, None] = None,
    minima: Optional[int] = None,
    maxima: Optional[int] = None,
    pairs: Optional[int] = None,
    keep_min: Optional[Sequence[int]] = None,
    keep_max: Optional[Sequence[int]] = None,
    keep_all_maxima: bool = False,
    keep_all_minima: bool = False,
    fill_missing: bool = False,
) -> Dict[str, np.ndarray]:
    """Every extremum of a field with its persistence (simulation of simplicity for ties).

    Parameters
    ----------
    values, x, spacing, origin, vertices, faces, fill_missing
        As in :func:`smooth`.
    persistence, minima, maxima, pairs, keep_min, keep_max, keep_all_maxima, keep_all_minima
        A selection, as in :func:`smooth` (default 5 % of the range), for the ``kept`` column.

    Returns
    -------
    dict of ndarray, one entry per extremum in vertex order
        ``vertex`` (int64 flat index), ``is_max`` (bool), ``endpoint`` (bool, a series'
        end), ``value`` (float64), ``persistence`` (float64, inf for each part's essential
        extrema, NaN for a series' endpoint maximum, which pairs with nothing),
        ``partner`` (int64, the vertex it pairs with, -1 for none), ``strict`` (bool, no
        equal neighbour), ``kept`` (bool, kept by the selection), and the pair as
        ``birth`` and ``death`` values (a minimum is born at its value, a maximum dies at its
        value; essential extrema have death inf, resp. birth -inf).
    """
    domain, flat, _ = _domain(values, x, spacing, origin, vertices, faces)
    flat, _ = _fill(domain, flat, fill_missing)
    sel = _resolve(
        dict(
            persistence=persistence,
            minima=minima,
            maxima=maxima,
            pairs=pairs,
            keep_min=keep_min,
            keep_max=keep_max,
            keep_all_maxima=keep_all_maxima,
            keep_all_minima=keep_all_minima,
        )
    )
    out = dict(_toposmooth.extrema(domain, flat, sel))
    # each extremum's persistence pair: a minimum is born at its value and dies at its partner's,
    # a maximum the other way round; essential extrema never die (death ±inf)
    partner_value = np.where(out["partner"] >= 0, flat[np.maximum(out["partner"], 0)], np.nan)
    is_max, essential = out["is_max"], np.isinf(out["persistence"])
    out["birth"] = np.where(is_max, partner_value, out["value"])
    out["death"] = np.where(is_max, out["value"], partner_value)
    out["birth"][essential & is_max] = -np.inf
    out["death"][essential & ~is_max] = np.inf
    # a series' endpoint maximum pairs with nothing (persistence NaN)
    unpaired = np.isnan(out["persistence"])
    out["birth"][unpaired] = np.nan
    out["death"][unpaired] = np.nan
    return out


def verify(
    smoothed: Any,
    roles: Any,
    input: Any = None,
    *,
    x: Any = None,
    spacing: Optional[Sequence[float]] = None,
    origin: Optional[Sequence[float]] = None,
    vertices: Any = None,
    faces: Any = None,
) -> Dict[str, Any]:
    """Re-check a field's certificate: its strict extrema are exactly the vertices whose role
    is -1 (minima) and 1 (maxima), every other vertex has a lower and a higher neighbour and,
    when ``input`` is given, the kept extrema keep their input values.

    Returns
    -------
    dict
        ``passed`` (bool), ``strict_minima``, ``strict_maxima``, ``flat`` (int), ``summary``
        (str), ``failures`` (list of str: item, vertex and reason) and ``report`` (dict).
    """
    domain, f, shape = _domain(smoothed, x, spacing, origin, vertices, faces)
    r = np.ascontiguousarray(np.asarray(roles), dtype=np.int8).reshape(-1)
    if r.size != f.size:
        raise InputError(f"roles has {r.size} entries, the field {f.size}")
    h = None if input is None else _float64("input", input).reshape(-1)
    out = dict(_toposmooth.certify(domain, f, r, h))
    out["report"] = json.loads(out["report"])
    return out


def geodesic(vertices: Any, faces: Any, sources: Sequence[int]) -> np.ndarray:
    """Geodesic distance on a triangle mesh from the ``sources``, by the heat method.

    Parameters
    ----------
    vertices : array_like of shape (n, 2) or (n, 3)
    faces : array_like of int, shape (m, 3)
    sources : sequence of int
        Source vertices.

    Returns
    -------
    ndarray of float64, shape (n,)
        The distance, 0 at the sources.
    """
    domain, _, _ = _domain(np.zeros(np.asarray(vertices).shape[0]), vertices=vertices, faces=faces)
    return _toposmooth.geodesic(domain, _indices("sources", sources))


def weights(
    vertices: Any,
    faces: Any,
    handles: Any,
    *,
    order: int = 2,
    method: str = "monotone",
    edges: str = "minimal",
    threads: int = 2,
    progress: Any = None,
    cancel: Any = None,
) -> Dict[str, Any]:
    """Smooth weight functions, one per handle, with no spurious extrema (certified).

    Parameters
    ----------
    vertices, faces
        The mesh, as in :func:`smooth`.
    handles : sequence of sequences of int, or dict
        Each handle's vertices (a point handle is one vertex; weight 1 there, 0 on the others),
        or handles in the JSON format of ``toposmooth weights --handles`` as a dict
        (``{"handles": [{"name": "head", "point": [x, y, z]}, {"name": "arm", "bone": [a, b]},
        ...]}``), placed on the mesh as the CLI places them.
    order : int
        Polyharmonic order k (1-4).
    method : {"monotone", "bounded", "unconstrained", "harmonic"}
        ``monotone`` certifies that each function has its extrema only at the handles.
    edges : {"minimal", "all"}
    threads : int
        Worker threads for the independent functions.
    progress, cancel
        As in :func:`smooth` (the stage ``"weights"`` tells the functions done).

    Returns
    -------
    dict
        ``weights`` (list of float64 arrays: a partition of unity), ``raw`` (as certified),
        ``names`` (the handles' names: "0", "1", ... for vertex lists), ``handles`` (each
        handle's vertices), ``certified`` (bool) and ``max_normalisation_change`` (float).
    """
    domain, _, _ = _domain(np.zeros(np.asarray(vertices).shape[0]), vertices=vertices, faces=faces)
    if isinstance(handles, dict):
        # numpy values (a vertex position V[3], an np.float32) as JSON numbers
        text = json.dumps(handles, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o))
        names, sets = _toposmooth.resolve_handles(domain, text)
    else:
        sets = [_indices(f"handle {k}", np.atleast_1d(h)) for k, h in enumerate(handles)]
        names = [str(k) for k in range(len(sets))]
    settings = {"order": int(order), "method": method, "edges": edges, "threads": int(threads)}
    out = dict(_toposmooth.weights(domain, sets, settings, progress, cancel))
    out.update(names=list(names), handles=sets)
    return out


class Dataset:
    """A field and its domain as a file holds them: what :func:`read` returns.

    Attributes
    ----------
    values : ndarray of float64
        The field, after deriving and filling: shape (n,) for a series or a mesh, (ny, nx) for
        a grid, (nz, ny, nx) for a volume (x fastest, as numpy holds a VTK image).
    kind : str
        ``"series"``, ``"grid"``, ``"volume"``, ``"mesh"`` or ``"tetrahedra"``.
    domain : Domain
        The domain (validated), ready for :class:`Smoother` or :meth:`smooth`.
    description : str
        What the values are: the column, the array or the derivation read.
    path : str
        The file read (the first velocity file with ``u``/``v``).
    notes : list of str
        What reading found worth saying (polygons split, an oblique affine).
    filled, mask : ndarray of bool or None
        The samples ``fill_missing`` filled; the pixels or voxels inside ``mask``.
    x, x_name, x_text, dates
        Series: the x coordinates (days since 1970-01-01 for dates), the x column's name and
        text, and whether x holds dates.
    spacing, origin : tuple of float or None
        Grids and volumes: the spacing and the first point (x first).
    vertices, faces : ndarray or None
        Meshes: positions (n, 3) and triangles (m, 3) or tetrahedra (m, 4).
    arrays : dict of ndarray
        Every point array of the file (VTK, PLY), (n,) or (n, components), the field's own
        included.
    """

    __slots__ = (
        "values", "kind", "domain", "description", "path", "notes", "filled", "mask", "x", "x_name",
        "x_text", "dates", "spacing", "origin", "vertices", "faces", "arrays", "_flat",
    )

    def __init__(self, raw: Dict[str, Any]) -> None:
        shape = tuple(raw["shape"])
        self._flat: np.ndarray = raw["values"]
        self.values: np.ndarray = self._flat.reshape(shape)
        self.kind: str = raw["kind"]
        self.domain = raw["domain"]
        self.description: str = raw["description"]
        self.path: str = raw["path"]
        self.notes: List[str] = list(raw["notes"])
        self.filled: Optional[np.ndarray] = None if raw["filled"] is None else raw["filled"].reshape(shape)
        self.mask: Optional[np.ndarray] = None if raw["mask"] is None else raw["mask"].reshape(shape)
        self.x: Optional[np.ndarray] = raw.get("x")
        self.x_name: Optional[str] = raw.get("x_name")
        self.x_text: Optional[List[str]] = raw.get("x_text")
        self.dates: bool = bool(raw.get("dates", False))
        self.spacing: Optional[tuple] = tuple(raw["spacing"]) if "spacing" in raw else None
        self.origin: Optional[tuple] = tuple(raw["origin"]) if "origin" in raw else None
        self.vertices: Optional[np.ndarray] = raw.get("vertices")
        self.faces: Optional[np.ndarray] = raw.get("faces")
        self.arrays: Dict[str, np.ndarray] = dict(raw["arrays"])

    def smooth(self, *, progress: Any = None, cancel: Any = None, **settings: Any) -> SmoothResult:
        """Smooths the field on its domain as the CLI's ``smooth`` does with the same input
        options (inside the mask when one was read); the settings are :func:`smooth`'s."""
        s = _resolve(settings)
        if self.mask is not None:
            inside = np.ascontiguousarray(self.mask.reshape(-1))
            raw = _toposmooth.smooth_masked(self.domain, s, self._flat, inside, progress, cancel)
        else:
            raw = _toposmooth.Smoother(self.domain, s).smooth(self._flat, progress, cancel)
        return SmoothResult(raw, self.values.shape, self.filled)

    def __repr__(self) -> str:
        return f"Dataset({self.kind} {self.values.shape} of {self.description!r} from {self.path!r})"


def read(
    path: Any = None,
    *,
    domain: Optional[str] = None,
    column: Union[str, int, None] = None,
    x_column: Union[str, int, None] = None,
    array: Optional[str] = None,
    spacing: Optional[Sequence[float]] = None,
    derive: Optional[str] = None,
    u: Any = None,
    v: Any = None,
    fill_missing: bool = False,
    values: Any = None,
    mask: Optional[str] = None,
    mask_below: Optional[float] = None,
) -> Dataset:
    """Read a file as the CLI reads its input: every format it knows, the same options.

    Parameters
    ----------
    path : str or os.PathLike, optional
        A series (CSV, .npy), a grid or volume (.vti, .vtk, .npy, .npz, CSV matrix, PNG, TIFF,
        .nii, .nii.gz) or a mesh (.obj, .off, .ply, .vtu, .vtp, legacy .vtk); None with ``u``
        and ``v``.
    domain : {"auto", "series", "grid", "mesh"}, optional
        How to read it (default: by extension; a CSV whose first line is three or more numbers
        is a grid matrix).
    column, x_column : str or int, optional
        Series: the value column and the x column (name or 0-based index; ``"none"``: x =
        0, 1, 2, ...), as the CLI's ``--column`` and ``--x``.
    array : str, optional
        The point array of a VTK file or .npz, a PLY vertex property, or a mesh's ``x``,
        ``y``, ``z``.
    spacing : (dx, dy) or (dx, dy, dz), optional
        Overrides the file's spacing (may be negative).
    derive : str, optional
        ``vorticity`` or ``magnitude`` of a 2D velocity; ``vorticity-magnitude``,
        ``vorticity-x|y|z`` or ``magnitude`` of a volume's.
    u, v : path, optional
        Two velocity component files (with ``derive``), instead of ``path``.
    fill_missing : bool
        Fill NaN samples (harmonically on grids and meshes, linearly on series) instead of
        raising :class:`InputError`.
    values : path, optional
        Meshes: one value per vertex and line of a text file.
    mask, mask_below : optional
        Grids and volumes: the point array that is non-zero inside, or the value below which
        a voxel is outside.

    Returns
    -------
    Dataset
        The values as numpy (float64), the domain and what the file carries besides.

    Raises
    ------
    InputError, IoError, UsageError
        As the CLI: the file, the problem and what to do.
    """
    import os

    options = dict(
        domain=domain,
        column=column,
        x_column=x_column,
        array=array,
        spacing=spacing,
        derive=derive,
        u=None if u is None else os.fspath(u),
        v=None if v is None else os.fspath(v),
        fill_missing=fill_missing,
        values=None if values is None else os.fspath(values),
        mask=mask,
        mask_below=mask_below,
    )
    return Dataset(_toposmooth.read(None if path is None else os.fspath(path), options))


def _flags(settings: Dict[str, Any]) -> List[str]:
    """Keyword settings as CLI flags: ``minima=9`` -> ``--minima 9``, ``fill_missing=True`` ->
    ``--fill-missing``, lists comma-joined; None and False are left out."""
    out: List[str] = []
    for key, value in settings.items():
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            out.append(flag)
        elif isinstance(value, (list, tuple, np.ndarray)):
            out += [flag, ",".join(str(v) for v in value)]
        else:
            out += [flag, str(value)]
    return out


def cli(*args: Any, threads: Optional[int] = None, progress: Any = None, cancel: Any = None) -> str:
    """Run one command of the command-line tool in this process and return what it prints.

    ``toposmooth.cli("smooth", "in.vti", "-o", "out.vti", "--minima", 3)`` is the CLI's
    ``toposmooth smooth in.vti -o out.vti --minima 3``, reading and writing the files the same
    way (every format the CLI knows, certified outputs, the JSON report). Errors are raised as
    this package's exceptions (:class:`UsageError` for arguments the CLI refuses).
    ``progress`` and ``cancel`` as in :func:`smooth`: a cancelled command leaves no output or
    temporary file behind.
    """
    return _toposmooth.run([str(a) for a in args], threads, progress, cancel)


# the submodules for many fields (they import xarray and dask only when used)
from . import dask, xarray  # noqa: E402
