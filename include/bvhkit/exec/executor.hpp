#pragma once
// Executor: the threads a build or a batch query may use, and the one place bvhkit runs code on
// them: parallel_for over fixed chunks, parallel_invoke of two calls, a sort, and run() (a call
// inside the executor's task arena), on oneTBB when the library was built with it, else plain
// serial code. Chunks have a fixed size and each index is handled by exactly one call, so code
// that writes only its own indices gives the same result with any number of threads: that is the
// rule every parallel path here follows (and the tests check it against one thread).
//
// Executor(0) uses every core oneTBB offers (or, called from inside another executor's arena, that
// arena's threads); Executor(1) runs serially on the calling thread; Executor(k) owns a task arena
// of min(k, hardware_threads()) threads, made once and shared by its copies, so nested calls
// (a parallel_invoke whose halves call parallel_for) stay in it instead of making one each. A k
// above the hardware's concurrency is clamped: more threads than cores only cost memory (oneTBB
// reserves per thread, and fails outright for arenas of some 2^18 threads).
//
// Pass it as `const Executor&`; copying shares the arena. Its calls are safe from many threads.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <utility>

#include "bvhkit/exec/parallel.hpp"

#if defined(BVHKIT_HAVE_TBB)
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#endif

namespace bvhkit {

namespace exec_detail {
/// The executor's task arena (with oneTBB); declared either way so an Executor has the same
/// layout whether or not a translation unit sees oneTBB.
struct Arena;
#if defined(BVHKIT_HAVE_TBB)
struct Arena {
    explicit Arena(int threads) : arena(threads) { arena.initialize(); }
    tbb::task_arena arena;
};
#endif
}  // namespace exec_detail

class Executor {
  public:
    /// Every core (0 threads asked).
    Executor() = default;
    /// `threads`: 0 = every core, 1 = serial on the calling thread, k = at most k threads.
    explicit Executor(unsigned threads) : threads_(threads) {
#if defined(BVHKIT_HAVE_TBB)
        // Not for 0 or 1: asking oneTBB the hardware's concurrency starts it up, which a serial
        // caller should not pay for.
        if (threads > 1) {
            const unsigned width = std::min(threads, hardware_threads());
            if (width > 1) arena_ = std::make_shared<exec_detail::Arena>(static_cast<int>(width));
        }
#endif
    }
    /// The calling thread only.
    static Executor serial() {
        return Executor(1u);
    }

    /// The threads asked for (0 = every core), as given.
    unsigned threads() const {
        return threads_;
    }
    /// True when this executor may run code on more than the calling thread.
    bool is_parallel() const {
        return have_parallel() && threads_ != 1;
    }

    /// Calls f() inside this executor's arena (directly when it has none, or is already in it).
    template <class F>
    void run(F&& f) const {
#if defined(BVHKIT_HAVE_TBB)
        if (arena_) {
            arena_->arena.execute(f);
            return;
        }
#endif
        f();
    }

    /// Calls body(begin, end) on consecutive chunks of [0, count), each of `grain` indices (the
    /// last may be shorter), possibly at the same time on several threads.
    template <class Body>
    void parallel_for(std::size_t count, std::size_t grain, Body&& body) const {
        if (count == 0) return;
        grain = std::max<std::size_t>(1, grain);
#if defined(BVHKIT_HAVE_TBB)
        if (threads_ != 1 && count > grain) {
            const std::size_t chunks = (count + grain - 1) / grain;
            run([&] {
                tbb::parallel_for(
                    tbb::blocked_range<std::size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t c = r.begin(); c != r.end(); ++c)
                            body(c * grain, std::min(count, (c + 1) * grain));
                    },
                    tbb::simple_partitioner());
            });
            return;
        }
#endif
        for (std::size_t b = 0; b < count; b += grain) body(b, std::min(count, b + grain));
    }

    /// Calls f() and g(), possibly at the same time, else f() then g().
    template <class F, class G>
    void parallel_invoke(F&& f, G&& g) const {
#if defined(BVHKIT_HAVE_TBB)
        if (threads_ != 1) {
            run([&] { tbb::parallel_invoke(f, g); });
            return;
        }
#endif
        f();
        g();
    }

    /// Sorts [first, last) by `less`, in parallel when `parallel_from` or more items. Only for
    /// a total order (no two items equivalent): then every sort gives the same result.
    template <class It, class Less>
    void sort_total(It first, It last, Less less, std::size_t parallel_from = 16384) const {
#if defined(BVHKIT_HAVE_TBB)
        if (threads_ != 1 && static_cast<std::size_t>(last - first) > parallel_from) {
            run([&] { tbb::parallel_sort(first, last, less); });
            return;
        }
#else
        (void)parallel_from;
#endif
        std::sort(first, last, less);
    }

  private:
    unsigned threads_ = 0;
    std::shared_ptr<exec_detail::Arena> arena_;
};

}  // namespace bvhkit
