// side_thread.hpp - one job at a time on a thread of its own, started with the
// first job and kept for the next ones: the pose tracker's census runs the
// detector there beside the tracked ROI's landmarks (each network has its own
// request and buffers), so a census frame takes the network thread the longer
// of the two calls instead of both.
#ifndef GS_SIDE_THREAD_HPP
#define GS_SIDE_THREAD_HPP

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace gs {

// start(job) runs job on the thread; finish() waits for it and gives what it threw.
class SideThread {
public:
    ~SideThread()
    {
        {
            std::lock_guard<std::mutex> lk(m_);
            stop_ = true;
        }
        cv_.notify_all();
        if (t_.joinable()) t_.join();
    }
    void start(std::function<void()> job)
    {
        std::lock_guard<std::mutex> lk(m_);
        if (!t_.joinable()) t_ = std::thread([this] { run(); });
        job_ = std::move(job);
        busy_ = true;
        cv_.notify_all();
    }
    std::exception_ptr finish()
    {
        std::unique_lock<std::mutex> lk(m_);
        cv_.wait(lk, [this] { return !busy_; });
        std::exception_ptr e = error_;
        error_ = nullptr;
        return e;
    }

private:
    void run()
    {
        std::unique_lock<std::mutex> lk(m_);
        for (;;) {
            cv_.wait(lk, [this] { return job_ || stop_; });
            if (stop_) return;
            std::function<void()> job = std::move(job_);
            job_ = nullptr;
            lk.unlock();
            std::exception_ptr e;
            try {
                job();
            } catch (...) {
                e = std::current_exception();
            }
            lk.lock();
            error_ = e;
            busy_ = false;
            cv_.notify_all();
        }
    }
    std::mutex m_;
    std::condition_variable cv_;
    std::function<void()> job_;
    bool busy_ = false, stop_ = false;
    std::exception_ptr error_;
    std::thread t_;
};

// Waits for a side job when it leaves scope (also when the landmarks throw: the
// job reads the frame); rethrow() gives the job's own exception.
class SideJob {
public:
    explicit SideJob(SideThread &t) : t_(t) {}
    ~SideJob()
    {
        if (!done_) t_.finish();
    }
    void rethrow()
    {
        done_ = true;
        if (std::exception_ptr e = t_.finish()) std::rethrow_exception(e);
    }

private:
    SideThread &t_;
    bool done_ = false;
};

}  // namespace gs

#endif
