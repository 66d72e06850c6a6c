#!/usr/bin/env bash
# Install the pose networks' inference engine, OpenVINO (tools/requirements-engine.txt,
# Apache-2.0), from PyPI into the ignored venv .venv-engine/, where CMake finds its
# package (CMakeLists.txt); idempotent, offline once done.
#   tools/fetch_engine.sh
# Without it (no wheel for this machine, or no registry) gravscale builds and runs the
# networks in OpenCV's DNN: the script says so and exits 0, unless GS_ENGINE_REQUIRED=1.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
venv="$top/.venv-engine"
req="$top/tools/requirements-engine.txt"
say() { echo "fetch_engine: $*"; }
req_sum=$(sha256sum "$req" | cut -d' ' -f1)
if [ -x "$venv/bin/python" ] && [ "$(cat "$venv/.gravscale-engine" 2>/dev/null)" = "$req_sum" ]; then
  say "OpenVINO present in $venv"
  exit 0
fi
fallback() {
  say "$* - the pose networks will run in OpenCV's DNN (slower; docs/pose.md, \"Engines\")" >&2
  [ "${GS_ENGINE_REQUIRED:-0}" = 1 ] && exit 1
  exit 0
}
# Debian's python3 and its venv module (python3-venv: tools/bootstrap.sh installs it)
[ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv "$venv" || fallback "could not create $venv"
say "installing $(grep -v '^#' "$req" | tr '\n' ' ')into $venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --no-deps -r "$req" ||
  fallback "pip could not install $req (no wheel for this machine, or no registry)"
echo "$req_sum" > "$venv/.gravscale-engine"
say "OpenVINO installed in $venv (configure the build again if it existed before)"
