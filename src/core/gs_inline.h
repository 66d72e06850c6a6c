/* gs_inline.h - NOINLINE for the core's small helpers called from several places, and
 * ALWAYS_INLINE for the few that the size build would otherwise keep as calls. */
#ifndef GS_INLINE_H
#define GS_INLINE_H

/* one copy is smaller than inlining it everywhere where the build optimises for size
 * (the firmware); elsewhere the compiler inlines what pays */
#ifdef __OPTIMIZE_SIZE__
#define NOINLINE __attribute__((noinline))
#else
#define NOINLINE
#endif

/* the size build's outlining heuristics keep some tiny helpers as calls, though inline
 * they are smaller; elsewhere the compiler inlines them anyway */
#ifdef __OPTIMIZE_SIZE__
#define ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define ALWAYS_INLINE inline
#endif

#endif
