// The extension's thread pool (batch.hpp): workers started on first need and parked between
// batches, so a batch costs a wake-up rather than starting and joining OS threads.
//
// One batch holds the pool at a time; a batch that finds it held runs on its calling thread
// alone. After fork() the child has none of the parent's workers (only the forking thread is
// copied) and the pool's mutexes may be held by threads that no longer exist, so the child drops
// the parent's pool without touching it (its memory is left as it is) and starts a fresh one on
// its first parallel batch.
#include <pthread.h>

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <system_error>

#include "batch.hpp"

namespace bvhkit::python {
namespace {

class Pool {
  public:
    /// False, without running anything, when another batch holds the pool.
    bool help(unsigned helpers, void (*work)(void*), void* context) {
        // A thread inside a batch may not take busy_ again (it may hold it already).
        if (inside_batch) return false;
        std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
        if (!busy.owns_lock()) return false;
        // Threads the system refuses to start (a process limit) are left out: the batch runs
        // on those it has, at worst on the calling thread alone.
        try {
            grow(helpers);
        } catch (const std::system_error&) {
        }
        helpers = std::min(helpers, workers_);
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            work_ = work;
            context_ = context;
            openings_ = helpers;
        }
        if (helpers == 1)
            wake_.notify_one();
        else
            wake_.notify_all();
        inside_batch = true;
        work(context);
        inside_batch = false;
        std::unique_lock<std::mutex> lock(mutex_);
        openings_ = 0;  // a worker that wakes only now finds nothing to join
        idle_.wait(lock, [&] { return running_ == 0; });
        work_ = nullptr;
        return true;
    }

  private:
    /// Starts workers until there are at least `helpers` (the caller holds busy_).
    void grow(unsigned helpers) {
        for (; workers_ < helpers; ++workers_)
            std::thread([this] { serve(); }).detach();  // parked for the life of the process
    }

    void serve() {
        inside_batch = true;  // a batch started from work() runs on this thread alone
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return openings_ > 0; });
            --openings_;
            ++running_;
            void (*work)(void*) = work_;
            void* context = context_;
            lock.unlock();
            work(context);
            lock.lock();
            if (--running_ == 0) idle_.notify_one();
        }
    }

    std::mutex busy_;   // held by the batch that has the pool
    std::mutex mutex_;  // guards the fields below
    std::condition_variable wake_, idle_;
    void (*work_)(void*) = nullptr;
    void* context_ = nullptr;
    unsigned openings_ = 0;  // workers the current batch still takes
    unsigned running_ = 0;   // workers inside work_
    unsigned workers_ = 0;   // started so far (busy_ guards it)
    static thread_local bool inside_batch;
};

thread_local bool Pool::inside_batch = false;

std::atomic<Pool*> pool{nullptr};

/// The fork child's handler: the parent's pool is not ours (see the file's comment).
void forget_pool() {
    pool.store(nullptr);
}

Pool& the_pool() {
    Pool* p = pool.load(std::memory_order_acquire);
    if (p) return *p;
    static const int registered = pthread_atfork(nullptr, nullptr, forget_pool);
    (void)registered;
    auto fresh = std::make_unique<Pool>();
    if (pool.compare_exchange_strong(p, fresh.get(), std::memory_order_acq_rel))
        return *fresh.release();  // kept for the life of the process: its workers never exit
    return *p;
}

}  // namespace

void pool_help(unsigned helpers, void (*work)(void*), void* context) {
    if (!the_pool().help(helpers, work, context)) work(context);
}

}  // namespace bvhkit::python
