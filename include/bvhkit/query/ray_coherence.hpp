#pragma once
// Whether a run of rays is coherent enough to walk as one packet (query/ray_octant_stream.hpp):
// the test by which trace batches choose the packet walk for a run, without being told. A packet
// pays when its rays meet mostly the same boxes: then a node's loads, its push and its pop serve
// all of them. Rays that share a direction octant, with close directions and origins (camera
// rays of a row or a tile; shadow rays from nearby points towards one light) do; random rays do
// not, and go as before. The test reads six rays of a run (its ends, its quarters and its
// middle: the corners of an 8x4 tile, the ends of a row), since reading all of them cost a
// tenth of a camera ray's walk. Every path gives the same answers, so a run misjudged here
// costs time, never an answer.
#include <cmath>
#include <cstddef>
#include <span>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// Whether the sampled rays of `rays` (a run of a batch) share a direction octant (by sign bit,
/// -0 negative as the walks read it), their unit directions lie in a box
/// tuning::packet_direction_spread wide on each axis, and their origins in a box
/// tuning::packet_origin_spread of `bounds`' largest extent. False for an empty run, or one with
/// a sampled ray whose origin or direction is not finite or whose direction is zero.
inline bool coherent_rays(std::span<const Ray<float, 3>> rays, const Aabb<float, 3>& bounds) {
    if (rays.empty()) return false;
    float dlo[3], dhi[3], olo[3], ohi[3];
    bool sign[3];
    constexpr int samples = 6;
    for (int i = 0; i < samples; ++i) {
        const Ray<float, 3>& r = rays[(rays.size() - 1) * std::size_t(i) / (samples - 1)];
        const float length =
            std::sqrt(r.direction[0] * r.direction[0] + r.direction[1] * r.direction[1] +
                      r.direction[2] * r.direction[2]);
        if (!(length > 0.0f) || !std::isfinite(length)) return false;
        const float inverse = 1.0f / length;
        for (int a = 0; a < 3; ++a) {
            const float d = r.direction[a] * inverse, o = r.origin[a];
            if (!std::isfinite(o)) return false;
            if (i == 0) {
                sign[a] = std::signbit(r.direction[a]);
                dlo[a] = dhi[a] = d;
                olo[a] = ohi[a] = o;
                continue;
            }
            if (std::signbit(r.direction[a]) != sign[a]) return false;
            dlo[a] = std::fmin(dlo[a], d);
            dhi[a] = std::fmax(dhi[a], d);
            olo[a] = std::fmin(olo[a], o);
            ohi[a] = std::fmax(ohi[a], o);
        }
    }
    float extent = 0.0f;
    for (int a = 0; a < 3; ++a) extent = std::fmax(extent, bounds.max[a] - bounds.min[a]);
    const float origin_limit = tuning::packet_origin_spread * extent;
    for (int a = 0; a < 3; ++a)
        if (!(dhi[a] - dlo[a] <= tuning::packet_direction_spread) ||
            !(ohi[a] - olo[a] <= origin_limit))
            return false;
    return true;
}

}  // namespace bvhkit
