// cpu_avx2.hpp - whether this x86-64 CPU runs AVX2, asked once per process:
// the vision code's AVX2 loops and their plain fallbacks choose by it.
#pragma once

namespace gs {

#if defined(__x86_64__) && defined(__GNUC__)
inline bool have_avx2()
{
    static const bool yes = __builtin_cpu_supports("avx2");
    return yes;
}
#endif

}  // namespace gs
