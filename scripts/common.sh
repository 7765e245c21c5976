# Shared by setup.sh and test.sh: install what a fresh Debian 12 machine lacks, then
# configure and build (Release) in build/. Idempotent: fast when nothing is missing.
set -euo pipefail
SSLPV_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SSLPV_BUILD="${SSLPV_BUILD:-$SSLPV_ROOT/build}"

SSLPV_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libopenvdb-dev libboost-iostreams-dev libtbb-dev libglm-dev libembree-dev
  libassimp-dev nlohmann-json3-dev libcli11-dev libopenexr-dev libstb-dev
  libgtest-dev libgmock-dev libvtk9-dev xvfb xauth
  libvulkan-dev mesa-vulkan-drivers glslang-tools glslang-dev spirv-tools vulkan-validationlayers
)

sslpv_install_packages() {
  local missing=()
  for p in "${SSLPV_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "sslpv: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

sslpv_build() {
  local extra=()
  [ "${CI:-}" = "true" ] && extra+=(-DSSLPV_WERROR=ON)
  if [ ! -f "$SSLPV_BUILD/build.ninja" ]; then
    cmake -S "$SSLPV_ROOT" -B "$SSLPV_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${extra[@]}"
  fi
  cmake --build "$SSLPV_BUILD" -j "$(nproc)"
}
