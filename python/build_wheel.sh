#!/usr/bin/env bash
# Builds the Python package's wheel (abi3: one wheel for CPython 3.9 and later) into
# target/wheels, with maturin from PyPI installed in a build environment under target/.
# Usage: python/build_wheel.sh   (then: pip install target/wheels/rapier_fvm-*.whl)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/python-build
if [ ! -x "$venv/bin/maturin" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet "maturin>=1.16,<2"
fi
rm -f target/wheels/rapier_fvm-*.whl
"$venv/bin/maturin" build --release --manifest-path python/Cargo.toml --out target/wheels "$@"
ls target/wheels/rapier_fvm-*.whl
