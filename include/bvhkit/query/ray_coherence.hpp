#pragma once
// Whether a run of rays is coherent enough to walk as one packet (query/ray_octant_stream.hpp):
// the test by which trace batches choose the packet walk for a run, without being told. A packet
// pays when its rays meet mostly the same boxes: then a node's loads, its push and its pop serve
// all of them. Rays that share a direction octant, with close directions and origins (camera
// rays of a row or a tile; shadow rays from nearby points towards one light) do; random rays do
// not, and go as before. The test reads six rays of a run (its ends, its quarters and its
// middle: the corners of an 8x4 tile, the ends of a row), since it is paid on every run, coherent
// or not. Every path gives the same answers, so a run misjudged here costs time, never an answer.
#include <cmath>
#include <cstddef>
#include <span>

#include "bvhkit/math/aabb.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

/// Whether the sampled rays of `rays` (a run of a batch) share a direction octant (by sign bit,
/// -0 negative as the walks read it), each one's direction lies within an angle whose sine is
/// tuning::packet_direction_spread of the first one's, and each one's origin within
/// tuning::packet_origin_spread of `bounds`' largest extent of the first one's on every axis.
/// False for an empty run, or one with a sampled ray whose origin or direction is not finite or
/// whose direction is zero. No square root or division: the angle's sine is compared squared
/// (|a x b|^2 against s^2 |a|^2 |b|^2, in double, where the products cannot overflow).
inline bool coherent_rays(std::span<const Ray<float, 3>> rays, const Aabb<float, 3>& bounds) {
    if (rays.empty()) return false;
    float extent = 0.0f;
    for (int a = 0; a < 3; ++a) extent = std::fmax(extent, bounds.max[a] - bounds.min[a]);
    const float origin_limit = tuning::packet_origin_spread * extent;
    const double spread2 =
        double(tuning::packet_direction_spread) * tuning::packet_direction_spread;
    const Ray<float, 3>& first = rays[0];
    const double f[3] = {first.direction[0], first.direction[1], first.direction[2]};
    const double f2 = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
    if (!(f2 > 0.0) || !std::isfinite(f2)) return false;
    constexpr int samples = 6;
    for (int i = 0; i < samples; ++i) {
        const Ray<float, 3>& r = rays[(rays.size() - 1) * std::size_t(i) / (samples - 1)];
        for (int a = 0; a < 3; ++a)
            if (std::signbit(r.direction[a]) != std::signbit(first.direction[a]) ||
                !(std::fabs(r.origin[a] - first.origin[a]) <= origin_limit))
                return false;
        const double d[3] = {r.direction[0], r.direction[1], r.direction[2]};
        const double c[3] = {d[1] * f[2] - d[2] * f[1], d[2] * f[0] - d[0] * f[2],
                             d[0] * f[1] - d[1] * f[0]};
        const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] <= spread2 * d2 * f2) || !(d2 > 0.0))
            return false;
    }
    return true;
}

}  // namespace bvhkit
