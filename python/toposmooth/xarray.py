"""toposmooth over xarray: every field of a DataArray smoothed along its spatial dimensions,
mapped over the others (time, ensemble member) with ``xarray.apply_ufunc``; a Dask-backed
array is smoothed chunk by chunk by whatever Dask scheduler or cluster is active.

>>> import numpy as np, xarray as xr, toposmooth.xarray
>>> t, y, x = np.arange(3), np.arange(32.0), np.arange(48.0)
>>> data = np.sin(x / 6 + t[:, None, None]) * np.cos(y[:, None] / 5) + 0.0 * y[:, None]
>>> da = xr.DataArray(data, dims=("time", "y", "x"), coords={"time": t, "y": y, "x": x})
>>> out = toposmooth.xarray.smooth(da, dims=("y", "x"), persistence="10%")
>>> out.dims, out.shape
(('time', 'y', 'x'), (3, 32, 48))
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from . import Smoother, UsageError

__all__ = ["smooth", "geometry"]


def _uniform(name: str, c: np.ndarray) -> Tuple[float, float]:
    """(first value, step) of a uniformly spaced coordinate."""
    dtype = np.asarray(c).dtype
    c = np.asarray(c, dtype=np.float64)
    if c.size < 2:
        raise UsageError(f"coordinate `{name}` needs at least 2 values")
    step = (c[-1] - c[0]) / (c.size - 1)
    # float32 coordinates (np.arange(0, 36, 0.1, dtype=float32)) are uniform to their precision
    rtol = 1e-9 if dtype.itemsize >= 8 else 1e-4
    if step == 0 or not np.allclose(np.diff(c), step, rtol=rtol, atol=0):
        raise UsageError(f"coordinate `{name}` is not uniformly spaced: a grid needs a constant spacing")
    return float(c[0]), float(step)


def geometry(da: Any, dims: Sequence[str]) -> Dict[str, Any]:
    """The domain arguments of :class:`toposmooth.Smoother` for ``da`` along ``dims``: for
    two dims (rows, columns) ``spacing`` and ``origin`` from their coordinates (1 and 0 where
    a dim has none); for one dim ``x`` from its coordinate (dates become days since
    1970-01-01, as in :func:`toposmooth.smooth`)."""
    dims = tuple(dims)
    if len(dims) == 2:
        (ry, rx) = dims
        y0, dy = _uniform(ry, da[ry].values) if ry in da.coords else (0.0, 1.0)
        x0, dx = _uniform(rx, da[rx].values) if rx in da.coords else (0.0, 1.0)
        return {"spacing": (dx, dy), "origin": (x0, y0)}
    if len(dims) == 1:
        (d,) = dims
        if d not in da.coords:
            return {}
        c = da[d].values
        if np.issubdtype(c.dtype, np.datetime64):
            import pandas as pd

            from . import _days_since_epoch

            return {"x": _days_since_epoch(pd.DatetimeIndex(c))}
        return {"x": np.asarray(c, dtype=np.float64)}
    raise UsageError(f"dims must name one (a series) or two (a grid: rows, columns) dimensions, got {dims}")


def _smooth_stack(
    arr: np.ndarray, core: Tuple[int, ...], domain: Dict[str, Any], settings: Dict[str, Any], output: str
) -> np.ndarray:
    """Smooths every field of ``arr`` (leading dims, then the core dims) with one Smoother."""
    out = np.empty(arr.shape, dtype=np.int8 if output == "roles" else np.float64)
    settings = dict(settings)  # every chunk of a process gets the same dict
    fill = settings.pop("fill_missing", False)
    smoother = Smoother(core, fill_missing=fill, **domain, **settings)
    for idx in np.ndindex(*arr.shape[: arr.ndim - len(core)]):
        r = smoother.smooth(arr[idx])
        out[idx] = getattr(r, output)
    return out


def smooth(
    da: Any,
    dims: Sequence[str] = ("y", "x"),
    *,
    output: str = "smoothed",
    **settings: Any,
) -> Any:
    """Smooth each field of ``da`` along ``dims``, keeping exactly the chosen extrema.

    Parameters
    ----------
    da : xarray.DataArray
        Numbers; other dimensions (time, member, ...) are mapped over. A Dask-backed array
        stays lazy: each chunk is one task (the ``dims`` are put in one chunk each).
    dims : sequence of str
        Two dims (rows, columns: a grid; spacing and origin from their coordinates, which must
        be uniform) or one (a series along it; x from its coordinate).
    output : {"smoothed", "representative", "roles"}
        The array returned.
    **settings
        Every setting of :func:`toposmooth.smooth` (``persistence``, ``minima``, ``maxima``,
        ``order``, ``fill_missing``, ``threads`` ...).

    Returns
    -------
    xarray.DataArray
        ``da``'s dims, coordinates and attributes, float64 (int8 for ``roles``). Every field
        is certified: one that cannot be raises :class:`toposmooth.CertificateError` when
        computed.
    """
    import xarray as xr

    if output not in ("smoothed", "representative", "roles"):
        raise UsageError(f'output must be "smoothed", "representative" or "roles", got "{output}"')
    dims = tuple(dims)
    missing = [d for d in dims if d not in da.dims]
    if missing:
        raise UsageError(f"dims {missing} are not dimensions of the array, which has {tuple(da.dims)}")
    domain = geometry(da, dims)
    # explicit geometry overrides the coordinates'
    for key in ("spacing", "origin", "x"):
        if key in settings:
            domain[key] = settings.pop(key)
    core = tuple(da.sizes[d] for d in dims)
    if da.chunks is not None:
        da = da.chunk({d: -1 for d in dims})
    return xr.apply_ufunc(
        _smooth_stack,
        da,
        input_core_dims=[list(dims)],
        output_core_dims=[list(dims)],
        kwargs={"core": core, "domain": domain, "settings": dict(settings), "output": output},
        dask="parallelized",
        output_dtypes=[np.int8 if output == "roles" else np.float64],
        keep_attrs=True,
    ).transpose(*da.dims)
