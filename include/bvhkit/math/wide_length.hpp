#pragma once
// Lengths and sizes of extreme-scale geometry without the overflow or underflow of squaring: a
// float mesh at 1e19 has edges whose squares exceed FLT_MAX, one at 1e-25 edges whose squares sink
// below the smallest float, and a double mesh does the same at 1e155 and 1e-155. The squares are
// taken in double, after scaling by a power of two (exact) where double itself would not hold
// them, so the result is the length to a few ulps of double wherever it is finite.
#include <algorithm>
#include <cmath>
#include <limits>

#include "bvhkit/math/vec.hpp"

namespace bvhkit {

/// |v| in double; inf only if |v| is beyond double's range (or v has an infinite component), NaN
/// if v has a NaN.
template <class T, std::size_t N>
double wide_length(const Vec<T, N>& v) {
    double m = 0;
    for (std::size_t i = 0; i < N; ++i) m = std::max(m, std::fabs(double(v[i])));
    if (!(m > 0) || !std::isfinite(m)) {  // zero, infinite or NaN: no scaling to do
        double s = 0;
        for (std::size_t i = 0; i < N; ++i) s += double(v[i]) * double(v[i]);
        return std::sqrt(s);
    }
    const int k = std::ilogb(m);
    double s = 0;
    for (std::size_t i = 0; i < N; ++i) {
        const double x = std::ldexp(double(v[i]), -k);
        s += x * x;
    }
    return std::ldexp(std::sqrt(s), k);
}

/// The power of two 2^k to divide coordinates of magnitude up to m by before squaring them in
/// double: 0 (no scaling, results bit for bit as before) while m lies in [2^-256, 2^256], where
/// sums of squares and of products of three such values neither overflow nor sink into
/// denormals, and their differences stay within the exact predicates' 2^+-300; else a k that
/// brings m to about 2^250 from above (scaling down: tinier coordinates in the same set keep more
/// bits than scaling to 1 would) or to about 1 from below (scaling up is exact). Not for
/// products of four (they overflow from 2^256).
inline int squaring_exponent(double m) {
    if (!(m > 0) || !std::isfinite(m)) return 0;
    const int e = std::ilogb(m);
    if (e > 256) return e - 250;
    if (e < -256) return e;
    return 0;
}

/// x rounded to T: to nearest, inf beyond T's largest finite value (rather than the undefined
/// conversion of an out-of-range double).
template <class T>
T narrow_or_inf(double x) {
    constexpr double top = double(std::numeric_limits<T>::max());
    if (x > top) return std::numeric_limits<T>::infinity();
    if (x < -top) return -std::numeric_limits<T>::infinity();
    return T(x);
}

/// x rounded up to T (inf beyond T's largest finite value): a size that must not shrink.
template <class T>
T round_up_to(double x) {
    T y = narrow_or_inf<T>(x);
    if (double(y) < x) y = std::nextafter(y, std::numeric_limits<T>::infinity());
    return y;
}

/// The midpoint of a and b, never overflowing (a + b can): halving is exact outside denormals.
template <class T>
T midpoint_of(T a, T b) {
    return a * T(0.5) + b * T(0.5);
}

}  // namespace bvhkit
