/* gs_inline.h - NOINLINE for the core's small helpers called from several places. */
#ifndef GS_INLINE_H
#define GS_INLINE_H

/* one copy is smaller than inlining it everywhere where the build optimises for size
 * (the firmware); elsewhere the compiler inlines what pays */
#ifdef __OPTIMIZE_SIZE__
#define NOINLINE __attribute__((noinline))
#else
#define NOINLINE
#endif

#endif
