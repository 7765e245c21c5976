#!/usr/bin/env bash
# The heterogeneous accuracy suite: seven scenes whose material changes within a few mean
# free paths of the surface (two- and three-layer slabs, front- and back-lit, one tilted
# against the grid; a veined block; a sphere with inclusions and g = 0.5; a thin plate;
# a sphere painted with `sslpv paint`), rendered by bench-error against path-traced
# references cached in bench/hetero_references/ (tracing them anew takes hours).
#
#   scripts/hetero-suite.sh [OUT_PREFIX] [bench-error flags...]
#
# Default: OUT_PREFIX build/hetero/suite, the calibrated scheme on the CPU at 32³ and 64³
# with --steps auto, 64-spp references; later flags override (e.g. --backend cpu,vulkan).
source "$(dirname "$0")/common.sh"
sslpv_install_packages
sslpv_build
SUITE="$SSLPV_BUILD/hetero"
PREFIX="${1:-$SUITE/suite}"
shift || true
"$SSLPV_BUILD/bench/hetero_scenes" "$SUITE"
(cd "$SUITE" && "$SSLPV_BUILD/sslpv" paint painted_strokes.unpainted.json \
   --strokes painted_strokes.strokes.json -o painted_strokes.vdb >/dev/null)
SCENES=()
for name in layers2_backlit layers2_frontlit layers3_tilted veins_block inclusions_sphere thin_plate painted_strokes; do
  SCENES+=("$SUITE/$name.json")
done
"$SSLPV_BUILD/sslpv" bench-error "${SCENES[@]}" -o "$PREFIX" \
  --cache "$SSLPV_ROOT/bench/hetero_references" --grid 32,64 --steps auto --backend cpu \
  --scheme calibrated --spp 64 "$@"
