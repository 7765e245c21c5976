#!/usr/bin/env bash
# Quick start, step 2: install dependencies, build, and run the whole test suite.
source "$(dirname "$0")/scripts/common.sh"
sslpv_install_packages
sslpv_build
cd "$SSLPV_BUILD"
ctest -j "$(nproc)" --output-on-failure --timeout 900
