#pragma once
// A small fixed pool for the CPU backend: parallel_for hands out [begin, end)
// chunks of an index range to the workers and the calling thread, and returns
// when all are done. No allocation per call (the task is passed by reference,
// not wrapped in std::function).
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace emoface::morph::detail {

class ThreadPool {
public:
    // threads <= 0: one per hardware thread.
    explicit ThreadPool(int threads = 0) {
        int n = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
        if (n < 1) n = 1;
        size_ = n;
        for (int i = 1; i < n; ++i) workers_.emplace_back([this] { work(); });
    }
    ~ThreadPool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : workers_) t.join();
    }
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return size_; }

    // Calls fn(begin, end) over [0, count) in chunks of `chunk`.
    template <class Fn>
    void parallel_for(int count, int chunk, const Fn& fn) {
        if (count <= 0) return;
        chunk = std::max(chunk, 1);
        if (workers_.empty() || count <= chunk) {
            fn(0, count);
            return;
        }
        std::lock_guard<std::mutex> one_job_at_a_time(job_mutex_);
        Job job;
        job.count = count;
        job.chunk = chunk;
        job.context = &fn;
        job.call = [](const void* context, int begin, int end) {
            (*static_cast<const Fn*>(context))(begin, end);
        };
        {
            std::lock_guard<std::mutex> lock(mutex_);
            job_ = &job;
            ++generation_;
        }
        wake_.notify_all();
        run(job);
        std::unique_lock<std::mutex> lock(mutex_);
        done_.wait(lock, [&] { return job.busy_workers == 0 && job.next.load() >= job.count; });
        job_ = nullptr;
    }

private:
    struct Job {
        int count = 0;
        int chunk = 1;
        const void* context = nullptr;
        void (*call)(const void*, int, int) = nullptr;
        std::atomic<int> next{0};
        int busy_workers = 0;  // guarded by mutex_
    };

    static void run(Job& job) {
        for (;;) {
            const int begin = job.next.fetch_add(job.chunk);
            if (begin >= job.count) return;
            job.call(job.context, begin, std::min(begin + job.chunk, job.count));
        }
    }

    void work() {
        std::uint64_t seen = 0;
        for (;;) {
            Job* job = nullptr;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return stop_ || (generation_ != seen && job_ != nullptr); });
                if (stop_) return;
                seen = generation_;
                job = job_;
                ++job->busy_workers;
            }
            run(*job);
            {
                std::lock_guard<std::mutex> lock(mutex_);
                --job->busy_workers;
            }
            done_.notify_all();
        }
    }

    int size_ = 1;
    std::vector<std::thread> workers_;
    std::mutex job_mutex_;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable done_;
    Job* job_ = nullptr;
    std::uint64_t generation_ = 0;
    bool stop_ = false;
};

}  // namespace emoface::morph::detail
