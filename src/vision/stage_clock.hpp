// stage_clock.hpp - where the time of a frame loop goes: per stage, the wall
// time spent in it and the CPU time of the thread that ran it (OpenCV's and
// FFmpeg's helper threads not included: with one OpenCV thread the stage's
// own CPU time is all of it except the decoder's threads). Each StageClock is
// used by one thread at a time; read it after that thread is done.
#ifndef GS_STAGE_CLOCK_HPP
#define GS_STAGE_CLOCK_HPP

#include <time.h>

#include <chrono>
#include <cstdint>

namespace gs {

inline double wall_ms_now()
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline double thread_cpu_ms_now()
{
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

inline double process_cpu_ms_now()
{
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct StageClock {
    double wall_ms = 0.0, cpu_ms = 0.0;
    int64_t calls = 0;

    // times the scope it lives in into the clock
    class Scope {
    public:
        explicit Scope(StageClock &c) : c_(c), w0_(wall_ms_now()), c0_(thread_cpu_ms_now()) {}
        ~Scope()
        {
            c_.wall_ms += wall_ms_now() - w0_;
            c_.cpu_ms += thread_cpu_ms_now() - c0_;
            c_.calls++;
        }
        Scope(const Scope &) = delete;
        Scope &operator=(const Scope &) = delete;

    private:
        StageClock &c_;
        double w0_, c0_;
    };
};

}  // namespace gs

#endif
