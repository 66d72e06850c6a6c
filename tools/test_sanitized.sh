#!/usr/bin/env bash
# Build everything with AddressSanitizer + UndefinedBehaviorSanitizer (gcc) in a
# second build dir and run the WHOLE CTest suite there (C, C++ vision, Python
# tests that start the sanitized gravscale). Any finding fails the run.
#   tools/test_sanitized.sh            (SAN_BUILD_DIR=build-san by default)
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
SAN_BUILD_DIR=${SAN_BUILD_DIR:-build-san}
# float-cast-overflow is UB (a double too large for an int) but not in gcc's "undefined" set
SAN=${GS_SANITIZE:-address,undefined,float-cast-overflow}

cmake -S . -B "$SAN_BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGS_SANITIZE="$SAN" >/dev/null
cmake --build "$SAN_BUILD_DIR" -j "$(nproc)"

# halt on the first report; leaks are checked at exit (LSan), with suppressions
# only for third-party libraries (tools/sanitizer/lsan.supp says why for each)
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$top/tools/sanitizer/lsan.supp:print_suppressions=0}
# generous per-test limit: instrumented code runs 2-4x slower
ctest --test-dir "$SAN_BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 1800 "$@"
