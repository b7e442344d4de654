#pragma once
// ConvexShape<T>: one of the convex shapes (convex/shapes.hpp, convex/polytope.hpp) as a tagged
// union (std::variant), so that GJK and EPA take any pair of them with one code path and dispatch
// the support mapping by the tag, without virtual calls.
#include <cstdint>
#include <variant>

#include "bvhkit/convex/polytope.hpp"
#include "bvhkit/convex/shapes.hpp"
#include "bvhkit/math/transform.hpp"

namespace bvhkit {

/// Which shape a ConvexShape holds (the variant's index).
enum class ConvexKind : std::uint8_t { sphere, box, capsule, cylinder, cone, polytope };

template <class T>
class ConvexShape {
  public:
    using Scalar = T;
    using Variant = std::variant<SphereShape<T>, BoxShape<T>, CapsuleShape<T>, CylinderShape<T>,
                                 ConeShape<T>, ConvexPolytope<T>>;

    ConvexShape(SphereShape<T> s) : shape_(std::move(s)) {}
    ConvexShape(BoxShape<T> s) : shape_(std::move(s)) {}
    ConvexShape(CapsuleShape<T> s) : shape_(std::move(s)) {}
    ConvexShape(CylinderShape<T> s) : shape_(std::move(s)) {}
    ConvexShape(ConeShape<T> s) : shape_(std::move(s)) {}
    ConvexShape(ConvexPolytope<T> s) : shape_(std::move(s)) {}

    ConvexKind kind() const { return ConvexKind(shape_.index()); }
    const Variant& variant() const { return shape_; }

    /// The support point of the whole shape along d (local frame).
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        return std::visit([&](const auto& s) { return s.support(d); }, shape_);
    }
    /// The support point of the core (the shape less its margin ball) along d (local frame).
    Vec<T, 3> core_support(const Vec<T, 3>& d) const {
        return std::visit([&](const auto& s) { return s.core_support(d); }, shape_);
    }
    /// The same, starting a hull's climb from vertex `hint` and leaving the answer's vertex there
    /// (volumes/hull_support.hpp); the other shapes ignore it.
    Vec<T, 3> support(const Vec<T, 3>& d, std::uint32_t& hint) const {
        return std::visit(
            [&](const auto& s) {
                if constexpr (requires { s.support(d, hint); })
                    return s.support(d, hint);
                else
                    return s.support(d);
            },
            shape_);
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d, std::uint32_t& hint) const {
        return std::visit(
            [&](const auto& s) {
                if constexpr (requires { s.core_support(d, hint); })
                    return s.core_support(d, hint);
                else
                    return s.core_support(d);
            },
            shape_);
    }
    /// The radius of the ball swept over the core: sphere and capsule radius, 0 for the others.
    T margin() const {
        return std::visit([](const auto& s) { return s.margin(); }, shape_);
    }
    /// The largest distance of a point of the shape from the local origin.
    T bounding_radius() const {
        return std::visit([](const auto& s) { return s.bounding_radius(); }, shape_);
    }

  private:
    Variant shape_;
};

}  // namespace bvhkit
