#!/bin/sh
# firmware_size.sh - build the core for a Cortex-M4F (cmake/cortex-m4.cmake: Debian's
# gcc-arm-none-eabi + libnewlib-arm-none-eabi, newlib nano) with the firmware link test
# tools/fw/fw_main.c, check that no heap, stdio or strtod code is linked, and report the
# sizes against the budgets of issue 5.
#   tools/firmware_size.sh [BUILD_DIR]        (default build-m4)
# Exit 0: built, no forbidden symbol, code within the 24 KB target, state within budget,
# and (with QEMU) the run checks passed. 1: a check failed. 2: no cross compiler or the
# build failed. GS_FW_STRICT=0 reports the code target as OVER instead of failing (the
# everything-in firmware misses it; docs/firmware.md says where the bytes are).
# GS_FW_REAL=double builds the fits in double instead of float (for comparison).
# GS_FW_LTO=OFF links the firmware without link-time optimisation.
# A device selection (include/gravscale/gs_features.h, docs/firmware.md):
#   GS_FW_DEVICE=all (default: every feature, the profile parsed from text)
#     | ball-lab (point input, NMEA, profile baked at build time, no trace events, no ransac)
#     | camera-coco17 | camera-blazepose33 (that skeleton layout, NMEA, profile baked at
#       build time, no trace events, no ransac)
#   GS_FW_FEATURES="GS_WITH_JSON=0 GS_WITH_BLAZEPOSE33=0"  features left out (overrides the device's)
#   GS_FW_PROFILE=OFF  the profile baked at build time (tools/fw/fw_bake.c: parsed and checked
#     on the host, no text parser linked) instead of its text parsed at boot
#   GS_FW_PROFILE_FILE=firmware_cfg/ball_lab.cfg  the firmware's profile (default
#     tools/fw/workload.cfg, which the workload's ball and skeleton both pass)
# e.g. GS_FW_DEVICE=ball-lab tools/firmware_size.sh build-m4-ball
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
bdir=${1:-$top/build-m4}
case $bdir in /*) ;; *) bdir=$(pwd)/$bdir ;; esac

CODE_TARGET=24576      # flash: text + data (initialisers)
STATE_BUDGET=2048      # RAM beyond the ring: pipeline state + scratch
RING_SAMPLES=512

for t in arm-none-eabi-gcc arm-none-eabi-nm arm-none-eabi-size cmake; do
  command -v $t >/dev/null 2>&1 || { echo "firmware_size: $t not found (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi)" >&2; exit 2; }
done
gen=""
command -v ninja >/dev/null 2>&1 && gen="-G Ninja"
lto=${GS_FW_LTO:-ON}
dev_features=""; dev_profile=ON
case ${GS_FW_DEVICE:-all} in
  all) ;;
  ball-lab) dev_features="GS_WITH_JSON=0 GS_WITH_COCO17=0 GS_WITH_BLAZEPOSE33=0 GS_WITH_TRACE=0 GS_WITH_RANSAC=0"
            dev_profile=OFF ;;
  camera-coco17) dev_features="GS_WITH_JSON=0 GS_WITH_POINT=0 GS_WITH_BLAZEPOSE33=0 GS_WITH_TRACE=0 GS_WITH_RANSAC=0"
                 dev_profile=OFF ;;
  camera-blazepose33) dev_features="GS_WITH_JSON=0 GS_WITH_POINT=0 GS_WITH_COCO17=0 GS_WITH_TRACE=0 GS_WITH_RANSAC=0"
                      dev_profile=OFF ;;
  *) echo "firmware_size: unknown GS_FW_DEVICE '$GS_FW_DEVICE' (all, ball-lab, camera-coco17, camera-blazepose33)" >&2; exit 2 ;;
esac
features=${GS_FW_FEATURES:-$dev_features}
profile=${GS_FW_PROFILE:-$dev_profile}
profile_file=${GS_FW_PROFILE_FILE:-$top/tools/fw/workload.cfg}
case $profile_file in /*) ;; *) profile_file=$(pwd)/$profile_file ;; esac
# the same selection for the host twin (cc -D...)
twin_defs=""
for f in $features; do twin_defs="$twin_defs -D$f"; done
[ "$profile" = OFF ] && twin_defs="$twin_defs -DFW_PROFILE_BAKED=1 -DGS_BAKED_PROFILE=1"
echo "--- device ${GS_FW_DEVICE:-all}: features off: ${features:-none}; profile $(basename "$profile_file") parsed at boot: $profile (OFF: baked)"
# build_fw DIR LTO: configure and build the firmware in DIR
build_fw() {
  if ! cmake -S "$top" -B "$1" $gen -DCMAKE_TOOLCHAIN_FILE="$top/cmake/cortex-m4.cmake" -DGS_FW_LTO=$2 \
       -DGS_BUILD_HOST=OFF -DGS_REAL=${GS_FW_REAL:-float} -DCMAKE_BUILD_TYPE=MinSizeRel \
       -DGS_FEATURES="$(echo $features | tr ' ' ';')" -DGS_FW_PROFILE=$profile \
       -DGS_FW_PROFILE_FILE="$profile_file" >"$1.configure.log" 2>&1; then
    cat "$1.configure.log" >&2; echo "firmware_size: configure failed" >&2; exit 2
  fi
  rm -f "$1.configure.log"
  if ! cmake --build "$1" >"$1/build.log" 2>&1; then
    cat "$1/build.log" >&2; echo "firmware_size: build failed" >&2; exit 2
  fi
}
build_fw "$bdir" "$lto"
elf=$bdir/gravscale_fw.elf
# the firmware is linked with LTO (GS_FW_LTO=OFF: without); the breakdown by file, the
# core library's references and its stack frames come from a build without LTO (LTO
# merges the files), in $bdir/nolto
nbdir=$bdir
if [ "$lto" != OFF ]; then
  nbdir=$bdir/nolto
  build_fw "$nbdir" OFF
fi
map=$nbdir/gravscale_fw.map
lib=$nbdir/libgravscale_core.a
fail=0

# 1. nothing from the heap, printf or strtod families is linked (nor sbrk, which a heap needs)
bad=$(arm-none-eabi-nm "$elf" | awk '$2 ~ /^[TtWw]$/ {print $3}' | grep -E \
  '^_?(malloc|calloc|realloc|free|_malloc_r|_free_r|_calloc_r|_realloc_r|sbrk|_sbrk|_sbrk_r|printf|fprintf|sprintf|snprintf|vprintf|vfprintf|vsprintf|vsnprintf|_printf_r|_vfprintf_r|_svfprintf_r|_vfiprintf_r|puts|putchar|strtod|strtof|strtold|_strtod_r|atof|sscanf|_svfscanf_r)$' || true)
if [ -n "$bad" ]; then
  echo "FAIL forbidden symbols linked:" $bad; fail=1
else
  echo "ok   no malloc/free/printf/strtod family symbol in the firmware"
fi
# ... and the core library references none either (whatever firmware links it)
undef=$(arm-none-eabi-nm -u "$lib" | awk '$1 == "U" {print $2}' | sort -u)
ubad=$(echo "$undef" | grep -E \
  '^(malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|vsnprintf|puts|strtod|strtof|atof|sscanf)$' || true)
if [ -n "$ubad" ]; then
  echo "FAIL the core library references:" $ubad; fail=1
else
  echo "ok   the core library references no heap/stdio/strtod; it needs: $(echo "$undef" | grep -v -E '^(__aeabi_|gs_)' | tr '\n' ' ')"
  echo "     + $(echo "$undef" | grep -c '^__aeabi_') soft-float/64-bit helpers from libgcc: $(echo "$undef" | grep '^__aeabi_' | tr '\n' ' ')"
fi

# 2. sizes
echo "--- arm-none-eabi-size $elf"
arm-none-eabi-size "$elf"
set -- $(arm-none-eabi-size "$elf" | awk 'NR == 2 {print $1, $2, $3}')
text=$1; data=$2; bss=$3
# linked bytes per input file, from the map (after --gc-sections)
[ "$nbdir" = "$bdir" ] || echo "--- without LTO: $(arm-none-eabi-size "$nbdir/gravscale_fw.elf" | awk 'NR == 2 {print $1 " text + " $2 " data = " $1 + $2}') B"
echo "--- linked code+rodata by origin (bytes, without LTO)"
awk '
  function hex(s,   i, c, v) { v = 0; s = tolower(substr(s, 3)); for (i = 1; i <= length(s); i++) { c = index("0123456789abcdef", substr(s, i, 1)) - 1; v = v * 16 + c } return v }
  /^Linker script and memory map/ {on = 1; next}
  !on {next}
  /^ \.(text|rodata)/ {
    if (NF >= 4) { sz = $3; f = $4 } else { getline; sz = $2; f = $3 }
    if (f == "" || sz !~ /^0x/) next
    n = hex(sz)
    if (f ~ /libgravscale_core\.a\(/) { sub(/.*\(/, "", f); sub(/\.c\.obj\)/, "", f); k = "core " f }
    else if (f ~ /libm\.a/) k = "libm (double/float maths)"
    else if (f ~ /libgcc\.a/) k = "libgcc (soft double, 64-bit division)"
    else if (f ~ /libc_nano\.a/) k = "libc nano (memset/memcpy)"
    else if (f ~ /fw_main|fw_scenario/) k = "fw_main + fw_scenario (app, start-up)"
    else k = "other " f
    tot[k] += n
  }
  END { for (k in tot) printf "%7d  %s\n", tot[k], k }' "$map" | sort -k2 > "$bdir/origin.txt" 2>/dev/null || true
if [ -s "$bdir/origin.txt" ]; then
  cat "$bdir/origin.txt"
  core=$(awk '$2 == "core" {s += $1} END {print s + 0}' "$bdir/origin.txt")
else
  core=unknown
fi
code=$((text + data))
echo "--- budgets"
echo "code (flash: text + data)      : $code B (core $core B without LTO); target <= $CODE_TARGET B"
if [ "$code" -gt "$CODE_TARGET" ]; then
  if [ "${GS_FW_STRICT:-1}" != 0 ]; then echo "FAIL code over the target"; fail=1; else echo "OVER code target (reported only: GS_FW_STRICT=0)"; fi
else
  echo "ok   code within target"
fi
# RAM: the ring, the rest of the core's state, and what the app adds
sym_size() { arm-none-eabi-nm -S -t d "$elf" | awk -v s="$1" '$4 == s {print $2 + 0}'; }
storage=$(sym_size g_storage); pipe=$(sym_size g_pipe); cfg=$(sym_size g_cfg); cfg=${cfg:-0}; line=$(( $(sym_size g_line) + $(sym_size g_last) ))
ring=$((RING_SAMPLES * 16))
state=$((pipe + storage - ring))
echo "ram  ring ($RING_SAMPLES x 16 B)       : $ring B"
echo "ram  state (gs_pipeline $pipe B + inlier bits $((storage - ring)) B): $state B; budget <= $STATE_BUDGET B"
echo "ram  app (line buffers $line B, parsed profile $cfg B: none when baked), .data+.bss total $((data + bss)) B incl. the stack reserve"
if [ "$state" -gt "$STATE_BUDGET" ] || [ "$storage" -lt "$ring" ]; then
  echo "FAIL state over budget"; fail=1
else
  echo "ok   state within budget"
fi
# deepest stack frames of the core (-fstack-usage), for the stack reserve
su=$(find "$nbdir/CMakeFiles/gravscale_core.dir" -name '*.su' 2>/dev/null | head -1)
if [ -n "$su" ]; then
  echo "--- largest core stack frames (bytes, without LTO)"
  find "$nbdir/CMakeFiles/gravscale_core.dir" -name '*.su' -exec cat {} + | sort -t'	' -k2 -n -r | head -5 |
    awk -F'\t' '{n = split($1, a, ":"); printf "%7d  %s\n", $2, a[n]}'
fi
# 3. run it: QEMU's Cortex-M4 board (netduinoplus2, STM32F405) with semihosting prints the
# lines; they must equal the same workload built for the host with the same GS_REAL,
# byte for byte (IEEE single precision on both), and match the double build's events
if command -v qemu-system-arm >/dev/null 2>&1; then
  real=${GS_FW_REAL:-float}
  qout=$bdir/fw_qemu.out
  rm -f "$qout"
  if timeout 300 qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial none \
       -chardev file,id=semi,path="$qout" -semihosting-config enable=on,target=native,chardev=semi \
       -kernel "$bdir/gravscale_fw_qemu.elf" >"$bdir/fw_qemu.err" 2>&1 && [ -s "$qout" ]; then
    # lines starting with '#' are the firmware's own report (stack high-water mark)
    stack=$(awk '/^# stack bytes/ {print $4}' "$qout")
    grep -v '^#' "$qout" >"$qout.lines" && mv "$qout.lines" "$qout"
    hcc=${CC_HOST:-cc}
    for r in "$real" double; do
      "$hcc" -std=c11 -O2 -DGS_REAL=$r $twin_defs -I"$top/include" -I"$top/tools/fw" -I"$bdir" "$top"/src/core/*.c \
        "$top/tools/fw/fw_scenario.c" "$top/tools/fw/fw_host.c" -lm -o "$bdir/fw_host_$r" &&
        "$bdir/fw_host_$r" >"$bdir/fw_host_$r.out" || { echo "FAIL host twin ($r) did not build or run"; fail=1; }
    done
    n=$(grep -c -E '"event":"jump"|^[$]GSJMP' "$qout" || true)
    if cmp -s "$qout" "$bdir/fw_host_$real.out"; then
      echo "ok   on QEMU's Cortex-M4: $n jump events, every line identical to the host build with GS_REAL=$real"
      reserve=$(awk '/_stack_size =/ {gsub(/[^0-9]/, "", $3); print $3 * 1024; exit}' "$top/tools/fw/m4.ld")
      if [ -n "$stack" ] && [ "$stack" -le "$reserve" ]; then
        echo "ok   stack high-water mark on the target: $stack B (reserve $reserve B)"
      else
        echo "FAIL stack high-water mark '$stack' B beyond the reserve $reserve B"; fail=1
      fi
    else
      echo "FAIL the Cortex-M4 lines differ from the host's (GS_REAL=$real):"; diff "$qout" "$bdir/fw_host_$real.out" | head -5; fail=1
    fi
    # against double: the same events and decisions, heights within 1 mm
    # (JSON: "height_m" and "accepted"; NMEA: $GSJMP field 6 and A/R, $GSHGT/$GSSUM field 2)
    if awk -F'"height_m":' '
         function ht(s,   x, f) {
           if (s ~ /^[$]GS(JMP|HGT|SUM)/) { split(s, f, ","); return f[s ~ /^[$]GSJMP/ ? 6 : 2] }
           if (split(s, x, "\"height_m\":") > 1) return x[2] + 0
           return "" }
         function acc(s,   f) { if (s ~ /^[$]GSJMP/) { split(s, f, ","); return f[10] == "A" } return s ~ /"accepted":true/ }
         FNR == NR {a[FNR] = $0; next}
         { if (!(FNR in a)) exit 1
           if (acc(a[FNR]) != acc($0)) exit 1
           hx = ht(a[FNR]); hy = ht($0)
           if (hx != "" && hy != "") { d = (hx + 0) - (hy + 0); if (d < 0) d = -d; if (d > m) m = d }
           n++ }
         END { if (n != NR - length(a)) exit 1; printf "ok   vs the double build: same events and decisions, heights within %.4f m\n", m; if (m > 0.001) exit 1 }' \
         "$qout" "$bdir/fw_host_double.out"; then :; else echo "FAIL float vs double beyond 1 mm or other events"; fail=1; fi
  else
    echo "FAIL the firmware did not run to its end under QEMU:"; head -5 "$bdir/fw_qemu.err"; fail=1
  fi
else
  echo "skip qemu-system-arm not installed: the firmware was linked, not run (apt-get install --no-install-recommends qemu-system-arm)"
fi
if [ $fail -ne 0 ]; then echo "firmware_size: FAILED"; exit 1; fi
echo "firmware_size: ok"
