#!/usr/bin/env bash
# Builds the wheel (python/build_wheel.sh), installs it with its test extras into a fresh
# virtual environment under target/, and runs the Python tests (pytest) against it, then checks
# the type stubs against the module (mypy's stubtest): the whole set-up a user needs is `pip
# install` of that wheel.
# Usage: python/run_tests.sh [pytest arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
python/build_wheel.sh
venv=target/python-test
rm -rf "$venv"
python3 -m venv "$venv"
wheel=$(ls target/wheels/rapier_fvm-*.whl)
"$venv/bin/pip" install --quiet "${wheel}[test]"
# From outside the source tree, so that `import rapier_fvm` is the installed wheel.
cd python/tests
"../../$venv/bin/python" -m pytest -q "$@"
# The type stubs against the module as built: every name, signature and default.
"../../$venv/bin/python" -m mypy.stubtest rapier_fvm._native
