#pragma once
// Kdop<T, K>: a discrete oriented polytope, the intersection of K/2 slabs along fixed directions
// (Klosowski, Held, Mitchell et al. 1998). K = 14, 18, 26 in 3D; K = 8 in 2D. The first slabs are
// always the coordinate axes, so a k-DOP contains its own AABB as slabs 0..N-1.
//
//   K = 14: axes + the 4 cube diagonals (±1, ±1, ±1);
//   K = 18: axes + the 6 face diagonals (1, ±1, 0), (1, 0, ±1), (0, 1, ±1);
//   K = 26: axes + both;
//   K =  8 (2D): axes + (1, ±1).
//
// Under a rotation the slab directions do not map to slab directions, so the test under a pose is
// conservative: A's K/2 slabs against B's AABB part (carried into A's frame as an oriented box),
// then B's three face normals against A's AABB part. It never reports "apart" for volumes that
// meet, and may report "overlap" for some that do not. Distance lower bound: the largest of those
// gaps, or the box-box bound of the AABB parts. The 2D Kdop<T, 8> (K = 8) is the volume type alone:
// it has no VolumeTraits, so it cannot serve a CollisionModel.
#include <array>

#include "bvhkit/volumes/bounding_volume.hpp"

namespace bvhkit {

namespace detail {
template <std::size_t K>
constexpr auto kdop_directions() {
    if constexpr (K == 8) {
        return std::array<std::array<int, 2>, 4>{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
    } else if constexpr (K == 14) {
        return std::array<std::array<int, 3>, 7>{
            {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, -1, -1}}};
    } else if constexpr (K == 18) {
        return std::array<std::array<int, 3>, 9>{{{1, 0, 0},
                                                  {0, 1, 0},
                                                  {0, 0, 1},
                                                  {1, 1, 0},
                                                  {1, -1, 0},
                                                  {1, 0, 1},
                                                  {1, 0, -1},
                                                  {0, 1, 1},
                                                  {0, 1, -1}}};
    } else {
        static_assert(K == 26, "Kdop is defined for K = 8 (2D), 14, 18 and 26 (3D)");
        return std::array<std::array<int, 3>, 13>{{{1, 0, 0},
                                                   {0, 1, 0},
                                                   {0, 0, 1},
                                                   {1, 1, 1},
                                                   {1, 1, -1},
                                                   {1, -1, 1},
                                                   {1, -1, -1},
                                                   {1, 1, 0},
                                                   {1, -1, 0},
                                                   {1, 0, 1},
                                                   {1, 0, -1},
                                                   {0, 1, 1},
                                                   {0, 1, -1}}};
    }
}
}  // namespace detail

template <class T, std::size_t K>
struct Kdop {
    using Scalar = T;
    static constexpr std::size_t dimension = K == 8 ? 2 : 3;
    static constexpr std::size_t slabs = K / 2;
    static constexpr auto directions_int = detail::kdop_directions<K>();

    std::array<T, slabs> lo, hi;

    Kdop() {
        lo.fill(std::numeric_limits<T>::infinity());
        hi.fill(-std::numeric_limits<T>::infinity());
    }
    static Vec<T, dimension> direction(std::size_t d) {
        Vec<T, dimension> v;
        for (std::size_t i = 0; i < dimension; ++i) v[i] = T(directions_int[d][i]);
        return v;
    }
    static T project(std::size_t d, const Vec<T, dimension>& p) {
        T s = 0;
        for (std::size_t i = 0; i < dimension; ++i) {
            const int k = directions_int[d][i];
            s += k == 0 ? T(0) : (k > 0 ? p[i] : -p[i]);
        }
        return s;
    }
    Kdop& grow(const Vec<T, dimension>& p) {
        for (std::size_t d = 0; d < slabs; ++d) {
            const T s = project(d, p);
            lo[d] = std::min(lo[d], s);
            hi[d] = std::max(hi[d], s);
        }
        return *this;
    }
    bool is_empty() const { return !(lo[0] <= hi[0]); }
    /// Widened by the rounding of the sums in project() (at most 3 terms).
    Kdop& pad() {
        for (std::size_t d = 0; d < slabs; ++d) {
            const T m = std::max(std::fabs(lo[d]), std::fabs(hi[d])) * detail::fit_pad<T>;
            lo[d] -= m;
            hi[d] += m;
        }
        return *this;
    }
    bool overlaps(const Kdop& b) const {
        for (std::size_t d = 0; d < slabs; ++d)
            if (lo[d] > b.hi[d] || b.lo[d] > hi[d]) return false;
        return true;
    }
    Vec<T, dimension> box_center() const {
        Vec<T, dimension> c;
        for (std::size_t i = 0; i < dimension; ++i) c[i] = (lo[i] + hi[i]) * T(0.5);
        return c;
    }
    Vec<T, dimension> box_half() const {
        Vec<T, dimension> e;
        for (std::size_t i = 0; i < dimension; ++i) e[i] = (hi[i] - lo[i]) * T(0.5);
        return e;
    }
};

/// Pose constants for k-DOPs: besides R, |R| and t, each of A's directions n_d against the columns
/// of R (d_nr[d][j] = n_d . R e_j) and against t, so a node test does no matrix product.
template <class T, std::size_t K>
struct PreparedKdopPose : PreparedPose<T> {
    std::array<Vec<T, 3>, K / 2> nr, abs_nr;
    std::array<T, K / 2> nt, slack_d;

