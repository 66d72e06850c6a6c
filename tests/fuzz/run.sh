#!/usr/bin/env bash
# Build the libFuzzer harnesses with clang (ASan + UBSan) and run each for a
# bounded time. Usage: tests/fuzz/run.sh [seconds per harness, default 30]
# Exits non-zero when a harness crashes; exits 0 with a note when clang is missing.
set -euo pipefail
secs=${1:-30}
top=$(cd "$(dirname "$0")/../.." && pwd)
if ! command -v clang >/dev/null 2>&1; then
  echo "fuzz: clang is not installed; skipping (install clang to fuzz)"
  exit 0
fi
out=${FUZZ_OUT:-$top/build-fuzz}
mkdir -p "$out"
# clang without its fuzzer/sanitizer runtime (e.g. Debian's libclang-rt-*-dev) cannot fuzz either
printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n);\nint LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' > "$out/probe.c"
if ! clang -fsanitize=fuzzer,address,undefined "$out/probe.c" -o "$out/probe" >/dev/null 2>&1; then
  echo "fuzz: clang cannot link -fsanitize=fuzzer (runtime library missing); skipping"
  exit 0
fi
core="$top/src/core"
flags=(-std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I"$top/include")
clang "${flags[@]}" "$top/tests/fuzz/fuzz_num.c" "$core/gs_num.c" -lm -o "$out/fuzz_num"
clang "${flags[@]}" "$top/tests/fuzz/fuzz_config.c" "$core"/gs_config.c "$core"/gs_num.c \
  "$core"/gs_status.c "$core"/gs_emit.c "$core"/gs_com.c "$core"/gs_fit.c "$core"/gs_ring.c -lm -o "$out/fuzz_config"
# seed corpora: the shipped configs and a few numbers
mkdir -p "$out/corpus_config" "$out/corpus_num"
cp "$top"/firmware_cfg/*.cfg "$out/corpus_config/" 2>/dev/null || true
i=0
for n in 0 -0 1.5 1e308 2.2250738585072011e-308 .5 5. 123456789012345678901234567890 1e-400; do
  printf '%s' "$n" > "$out/corpus_num/seed$i"; i=$((i + 1))
done
status=0
for h in num config; do
  echo "fuzz: fuzz_$h for ${secs}s"
  if ! "$out/fuzz_$h" -max_total_time="$secs" -max_len=4096 -artifact_prefix="$out/crash_${h}_" \
       "$out/corpus_$h" >"$out/fuzz_$h.log" 2>&1; then
    echo "fuzz: fuzz_$h FAILED, see $out/fuzz_$h.log"; tail -n 30 "$out/fuzz_$h.log"; status=1
  else
    grep -E '^#[0-9]+.*DONE|Done [0-9]+ runs' "$out/fuzz_$h.log" | tail -n 1 || true
  fi
done
exit $status
