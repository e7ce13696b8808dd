#!/usr/bin/env bash
# The tests, as CI runs them (.ci/run): set up (system packages, a virtual environment, the
# package with its test extras), then lint, the import layers, the types (mypy), the C++ unit tests
# and the Python suite. Extra arguments go to pytest (e.g. -m "not slow" for the fast set); they come
# after the defaults, so `-n 0` runs the suite in one process and `-n 4` on four workers.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
venv="${STABLEPUSH_VENV:-.venv}"
case "$venv" in /*) ;; *) venv="$PWD/$venv" ;; esac  # STABLEPUSH_VENV may be absolute too
export PATH="$venv/bin:$PATH"

echo "test: ruff" >&2
ruff check .
echo "test: import layers (lint-imports)" >&2
lint-imports
echo "test: types (mypy)" >&2
mypy  # python/ and cli/, as pyproject.toml's [tool.mypy] says
if [ -f cpp/tests/CMakeLists.txt ]; then
  echo "test: clang-format" >&2
  find cpp -name '*.hpp' -o -name '*.cpp' | xargs clang-format --dry-run --Werror
  echo "test: C++ unit tests (ctest)" >&2
  cmake -S . -B build/tests -DSTABLEPUSH_TESTS=ON -DSTABLEPUSH_PYTHON=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build/tests -j2 >/dev/null
  ctest --test-dir build/tests --output-on-failure
fi
echo "test: pytest" >&2
# From the repo, the tests import the installed package, never python/ itself.
# pytest-xdist: one worker per core (-n auto; PYTEST_XDIST_AUTO_NUM_WORKERS=N sets another count).
# worksteal: a worker that runs out takes half of another's queue, so the minute-long tests (the
# fuzz campaign, Drake's closed loop, the README walk-through) need no ordering by hand. The 15
# slowest tests are listed, so that one that grows shows in CI's log.
python -m pytest -q -n auto --dist worksteal --durations=15 "$@"
