#!/usr/bin/env bash
# Set up a fresh Debian 12 machine and build gravscale, then run the main job on
# the bundled sample. Safe to run again: it only installs what is missing.
#   tools/bootstrap.sh            (BUILD_DIR=build by default)
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
BUILD_DIR=${BUILD_DIR:-build}

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

# OpenCV and FFmpeg's libavformat, libavcodec and libswscale for the video command (tests render clips with them);
# python3-opencv, python3-venv and opencv-doc for the pose models' converter and its test;
# Eigen for the ball detector's ballistic fits (and the tests' batch references);
# clang with its sanitizer/libFuzzer runtime and llvm-symbolizer for tests/fuzz/run.sh;
# the arm-none-eabi cross compiler with newlib nano and QEMU for the Cortex-M4 firmware check;
# valgrind (callgrind) for bench_core's instruction counts, python3-numpy for tools/bench_paper.py;
# the kiosk (docs/kiosk.md): civetweb for its page, SQLite for the history, nlohmann-json;
# libmosquitto for the MQTT sink and the mosquitto broker (and its clients) its tests start;
# chromium and chromedriver for the kiosk's browser test (about 13 s to install here)
pkgs=(build-essential cmake ninja-build python3 binutils pkg-config libopencv-dev libavformat-dev libavcodec-dev libswscale-dev
      python3-opencv python3-venv opencv-doc libeigen3-dev
      clang libclang-rt-14-dev llvm-14
      gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi qemu-system-arm
      valgrind python3-numpy
      libcivetweb-dev libsqlite3-dev nlohmann-json3-dev libmosquitto-dev mosquitto mosquitto-clients
      openssl chromium chromium-driver)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

bash tools/setup_cam.sh      # GStreamer base plugins (videotestsrc) and libcamera-dev for gravscale cam
bash tools/fetch_unity.sh
bash tools/fetch_models.sh   # BlazePose: npm package -> ONNX in models/ (checksummed)
bash tools/fetch_engine.sh   # OpenVINO for the pose networks: PyPI wheel into .venv-engine/ (else OpenCV DNN)

cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$BUILD_DIR" -j "$(nproc)"

echo "bootstrap: main job on the bundled sample (tests/data/sample_jumps.csv):"
"$BUILD_DIR/gravscale" replay --keypoints tests/data/sample_jumps.csv | tee "$BUILD_DIR/sample_out.jsonl" | tail -n 2
python3 - "$BUILD_DIR/sample_out.jsonl" <<'PY'
import json, sys
last = [json.loads(l) for l in open(sys.argv[1])][-1]
assert last["event"] == "summary", last
h = last["height_m"]
print("bootstrap: height from the sample: %s m over %d jumps (95%% interval %s)" % (
    "%.3f" % h if h is not None else "unknown", last["n_jumps"], last["ci95_m"]))
PY
