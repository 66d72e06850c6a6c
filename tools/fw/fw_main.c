/* fw_main.c - firmware link test of the core on a Cortex-M4F: start-up code and
 * the workload of fw_scenario.c (the ball, or the skeleton when g_use_pose is
 * set, so both input paths are linked). Lines go to a buffer as a serial sink
 * would send them; built with FW_SEMIHOST they are also written to the
 * debugger's console (QEMU -semihosting) and the program exits with the
 * scenario's status. tools/firmware_size.sh checks the symbols and sizes. */
#include <stdint.h>
#include <string.h>

#include "fw_scenario.h"

/* what a serial sink would send: the last line and a count */
static char g_last[700];
volatile uint32_t g_line_len;
volatile uint32_t g_n_lines;
volatile uint32_t g_status;
/* set by a debugger to drive the keypoint path */
volatile uint32_t g_use_pose;

extern uint32_t _sstack_reserve, _estack;

#ifdef FW_SEMIHOST
/* ARM semihosting: r0 = operation, r1 = argument, BKPT 0xAB */
static uint32_t semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}
#endif

static void on_line(const char *line, size_t len)
{
    size_t n = len < sizeof g_last - 1u ? len : sizeof g_last - 1u;
    memcpy(g_last, line, n);
    g_last[n] = '\0';
    g_line_len = (uint32_t)n;
    g_n_lines++;
#ifdef FW_SEMIHOST
    semihost(0x04u, g_last);  /* SYS_WRITE0 */
#endif
}

int main(void)
{
#ifndef FW_SEMIHOST
    g_status = fw_scenario_run(g_use_pose != 0u, on_line);
#else
    /* both paths when run under a debugger: the ball, then the skeleton */
    g_status = fw_scenario_run_both(on_line);
    {
        /* stack high-water mark: the reset handler painted the reserve */
        const uint32_t *p = &_sstack_reserve;
        while (p < &_estack && *p == 0xA5A5A5A5u) p++;
        uint32_t used = (uint32_t)((uintptr_t)&_estack - (uintptr_t)p);
        char msg[32] = "# stack bytes ";
        char *d = msg + 14, tmp[12];
        int n = 0;
        do { tmp[n++] = (char)('0' + used % 10u); used /= 10u; } while (used > 0u);
        while (n > 0) *d++ = tmp[--n];
        *d++ = '\n';
        *d = '\0';
        semihost(0x04u, msg);
    }
    /* SYS_EXIT with ADP_Stopped_ApplicationExit: QEMU exits */
    semihost(0x18u, (const void *)(uintptr_t)0x20026u);
#endif
    for (;;) {
    }
}

/* ---- start-up: vectors, .data/.bss, the FPU ----------------------------------- */

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss;
void Reset_Handler(void);
void Default_Handler(void);

void Default_Handler(void)
{
    for (;;) {
    }
}

void Reset_Handler(void)
{
    uint32_t *src = &_sidata, *dst = &_sdata;
    while (dst < &_edata) *dst++ = *src++;
    for (dst = &_sbss; dst < &_ebss;) *dst++ = 0u;
#ifdef FW_SEMIHOST
    /* paint the stack reserve below the current frame (main reports the high-water mark) */
    for (dst = &_sstack_reserve; (uintptr_t)dst < (uintptr_t)__builtin_frame_address(0) - 64u;) *dst++ = 0xA5A5A5A5u;
#endif
    /* CP10/CP11 full access: hard-float code faults without it */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm volatile("dsb\n isb" ::: "memory");
    (void)main();
    Default_Handler();
}

/* initial stack pointer, reset, then NMI .. SysTick on the default handler */
__attribute__((section(".isr_vector"), used)) static void (*const k_vectors[16])(void) = {
    (void (*)(void))(&_estack), Reset_Handler,
    Default_Handler, Default_Handler, Default_Handler, Default_Handler, Default_Handler,
    0, 0, 0, 0,
    Default_Handler, Default_Handler, 0, Default_Handler, Default_Handler,
};

/* ---- memcpy, memset: byte loops ------------------------------------------------- */
/* newlib nano's word-at-a-time copies cost 470 B of flash; the core copies small structs
 * and line buffers, where a byte loop is fast enough. Kept out of the loop-to-call pattern
 * (it would call itself) and marked used: LTO emits calls to them late. */
#define FW_MEM_FN __attribute__((used, noinline, optimize("no-tree-loop-distribute-patterns")))
FW_MEM_FN void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    unsigned char *d = dst;
    const unsigned char *s = src;
    while (n--) *d++ = *s++;
    return dst;
}

FW_MEM_FN void *memset(void *dst, int c, size_t n)
{
    unsigned char *d = dst;
    while (n--) *d++ = (unsigned char)c;
    return dst;
}
