#!/usr/bin/env bash
# Build the libFuzzer harnesses with clang (ASan + UBSan) and run each for a
# bounded time; any crash, sanitizer report, leak, failed property, slow input
# (> 10 s) or out-of-memory fails the run. docs/fuzz.md says more.
#   tests/fuzz/run.sh [SECONDS_PER_HARNESS [HARNESS...]]
#   SECONDS defaults to $FUZZ_SECONDS or 20; harnesses: num config sink_config
#   emit json_tok csv alphapose openpose core (default: all).
#   FUZZ_OUT=dir (default build-fuzz/) keeps the objects, the grown corpora and
#   crash_<harness>_* artifacts; a second run continues from the grown corpora.
# Without clang or its fuzzer runtime it says so and exits 0 (tools/bootstrap.sh
# installs clang and libclang-rt-14-dev).
set -euo pipefail
secs=${1:-${FUZZ_SECONDS:-20}}
shift || true
all=(num config sink_config emit json_tok csv alphapose openpose core)
if [ $# -gt 0 ]; then harnesses=("$@"); else harnesses=("${all[@]}"); fi
top=$(cd "$(dirname "$0")/../.." && pwd)
CC=${FUZZ_CC:-clang}
if ! command -v "$CC" >/dev/null 2>&1; then
  echo "fuzz: $CC is not installed; skipping (tools/bootstrap.sh installs clang)"
  exit 0
fi
out=${FUZZ_OUT:-$top/build-fuzz}
mkdir -p "$out/obj"
# clang without its fuzzer/sanitizer runtime (Debian's libclang-rt-14-dev) cannot fuzz either
printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n);\nint LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' > "$out/probe.c"
if ! "$CC" -fsanitize=fuzzer,address,undefined "$out/probe.c" -o "$out/probe" >/dev/null 2>&1; then
  echo "fuzz: $CC cannot link -fsanitize=fuzzer (libclang-rt-14-dev missing?); skipping"
  exit 0
fi
for s in llvm-symbolizer /usr/lib/llvm-14/bin/llvm-symbolizer; do
  if command -v "$s" >/dev/null 2>&1; then export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-$(command -v "$s")}; break; fi
done

t_build=$(date +%s)
san=(-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer)
cflags=(-std=c11 -g -O1 -Wall -Wextra "${san[@]}" -I"$top/include" -I"$top/src/io")
# the code under test: instrumented for coverage, linked into every harness
objs=()
for src in "$top"/src/core/*.c "$top"/src/io/*.c; do
  o="$out/obj/$(basename "$(dirname "$src")")_$(basename "$src" .c).o"
  defs=()
  [[ $src == */src/io/* ]] && defs=(-D_POSIX_C_SOURCE=200809L)
  if [ ! -f "$o" ] || [ "$src" -nt "$o" ] || [ "$0" -nt "$o" ] || \
     [ -n "$(find "$top/include" "$top/src/io" -name '*.h' -newer "$o" 2>/dev/null | head -n 1)" ]; then
    "$CC" "${cflags[@]}" "${defs[@]}" -fsanitize=fuzzer-no-link -c "$src" -o "$o"
  fi
  objs+=("$o")
done
for h in "${harnesses[@]}"; do
  src="$top/tests/fuzz/fuzz_$h.c"
  [ -f "$src" ] || { echo "fuzz: no harness $src"; exit 2; }
  "$CC" "${cflags[@]}" -Werror -D_POSIX_C_SOURCE=200809L -fsanitize=fuzzer "$src" "${objs[@]}" -lm -o "$out/fuzz_$h"
done
# seed corpora: generated from tests/data and firmware_cfg, plus the small committed ones
rm -rf "$out/seeds"
python3 "$top/tests/fuzz/make_seeds.py" "$out/seeds"
mkdir -p "$out/seeds/num"
i=0
for n in 0 -0 1.5 1e308 2.2250738585072011e-308 .5 5. 123456789012345678901234567890 1e-400; do
  printf '%s' "$n" > "$out/seeds/num/seed$i"; i=$((i + 1))
done
echo "fuzz: built ${#harnesses[@]} harnesses in $(( $(date +%s) - t_build )) s; ${secs} s each"

# the reader harnesses write their inputs to temp files and folders: keep them here
export TMPDIR="$out/tmp"
rm -rf "$TMPDIR"
mkdir -p "$TMPDIR"
status=0
for h in "${harnesses[@]}"; do
  mkdir -p "$out/corpus/$h" "$out/seeds/$h"
  dirs=("$out/corpus/$h" "$out/seeds/$h")
  [ -d "$top/tests/fuzz/corpus/$h" ] && dirs+=("$top/tests/fuzz/corpus/$h")
  case $h in csv|alphapose|openpose) maxlen=65536 ;; *) maxlen=4096 ;; esac
  t0=$(date +%s)
  # the first corpus dir takes new inputs; the seed dirs are only read
  if ! (cd "$out" && "./fuzz_$h" -max_total_time="$secs" -max_len="$maxlen" -timeout=10 -rss_limit_mb=2048 \
        -print_final_stats=1 -artifact_prefix="$out/crash_${h}_" "${dirs[@]}" >"$out/fuzz_$h.log" 2>&1); then
    echo "fuzz: fuzz_$h FAILED after $(( $(date +%s) - t0 )) s, see $out/fuzz_$h.log:"
    grep -E 'ERROR|property failed|runtime error|SUMMARY|Test unit written' "$out/fuzz_$h.log" | head -n 20 || true
    tail -n 40 "$out/fuzz_$h.log"
    status=1
  else
    runs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$out/fuzz_$h.log" | grep -Eo '[0-9]+$' || echo '?')
    cov=$(grep -E '^#[0-9]+' "$out/fuzz_$h.log" | tail -n 1 | grep -Eo 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+/[0-9]+[a-zA-Z]*' || true)
    echo "fuzz: fuzz_$h ok: $runs inputs in $(( $(date +%s) - t0 )) s ($cov)"
  fi
done
exit $status
