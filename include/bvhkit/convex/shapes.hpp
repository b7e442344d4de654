#pragma once
// The primitive convex shapes, each in its own local frame (the frame's origin is the shape's
// centre, its axis is local z): SphereShape, BoxShape, CapsuleShape, CylinderShape, ConeShape. Each
// gives its support point, the point of the shape farthest along a direction d (a maximiser of d .
// x), which is all GJK and EPA need of a convex set (Gilbert, Johnson and Keerthi 1988).
//
// Spheres and capsules are a core (a point, a segment) swept by a ball: `core_support` and `margin`
// describe that split, so the distance queries run GJK on the core and subtract the radius, which
// keeps their answers exact to rounding instead of converging on a curved surface (van den Bergen,
// Collision Detection in Interactive 3D Environments, 2003, on margins). The other shapes are their
// own core with margin 0.
//
// The parameters are checked on construction: a negative, NaN or infinite one throws Error naming
// it. Zero is allowed (a sphere of radius 0 is a point, a box with a zero extent is a rectangle).
#include <cmath>
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/math/vec.hpp"

namespace bvhkit {

namespace convex_detail {

template <class T>
T checked_size(T value, const char* shape, const char* parameter) {
    if (!(value >= T(0)) || !std::isfinite(value))
        throw Error(std::string(shape) + ": " + parameter + " must be finite and >= 0 (got " +
                    std::to_string(double(value)) + ")");
    return value;
}

/// d scaled to length r; a zero d gives r along +z (any unit direction is a support direction).
template <class T>
Vec<T, 3> scaled_to(const Vec<T, 3>& d, T r) {
    const T len = length(d);
    if (!(len > T(0)) || !std::isfinite(len)) return {T(0), T(0), r};
    return d * (r / len);
}

template <class T>
T sign_or_plus(T x) {
    return x < T(0) ? T(-1) : T(1);
}

}  // namespace convex_detail

/// A ball of `radius` about the local origin; its core is the origin.
template <class T>
class SphereShape {
  public:
    explicit SphereShape(T radius)
        : radius_(convex_detail::checked_size(radius, "SphereShape", "radius")) {}
    T radius() const { return radius_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const { return convex_detail::scaled_to(d, radius_); }
    Vec<T, 3> core_support(const Vec<T, 3>&) const { return {}; }
    T margin() const { return radius_; }
    /// The largest distance of a point of the shape from the local origin.
    T bounding_radius() const { return radius_; }

  private:
    T radius_;
};

/// The box [-h, h] in each local axis, h = `half_extents`.
template <class T>
class BoxShape {
  public:
    explicit BoxShape(const Vec<T, 3>& half_extents) : half_(half_extents) {
        static const char* const names[3] = {"half_extents.x", "half_extents.y", "half_extents.z"};
        for (std::size_t i = 0; i < 3; ++i)
            convex_detail::checked_size(half_extents[i], "BoxShape", names[i]);
    }
    const Vec<T, 3>& half_extents() const { return half_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        return {convex_detail::sign_or_plus(d[0]) * half_[0],
                convex_detail::sign_or_plus(d[1]) * half_[1],
                convex_detail::sign_or_plus(d[2]) * half_[2]};
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const { return support(d); }
    T margin() const { return T(0); }
    T bounding_radius() const { return length(half_); }

  private:
    Vec<T, 3> half_;
};

/// The points within `radius` of the segment from (0, 0, -half_length) to (0, 0, half_length).
template <class T>
class CapsuleShape {
  public:
    CapsuleShape(T radius, T half_length)
        : radius_(convex_detail::checked_size(radius, "CapsuleShape", "radius")),
          half_length_(convex_detail::checked_size(half_length, "CapsuleShape", "half_length")) {}
    T radius() const { return radius_; }
    T half_length() const { return half_length_; }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const {
        return {T(0), T(0), convex_detail::sign_or_plus(d[2]) * half_length_};
    }
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        return core_support(d) + convex_detail::scaled_to(d, radius_);
    }
    T margin() const { return radius_; }
    T bounding_radius() const { return half_length_ + radius_; }

  private:
    T radius_, half_length_;
};

/// The solid cylinder of `radius` about local z, from z = -half_height to z = half_height.
template <class T>
class CylinderShape {
  public:
    CylinderShape(T radius, T half_height)
        : radius_(convex_detail::checked_size(radius, "CylinderShape", "radius")),
          half_height_(convex_detail::checked_size(half_height, "CylinderShape", "half_height")) {}
    T radius() const { return radius_; }
    T half_height() const { return half_height_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        const T z = convex_detail::sign_or_plus(d[2]) * half_height_;
        const T planar = std::sqrt(d[0] * d[0] + d[1] * d[1]);
        // Along the axis every point of a cap supports; its centre is as good as any.
        if (!(planar > T(0))) return {T(0), T(0), z};
        const T s = radius_ / planar;
        return {d[0] * s, d[1] * s, z};
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const { return support(d); }
    T margin() const { return T(0); }
    T bounding_radius() const { return std::sqrt(radius_ * radius_ + half_height_ * half_height_); }

  private:
    T radius_, half_height_;
};

/// The solid cone about local z: the base disc of `radius` at z = -height / 2, the apex at
/// (0, 0, height / 2) (the local origin is the middle of the axis, as for the cylinder).
template <class T>
class ConeShape {
  public:
    ConeShape(T radius, T height)
        : radius_(convex_detail::checked_size(radius, "ConeShape", "radius")),
          height_(convex_detail::checked_size(height, "ConeShape", "height")) {}
    T radius() const { return radius_; }
    T height() const { return height_; }
    Vec<T, 3> support(const Vec<T, 3>& d) const {
        const T half = height_ / T(2);
        const T planar = std::sqrt(d[0] * d[0] + d[1] * d[1]);
        // The cone is the hull of the apex and the base rim: the support is whichever is farther.
        const T apex_value = d[2] * half;
        const T rim_value = radius_ * planar - d[2] * half;
        if (apex_value >= rim_value) return {T(0), T(0), half};
        if (!(planar > T(0))) return {T(0), T(0), -half};
        const T s = radius_ / planar;
        return {d[0] * s, d[1] * s, -half};
    }
    Vec<T, 3> core_support(const Vec<T, 3>& d) const { return support(d); }
    T margin() const { return T(0); }
    T bounding_radius() const {
        const T half = height_ / T(2);
        return std::sqrt(radius_ * radius_ + half * half);
    }

  private:
    T radius_, height_;
};

}  // namespace bvhkit
