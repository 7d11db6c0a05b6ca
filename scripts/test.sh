#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Install what is missing, build, and run the whole test suite (render tests need an X
# server, so ctest runs under xvfb-run). Exits non-zero on any failure.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_deps
build
say "Running ctest (under xvfb-run -a)"
cd "$BUILD"
xvfb-run -a ctest --output-on-failure -j2 --timeout 600
