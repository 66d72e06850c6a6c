#!/usr/bin/env bash
# Fetch the Unity test framework (ThrowTheSwitch v2.4.3, as carried in Debian's
# cjson source package under tests/unity) into third_party/unity, keeping its
# layout (src/unity_internals.h includes ../examples/unity_config.h), and check
# every file we use against pinned checksums. Needs apt (root or sudo).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dest="$top/third_party/unity"
cache="$top/third_party/.cache"

want() {
  cat <<'SUMS'
a89aaeeaebb8a9f8b9379493592c1a8a135ece211d48128752d2c4c49724690a  src/unity.c
2d356dcffe0f8d887ece0ad8d5cd0d388aeef5482800a7b8fea6d415be8bcf1f  src/unity.h
874c2af0bcebead08d0f609f77e2306a735ba55205b7776d937120cb616d4304  src/unity_internals.h
c3d7d8f48c9dfb38a4cbaabc2d30a0a5335d2bdd8b454fd70326876e90133299  examples/unity_config.h
SUMS
}

check() { (cd "$dest" && want | sha256sum --quiet -c - >/dev/null 2>&1); }

if [ -d "$dest" ] && check; then
  echo "fetch_unity: Unity already present and verified in $dest"
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

# A deb-src entry derived from the machine's own Debian sources (deb822 first, then one-line).
srcfile=/etc/apt/sources.list.d/gravscale-deb-src.sources
if ! grep -rqsE '^(Types:.*deb-src|deb-src )' /etc/apt/sources.list /etc/apt/sources.list.d/ ; then
  tmp=$(mktemp)
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    grep -qs 'debian-archive-keyring' "$f" || continue
    sed -e 's/^Types:[[:space:]]*deb[[:space:]]*$/Types: deb-src/' "$f" >> "$tmp"
    echo >> "$tmp"
  done
  if [ ! -s "$tmp" ] && [ -f /etc/apt/sources.list ]; then
    grep -E '^deb ' /etc/apt/sources.list | sed 's/^deb /deb-src /' > "$tmp.list" || true
    if [ -s "$tmp.list" ]; then srcfile=/etc/apt/sources.list.d/gravscale-deb-src.list; mv "$tmp.list" "$tmp"; fi
  fi
  [ -s "$tmp" ] || { echo "fetch_unity: no Debian apt source found to derive a deb-src entry from" >&2; exit 1; }
  $SUDO install -m 0644 "$tmp" "$srcfile"
  rm -f "$tmp"
  echo "fetch_unity: added $srcfile"
fi
$SUDO apt-get update -qq

mkdir -p "$cache"
rm -rf "$cache"/cjson* "$cache"/cJSON*
( cd "$cache" && apt-get source --download-only -qq cjson 2>&1 | grep -v 'unsandboxed' || true )
orig=$(ls "$cache"/cjson_*.orig.tar.* 2>/dev/null | head -n1)
[ -n "$orig" ] || { echo "fetch_unity: apt-get source cjson gave no orig tarball" >&2; exit 1; }

rm -rf "$dest" "$cache/extract"
mkdir -p "$cache/extract" "$dest"
tar -xf "$orig" -C "$cache/extract" --wildcards '*/tests/unity/*'
cp -r "$cache"/extract/*/tests/unity/. "$dest/"
if ! check; then
  echo "fetch_unity: checksum mismatch for Unity files from $orig:" >&2
  (cd "$dest" && want | sha256sum -c - >&2) || true
  rm -rf "$dest"
  exit 1
fi
echo "fetch_unity: Unity $(cat "$dest/release/version.info" 2>/dev/null) from $(basename "$orig") verified in $dest"
