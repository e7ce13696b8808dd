#!/usr/bin/env bash
# One-step set-up on Debian 12: the system libraries the C++ core builds against, then a virtual
# environment (.venv, or $STABLEPUSH_VENV) with the Python package built by scikit-build-core.
# `--test` also installs what the tests, the linters and the C++ unit tests need.
#
#   bash scripts/setup.sh          # then: .venv/bin/stablepush ...  (or: . .venv/bin/activate)
#   bash scripts/setup.sh --test   # what scripts/test.sh runs first
set -euo pipefail
cd "$(dirname "$0")/.."

test_extras=false
[ "${1:-}" = "--test" ] && test_extras=true
venv="${STABLEPUSH_VENV:-.venv}"

# libosmesa6: MuJoCo's headless renderer (execute --video draws with MUJOCO_GL=osmesa)
packages=(g++ cmake libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libompl-dev libboost-filesystem-dev python3-venv
  libosmesa6)
$test_extras && packages+=(catch2 clang-format)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "setup: installing Debian packages: ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# A venv of its own (no system site-packages), so a dependency pyproject.toml forgot fails here.
if [ ! -x "$venv/bin/python" ]; then
  echo "setup: creating the virtual environment $venv" >&2
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --upgrade pip

# Every optional part (pyproject.toml's extras: the simulators, Ray, ROS bags, video) besides the
# planner, so that every command and test runs; `pip install .` alone plans, checks, draws and exports.
extra="[all]"
$test_extras && extra="[all,test]"
echo "setup: building and installing stablepush${extra} into $venv (a few minutes the first time)" >&2
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check ".${extra}"
echo "setup: done; run $venv/bin/stablepush, or activate with: . $venv/bin/activate" >&2
