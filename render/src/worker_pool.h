#pragma once
// A small persistent pool for the per-frame loops (tangent frames): workers
// are started once and woken per call, so a frame pays microseconds, not a
// thread start per worker. Internal to render/.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace emoface::render::detail {

class WorkerPool {
public:
    // `threads` including the caller; 0 = hardware threads, at most 8.
    explicit WorkerPool(int threads = 0) {
        if (threads <= 0) threads = int(std::thread::hardware_concurrency());
        threads = std::max(1, std::min(threads, 8));
        for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
    }
    ~WorkerPool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
            ++generation_;
        }
        wake_.notify_all();
        for (auto& t : workers_) t.join();
    }
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    int threads() const { return int(workers_.size()) + 1; }

    // Calls fn(chunk) for chunk in [0, chunks), spread over the threads, and
    // returns when all are done. fn must not throw. Callers on several
    // threads take turns.
    void run(int chunks, const std::function<void(int)>& fn) {
        if (chunks <= 0) return;
        std::lock_guard<std::mutex> turn(run_mutex_);
        if (workers_.empty() || chunks == 1) {
            for (int c = 0; c < chunks; ++c) fn(c);
            return;
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            fn_ = &fn;
            chunks_ = chunks;
            next_.store(0);
            pending_ = int(workers_.size());
            ++generation_;
        }
        wake_.notify_all();
        drain();
        std::unique_lock<std::mutex> lock(mutex_);
        done_.wait(lock, [this] { return pending_ == 0; });
        fn_ = nullptr;
    }

private:
    void drain() {
        for (int c; (c = next_.fetch_add(1)) < chunks_;) (*fn_)(c);
    }
    void work() {
        unsigned seen = 0;
        for (;;) {
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return generation_ != seen; });
                seen = generation_;
                if (stop_) return;
            }
            drain();
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (--pending_ == 0) done_.notify_one();
            }
        }
    }

    std::vector<std::thread> workers_;
    std::mutex run_mutex_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    const std::function<void(int)>* fn_ = nullptr;
    int chunks_ = 0;
    std::atomic<int> next_{0};
    int pending_ = 0;
    unsigned generation_ = 0;
    bool stop_ = false;
};

// The process's pool (created on first use; EMOFACE_THREADS overrides the
// thread count).
WorkerPool& shared_worker_pool();

}  // namespace emoface::render::detail
