#pragma once
// What bvhkit knows of the machine's threads: whether the library was built with oneTBB
// (BVHKIT_HAVE_TBB) and how many threads it may use. The Executor (exec/executor.hpp) is the one
// place that runs anything on them; this header stays free of it so that a caller can ask
// "parallel at all?" without the executor's oneTBB includes.
//
// Headers of exec/ include only the standard library, oneTBB (when built with it) and
// bvhkit/error.hpp, so that build/, bvh/ and query/ can all use them.
#include <algorithm>

#if defined(BVHKIT_HAVE_TBB)
#include <tbb/info.h>
#endif

namespace bvhkit {

/// True when an Executor really runs in parallel (the library was built with oneTBB).
constexpr bool have_parallel() {
#if defined(BVHKIT_HAVE_TBB)
    return true;
#else
    return false;
#endif
}

/// The most threads an Executor is given: the hardware's concurrency (at least 1).
inline unsigned hardware_threads() {
#if defined(BVHKIT_HAVE_TBB)
    static const unsigned n = static_cast<unsigned>(std::max(1, tbb::info::default_concurrency()));
    return n;
#else
    return 1;
#endif
}

}  // namespace bvhkit
