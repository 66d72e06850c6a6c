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
# The sanitized build runs the pose networks in OpenCV's DNN (OpenVINO's CPU plugin
# cannot load under the sanitizer runtime: CMakeLists.txt). Two tests of the handheld gym
# clip assert what the OpenVINO keypoints give and run in the plain suite only: with a
# walker hiding the feet at the apex (test_pose_crossing) the flight is timed from the COM,
# and OpenCV's keypoints put that 0.667 s instead of 0.826 s; the kiosk (cam path, no
# stabilisation) sees the tilting camera's floor drop by 0.1 stature with OpenCV's toes and
# rejects the jump as a fall (py_test_kiosk_browser). test_pose_video times the same clip
# with both engines.
ctest --test-dir "$SAN_BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 1800 \
  -E '^(test_pose_crossing|py_test_kiosk_browser)$' "$@"
