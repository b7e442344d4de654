#pragma once
// build_bvh(): the one entry point to every builder. Give it one box and one centroid per primitive
// (or a span of any Primitive) and BuildOptions; the default is binned SAH.
//
// Rule for bad input: a primitive with a NaN or infinite coordinate (or an empty box) is left out
// of the tree and listed in BuildReport::skipped; with NonFinitePolicy::Reject it is an error
// instead. Empty input gives an empty tree; one primitive gives a single leaf.
#include <cmath>
#include <limits>

#include "bvhkit/build/binned_sah.hpp"
#include "bvhkit/build/bottom_up.hpp"
#include "bvhkit/build/insertion.hpp"
#include "bvhkit/build/lbvh.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/build/reinsertion.hpp"
#include "bvhkit/build/sweep_sah.hpp"
#include "bvhkit/build/top_down.hpp"
#include "bvhkit/primitives/primitive.hpp"

namespace bvhkit {

namespace build_detail {

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_unoptimized(BuildInput<T, N>& in, std::vector<std::uint32_t> indices,
                                  const BuildOptions& options, const Executor& exec) {
    switch (options.builder) {
        case Builder::BinnedSah: {
            BinnedSahRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule, exec);
        }
        case Builder::SweepSah: {
            SweepSahRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule, exec);
        }
        case Builder::TopDown: {
            TopDownRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule, exec);
        }
        case Builder::BottomUp:
            return build_bottom_up(in.boxes, in.centroids, std::span<const std::uint32_t>(indices),
                                   options, exec);
        case Builder::Insertion:
            return build_insertion(in.boxes, std::span<const std::uint32_t>(indices), options);
        case Builder::Lbvh:
            return build_lbvh(in.boxes, in.centroids, std::span<const std::uint32_t>(indices),
                              options, exec);
    }
    throw Error("build_bvh: unknown builder");
}

/// The power of two 2^e that brings the largest finite coordinate of `boxes` near 1 when it lies
/// where areas (products of two extents) could overflow or lose their precision to underflow, else
/// e = 0. Scaling by a power of two is exact (but for coordinates that underflow, which only
/// coarsens the build's decisions: the final boxes are refitted from the originals).
template <class T, std::size_t N>
int range_exponent(std::span<const Aabb<T, N>> boxes) {
    T largest = 0;
    for (const Aabb<T, N>& b : boxes)
        for (std::size_t a = 0; a < N; ++a) {
            const T lo = std::fabs(b.min[a]), hi = std::fabs(b.max[a]);
            // NaN fails both comparisons; infinite boxes are skipped by the build anyway.
            if (lo > largest && lo <= std::numeric_limits<T>::max()) largest = lo;
            if (hi > largest && hi <= std::numeric_limits<T>::max()) largest = hi;
        }
    if (!(largest > 0)) return 0;
    int e = 0;
    (void)std::frexp(largest, &e);
    constexpr int too_large = std::numeric_limits<T>::max_exponent / 2 - 4;  // float: 2^60
    constexpr int too_small = std::numeric_limits<T>::min_exponent / 4;      // float: 2^-31
    return e > too_large || e < too_small ? -e : 0;
}

}  // namespace build_detail

/// Builds a Bvh over `boxes` (one per primitive) with `centroids` (the split and sort keys), as
/// `options` says; throws bvhkit::Error for invalid options (validate_options). Input whose
/// coordinates reach beyond 2^60 (float; 2^508 double) or stay below 2^-31 is built on a copy
/// scaled by a power of two (so surface areas neither overflow nor underflow) and the node boxes
/// are then refitted to the original boxes.
template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_bvh(std::span<const Aabb<T, N>> boxes, std::span<const Vec<T, N>> centroids,
                          const BuildOptions& options = {}, BuildReport* report = nullptr) {
    validate_options(options);
    if (report) report->skipped.clear();
    const int e = boxes.size() == centroids.size() ? build_detail::range_exponent(boxes) : 0;
    std::vector<Aabb<T, N>> scaled_boxes;
    std::vector<Vec<T, N>> scaled_centroids;
    if (e != 0) {
        scaled_boxes.resize(boxes.size());
        scaled_centroids.resize(boxes.size());
        for (std::size_t i = 0; i < boxes.size(); ++i)
            for (std::size_t a = 0; a < N; ++a) {
                scaled_boxes[i].min[a] = std::ldexp(boxes[i].min[a], e);
                scaled_boxes[i].max[a] = std::ldexp(boxes[i].max[a], e);
                scaled_centroids[i][a] = std::ldexp(centroids[i][a], e);
            }
    }
    BuildInput<T, N> in{e ? std::span<const Aabb<T, N>>(scaled_boxes) : boxes,
                        e ? std::span<const Vec<T, N>>(scaled_centroids) : centroids};
    std::vector<Vec<T, N>> fixed_centroids;
    // The user's knob is options.threads; everything below runs on this one executor (one task
    // arena for the whole build).
    const Executor exec(options.threads);
    std::vector<std::uint32_t> indices =
        usable_primitives(in, fixed_centroids, options, exec, report);
    Bvh<Aabb<T, N>> bvh = build_detail::build_unoptimized(in, std::move(indices), options, exec);
    if (options.optimize) {
        ReinsertionOptions r;
        r.flatten = {options.max_leaf_size, options.max_depth, options.costs};
        optimize_reinsertion(bvh, in.boxes, r);
    }
    if (e != 0) refit(bvh, boxes);
    return bvh;
}

/// Boxes and centroids of a span of primitives, in order.
template <Primitive P>
auto primitive_boxes(std::span<const P> primitives) {
    using Box = decltype(primitives[0].bounds());
    std::vector<Box> boxes(primitives.size());
    for (std::size_t i = 0; i < primitives.size(); ++i) boxes[i] = primitives[i].bounds();
    return boxes;
}

template <Primitive P>
auto build_bvh(std::span<const P> primitives, const BuildOptions& options = {},
               BuildReport* report = nullptr) {
    using T = typename P::Scalar;
    constexpr std::size_t N = primitive_dimension<P>;
    const std::vector<Aabb<T, N>> boxes = primitive_boxes(primitives);
    std::vector<Vec<T, N>> centroids(primitives.size());
    for (std::size_t i = 0; i < primitives.size(); ++i) centroids[i] = primitives[i].centroid();
    return build_bvh<T, N>(boxes, centroids, options, report);
}

template <Primitive P>
auto build_bvh(const std::vector<P>& primitives, const BuildOptions& options = {},
               BuildReport* report = nullptr) {
    return build_bvh(std::span<const P>(primitives), options, report);
}

}  // namespace bvhkit
