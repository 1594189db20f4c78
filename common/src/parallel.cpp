// The process's thread pool behind emoface::parallel_for (parallel.h).
#include "emoface/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace emoface {
namespace {

// True on the pool's workers, and on a caller while it runs chunks itself: a
// parallel_for from there runs inline (the pool is busy with the outer one).
thread_local bool t_inside_chunk = false;

class Pool {
public:
    explicit Pool(int threads) {
        for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
    }
    ~Pool() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : workers_) t.join();
    }
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    int threads() const { return static_cast<int>(workers_.size()) + 1; }

    void run(int count, int chunk, detail::ParallelBody body, const void* context) {
        if (count <= 0) return;
        chunk = std::max(chunk, 1);
        if (t_inside_chunk || workers_.empty() || count <= chunk) {
            body(context, 0, count);
            return;
        }
        std::lock_guard<std::mutex> one_job_at_a_time(job_mutex_);
        Job job;
        job.count = count;
        job.chunk = chunk;
        job.body = body;
        job.context = context;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            job_ = &job;
            ++generation_;
        }
        wake_.notify_all();
        t_inside_chunk = true;
        run_chunks(job);
        t_inside_chunk = false;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            done_.wait(lock, [&] { return job.busy_workers == 0; });
            job_ = nullptr;
        }
        if (job.error) std::rethrow_exception(job.error);
    }

private:
    struct Job {
        int count = 0;
        int chunk = 1;
        detail::ParallelBody body = nullptr;
        const void* context = nullptr;
        // 64 bits: every thread overshoots count by up to one chunk.
        std::atomic<std::int64_t> next{0};
        std::atomic<bool> failed{false};
        std::exception_ptr error;  // the first one; written once, under failed
        int busy_workers = 0;      // guarded by mutex_
    };

    static void run_chunks(Job& job) {
        while (!job.failed.load(std::memory_order_relaxed)) {
            const std::int64_t begin = job.next.fetch_add(job.chunk);
            if (begin >= job.count) return;
            const int end = static_cast<int>(std::min<std::int64_t>(begin + job.chunk, job.count));
            try {
                job.body(job.context, static_cast<int>(begin), end);
            } catch (...) {
                if (!job.failed.exchange(true)) job.error = std::current_exception();
            }
        }
    }

    void work() {
        t_inside_chunk = true;
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
            run_chunks(*job);
            {
                std::lock_guard<std::mutex> lock(mutex_);
                --job->busy_workers;
            }
            done_.notify_all();
        }
    }

    std::vector<std::thread> workers_;
    std::mutex job_mutex_;
    std::mutex mutex_;  // guards job_, generation_, stop_ and Job::busy_workers
    std::condition_variable wake_;
    std::condition_variable done_;
    Job* job_ = nullptr;
    std::uint64_t generation_ = 0;
    bool stop_ = false;
};

int configured_threads() {
    if (const char* v = std::getenv("EMOFACE_THREADS")) {
        const int n = std::atoi(v);
        if (n >= 1 && n <= 1024) return n;
    }
    return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

Pool& pool() {
    static Pool instance(configured_threads());
    return instance;
}

}  // namespace

int parallel_threads() { return pool().threads(); }

namespace detail {
void run_parallel(int count, int chunk, ParallelBody body, const void* context) {
    pool().run(count, chunk, body, context);
}
}  // namespace detail

}  // namespace emoface
