#!/usr/bin/env bash
# Installs the Debian packages stepbench needs, and only those missing: quick and
# silent when everything is present. Needs root (or sudo) only when something is missing.
set -euo pipefail
packages=(
  g++ cmake make ninja-build git pkg-config clang-format ccache
  libeigen3-dev libgsl-dev libsundials-dev libhdf5-dev hdf5-tools
  libbenchmark-dev libbenchmark-tools libcli11-dev libfmt-dev nlohmann-json3-dev libboost-dev libtomlplusplus-dev
  googletest libgtest-dev
  python3-h5py python3-matplotlib python3-numpy python3-scipy python3-pytest python3-markdown
  chromium  # renders the report in tests/python/test_report_browser.py
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing: ${missing[*]}"
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
