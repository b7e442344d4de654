#!/usr/bin/env bash
# Builds the Python package from this checkout into a virtual environment under build/ and runs
# its pytest suite (tests/python). Reruns are incremental: the CMake build lives in build/python.
#   scripts/test-python.sh [pytest arguments]
# Environment: PYTHON (default python3), BVHKIT_PY_VENV (default build/python-venv).
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
venv=${BVHKIT_PY_VENV:-build/python-venv}

# Debian's python3 lacks venv (and ensurepip) until python3-venv is installed.
if ! "$python" -c 'import venv, ensurepip' >/dev/null 2>&1; then
  command -v apt-get >/dev/null || { echo "test-python: $python has no venv module" >&2; exit 1; }
  pkgs=(python3-venv python3-dev)
  echo "test-python: installing ${pkgs[*]}"
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "test-python: need root to install ${pkgs[*]}" >&2; exit 1; }
    sudo_cmd="sudo"
  fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${pkgs[@]}"
fi

if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --upgrade pip
# The build tools live in the venv and the build is not isolated, so that build/python stays
# valid between runs (an isolated build gets a fresh nanobind path each time and rebuilds all).
"$venv/bin/python" -m pip install -q "scikit-build-core>=0.10" "nanobind>=2.0" numpy pytest
# Optional for the package; the tests of bvhkit.dask and sample-sdf need it.
"$venv/bin/python" -m pip install -q "dask[distributed]"
# Optional too: tests/python/test_arguments.py checks the package's annotations with mypy.
"$venv/bin/python" -m pip install -q mypy
"$venv/bin/python" -m pip install -q --no-build-isolation \
  --config-settings=build-dir=build/python .
cd tests/python  # import the installed package, not python/bvhkit
exec "../../$venv/bin/python" -m pytest -q "$@"
