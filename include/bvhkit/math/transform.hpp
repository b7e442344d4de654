#pragma once
// Mat3<T> and Transform<T>: a 3x3 matrix (rows) and a rigid transform x' = R x + t, the pose of one
// model in the frame of another. Collision queries take the pose of B in A's frame and apply it to
// B's volumes and triangles on the fly, so no mesh is ever copied or re-transformed per query.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/math/vec.hpp"

namespace bvhkit {

template <class T>
struct Mat3 {
    Vec<T, 3> row[3] = {{T(1), T(0), T(0)}, {T(0), T(1), T(0)}, {T(0), T(0), T(1)}};

    static constexpr Mat3 identity() { return {}; }
    constexpr Vec<T, 3>& operator[](std::size_t i) { return row[i]; }
    constexpr const Vec<T, 3>& operator[](std::size_t i) const { return row[i]; }
    constexpr Vec<T, 3> column(std::size_t j) const { return {row[0][j], row[1][j], row[2][j]}; }

    constexpr Vec<T, 3> operator*(const Vec<T, 3>& v) const {
        return {dot(row[0], v), dot(row[1], v), dot(row[2], v)};
    }
    constexpr Mat3 operator*(const Mat3& b) const {
        Mat3 r;
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = 0; j < 3; ++j)
                r.row[i][j] =
                    row[i][0] * b.row[0][j] + row[i][1] * b.row[1][j] + row[i][2] * b.row[2][j];
        return r;
    }
    constexpr Mat3 transposed() const {
        Mat3 r;
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = 0; j < 3; ++j) r.row[i][j] = row[j][i];
        return r;
    }
    /// Rᵀ v (for a rotation: the inverse applied to v).
    constexpr Vec<T, 3> transpose_times(const Vec<T, 3>& v) const {
        return row[0] * v[0] + row[1] * v[1] + row[2] * v[2];
    }
    template <class U>
    constexpr explicit operator Mat3<U>() const {
        Mat3<U> r;
        for (std::size_t i = 0; i < 3; ++i) r.row[i] = Vec<U, 3>(row[i]);
        return r;
    }
};

/// A rigid transform: apply(x) = R x + t with R a rotation (the collision queries check it:
/// check_rigid_pose below).
template <class T>
struct Transform {
    Mat3<T> rotation{};
    Vec<T, 3> translation{};

    static constexpr Transform identity() { return {}; }
    constexpr Vec<T, 3> apply(const Vec<T, 3>& p) const { return rotation * p + translation; }
    constexpr Vec<T, 3> apply_vector(const Vec<T, 3>& v) const { return rotation * v; }
    constexpr Transform inverse() const {
        const Mat3<T> rt = rotation.transposed();
        return {rt, -(rt * translation)};
    }
    /// (a * b).apply(x) == a.apply(b.apply(x)).
    friend constexpr Transform operator*(const Transform& a, const Transform& b) {
        return {a.rotation * b.rotation, a.rotation * b.translation + a.translation};
    }
    template <class U>
    constexpr explicit operator Transform<U>() const {
        return {Mat3<U>(rotation), Vec<U, 3>(translation)};
    }
};

/// A rotation by `angle` radians about the unit axis `axis` (Rodrigues' formula).
template <class T>
Mat3<T> rotation_about(const Vec<T, 3>& axis, T angle) {
    const T c = std::cos(angle), s = std::sin(angle), k = T(1) - c;
    const T x = axis[0], y = axis[1], z = axis[2];
    Mat3<T> r;
    r.row[0] = {c + x * x * k, x * y * k - z * s, x * z * k + y * s};
    r.row[1] = {y * x * k + z * s, c + y * y * k, y * z * k - x * s};
    r.row[2] = {z * x * k - y * s, z * y * k + x * s, c + z * z * k};
    return r;
}

/// A rotation from a unit quaternion (w, x, y, z).
template <class T>
Mat3<T> rotation_from_quaternion(T w, T x, T y, T z) {
    Mat3<T> r;
    r.row[0] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)};
    r.row[1] = {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)};
    r.row[2] = {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    return r;
}

/// How far R may be from a rotation and still count as one: max |(R^T R - I)_ij| and |det R - 1|,
/// for float and double poses alike. A rotation rounded to float is within ~1e-7 of one, and a few
/// dozen float compositions stay well under 1e-5; a double model takes such a rotation (read from
/// float data, say) as it is. A scale or shear of 1e-4 would already move a point 1 unit away by
/// 1e-4, which no caller means by "rigid". The pose is used as given: the queries decide for
/// R x + t with the caller's R (exactly, for collide), and widen their volume tests by what R's
/// distance from a rotation can move (pose_slack, query/pose_slack.hpp).
template <class T>
constexpr double rigid_tolerance() {
    return 1e-4;
}

/// max(max |(R^T R - I)_ij|, |det R - 1|), computed in double (NaN for a non-finite R).
template <class T>
double rigid_deviation(const Mat3<T>& rotation) {
    const Mat3<double> r(rotation);
    double worst = 0;
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
            const double d = dot(r.column(i), r.column(j)) - (i == j ? 1.0 : 0.0);
            worst = std::max(worst, std::fabs(d));
        }
    const double det = dot(r.row[0], cross(r.row[1], r.row[2]));
    return std::max(worst, std::fabs(det - 1.0));
}

/// Throws Error unless `pose` is finite and rigid (R^T R = I and det R = +1 within
/// rigid_tolerance<T>()). `where` and `argument` name the call and the argument in the message.
template <class T>
void check_rigid_pose(const Transform<T>& pose, const char* where, const char* argument) {
    const auto fail = [&](const std::string& why) {
        throw Error(std::string(where) + ": " + argument + " " + why);
    };
    for (std::size_t i = 0; i < 3; ++i) {
        if (!std::isfinite(double(pose.translation[i])))
            fail("has a non-finite translation (NaN or infinity); a pose must be finite");
        for (std::size_t j = 0; j < 3; ++j)
            if (!std::isfinite(double(pose.rotation[i][j])))
                fail("has a non-finite rotation entry (NaN or infinity); a pose must be finite");
    }
    const double tol = rigid_tolerance<T>();
    if (const double deviation = rigid_deviation(pose.rotation); deviation > tol) {
        const Mat3<double> r(pose.rotation);
        const double det = dot(r.row[0], cross(r.row[1], r.row[2]));
        std::ostringstream m;
        m << "is not a rigid motion: its rotation must satisfy R^T R = I and det R = +1 within "
          << tol << " (found max(|R^T R - I|, |det R - 1|) = " << deviation << ", det R = " << det
          << "); scaled, sheared or mirrored poses are not supported";
        fail(m.str());
    }
}

using Transformf = Transform<float>;
using Transformd = Transform<double>;

}  // namespace bvhkit
