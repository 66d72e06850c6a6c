#!/bin/sh
# gravscale itself maps no vision library (replay starts in a millisecond), and
# video / cam without gravscale-vision.so next to it fail with a line naming it.
prog="$1"
[ -x "$prog" ] || { echo "program_light: no program at '$prog'" >&2; exit 2; }
heavy=$(ldd "$prog" | grep -E 'opencv|openvino|avformat|civetweb|sqlite|camera' || true)
if [ -n "$heavy" ]; then
  echo "program_light: $prog links vision libraries:" >&2
  echo "$heavy" >&2
  exit 1
fi
[ -f "$(dirname "$prog")/gravscale-vision.so" ] || { echo "program_light: no gravscale-vision.so next to $prog" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$prog" "$tmp/gravscale"
for cmd in video cam; do
  "$tmp/gravscale" "$cmd" --help >"$tmp/out" 2>"$tmp/err"
  rc=$?
  if [ "$rc" -ne 2 ] || ! grep -q "gravscale-vision.so" "$tmp/err"; then
    echo "program_light: $cmd without the module: exit $rc, stderr:" >&2
    cat "$tmp/err" >&2
    exit 1
  fi
done
"$tmp/gravscale" --help >/dev/null || { echo "program_light: --help failed without the module" >&2; exit 1; }
echo "program_light: $(ldd "$prog" | wc -l) shared objects; video and cam without the module: exit 2 naming it"
echo "1 passed, 0 failed"
