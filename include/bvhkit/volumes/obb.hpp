#pragma once
// Obb<T>: an oriented box (centre, three unit axes as the rows of `axes`, half extents along
// them). Fitted by the covariance of the triangles' surfaces: the eigenvectors of the
// area-weighted covariance matrix are the axes (Gottschalk, Lin, Manocha 1996, "OBBTree"); the
// matrix is diagonalized by cyclic Jacobi rotations. Overlap under a pose: the exact 15-axis
// separating-axis test. Distance lower bound: the largest gap along the 15 axes, or
// the gap of the circumscribed spheres when larger (bounding_volume.hpp, boxes_gap).
#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

template <class T>
struct Obb {
    using Scalar = T;
    Vec<T, 3> center{};
    Mat3<T> axes{};            // row i is the i-th axis (unit, orthogonal)
    Vec<T, 3> extents{T(-1)};  // half extents; negative: empty
};

namespace detail {

/// Eigenvectors of a symmetric 3x3 matrix by cyclic Jacobi rotations; returned as the rows.
inline Mat3<double> symmetric_eigenvectors(Mat3<double> a) {
    Mat3<double> v;  // columns: eigenvectors so far
    for (int sweep = 0; sweep < 32; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0.0) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t =
                    (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {  // a = Jᵀ a J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    Mat3<double> rows = v.transposed();
    // Re-orthonormalize (Gram-Schmidt, then a right-handed third axis) against drift.
    rows[0] = normalize(rows[0]);
    rows[1] = normalize(rows[1] - rows[0] * dot(rows[0], rows[1]));
    rows[2] = cross(rows[0], rows[1]);
    return rows;
}

/// The box with the given axes around some points (in double, then padded and rounded out).
template <class T, class ForEachPoint>
Obb<T> obb_around(const Mat3<double>& axes, ForEachPoint&& for_each_point) {
    // Projections of the halved points: a double model's projections onto a skew axis may pass
    // DBL_MAX (their sum of three products) where the halves' cannot. Halving is exact outside
    // denormals, so this is the box of the points themselves, bit for bit.
    Vec3d lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for_each_point([&](const Vec3d& p) {
        const Vec3d q = axes * (p * 0.5);
        lo = min(lo, q);
        hi = max(hi, q);
    });
    Obb<T> o;
    if (!(lo[0] <= hi[0])) return o;
    const Vec3d mid = (lo + hi) * 0.5;
    const Vec3d c = axes.transpose_times(mid) * 2.0;
    // The coordinates' scale, halved too (the whole of it passes DBL_MAX at the top of the
    // range); the pad is the same product, as doubling is exact.
    const double half_scale = max_component(max(hi, -lo)) + max_component(max(c, -c)) * 0.5;
    const Vec3d e = (hi - lo) + Vec3d(half_scale * (2.0 * double(fit_pad<T>)));
    o.center = Vec<T, 3>(c);
    o.axes = Mat3<T>(axes);
    o.extents = Vec<T, 3>(e);
    return o;
}

/// Oriented volumes (Obb, Rss: a centre and three axes as rows) under a pose. frame_placed carries
/// b into A's frame once, for the several tests a traversal step makes against it (each then skips
/// the product of a's axes with the pose's rotation).
template <class V, class T>
V frame_placed(const V& b, const PreparedPose<T>& p) {
    V w = b;
    w.center = p.r * b.center + p.t;
    for (std::size_t j = 0; j < 3; ++j) w.axes[j] = p.r * b.axes[j];
    return w;
}

/// b's axes as the columns of c (abs_c: their magnitudes, padded for rounding) and its centre t,
/// both in a's frame; w already placed (frame_placed).
template <class V, class T>
void frames_relative_placed(const V& a, const V& w, Mat3<T>& c, Mat3<T>& abs_c, Vec<T, 3>& t) {
    constexpr T eps = std::numeric_limits<T>::epsilon() * T(16);
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
            c[i][j] = dot(a.axes[i], w.axes[j]);
            abs_c[i][j] = std::fabs(c[i][j]) + eps;
        }
    t = a.axes * (w.center - a.center);
}

/// The same for b given in its own model frame and the pose of B in A.
template <class V, class T>
void frames_relative(const V& a, const V& b, const PreparedPose<T>& p, Mat3<T>& c, Mat3<T>& abs_c,
                     Vec<T, 3>& t) {
    constexpr T eps = std::numeric_limits<T>::epsilon() * T(16);
    const Mat3<T> ar = a.axes * p.r;  // a's axes expressed in B's model frame, as rows
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
            c[i][j] = dot(ar[i], b.axes[j]);
            abs_c[i][j] = std::fabs(c[i][j]) + eps;
        }
    t = a.axes * (p.r * b.center + p.t - a.center);
}

}  // namespace detail

template <class T>
struct VolumeTraits<Obb<T>> {
    using V = Obb<T>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = false;

