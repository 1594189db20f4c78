#pragma once
// One thread pool for the process, and parallel_for over it. Every loop that
// is split over threads (the morph's rows, tangent frames, wrinkle-map rows,
// the key maps of a session) shares these workers, so the process never runs
// more threads than cores and no loop pays a thread start per call.
//
//   emoface::parallel_for(rows, 1, [&](int begin, int end) { ... });
//
// fn(begin, end) is called over [0, count) in chunks of `chunk` indices, on
// the pool's workers and on the calling thread, and parallel_for returns when
// every chunk is done. Which thread runs which chunk varies from call to call:
// a result must not depend on it. The first exception a chunk throws stops
// the handing out of further chunks and is rethrown to the caller once the
// chunks already started have finished.
//
// A parallel_for called from inside a chunk (nested) runs inline on that
// thread: the pool's threads are already busy with the outer loop. Calls from
// several threads take turns.
#include <type_traits>

namespace emoface {

// The pool's thread count including the calling thread: one per hardware
// thread, or EMOFACE_THREADS=n (read when the pool starts, at first use).
int parallel_threads();

namespace detail {
using ParallelBody = void (*)(const void* context, int begin, int end);
void run_parallel(int count, int chunk, ParallelBody body, const void* context);
}  // namespace detail

template <class Fn>
void parallel_for(int count, int chunk, const Fn& fn) {
    static_assert(std::is_invocable_v<const Fn&, int, int>, "parallel_for: fn(int begin, int end)");
    // The task travels as a pointer and a plain function, not a
    // std::function: a call allocates nothing.
    detail::run_parallel(
        count, chunk, [](const void* context, int begin, int end) { (*static_cast<const Fn*>(context))(begin, end); },
        &fn);
}

}  // namespace emoface
