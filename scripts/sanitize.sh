#!/usr/bin/env bash
# Sanitizer runs (clang-14). Usage: scripts/sanitize.sh [full|core|tsan|all] (default all)
#   full  AddressSanitizer + UndefinedBehaviorSanitizer over the whole test suite
#         (build-asan/, every target; the GUI tests start their own xvfb-run).
#   core  the same sanitizers over the core library's fast tests only (what test.sh runs;
#         SSLPV_ASAN_BUILD picks the build folder, test.sh shares build-fuzz/).
#   tsan  ThreadSanitizer over the TBB-parallel stages' tests (build-tsan/).
#   all   full, then tsan.
# Any sanitizer report fails the run (no recovery). Leaks are checked by the fuzz
# harnesses only (see run_core).
source "$(dirname "$0")/common.sh"
MODE="${1:-all}"

# The core library's faster tests under ASan: input parsing, material sets, meshes and
# CPU LPV stages. voxelize_test and propagate_test (100 and 220 s under ASan on the
# 2-core machine) run in the full and tsan modes only.
CORE_TESTS=(scene_test material_set_test material_test mesh_test sh_test
            inject_test resample_test exit_law_test pbrt_export_test)
# The TBB stages: voxelize/inject/propagate/resample, CPU shading and rendering; the
# editor's preview worker (its render thread, drafts and superseded requests).
TSAN_TESTS=(voxelize_test inject_test propagate_test resample_test render_test preview_async_test)

# Full-suite exclusions (a ctest -E regex; SSLPV_ASAN_EXCLUDE replaces it): tests that
# cannot work under ASan, each with the reason.
#  - HostileInput.OutOfMemory... runs the CLI under `ulimit -v`, where ASan cannot even
#    reserve its shadow memory (it aborts before main).
#  - RenderLimits.TheCpuMemoryEstimate... compares the renderer's memory estimate with the
#    process's peak RSS, which ASan's redzones and quarantine inflate.
FULL_EXCLUDE="${SSLPV_ASAN_EXCLUDE-HostileInput.OutOfMemoryNamesTheCommandAndItsInput|RenderLimits.TheCpuMemoryEstimateMatchesThePeakResidentMemory}"

export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

run_binaries() {  # build dir, then test names: each binary runs on its own, stops at a report
  local dir="$1" status=0
  shift
  for t in "$@"; do
    echo "sanitize: $t"
    if ! "$dir/tests/$t" --gtest_brief=1; then
      echo "sanitize: $t FAILED (sanitizer report or test failure above)"
      status=1
    fi
  done
  return $status
}

run_core() {
  local dir="${SSLPV_ASAN_BUILD:-$SSLPV_ROOT/build-asan}"
  sslpv_configure_sanitized "$dir" address,undefined
  cmake --build "$dir" -j "$(nproc)" --target "${CORE_TESTS[@]}"
  # No leak check: the VDB and mesh readers' forked children end with _exit(), which LSan
  # intercepts to leak-check the whole inherited heap (slow, and a spurious exit code).
  ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}" run_binaries "$dir" "${CORE_TESTS[@]}"
}

run_full() {
  local dir="$SSLPV_ROOT/build-asan-full"
  sslpv_configure_sanitized "$dir" address,undefined -DCMAKE_DISABLE_FIND_PACKAGE_Vulkan=OFF
  cmake --build "$dir" -j "$(nproc)"
  local exclude=()
  [ -n "$FULL_EXCLUDE" ] && exclude=(-E "$FULL_EXCLUDE")
  # Child processes (the CLI, the editor under xvfb-run) inherit the options.
  (cd "$dir" && ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}" \
     ctest -j "$(nproc)" --output-on-failure --timeout 1800 "${exclude[@]}")
}

# ThreadSanitizer only sees synchronisation in instrumented code. Debian's libtbb is not
# instrumented, so every TBB task handed from one thread to another looks like a race
# (reports inside oneTBB's partitioner.h on every parallel_for). Suppressing them would
# suppress our own races too, since our loop bodies run under those same frames; instead
# the run uses oneTBB built with -fsanitize=thread from Debian's own source package of the
# installed version (same headers, same soname, so OpenVDB picks it up as well).
TBB_VERSION=2021.8.0
TBB_ORIG_SHA256=7e9111b8bb59c8800bf6d0b06afe7b0891937443d2dae1ee1101c8e2ede6a7ef
tsan_tbb() {  # prints the folder holding the instrumented libtbb.so.12
  local root="$SSLPV_ROOT/build-tsan/onetbb" lib
  lib="$root/build/clang_14.0_cxx11_64_relwithdebinfo"
  if [ ! -f "$lib/libtbb.so.12" ]; then
    mkdir -p "$root"
    local tarball="$root/onetbb_$TBB_VERSION.orig.tar.xz"
    if [ ! -f "$tarball" ]; then
      curl -sSfL -o "$tarball.tmp" "http://deb.debian.org/debian/pool/main/o/onetbb/onetbb_$TBB_VERSION.orig.tar.xz" >&2
      echo "$TBB_ORIG_SHA256  $tarball.tmp" | sha256sum -c --quiet - >&2
      mv "$tarball.tmp" "$tarball"
    fi
    tar -xf "$tarball" -C "$root"
    CC=clang-14 CXX=clang++-14 cmake -S "$root/oneTBB-$TBB_VERSION" -B "$root/build" -G Ninja \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_STRICT=OFF \
      -DTBB_EXAMPLES=OFF >&2
    cmake --build "$root/build" -j "$(nproc)" --target tbb >&2
  fi
  echo "$lib"
}

run_tsan() {
  local dir="$SSLPV_ROOT/build-tsan" tbb
  sslpv_configure_sanitized "$dir" thread
  cmake --build "$dir" -j "$(nproc)" --target "${TSAN_TESTS[@]}"
  tbb="$(tsan_tbb)"
  LD_LIBRARY_PATH="$tbb${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
  TSAN_OPTIONS="${TSAN_OPTIONS:-halt_on_error=1 second_deadlock_stack=1 suppressions=$SSLPV_ROOT/scripts/tsan.supp}" \
    run_binaries "$dir" "${TSAN_TESTS[@]}"
}

case "$MODE" in
  full) run_full ;;
  core) run_core ;;
  tsan) run_tsan ;;
  all) run_full && run_tsan ;;
  *) echo "usage: $0 [full|core|tsan|all]" >&2; exit 2 ;;
esac
