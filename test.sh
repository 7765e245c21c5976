#!/usr/bin/env bash
# Quick start, step 2: install dependencies, build, and run the whole test suite; then
# replay every libFuzzer harness's corpus and fuzz it briefly from a fixed seed and run the core
# library's fast tests under AddressSanitizer + UndefinedBehaviorSanitizer. Any failing
# step (test, fuzz finding, sanitizer report) fails the script.
source "$(dirname "$0")/scripts/common.sh"
# Each step's wall time is printed, so the cost of every CI step stays visible.
timed() {
  local start=$SECONDS
  "$@"
  echo "test.sh: '$*' took $((SECONDS - start)) s"
}
timed sslpv_install_packages
timed sslpv_build
run_ctest() { (cd "$SSLPV_BUILD" && ctest -j "$(nproc)" --output-on-failure --timeout 900); }
timed run_ctest
# One clang ASan+UBSan build serves both extra steps: the fuzz harnesses and the core tests.
timed "$SSLPV_ROOT/scripts/fuzz.sh" ci
export SSLPV_ASAN_BUILD="${SSLPV_FUZZ_BUILD:-$SSLPV_ROOT/build-fuzz}"
timed "$SSLPV_ROOT/scripts/sanitize.sh" core
