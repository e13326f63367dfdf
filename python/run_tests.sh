#!/usr/bin/env bash
# The Python package's tests: a fresh venv outside the repository, `pip install .[test]` (maturin
# builds the extension in the repository's target directory, beside the CLI's build), then
# pytest, which compares the package with the CLI (TOPOSMOOTH_BIN, default
# target/release/toposmooth).
# Usage: python/run_tests.sh [PYTEST ARGS]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$(mktemp -d "${TMPDIR:-/tmp}/toposmooth-py-XXXXXX")"
trap 'rm -rf "$VENV"' EXIT
"${PYTHON:-python3}" -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "$ROOT[test]" -c "$ROOT/python/constraints.txt"
export TOPOSMOOTH_BIN="${TOPOSMOOTH_BIN:-$ROOT/target/release/toposmooth}"
cd "$ROOT/python/tests"
"$VENV/bin/python" -m pytest -q "$@"
