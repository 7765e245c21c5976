#!/usr/bin/env bash
# Quick start, step 1: install dependencies, build (Release) and render the default
# example to build/example.png with a per-stage timing table (--backend auto: Vulkan on
# a GPU, the CPU backend where Vulkan would run on the CPU through lavapipe).
source "$(dirname "$0")/scripts/common.sh"
sslpv_install_packages
sslpv_build
"$SSLPV_BUILD/sslpv" render "$SSLPV_ROOT/examples/marble_pebble.json" \
  -o "$SSLPV_BUILD/example.png" --timings
echo "sslpv: wrote $SSLPV_BUILD/example.png"
