#pragma once
// Per-query statistics. Queries take a Stats type as a template parameter: NoStats compiles to
// nothing, TraversalStats counts. nodes_visited counts node boxes tested, primitives_tested
// primitive tests.
#include <cstdint>

namespace bvhkit {

struct NoStats {
    static constexpr void node() {}
    static constexpr void primitive() {}
};

struct TraversalStats {
    std::uint64_t nodes_visited = 0;
    std::uint64_t primitives_tested = 0;
    void node() { ++nodes_visited; }
    void primitive() { ++primitives_tested; }
};

}  // namespace bvhkit
