#!/usr/bin/env bash
# Debian packages for `gravscale cam` beyond tools/bootstrap.sh's list
# (call it from bootstrap before configuring; safe to run again):
#   gstreamer1.0-plugins-base  videotestsrc, videoconvert, appsink (test_capture,
#                              the gstreamer backend; OpenCV 4.6 links GStreamer 1.22)
#   libcamera-dev              the libcamera backend (optional in CMake: without
#                              it the backend says so; found via pkg-config)
set -euo pipefail
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
pkgs=(gstreamer1.0-plugins-base libcamera-dev)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup_cam: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
