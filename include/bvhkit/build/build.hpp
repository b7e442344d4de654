#pragma once
// build_bvh(): the one entry point to every builder. Give it one box and one centroid per primitive
// (or a span of any Primitive) and BuildOptions; the default is binned SAH.
//
// Rule for bad input: a primitive with a NaN or infinite coordinate (or an empty box) is left out
// of the tree and listed in BuildReport::skipped; with NonFinitePolicy::Reject it is an error
// instead. Empty input gives an empty tree; one primitive gives a single leaf.
#include "bvhkit/build/binned_sah.hpp"
#include "bvhkit/build/bottom_up.hpp"
#include "bvhkit/build/insertion.hpp"
#include "bvhkit/build/lbvh.hpp"
#include "bvhkit/build/reinsertion.hpp"
#include "bvhkit/build/sweep_sah.hpp"
#include "bvhkit/build/top_down.hpp"
#include "bvhkit/primitives/primitive.hpp"

namespace bvhkit {

namespace build_detail {

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_unoptimized(BuildInput<T, N>& in, std::vector<std::uint32_t> indices,
                                  const BuildOptions& options) {
    switch (options.builder) {
        case Builder::BinnedSah: {
            BinnedSahRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule);
        }
        case Builder::SweepSah: {
            SweepSahRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule);
        }
        case Builder::TopDown: {
            TopDownRule<T, N> rule(in, options);
            return build_top_down(in, std::move(indices), options, rule);
        }
        case Builder::BottomUp:
            return build_bottom_up(in.boxes, in.centroids, std::span<const std::uint32_t>(indices),
                                   options);
        case Builder::Insertion:
            return build_insertion(in.boxes, std::span<const std::uint32_t>(indices), options);
        case Builder::Lbvh:
            return build_lbvh(in.boxes, in.centroids, std::span<const std::uint32_t>(indices),
                              options);
    }
    throw Error("build_bvh: unknown builder");
}

}  // namespace build_detail

template <class T, std::size_t N>
Bvh<Aabb<T, N>> build_bvh(std::span<const Aabb<T, N>> boxes, std::span<const Vec<T, N>> centroids,
                          const BuildOptions& options = {}, BuildReport* report = nullptr) {
    validate_options(options);
    BuildInput<T, N> in{boxes, centroids};
    if (report) report->skipped.clear();
    std::vector<Vec<T, N>> fixed_centroids;
    std::vector<std::uint32_t> indices = usable_primitives(in, fixed_centroids, options, report);
    Bvh<Aabb<T, N>> bvh = build_detail::build_unoptimized(in, std::move(indices), options);
    if (options.optimize) {
        ReinsertionOptions r;
        r.flatten = {options.max_leaf_size, options.max_depth, options.costs};
        optimize_reinsertion(bvh, boxes, r);
    }
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
