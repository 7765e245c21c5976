# Shared by setup.sh and test.sh: install what a fresh Debian 12 machine lacks, then
# configure and build (Release) in build/. Idempotent: fast when nothing is missing.
set -euo pipefail
SSLPV_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SSLPV_BUILD="${SSLPV_BUILD:-$SSLPV_ROOT/build}"

# clang-14 + libclang-rt-14-dev: the fuzz and sanitizer builds (libFuzzer's runtime is in
# libclang-rt-14-dev; libfuzzer-14-dev only adds the standalone library, unused here).
# curl: sanitize.sh tsan fetches Debian's oneTBB source package to instrument it.
# python3: the layer check (scripts/check_layers.py), a CTest test.
# libvtk9-qt-dev, qtbase5-dev, libx11-dev: the editor, VTK's views in a Qt 5 main window
# (QVTKOpenGLNativeWidget); X11 to check the display before Qt would abort on a bad one.
SSLPV_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libopenvdb-dev libboost-iostreams-dev libtbb-dev libglm-dev libembree-dev
  libassimp-dev nlohmann-json3-dev libcli11-dev libopenexr-dev libstb-dev
  libgtest-dev libgmock-dev libvtk9-dev libvtk9-qt-dev qtbase5-dev libx11-dev xvfb xauth libglfw3-dev
  libvulkan-dev mesa-vulkan-drivers glslang-tools glslang-dev spirv-tools vulkan-validationlayers
  clang-14 libclang-rt-14-dev curl python3
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

# Configures a clang-14 build with the given -fsanitize= list in $1 (scripts/fuzz.sh,
# scripts/sanitize.sh, test.sh); extra arguments go to cmake. Only the targets a script
# runs are built, so these builds stay a fraction of the normal one.
sslpv_configure_sanitized() {
  local dir="$1" sanitizers="$2"
  shift 2
  if [ ! -f "$dir/build.ninja" ]; then
    local launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    # -O1 with line tables only: symbolized reports at a fraction of -O2 -g's compile time.
    # Asserts stay on (no NDEBUG): a failed assertion is a finding too. No Vulkan: these
    # builds run the CPU library (sanitize.sh full turns Vulkan back on).
    CC=clang-14 CXX=clang++-14 cmake -S "$SSLPV_ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize \
      -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -gline-tables-only" -DCMAKE_C_FLAGS_SANITIZE="-O1 -gline-tables-only" \
      -DSSLPV_SANITIZE="$sanitizers" -DCMAKE_DISABLE_FIND_PACKAGE_Vulkan=ON "${launcher[@]}" "$@"
  fi
}
