#!/usr/bin/env bash
# The tests, as CI runs them (.ci/run): set up (system packages, a virtual environment, the
# package with its test extras), then lint, the import layers, the C++ unit tests and the Python
# suite. Extra arguments go to pytest (e.g. -m "not slow" for the fast set).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
venv="${STABLEPUSH_VENV:-.venv}"
export PATH="$PWD/$venv/bin:$PATH"

echo "test: ruff" >&2
ruff check .
echo "test: import layers (lint-imports)" >&2
lint-imports
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
python -m pytest -q "$@"
