#pragma once
// The one place bvhkit touches threads: parallel_for over fixed chunks, parallel_invoke of two
// calls, and with_threads (a task arena), on oneTBB when the library was built with it
// (BVHKIT_HAVE_TBB), else plain serial code. Chunks have a fixed size and each index is handled by
// exactly one call, so code that writes only its own indices gives the same result with any number
// of threads: that is the rule every parallel path here follows (and the tests check it against
// threads = 1).
//
// `threads`: 0 uses every core TBB offers (or, inside with_threads, the arena's), 1 runs serially
// on the calling thread, k limits TBB to k threads (a task arena). Code already inside with_threads
// passes 0, so nested calls stay in that arena instead of making one each. A k above the hardware's
// concurrency is clamped to it: more threads than cores only cost memory (oneTBB reserves per
// thread, and fails outright for arenas of some 2^18 threads).
#include <algorithm>
#include <cstddef>

#if defined(BVHKIT_HAVE_TBB)
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#endif

namespace bvhkit {

/// True when parallel_for really runs in parallel (the library was built with oneTBB).
constexpr bool have_parallel() {
#if defined(BVHKIT_HAVE_TBB)
    return true;
#else
    return false;
#endif
}

/// The most threads an arena is given: the hardware's concurrency (at least 1).
inline unsigned hardware_threads() {
#if defined(BVHKIT_HAVE_TBB)
    static const unsigned n = static_cast<unsigned>(std::max(1, tbb::info::default_concurrency()));
    return n;
#else
    return 1;
#endif
}

/// Calls f() in a task arena of min(`threads`, hardware_threads()) threads when that is more than
/// one, else directly. Inside, pass threads = 0 to parallel_for and parallel_invoke: they then run
/// in this arena, at most `threads` wide, without making an arena per call.
template <class F>
void with_threads(unsigned threads, F&& f) {
#if defined(BVHKIT_HAVE_TBB)
    threads = std::min(threads, hardware_threads());
    if (threads > 1) {
        tbb::task_arena arena(static_cast<int>(threads));
        arena.execute(f);
        return;
    }
#else
    (void)threads;
#endif
    f();
}

/// Calls body(begin, end) on consecutive chunks of [0, count), each of `grain` indices (the last
/// may be shorter), possibly at the same time on several threads.
template <class Body>
void parallel_for(std::size_t count, std::size_t grain, unsigned threads, Body&& body) {
    if (count == 0) return;
    grain = std::max<std::size_t>(1, grain);
#if defined(BVHKIT_HAVE_TBB)
    if (threads != 1 && count > grain) {
        const std::size_t chunks = (count + grain - 1) / grain;
        auto run = [&] {
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, chunks, 1),
                [&](const tbb::blocked_range<std::size_t>& r) {
                    for (std::size_t c = r.begin(); c != r.end(); ++c)
                        body(c * grain, std::min(count, (c + 1) * grain));
                },
                tbb::simple_partitioner());
        };
        with_threads(threads, run);
        return;
    }
#else
    (void)threads;
#endif
    for (std::size_t b = 0; b < count; b += grain) body(b, std::min(count, b + grain));
}

/// Calls f() and g(), possibly at the same time (threads != 1, with oneTBB), else f() then g().
template <class F, class G>
void parallel_invoke(unsigned threads, F&& f, G&& g) {
#if defined(BVHKIT_HAVE_TBB)
    if (threads != 1) {
        with_threads(threads, [&] { tbb::parallel_invoke(f, g); });
        return;
    }
#else
    (void)threads;
#endif
    f();
    g();
}

}  // namespace bvhkit
