#pragma once
// The Primitive concept: what a user type needs so bvhkit can build a tree over it and trace rays
// through it. Triangle and Segment model it; so can a sphere, a box or a curve of the user's own.
#include <concepts>
#include <optional>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit {

/// Bounds and centroid are what the builders need.
template <class P>
concept Primitive = requires(const P& p) {
    typename P::Scalar;
    { p.bounds() } -> std::same_as<Aabb<typename P::Scalar, decltype(p.bounds())::dimension>>;
    { p.centroid() } -> std::same_as<Vec<typename P::Scalar, decltype(p.bounds())::dimension>>;
};

template <Primitive P>
inline constexpr std::size_t primitive_dimension =
    decltype(std::declval<const P&>().bounds())::dimension;

/// A ray test returning the distance and (u, v) of the hit, or nothing: what the ray queries need.
template <class P>
concept RayPrimitive = Primitive<P> &&
    requires(const P& p, const Ray<typename P::Scalar, primitive_dimension<P>>& r) {
    { p.intersect(r) } -> std::same_as<std::optional<TriangleHit<typename P::Scalar>>>;
};

}  // namespace bvhkit
