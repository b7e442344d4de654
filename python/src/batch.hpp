#pragma once
// run_batch: a batch of independent items spread over the extension's thread pool (batch.cpp).
//
// The calling thread starts the batch alone and calls in the pool's workers only when the batch
// is still running after batch_spin_up (checked after chunk 1, 2, 4, 8, ...: the cost of reading
// the clock stays logarithmic in the chunk count). A small batch therefore runs as it would with
// threads=1 and never pays for waking threads, while a long one is spread over all of them.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>

namespace bvhkit::python {

/// The number of threads a batch of `chunks` chunks may use: `threads` (0 = every core), at most
/// one per chunk.
inline unsigned batch_threads(unsigned threads, std::size_t chunks) {
    // Read once: glibc answers hardware_concurrency() by reading sysfs files, which would cost a
    // one-item call more than its query.
    static const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    // Threads beyond any real machine's core count only add cost; the pool keeps them for good.
    const unsigned want = threads == 0 ? cores : std::min(threads, 1024u);
    return unsigned(std::min<std::size_t>(want, std::max<std::size_t>(chunks, 1)));
}

/// How long a batch runs on the calling thread alone before it asks the pool for help: about the
/// cost of waking the workers, so that asking costs a small batch little. The clock is read only
/// between chunks, so the first chunk always runs alone: a batch of a few long items (a handful
/// of expensive distance poses on many cores) can finish up to one item later than if every
/// thread had started at once.
inline constexpr std::chrono::microseconds batch_spin_up{50};

/// One batch's shared state: the next chunk to hand out and the first exception thrown.
struct BatchState {
    std::atomic<std::size_t> next{0};
    std::size_t chunks = 0;
    std::exception_ptr error;
    std::mutex error_mutex;
};

/// Calls work(context) on the calling thread and on up to `helpers` pool workers at once, and
/// returns when every one of those calls has returned. When another batch holds the pool (a
/// second Python thread, or a batch started from inside a batch) the calling thread runs it alone:
/// batches never wait for each other, so none can deadlock on the pool.
void pool_help(unsigned helpers, void (*work)(void*), void* context);

/// Calls body(begin, end) on consecutive chunks of `grain` items of [0, count), on up to
/// `threads` threads (0 = every core; the calling thread is one of them). Each item is handled by
/// exactly one call, so a body that writes only its own items gives the same answers for every
/// thread count. The first exception thrown by a body stops the batch and is rethrown here.
template <class Body>
void run_batch(std::size_t count, std::size_t grain, unsigned threads, Body&& body) {
    if (count == 0) return;
    grain = std::max<std::size_t>(grain, 1);
    const std::size_t chunks = (count + grain - 1) / grain;
    const unsigned n = batch_threads(threads, chunks);
    if (n <= 1) {
        body(std::size_t(0), count);
        return;
    }
    struct Context {
        BatchState state;
        std::remove_reference_t<Body>* body = nullptr;
        std::size_t count = 0, grain = 1;
        void run() {
            try {
                for (std::size_t c; (c = state.next.fetch_add(1)) < state.chunks;)
                    (*body)(c * grain, std::min(count, (c + 1) * grain));
            } catch (...) {
                const std::lock_guard<std::mutex> lock(state.error_mutex);
                if (!state.error) state.error = std::current_exception();
                state.next.store(state.chunks);
            }
        }
    } context;
    context.state.chunks = chunks;
    context.body = &body;
    context.count = count;
    context.grain = grain;
    const auto start = std::chrono::steady_clock::now();
    std::size_t done = 0;
    try {
        for (std::size_t c; (c = context.state.next.fetch_add(1)) < chunks;) {
            body(c * grain, std::min(count, (c + 1) * grain));
            ++done;
            if ((done & (done - 1)) == 0 &&
                std::chrono::steady_clock::now() - start >= batch_spin_up) {
                // Runs the rest of the batch: work() returns once every chunk is taken.
                pool_help(
                    n - 1, [](void* p) { static_cast<Context*>(p)->run(); }, &context);
                break;
            }
        }
    } catch (...) {
        context.state.next.store(chunks);  // alone so far: the exception is the batch's first
        throw;
    }
    if (context.state.error) std::rethrow_exception(context.state.error);
}

}  // namespace bvhkit::python
