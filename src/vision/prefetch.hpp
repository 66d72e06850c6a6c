// prefetch.hpp - a bounded queue filled ahead by a worker thread, for the
// frame loop of `gravscale video`: decoding (and the pose networks) of the
// next frames overlap with the work the caller does on the current one.
//
// Prefetch<T> runs produce(T &) on its own thread, again and again, until it
// returns false (the end) or throws; next(T &) hands the items out in the
// order they were produced, waiting when the queue is empty, and the worker
// waits when `depth` items are queued. Every stage still sees its items one
// after another and in order, so a chain of prefetchers gives the same
// results as one loop doing everything in turn: only the overlap changes.
// An exception thrown by produce is rethrown by next() once the items before
// it are handed out. The destructor stops and joins the worker (produce is
// not interrupted: the item it is making is dropped). Whatever produce
// touches must be left alone by other threads until next() returned false or
// the prefetcher is destroyed.
#ifndef GS_PREFETCH_HPP
#define GS_PREFETCH_HPP

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace gs {

template <class T>
class Prefetch {
public:
    using Produce = std::function<bool(T &)>;

    Prefetch(Produce produce, size_t depth) : produce_(std::move(produce)), depth_(depth ? depth : 1)
    {
        worker_ = std::thread([this] { run(); });
    }
    ~Prefetch()
    {
        {
            std::lock_guard<std::mutex> lk(m_);
            stop_ = true;
        }
        cv_.notify_all();
        if (worker_.joinable()) worker_.join();
    }
    Prefetch(const Prefetch &) = delete;
    Prefetch &operator=(const Prefetch &) = delete;

    // The next item; false at the end (the worker has finished by then).
    bool next(T &out)
    {
        std::unique_lock<std::mutex> lk(m_);
        cv_.wait(lk, [this] { return !q_.empty() || done_; });
        if (q_.empty()) {
            lk.unlock();
            if (worker_.joinable()) worker_.join();
            if (error_) {
                std::exception_ptr e = error_;
                error_ = nullptr;
                std::rethrow_exception(e);
            }
            return false;
        }
        out = std::move(q_.front());
        q_.pop_front();
        lk.unlock();
        cv_.notify_all();
        return true;
    }

private:
    void run()
    {
        for (;;) {
            {
                std::unique_lock<std::mutex> lk(m_);
                cv_.wait(lk, [this] { return q_.size() < depth_ || stop_; });
                if (stop_) break;
            }
            T item;
            bool more = false;
            try {
                more = produce_(item);
            } catch (...) {
                std::lock_guard<std::mutex> lk(m_);
                error_ = std::current_exception();
            }
            std::lock_guard<std::mutex> lk(m_);
            if (!more || stop_) break;
            q_.push_back(std::move(item));
            cv_.notify_all();
        }
        std::lock_guard<std::mutex> lk(m_);
        done_ = true;
        cv_.notify_all();
    }

    Produce produce_;
    size_t depth_;
    std::mutex m_;
    std::condition_variable cv_;
    std::deque<T> q_;
    bool done_ = false, stop_ = false;
    std::exception_ptr error_;
    std::thread worker_;
};

}  // namespace gs

#endif
