#pragma once
// The flat storage of a BSP tree: nodes in one array, children by index, and each node's polygons a
// contiguous run of the tree's PolygonPool.
#include <cstddef>
#include <cstdint>

#include "bvhkit/bsp/plane.hpp"

namespace bvhkit {

/// What an empty leaf of a solid BSP is (Thibault and Naylor 1987): the cell in front of a polygon
/// plane is outside a closed, outward-facing mesh, the cell behind it inside. Unknown for a leaf
/// that holds polygons (a halted build) or lies beside an axis-aligned splitter.
enum class BspCell : std::uint8_t { Unknown, Outside, Inside };

template <class T, std::size_t N = 3>
struct BspNode {
    static constexpr std::uint32_t none = 0xFFFFFFFFu;
    Plane<T, N> plane{};                      // the splitter (interior nodes)
    std::uint32_t front = none, back = none;  // children; both none for a leaf
    std::uint32_t first = 0;                  // first polygon of this node in the tree's pool
    std::uint32_t count = 0;  // interior: polygons in the splitter plane; leaf: polygons held
    std::uint32_t front_facing = 0;  // interior: of those, the first front_facing face along normal
    BspCell cell = BspCell::Unknown;  // empty leaves only
    bool axis_aligned = false;        // interior: the splitter is an axis-aligned candidate

    bool is_leaf() const { return front == none; }
};

struct BspStatistics {
    std::size_t input_triangles = 0;
    std::size_t dropped_degenerate = 0;  // zero-area (thinner than the plane thickness) triangles
    std::size_t nodes = 0;
    std::size_t interior_nodes = 0;
    std::size_t leaves = 0;
    std::size_t empty_leaves = 0;
    std::size_t depth = 0;              // deepest node's depth, the root's being 0
    std::size_t splits = 0;             // polygons cut in two by a splitter
    std::size_t polygons = 0;           // polygons stored after splitting
    std::size_t polygons_at_nodes = 0;  // of those, lying in an interior node's splitter plane
    std::size_t polygons_in_leaves = 0;
    std::size_t vertices = 0;      // vertices stored (each polygon its own)
    std::size_t memory_bytes = 0;  // nodes, polygons, vertices and planes
    bool solid = false;  // every leaf is empty with a known cell: classify_point is defined
    double epsilon = 0;  // the plane thickness used, in the input's units
};

}  // namespace bvhkit
