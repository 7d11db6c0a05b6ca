#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Install what is missing, build, and run the whole test suite (render tests need an X
# server, so ctest runs under xvfb-run); then build the unit and reader tests with clang
# under AddressSanitizer + UndefinedBehaviorSanitizer and run them. Exits non-zero on any
# failure.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_deps
build
say "Running ctest (under xvfb-run -a)"
cd "$BUILD"
xvfb-run -a ctest --output-on-failure -j2 --timeout 600

# The unit tests, the readers' tests (io, ONI playback) and the metrics, under ASan + UBSan
# (any report fails the step). Third-party leaks are suppressed by test/sanitizers/lsan.supp,
# which names each library and why.
SANITIZED_TESTS=(test_common test_io test_eval test_oni test_scene_flow
                 test_motion_segmentation test_registration)
SANITIZE_BUILD="$BUILD-sanitize"
SANITIZE_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
say "Configuring $SANITIZE_BUILD (clang, ASan + UBSan)"
CC=clang CXX=clang++ cmake -S "$ROOT" -B "$SANITIZE_BUILD" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DDYNVO_BUILD_APPS=OFF -DCMAKE_CXX_FLAGS="$SANITIZE_FLAGS" \
  -DCMAKE_EXE_LINKER_FLAGS="$SANITIZE_FLAGS" -DCMAKE_SHARED_LINKER_FLAGS="$SANITIZE_FLAGS" \
  >/dev/null
say "Building ${SANITIZED_TESTS[*]} under ASan + UBSan"
cmake --build "$SANITIZE_BUILD" -j2 --target "${SANITIZED_TESTS[@]}"
say "Running them under ASan + UBSan"
export LSAN_OPTIONS="suppressions=$ROOT/test/sanitizers/lsan.supp"
export UBSAN_OPTIONS="print_stacktrace=1"
for test in "${SANITIZED_TESTS[@]}"; do
  echo "$test"
  "$SANITIZE_BUILD/test_bin/$test" --gtest_brief=1
done
