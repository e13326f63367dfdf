#!/usr/bin/env bash
# The ParaView plugin under Debian's pvpython (python3-paraview, ParaView 5.11, installed here
# when missing): the package's wheel installed with --no-deps into a directory of its own (the
# system Python refuses pip installs, PEP 668, and its VTK is built against Debian's numpy),
# then paraview/test_plugin.py on a bundled .vti. paraview/compat/sitecustomize.py mends ParaView
# 5.11 on Python 3.11 (its plugin loader imports inspect.getargspec, removed in 3.11).
# Usage: paraview/run_test.sh WHEEL
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WHEEL="$1"
if ! command -v pvpython >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -q --no-install-recommends python3-paraview >/dev/null \
        || { apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends python3-paraview >/dev/null; }
fi
TARGET="$(mktemp -d "${TMPDIR:-/tmp}/toposmooth-pv-XXXXXX")"
trap 'rm -rf "$TARGET"' EXIT
python3 -m pip install --quiet --no-deps --target "$TARGET" "$WHEEL"
# pvpython as root under MPI needs these; harmless otherwise
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
PYTHONPATH="$TARGET:$ROOT/paraview/compat" pvpython --force-offscreen-rendering "$ROOT/paraview/test_plugin.py" \
    "$ROOT/paraview/toposmooth_filters.py" "$ROOT/datasets/karman_vortex_street_ttk_example1.vti"
