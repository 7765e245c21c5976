#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/, clang-14, ASan + UBSan) in build-fuzz/ and runs
# each for SECONDS (default 300) over its corpus. Usage: scripts/fuzz.sh [SECONDS|ci] [HARNESS...]
# (harnesses: scene stroke material_set mesh pbrt; default all). `ci` is the regression
# check the test script runs: the committed corpus replayed, then a fixed number of
# mutations from a fixed seed, so that the same tree gives the same verdict on any machine.
#
# Every input that crashes, hangs (> 10 s), runs out of memory or trips a sanitizer is
# written to fuzz/corpus/<harness>/regressions/, which every later run replays first:
# commit those files. Inputs that only add coverage stay in build-fuzz/fuzz-corpus/.
# Exit status: non-zero when any harness had a finding (all harnesses still run).
source "$(dirname "$0")/common.sh"
SECONDS_EACH="${1:-300}"
shift || true
HARNESSES=("$@")
[ ${#HARNESSES[@]} -eq 0 ] && HARNESSES=(scene stroke material_set mesh pbrt)
FUZZ_BUILD="${SSLPV_FUZZ_BUILD:-$SSLPV_ROOT/build-fuzz}"

sslpv_install_packages
sslpv_configure_sanitized "$FUZZ_BUILD" address,undefined -DSSLPV_FUZZ=ON
targets=(make_vdb_seeds make_mesh_seeds)
for h in "${HARNESSES[@]}"; do targets+=("${h}_fuzz"); done
cmake --build "$FUZZ_BUILD" -j "$(nproc)" --target "${targets[@]}"

# VDB seeds are binary and OpenVDB-version specific: made here, not committed.
"$FUZZ_BUILD/fuzz/make_vdb_seeds" "$FUZZ_BUILD/fuzz-seeds/material_set"
# Skinned glTF seeds (a base64 buffer in JSON), from the writer the tests use.
"$FUZZ_BUILD/fuzz/make_mesh_seeds" "$FUZZ_BUILD/fuzz-seeds/mesh"

# leak_check_at_exit=0: the VDB and mesh readers parse in a forked child that ends with
# _exit(), which LSan intercepts to leak-check the whole inherited heap (seconds per input
# and a spurious exit code). libFuzzer's own leak check between inputs stays on.
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:leak_check_at_exit=0:allocator_may_return_null=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
failed=()
for h in "${HARNESSES[@]}"; do
  committed="$SSLPV_ROOT/fuzz/corpus/$h"
  work="$FUZZ_BUILD/fuzz-corpus/$h"
  log="$FUZZ_BUILD/fuzz-logs/$h.log"
  mkdir -p "$work" "$committed/regressions" "$(dirname "$log")"
  corpora=("$work" "$committed")
  [ -d "$FUZZ_BUILD/fuzz-seeds/$h" ] && corpora+=("$FUZZ_BUILD/fuzz-seeds/$h")
  dict=()
  case "$h" in scene|stroke|pbrt) dict=(-dict="$SSLPV_ROOT/fuzz/json.dict") ;; esac
  echo "fuzz: $h for ${SECONDS_EACH} (log: $log)"
  # The first corpus folder receives new inputs; the committed one (with regressions/,
  # read recursively) is replayed in full before mutation starts.
  if [ "$SECONDS_EACH" = ci ]; then
    # Runs that take 10-20 s each here: the forking readers manage a few inputs a second.
    case "$h" in scene|stroke) budget=(-runs=20000) ;; pbrt) budget=(-runs=2000) ;; *) budget=(-runs=40) ;; esac
    budget+=(-seed=1)
  else
    budget=(-max_total_time="$SECONDS_EACH")
  fi
  if "$FUZZ_BUILD/fuzz/${h}_fuzz" "${budget[@]}" -timeout=10 -rss_limit_mb=4096 \
      -print_final_stats=1 -artifact_prefix="$committed/regressions/" "${dict[@]}" "${corpora[@]}" \
      >"$log" 2>&1; then
    echo "fuzz: $h: $(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}') inputs, no finding"
  else
    failed+=("$h")
    echo "fuzz: $h: FINDING (input saved under fuzz/corpus/$h/regressions/); end of its log:"
    tail -n 40 "$log"
  fi
done
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: findings in: ${failed[*]}"
  exit 1
fi
echo "fuzz: no findings"
