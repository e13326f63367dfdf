#!/usr/bin/env bash
# The Python package's tests: the wheel built once (pip wheel: maturin compiles the extension in
# the repository's target directory, beside the CLI's build), installed with its test extras in
# a fresh venv outside the repository for pytest, which compares the package with the CLI
# (TOPOSMOOTH_BIN, default target/release/toposmooth); then the same wheel in Debian's
# pvpython for the ParaView plugin (paraview/run_test.sh; TOPOSMOOTH_SKIP_PARAVIEW=1 skips it).
# Usage: python/run_tests.sh [PYTEST ARGS]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$(mktemp -d "${TMPDIR:-/tmp}/toposmooth-py-XXXXXX")"
trap 'rm -rf "$VENV"' EXIT
"${PYTHON:-python3}" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip wheel --quiet --no-deps -w "$VENV/wheels" "$ROOT"
WHEEL="$(ls "$VENV"/wheels/toposmooth-*.whl)"
"$VENV/bin/python" -m pip install --quiet "$WHEEL[test]" -c "$ROOT/python/constraints.txt"
export TOPOSMOOTH_BIN="${TOPOSMOOTH_BIN:-$ROOT/target/release/toposmooth}"
(cd "$ROOT/python/tests" && "$VENV/bin/python" -m pytest -q -p no:cacheprovider "$@")
if [ "${TOPOSMOOTH_SKIP_PARAVIEW:-0}" != 1 ]; then
    "$ROOT/paraview/run_test.sh" "$WHEEL"
fi
