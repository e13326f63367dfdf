"""Many files smoothed on a Dask cluster: one task per file, each running the CLI's
``smooth`` in the worker's process (every format the CLI reads and writes, certified
outputs), plus a ParaView ``.pvd`` collection of the outputs.

The same code runs on a laptop's ``LocalCluster`` and on a multi-node cluster: only the
scheduler's address changes (``Client("tcp://scheduler:8786")``); the input paths must then
be readable, and ``out_dir`` writable, on every worker (a shared file system).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, List, Optional, Sequence

from . import UsageError, _flags, cli

__all__ = ["smooth_files", "write_pvd"]


def _smooth_one(args: List[str], threads: Optional[int]) -> str:
    return cli(*args, threads=threads)


def write_pvd(path: os.PathLike, files: Sequence[os.PathLike], times: Optional[Sequence[float]] = None) -> Path:
    """Writes a ParaView collection (``.pvd``) of ``files`` as a time series (times 0, 1, ...
    unless given), with paths relative to the collection's directory."""
    path = Path(path)
    times = list(range(len(files))) if times is None else list(times)
    if len(times) != len(files):
        raise UsageError(f"{len(times)} times for {len(files)} files")
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">', "  <Collection>"]
    for t, f in zip(times, files):
        rel = os.path.relpath(Path(f).resolve(), path.resolve().parent)
        rel = rel.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")
        lines.append(f'    <DataSet timestep="{float(t)!r}" group="" part="0" file="{rel}"/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text("\n".join(lines))
    os.replace(tmp, path)
    return path


def smooth_files(
    paths: Sequence[os.PathLike],
    out_dir: os.PathLike,
    *,
    client: Any = None,
    pvd: Optional[str] = "collection.pvd",
    threads: Optional[int] = 1,
    **settings: Any,
) -> List[Path]:
    """Smooth every file of ``paths`` into ``out_dir`` (the same file names), one Dask task each.

    Parameters
    ----------
    paths : sequence of path-like
        Inputs in any format the CLI reads (``.vti``, ``.vtu``, ``.npy``, CSV, ...).
    out_dir : path-like
        Existing directory for the outputs; two inputs with one file name are a
        :class:`toposmooth.UsageError`.
    client : dask.distributed.Client, optional
        The cluster to run on (default: the current client if there is one, else a serial
        loop in this process).
    pvd : str or None
        File name of a ParaView collection of the outputs, in input order as time steps
        (None: none). Written only when every output is a VTK file.
    threads : int or None
        Threads per task (default 1: one task per worker thread).
    **settings
        CLI flags of ``toposmooth smooth`` as keywords: ``persistence="5%"``, ``minima=9``,
        ``fill_missing=True``, ``spacing="0.5,0.5"``, ``array="vorticity"`` ...

    Returns
    -------
    list of Path
        The outputs, in input order.
    """
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        raise UsageError(f"{out_dir}: the output directory does not exist")
    # resolved here: a worker on another node has another working directory
    paths = [Path(p).resolve() for p in paths]
    out_dir = out_dir.resolve()
    names = [p.name for p in paths]
    seen = {}
    for p, n in zip(paths, names):
        if n in seen:
            raise UsageError(f"{seen[n]} and {p} would both be written to {out_dir / n}")
        seen[n] = p
    outputs = [out_dir / n for n in names]
    jobs = [["smooth", str(p), "-o", str(o), *_flags(settings)] for p, o in zip(paths, outputs)]
    if client is None:
        try:
            from distributed import get_client

            client = get_client()
        except (ImportError, ValueError):
            client = None
    if client is None:
        for job in jobs:
            _smooth_one(job, threads)
    else:
        futures = client.map(_smooth_one, jobs, threads=threads, pure=False)
        client.gather(futures)
    if pvd and all(o.suffix.lower() in (".vti", ".vtu", ".vtp", ".vtk") for o in outputs):
        write_pvd(out_dir / pvd, outputs)
    return outputs
