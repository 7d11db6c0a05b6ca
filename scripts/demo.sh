#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Install what is missing, build, and run the main job on the embedded default input:
# the synthesised dynamic sequence "moving_crossing" (300 VGA frames, seed 0).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_deps
build
OUT="$BUILD/demo"
SEQ="$OUT/moving_crossing"
rm -rf "$OUT"
mkdir -p "$OUT"
say "Synthesising the default dynamic sequence into $SEQ"
"$BUILD/bin/dynvo_synthesize" -scenario moving_crossing -frames 300 -seed 0 -out "$SEQ"
say "Scoring its ground truth against itself (the odometry pipeline will replace this)"
"$BUILD/bin/dynvo_evaluate" "$SEQ/groundtruth.txt" "$SEQ/groundtruth.txt"
