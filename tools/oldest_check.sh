#!/usr/bin/env bash
# The tests against the oldest versions pyproject.toml allows (tools/oldest.txt; README, "Tests,
# benchmarks, CI"): this checkout's HEAD cloned into a temporary directory, a new virtualenv with
# mosys and its test extras installed at those versions, then the lints and the README's test command there.
# Arguments go to pytest (e.g. -m "not slow"). About 12 minutes on 2 cores (a cold numba cache).
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone -q . "$work/main"
cd "$work/main"
python3 -m venv .venv
. .venv/bin/activate
pip install -q -e ".[test]" -c tools/oldest.txt
# the versions installed: every package of tools/oldest.txt, and numba's llvmlite
names=$(grep -v '^#' tools/oldest.txt | cut -d= -f1 | paste -sd'|')
pip list 2>/dev/null | grep -i -E "^(${names}|llvmlite) "
ruff check .
ruff format --check .
lint-imports
pytest "$@"
