#!/usr/bin/env bash
# Opens toposmooth's VTK outputs with VTK's own readers (pip's vtk, pinned as for the
# fixtures) in a venv outside the repository: tests/vtk_open/check_outputs.py.
# Usage: tests/vtk_open/run.sh [TOPOSMOOTH_BINARY] (default target/release/toposmooth).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
VENV="${FIXTURE_VENV:-${TMPDIR:-/tmp}/toposmooth-fixture-venv}"
BIN="${1:-$ROOT/target/release/toposmooth}"
if [ ! -x "$VENV/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet "vtk==9.7.2" "numpy==2.4.6" -c "$ROOT/tests/fixtures/constraints.txt"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/python" "$HERE/check_outputs.py" "$BIN" "$ROOT/tests/fixtures/vtk" "$ROOT/datasets" "$WORK"
