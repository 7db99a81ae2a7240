#!/usr/bin/env bash
# Waxwork set-up for a Debian 12 machine, run as root (or with sudo available).
#   bash setup.sh demo   install what is missing, build, run the main demo
#   bash setup.sh test   install what is missing, build, run the whole test suite
# Idempotent: packages already installed are not touched, and the build is incremental.
set -euo pipefail

mode="${1:-}"
case "$mode" in
  demo|test) ;;
  *) echo "usage: bash setup.sh demo|test" >&2; exit 2 ;;
esac

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${WAXWORK_BUILD_DIR:-$here/build}"

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libtbb-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev libssl-dev
  libtet1.5-dev libopenmesh-dev libsuitesparse-dev petsc-dev
  libglfw3-dev libosmesa6-dev libgl-dev libegl-dev libimgui-dev libstb-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libpugixml-dev libnanoflann-dev
  xvfb xauth
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

jobs="$(nproc)"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$jobs"

if [ "$mode" = test ]; then
  cd "$build"
  ctest --output-on-failure -j "$jobs"
else
  "$build/app/waxwork" demo -o "$here/out/demo"
fi
