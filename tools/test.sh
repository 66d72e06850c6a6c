#!/usr/bin/env bash
# Build (incrementally) and run every test. Run tools/bootstrap.sh once first.
# Three parts, each must pass:
#   1. the CTest suite in $BUILD_DIR (build/);
#   2. the same whole suite built with ASan + UBSan in build-san/ (tools/test_sanitized.sh);
#   3. each libFuzzer harness for FUZZ_SECONDS (default 20) s (tests/fuzz/run.sh, clang).
# GS_TEST_SANITIZE=0 or GS_TEST_FUZZ=0 skips part 2 or 3 (for a quick local run).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
BUILD_DIR=${BUILD_DIR:-build}
t0=$(date +%s)
cmake --build "$BUILD_DIR" -j "$(nproc)"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)"
t1=$(date +%s)
if [ "${GS_TEST_SANITIZE:-1}" != 0 ]; then
  echo "test: the whole suite again under AddressSanitizer + UndefinedBehaviorSanitizer"
  bash tools/test_sanitized.sh
fi
t2=$(date +%s)
if [ "${GS_TEST_FUZZ:-1}" != 0 ]; then
  echo "test: fuzzing each harness for ${FUZZ_SECONDS:-20} s"
  bash tests/fuzz/run.sh "${FUZZ_SECONDS:-20}"
fi
t3=$(date +%s)
echo "test: all passed; wall time: suite $((t1 - t0)) s, sanitized suite $((t2 - t1)) s, fuzzing $((t3 - t2)) s"