    PreparedKdopPose(const Transform<T>& pose, T widen) : PreparedPose<T>(pose, widen) {
        for (std::size_t d = 0; d < K / 2; ++d) {
            const Vec<T, 3> n = Kdop<T, K>::direction(d);
            for (std::size_t j = 0; j < 3; ++j) {
                nr[d][j] = dot(n, this->r.column(j));
                abs_nr[d][j] = std::fabs(nr[d][j]) + std::numeric_limits<T>::epsilon() * T(16);
            }
            nt[d] = dot(n, this->t);
            slack_d[d] = widen * length(n);
        }
    }
};

template <class T, std::size_t K>
requires(K != 8) struct VolumeTraits<Kdop<T, K>> {
    using V = Kdop<T, K>;
    using Prepared = PreparedKdopPose<T, K>;
    static constexpr bool merge_is_tight = true;

    static V fit(std::span<const Triangle<T>> tris) {
        V v;
        for (const auto& t : tris) v.grow(t.p0).grow(t.p1).grow(t.p2);
        if (!tris.empty()) v.pad();
        return v;
    }
    static V merge(const V& a, const V& b) {
        V v;
        for (std::size_t d = 0; d < V::slabs; ++d) {
            v.lo[d] = std::min(a.lo[d], b.lo[d]);
            v.hi[d] = std::max(a.hi[d], b.hi[d]);
        }
        return v;
    }
    static bool overlaps(const V& a, const V& b) { return a.overlaps(b); }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        return gap(a, b, p, true) <= T(0);
    }
    static T size(const V& v) { return length_squared(v.box_half()); }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        // The slab gaps, or the box-box bound of the AABB parts (15 axes and the spheres).
        const Vec<T, 3> eb = b.box_half(), ea = a.box_half();
        const Vec<T, 3> t = p.r * b.box_center() + p.t - a.box_center();
        const T boxes = detail::boxes_gap(p.r, p.abs_r, t, ea, eb) - p.slack;
        return std::max({T(0), gap(a, b, p, false), boxes});
    }

  private:
    /// The largest separation found (with the slack taken off); `early`: stop at the first
    /// positive one.
    static T gap(const V& a, const V& b, const Prepared& p, bool early) {
        const Vec<T, 3> cb = b.box_center(), eb = b.box_half();
        T best = -std::numeric_limits<T>::infinity();
        for (std::size_t d = 0; d < V::slabs; ++d) {
            const T c = dot(p.nr[d], cb) + p.nt[d], r = dot(p.abs_nr[d], eb);
            const T g = std::max(a.lo[d] - (c + r), (c - r) - a.hi[d]) - p.slack_d[d];
            const T unit = d < 3 ? g : g / length(V::direction(d));
            if (unit > best) {
                best = unit;
                if (early && best > T(0)) return best;
            }
        }
        const Vec<T, 3> ca = a.box_center(), ea = a.box_half();
        const Vec<T, 3> t = p.r * cb + p.t - ca;
        for (std::size_t j = 0; j < 3; ++j) {
            const T ra = ea[0] * p.abs_r[0][j] + ea[1] * p.abs_r[1][j] + ea[2] * p.abs_r[2][j];
            const T proj = t[0] * p.r[0][j] + t[1] * p.r[1][j] + t[2] * p.r[2][j];
            const T g = std::fabs(proj) - ra - eb[j] - p.slack;
            if (g > best) {
                best = g;
                if (early && best > T(0)) return best;
            }
        }
        return best;
    }
};

using Kdop14f = Kdop<float, 14>;
using Kdop18f = Kdop<float, 18>;
using Kdop26f = Kdop<float, 26>;
using Kdop8f = Kdop<float, 8>;

}  // namespace bvhkit
