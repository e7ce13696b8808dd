#!/usr/bin/env bash
# One-step set-up on Debian 12: the system libraries the C++ core builds against, then the
# Python package (built by scikit-build-core). `--test` also installs the test dependencies.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libompl-dev libboost-filesystem-dev)
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

extra=""
[ "${1:-}" = "--test" ] && extra="[test]"
echo "setup: building and installing stablepush${extra} (about a minute)" >&2
python3 -m pip install --quiet --disable-pip-version-check ".${extra}"
