#!/usr/bin/env bash
# Build (incrementally) and run every test. Run tools/bootstrap.sh once first.
# Three parts, each must pass:
#   1. the CTest suite in $BUILD_DIR (build/);
#   2. the same whole suite built with ASan + UBSan in build-san/ (tools/test_sanitized.sh);
#   3. each libFuzzer harness for FUZZ_SECONDS (default 10) s (tests/fuzz/run.sh, clang).
# GS_TEST_SANITIZE=0 or GS_TEST_FUZZ=0 skips part 2 or 3 (for a quick local run).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
BUILD_DIR=${BUILD_DIR:-build}
t0=$(date +%s)
cmake --build "$BUILD_DIR" -j "$(nproc)"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)"
# The firmware check (tools/firmware_size.sh) is a CTest test where the cross compiler
# is installed; without it CTest skips it, so say so and fail rather than pass quietly.
if ! command -v arm-none-eabi-gcc >/dev/null 2>&1; then
  echo "test.sh: arm-none-eabi-gcc not found: the Cortex-M4 firmware check did not run" \
       "(apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi)" >&2
  exit 1
fi
t1=$(date +%s)
if [ "${GS_TEST_SANITIZE:-1}" != 0 ]; then
  echo "test: the whole suite again under AddressSanitizer + UndefinedBehaviorSanitizer"
  bash tools/test_sanitized.sh
fi
t2=$(date +%s)
if [ "${GS_TEST_FUZZ:-1}" != 0 ]; then
  echo "test: fuzzing each harness for ${FUZZ_SECONDS:-10} s"
  bash tests/fuzz/run.sh "${FUZZ_SECONDS:-10}"
fi
t3=$(date +%s)
echo "test: all passed; wall time: suite $((t1 - t0)) s, sanitized suite $((t2 - t1)) s, fuzzing $((t3 - t2)) s"
