#include "worker_pool.h"

#include <cstdlib>

namespace emoface::render::detail {

WorkerPool& shared_worker_pool() {
    static WorkerPool pool([] {
        const char* env = std::getenv("EMOFACE_THREADS");
        return env ? std::atoi(env) : 0;
    }());
    return pool;
}

}  // namespace emoface::render::detail
