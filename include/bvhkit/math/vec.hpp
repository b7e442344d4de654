#pragma once
// Vec<T, N>: a small fixed-size vector (N = 2 or 3 in practice) of float or double.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

namespace bvhkit {

template <class T, std::size_t N>
struct Vec {
    static_assert(std::is_floating_point_v<T>, "Vec holds float or double");
    static_assert(N >= 2 && N <= 4, "Vec is for 2, 3 or 4 components");
    using Scalar = T;
    static constexpr std::size_t size = N;

    T v[N] = {};

    constexpr Vec() = default;
    constexpr explicit Vec(T s) {
        for (std::size_t i = 0; i < N; ++i) v[i] = s;
    }
    template <class... A>
    requires(sizeof...(A) == N && N > 1 && (std::is_arithmetic_v<A> && ...)) constexpr Vec(A... a)
        : v{static_cast<T>(a)...} {}
    template <class U>
    constexpr explicit Vec(const Vec<U, N>& o) {
        for (std::size_t i = 0; i < N; ++i) v[i] = static_cast<T>(o[i]);
    }

    constexpr T& operator[](std::size_t i) { return v[i]; }
    constexpr const T& operator[](std::size_t i) const { return v[i]; }

    constexpr Vec& operator+=(const Vec& o) { return *this = *this + o; }
    constexpr Vec& operator-=(const Vec& o) { return *this = *this - o; }
    constexpr Vec& operator*=(T s) { return *this = *this * s; }

    friend constexpr bool operator==(const Vec&, const Vec&) = default;

#define BVHKIT_VEC_BINARY(op)                                          \
    friend constexpr Vec operator op(const Vec& a, const Vec& b) {     \
        Vec r;                                                         \
        for (std::size_t i = 0; i < N; ++i) r.v[i] = a.v[i] op b.v[i]; \
        return r;                                                      \
    }                                                                  \
    friend constexpr Vec operator op(const Vec& a, T s) {              \
        Vec r;                                                         \
        for (std::size_t i = 0; i < N; ++i) r.v[i] = a.v[i] op s;      \
        return r;                                                      \
    }
    BVHKIT_VEC_BINARY(+)
    BVHKIT_VEC_BINARY(-)
    BVHKIT_VEC_BINARY(*)
    BVHKIT_VEC_BINARY(/)
#undef BVHKIT_VEC_BINARY
    friend constexpr Vec operator*(T s, const Vec& a) {
        return a * s;
    }
    friend constexpr Vec operator-(const Vec& a) {
        return a * T(-1);
    }
};

template <class T, std::size_t N>
constexpr T dot(const Vec<T, N>& a, const Vec<T, N>& b) {
    T s = a[0] * b[0];
    for (std::size_t i = 1; i < N; ++i) s += a[i] * b[i];
    return s;
}
template <class T>
constexpr Vec<T, 3> cross(const Vec<T, 3>& a, const Vec<T, 3>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// The 2D cross product (z of the 3D one): positive when b is counter-clockwise from a.
template <class T>
constexpr T cross(const Vec<T, 2>& a, const Vec<T, 2>& b) {
    return a[0] * b[1] - a[1] * b[0];
}
template <class T, std::size_t N>
constexpr T length_squared(const Vec<T, N>& a) {
    return dot(a, a);
}
template <class T, std::size_t N>
T length(const Vec<T, N>& a) {
    return std::sqrt(dot(a, a));
}
template <class T, std::size_t N>
Vec<T, N> normalize(const Vec<T, N>& a) {
    return a * (T(1) / length(a));
}
template <class T, std::size_t N>
constexpr Vec<T, N> min(const Vec<T, N>& a, const Vec<T, N>& b) {
    Vec<T, N> r;
    for (std::size_t i = 0; i < N; ++i) r[i] = a[i] < b[i] ? a[i] : b[i];
    return r;
}
template <class T, std::size_t N>
constexpr Vec<T, N> max(const Vec<T, N>& a, const Vec<T, N>& b) {
    Vec<T, N> r;
    for (std::size_t i = 0; i < N; ++i) r[i] = a[i] > b[i] ? a[i] : b[i];
    return r;
}
template <class T, std::size_t N>
Vec<T, N> abs(const Vec<T, N>& a) {
    Vec<T, N> r;
    for (std::size_t i = 0; i < N; ++i) r[i] = std::abs(a[i]);
    return r;
}
template <class T, std::size_t N>
constexpr T min_component(const Vec<T, N>& a) {
    T m = a[0];
    for (std::size_t i = 1; i < N; ++i) m = a[i] < m ? a[i] : m;
    return m;
}
template <class T, std::size_t N>
constexpr T max_component(const Vec<T, N>& a) {
    T m = a[0];
    for (std::size_t i = 1; i < N; ++i) m = a[i] > m ? a[i] : m;
    return m;
}
/// Index of the largest component (the first one on ties).
template <class T, std::size_t N>
constexpr std::size_t largest_axis(const Vec<T, N>& a) {
    std::size_t k = 0;
    for (std::size_t i = 1; i < N; ++i)
        if (a[i] > a[k]) k = i;
    return k;
}
template <class T, std::size_t N>
bool is_finite(const Vec<T, N>& a) {
    for (std::size_t i = 0; i < N; ++i)
        if (!std::isfinite(a[i])) return false;
    return true;
}

using Vec2f = Vec<float, 2>;
using Vec3f = Vec<float, 3>;
using Vec2d = Vec<double, 2>;
using Vec3d = Vec<double, 3>;

}  // namespace bvhkit