    static V fit(std::span<const Triangle<T>> tris) {
        if (tris.empty()) return {};
        // Centre on the first vertex so the sums do not lose the small spread to a large offset,
        // and scale by a power of two that brings the spread to about 1: the sums hold fourth
        // powers of it, which overflow double for a model at 1e77 and sink at 1e-77. The scaling
        // is exact and leaves the eigenvectors as they are (bit for bit, where nothing over- or
        // underflowed without it).
        // Differences of halves, which cannot overflow (a double model may span more than
        // DBL_MAX), are the differences halved exactly outside denormals.
        const Vec3d half_o = Vec3d(tris[0].p0) * 0.5;
        const auto half_diff = [&](const Vec<T, 3>& p) { return Vec3d(p) * 0.5 - half_o; };
        double spread = 0;
        for (const auto& t : tris)
            for (const Vec<T, 3>& p : {t.p0, t.p1, t.p2})
                spread = std::max(spread, max_component(bvhkit::abs(half_diff(p))));
        const double unit = spread > 0 ? std::ldexp(1.0, -std::ilogb(spread)) : 2.0;
        const auto local = [&](const Vec<T, 3>& p) { return half_diff(p) * unit; };
        double area = 0;
        Vec3d mean{};
        double m[3][3] = {};
        for (const auto& t : tris) {
            const Vec3d p = local(t.p0), q = local(t.p1), r = local(t.p2);
            const double a = 0.5 * length(cross(q - p, r - p));
            const Vec3d c = (p + q + r) * (1.0 / 3.0);
            area += a;
            mean += c * a;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    m[i][j] +=
                        a / 12.0 * (9.0 * c[i] * c[j] + p[i] * p[j] + q[i] * q[j] + r[i] * r[j]);
        }
        Mat3<double> cov;
        if (area > 0) {
            mean = mean * (1.0 / area);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) cov[i][j] = m[i][j] / area - mean[i] * mean[j];
        } else {  // zero total area: the covariance of the vertices
            double n = 0;
            Vec3d s{};
            double s2[3][3] = {};
            for (const auto& t : tris)
                for (const Vec3d& p : {local(t.p0), local(t.p1), local(t.p2)}) {
                    n += 1;
                    s += p;
                    for (int i = 0; i < 3; ++i)
                        for (int j = 0; j < 3; ++j) s2[i][j] += p[i] * p[j];
                }
            s = s * (1.0 / n);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) cov[i][j] = s2[i][j] / n - s[i] * s[j];
        }
        const Mat3<double> axes = detail::symmetric_eigenvectors(cov);
        return detail::obb_around<T>(axes, [&](auto&& f) {
            for (const auto& t : tris) {
                f(Vec3d(t.p0));
                f(Vec3d(t.p1));
                f(Vec3d(t.p2));
            }
        });
    }
    /// A box with the larger box's axes around both boxes' corners.
    static V merge(const V& a, const V& b) {
        if (a.extents[0] < 0) return b;
        if (b.extents[0] < 0) return a;
        const V& big = size(a) >= size(b) ? a : b;
        return detail::obb_around<T>(Mat3<double>(big.axes), [&](auto&& f) {
            for (const V* v : {&a, &b})
                for (int k = 0; k < 8; ++k) {
                    Vec3d p(v->center);
                    for (int i = 0; i < 3; ++i)
                        p += Vec3d(v->axes[i]) *
                             double((k >> i & 1) ? v->extents[i] : -v->extents[i]);
                    f(p);
                }
        });
    }
    static bool overlaps(const V& a, const V& b) {
        return overlaps(a, b, prepare(Transform<T>::identity(), T(0)));
    }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    /// b's axes and centre in a's box frame, then the 15-axis test.
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative(a, b, p, c, abs_c, t);
        return !detail::boxes_separated(c, abs_c, t, a.extents, b.extents, p.slack);
    }
    static T size(const V& v) { return length_squared(v.extents); }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative(a, b, p, c, abs_c, t);
        return std::max(T(0), detail::boxes_gap(c, abs_c, t, a.extents, b.extents) - p.slack);
    }

    /// b carried into A's frame once, for the several tests a traversal step makes against it
    /// (each then skips the product of a's axes with the pose's rotation).
    static V place(const V& b, const Prepared& p) { return detail::frame_placed(b, p); }
    /// overlaps(a, b, p) for w = place(b, p).
    static bool overlaps_placed(const V& a, const V& w, T slack) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative_placed(a, w, c, abs_c, t);
        return !detail::boxes_separated(c, abs_c, t, a.extents, w.extents, slack);
    }
    static T distance_lower_bound_placed(const V& a, const V& w, T slack) {
        Mat3<T> c, abs_c;
        Vec<T, 3> t;
        detail::frames_relative_placed(a, w, c, abs_c, t);
        return std::max(T(0), detail::boxes_gap(c, abs_c, t, a.extents, w.extents) - slack);
    }
};

}  // namespace bvhkit
