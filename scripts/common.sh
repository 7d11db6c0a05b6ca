# SPDX-License-Identifier: BSD-3-Clause
# Shared by scripts/demo.sh and scripts/test.sh: install what is missing, then build.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${DYNVO_BUILD_DIR:-$ROOT/build}"

# Debian 12 packages dynvo needs (see README.md).
PACKAGES=(cmake ninja-build g++ libpcl-dev pcl-tools libopencv-dev libopencv-contrib-dev libvtk9-dev
          libeigen3-dev libflann-dev libgtest-dev libbenchmark-dev libopenni2-dev
          libopenni-dev xvfb xauth clang)

say() { printf '\n==> %s\n' "$*"; }

install_deps() {
  local missing=() p
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    say "All ${#PACKAGES[@]} Debian packages are installed"
    return
  fi
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  say "Installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

build() {
  say "Configuring $BUILD (Release, Ninja)"
  cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  say "Building with -j2"
  cmake --build "$BUILD" -j2
}
