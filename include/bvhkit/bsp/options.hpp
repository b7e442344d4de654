#pragma once
// BspOptions: how a BSP tree chooses its splitters and when it stops.
#include <cmath>
#include <cstdint>
#include <string>

#include "bvhkit/error.hpp"

namespace bvhkit {

/// Which planes a node considers as its splitter.
enum class BspCandidates : std::uint8_t {
    PolygonPlanes,  // the planes of the node's polygons (auto-partition): the classic BSP
    AxisAligned,  // planes x, y or z = a polygon centroid's coordinate; polygon planes as fallback
    Both,         // both sets, the better score wins
};

struct BspOptions {
    /// Score of a candidate: split_weight * spanning + (1 - split_weight) * |front - back|
    /// (the lowest wins). 1 minimizes splits only, 0 balance only. In [0, 1].
    double split_weight = 0.8;
    /// A node with at most leaf_size polygons becomes a leaf holding them. 0: partition until every
    /// polygon lies in a splitter plane (needed for the solid BSP of classify_point).
    std::uint32_t leaf_size = 0;
    /// A node at this depth becomes a leaf holding what reached it (the root has depth 0). An
    /// auto-partition of a convex mesh is a chain as deep as the mesh has triangles, so the default
    /// is high enough not to cut a solid build short on the meshes one builds a BSP of.
    std::uint32_t max_depth = 1u << 16;
    /// A node with more polygons than this considers only this many candidates, taken at an even
    /// stride through its list (deterministic); smaller nodes consider every polygon's plane.
    std::uint32_t candidate_count = 32;
    /// A candidate is scored on at most this many of the node's polygons (an even stride through
    /// the list): without it a convex mesh, whose auto-partition is a chain, would cost
    /// candidate_count * n^2 / 2 classifications. The split itself always classifies every one.
    std::uint32_t count_sample = 512;
    BspCandidates candidates = BspCandidates::PolygonPlanes;
    /// Thickness of a plane, relative to the input's bounding-box diagonal: vertices within
    /// epsilon * diagonal of a plane count as on it. 0 takes the scalar's default (1e-10 for
    /// double, 1e-5 for float). Triangles whose greatest height is at most this are dropped as
    /// degenerate.
    double epsilon = 0;

    /// Throws bvhkit::Error naming the first bad option.
    void validate() const {
        if (!(split_weight >= 0.0 && split_weight <= 1.0))
            throw Error("BspOptions: split_weight must lie in [0, 1], got " +
                        std::to_string(split_weight));
        if (max_depth > (1u << 24))
            throw Error("BspOptions: max_depth must be at most 2^24, got " +
                        std::to_string(max_depth));
        if (candidate_count < 1) throw Error("BspOptions: candidate_count must be at least 1");
        if (count_sample < 1) throw Error("BspOptions: count_sample must be at least 1");
        if (!(epsilon >= 0.0 && epsilon < 0.01))
            throw Error("BspOptions: epsilon must lie in [0, 0.01), got " +
                        std::to_string(epsilon));
        if (candidates != BspCandidates::PolygonPlanes &&
            candidates != BspCandidates::AxisAligned && candidates != BspCandidates::Both)
            throw Error("BspOptions: unknown candidates value");
    }
};

}  // namespace bvhkit
