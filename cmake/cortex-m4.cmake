# cortex-m4.cmake - cross toolchain for the core on a Cortex-M4F with Debian's
# gcc-arm-none-eabi and newlib nano (libnewlib-arm-none-eabi). Used by the
# `cortex-m4` preset (CMakePresets.json) and tools/firmware_size.sh.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
# a bare-metal compiler cannot link a test program without startup code
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(GS_M4_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
# Size: -Os still runs a few passes that cost bytes here; these turn them off. Together
# -1,096 B with LTO for camera-coco17 (-1,152 B all, -704 B ball-lab); each one's share
# (camera / all, put back alone): tree-fre 392/448, reorder-blocks 256/256,
# tree-dominator-opts 192/192, thread-jumps 192/192, inline-small-functions 128/320,
# if-conversion 128/128, schedule-insns2 128/128, ipa-strict-aliasing 64/64. None
# changes a value: they order, duplicate or merge code, never the arithmetic
# (contraction stays off with -std=c11), so QEMU's lines stay identical to the host's.
# A build directory configured before a change here keeps its cached flags: configure
# it afresh.
# A second set, measured on camera-blazepose33 with LTO (each alone; together -520 B):
# move-loop-invariants 136, ssa-phiopt 104, caller-saves 60, tree-loop-im 60,
# tree-loop-distribute-patterns 48, tree-loop-ivcanon 40, tree-ter 40, tree-phiprop 16,
# forward-propagate 16, expensive-optimizations 12, optimize-sibling-calls 12, ipa-sra 8.
# The same holds: code placement, register use and loop shape, no arithmetic changed.
# A third pair (camera-blazepose33 / camera-coco17 / ball-lab / all, with LTO; together
# -120/-120/-64/-120 B): max-completely-peeled-insns=0 88/92/40/56 (short fixed loops stay
# loops), tree-tail-merge 36/32/24/64 (merging equal block tails adds branches here).
# -fmerge-all-constants: equal read-only objects share one copy (the workload's baked
# profile and the core's, 76 B); nothing here compares two constants' addresses.
set(GS_M4_SIZE_FLAGS "-fno-reorder-blocks -fno-tree-fre -fno-if-conversion -fno-schedule-insns2 \
-fno-thread-jumps -fno-tree-dominator-opts -fno-inline-small-functions -fno-ipa-strict-aliasing \
-fno-move-loop-invariants -fno-ssa-phiopt -fno-caller-saves -fno-tree-loop-im \
-fno-tree-loop-distribute-patterns -fno-tree-loop-ivcanon -fno-tree-ter -fno-tree-phiprop \
-fno-forward-propagate -fno-expensive-optimizations -fno-optimize-sibling-calls -fno-ipa-sra \
-fno-tree-tail-merge --param=max-completely-peeled-insns=0 -fmerge-all-constants")
# -fno-math-errno: sqrtf is then the VSQRT instruction (no errno call on a negative
# argument; the value, NaN, is the same). Not -ffast-math: no result changes.
set(CMAKE_C_FLAGS_INIT "${GS_M4_CPU_FLAGS} -ffunction-sections -fdata-sections -fno-math-errno ${GS_M4_SIZE_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${GS_M4_CPU_FLAGS} --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections")
# GS_FW_LTO=ON (the cortex-m4 preset, tools/firmware_size.sh): link-time optimisation
# across the core's files (inlining, dead code), measured in docs/firmware.md. Fat
# objects keep the archive readable by nm and -fstack-usage's per-file frames.
if(GS_FW_LTO)
  string(APPEND CMAKE_C_FLAGS_INIT " -flto -ffat-lto-objects")
  string(APPEND CMAKE_EXE_LINKER_FLAGS_INIT " -flto -Os ${GS_M4_SIZE_FLAGS}")
  set(CMAKE_AR arm-none-eabi-gcc-ar)
  set(CMAKE_RANLIB arm-none-eabi-gcc-ranlib)
endif()

# libm by name: the driver picks the multilib for the flags above (a found path
# would be the wrong, soft-float one)
set(GS_LIBM m CACHE STRING "libm for the target")

# look for libraries and headers in the target's tree only, programs on the host
set(CMAKE_FIND_ROOT_PATH /usr/lib/arm-none-eabi)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
