#!/usr/bin/env bash
# Creates the Python environment for the peer comparison (pybullet and MuJoCo).
#
#   bash benches/compare/setup.sh            # venv at benches/compare/.venv
#   bash benches/compare/setup.sh /some/dir  # or at a path of your choice
#   COMPARE_VENV=/some/dir bash benches/compare/setup.sh
#
# Idempotent: an existing venv is reused and pip only installs what is missing.
# The versions are pinned so that numbers stay comparable between runs.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${1:-${COMPARE_VENV:-$here/.venv}}"
python="${PYTHON:-python3}"

PYBULLET_VERSION=3.2.7
MUJOCO_VERSION=4.0.0
NUMPY_VERSION=2.4.6

if [ ! -x "$venv/bin/python" ]; then
    echo "creating virtual environment at $venv" >&2
    "$python" -m venv "$venv"
fi

"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "numpy==$NUMPY_VERSION" \
    "pybullet==$PYBULLET_VERSION" \
    "mujoco==$MUJOCO_VERSION"

"$venv/bin/python" - <<'PY'
import sys, numpy, mujoco
import importlib.metadata as md
print("python", sys.version.split()[0])
print("numpy", numpy.__version__)
print("pybullet", md.version("pybullet"))
print("mujoco", mujoco.__version__)
PY
