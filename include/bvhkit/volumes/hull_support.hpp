#pragma once
// HullSupport<T>: the vertices of a convex hull together with their neighbours on the hull's
// surface (flat CSR arrays), for support queries, "which vertex maximises d . x", that cost a few
// neighbourhoods instead of a pass over every vertex.
//
// The query climbs: from a start vertex it moves to a neighbour of larger d . x until none is
// larger. On a convex surface a vertex that no neighbour beats is a maximiser over the whole hull
// (the cone of directions into the hull at a vertex is spanned by its edges, so d . x cannot rise
// along any direction into the hull) except at a vertex inside a flat facet, where that cone is a
// half-space: with d the facet's inward normal every neighbour ties and the vertex is a minimiser.
// Such vertices are marked when the graph is built; a climb that never moved from a marked start
// and saw only ties restarts from a start that is not marked, which it then can only leave by
// strict improvement, so it never stops at a minimiser again. (Hill climbing for GJK's support
// points: Cameron, "Enhancing GJK", ICRA 1997.)
//
// Exactness: every comparison the climb acts on is decided exactly. The values d . x are taken in
// double with a proved bound on their rounding; a difference within twice that bound is decided
// by the exact sign of d . (u - v) (floating-point expansions, or exact integers outside their
// range). Each move strictly raises the exact value, so the climb ends, also on a degenerate hull
// with many ties, and it ends at a vertex whose exact d . x equals the largest over the vertices.
// On ties the vertex may differ from the one a scan returns; the value does not.
//
// Starts: a table of start vertices over a cube map of directions (each face of the cube split in
// G x G cells, each cell holding the best vertex for its centre's direction among the vertices
// not inside a flat facet), and optionally a caller's hint (the previous answer). Hulls of fewer
// than `climb_threshold` vertices, or whose surface is flat in a way the graph does not describe
// (three points or fewer, collinear points), are answered by an exact scan.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "bvhkit/math/exact_integer.hpp"
#include "bvhkit/math/predicates.hpp"
#include "bvhkit/math/vec.hpp"
#include "bvhkit/volumes/quickhull.hpp"

namespace bvhkit {

namespace support_detail {

/// Whether e_i = u_i - v_i, p_i = d_i e_i and dot = p0 + p1 + p2, as rounded, are all exact:
/// each operation's rounding error is recovered exactly (Knuth's TwoSum, the FMA residual of a
/// product) and must be zero. Ties of axis-aligned directions on boxes and grids (the common
/// case in CAD scenes) end here instead of in expansion arithmetic. A product in the subnormal
/// range could lose a residual below the smallest subnormal, so it must be exactly zero from a
/// zero factor, or normal.
inline bool rounded_exactly(const Vec<double, 3>& d, const Vec<double, 3>& u,
                            const Vec<double, 3>& v, double e0, double e1, double e2, double p0,
                            double p1, double p2, double dot) {
    const auto sum_error = [](double a, double b, double s) {
        const double bb = s - a;
        return (a - (s - bb)) + (b - bb);
    };
    const double e[3] = {e0, e1, e2}, p[3] = {p0, p1, p2};
    for (std::size_t i = 0; i < 3; ++i) {
        if (sum_error(u[i], -v[i], e[i]) != 0) return false;
        if (p[i] == 0 ? (d[i] != 0 && e[i] != 0) : std::fabs(p[i]) < 0x1p-1000) return false;
        if (std::fma(d[i], e[i], -p[i]) != 0) return false;
    }
    const double p01 = p0 + p1;
    return sum_error(p0, p1, p01) == 0 && sum_error(p01, p2, dot) == 0;
}

/// The sign of d . (u - v), exact for every finite double input.
inline int dot_difference_sign(const Vec<double, 3>& d, const Vec<double, 3>& u,
                               const Vec<double, 3>& v) {
    // First the differences, then the dot product, in double: each difference rounds by at most
    // 2^-53 of itself, each product and the two sums add as much again, so |error| <= 4 * 2^-53 *
    // sum |d_i (u_i - v_i)| (rounded, hence 5), plus 2^-1073 for what underflowing products lose.
    // Neighbours on a hull are close compared with the hull's size, so this decides most of
    // what the values' own bound (tie_width) left open.
    const double e0 = u[0] - v[0], e1 = u[1] - v[1], e2 = u[2] - v[2];
    const double p0 = d[0] * e0, p1 = d[1] * e1, p2 = d[2] * e2;
    const double dot = p0 + p1 + p2;
    const double bound = 5 * 0x1p-53 * (std::fabs(p0) + std::fabs(p1) + std::fabs(p2)) + 0x1p-1073;
    if (dot > bound) return 1;
    if (-dot > bound) return -1;
    if (rounded_exactly(d, u, v, e0, e1, e2, p0, p1, p2, dot)) return (dot > 0) - (dot < 0);
    // The sign does not change when d or (u, v) is scaled by a power of two: each is brought into
    // the range where products of two terms are exact expansions (that of orient2d).
    exact::BitSpan span_d, span_x;
    for (std::size_t i = 0; i < 3; ++i) {
        span_d.add(d[i]);
        span_x.add(u[i]);
        span_x.add(v[i]);
    }
    if (!span_d.finite || !span_x.finite || span_d.empty() || span_x.empty()) return 0;
    int kd = 0, kx = 0;
    if (span_d.shift_into(exact::orient2d_low, exact::orient2d_high, kd) &&
        span_x.shift_into(exact::orient2d_low, exact::orient2d_high, kx)) {
        const auto scaled = [](double x, int k) { return k == 0 ? x : std::ldexp(x, k); };
        // Three terms of at most four doubles each: at most 12 in the sum.
        exact::Expansion<12> total;
        for (std::size_t i = 0; i < 3; ++i) {
            const exact::Expansion<2> diff = exact::difference(scaled(u[i], kx), scaled(v[i], kx));
            exact::Expansion<4> term;
            exact::scale(diff, scaled(d[i], kd), term);
            exact::Expansion<12> next;
            exact::sum(total, term, next);
            total = next;
        }
        return exact::sign(total);
    }
    int s = -4000;
    for (std::size_t i = 0; i < 3; ++i)
        s = std::max({s, exact::DyadicInt::lowest_shift(d[i]), exact::DyadicInt::lowest_shift(u[i]),
                      exact::DyadicInt::lowest_shift(v[i])});
    exact::DyadicInt total;
    for (std::size_t i = 0; i < 3; ++i)
        total = total +
                exact::DyadicInt::from_double(d[i], s) * (exact::DyadicInt::from_double(u[i], s) -
                                                          exact::DyadicInt::from_double(v[i], s));
    return total.sign();
}

}  // namespace support_detail

template <class T>
class HullSupport {
  public:
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    /// Below this many vertices the queries scan exactly, without a graph.
    static constexpr std::size_t climb_threshold = 16;
    static constexpr int grid = 4;  // cells per cube face edge

    HullSupport() = default;

    /// The hull of `sorted_unique` (sorted lexicographically, no duplicates, all finite; at least
    /// one point). Its vertices keep the input's order.
    explicit HullSupport(std::span<const Vec<T, 3>> sorted_unique) {
        if (sorted_unique.empty()) return;
        HullSurface surface = quickhull_surface<T>(sorted_unique);
        const std::vector<std::uint32_t> ring = surface.vertices;  // a polygon's, in order
        std::sort(surface.vertices.begin(), surface.vertices.end());
        std::vector<std::uint32_t> index(sorted_unique.size(), none);
        vertices_.reserve(surface.vertices.size());
        for (const std::uint32_t i : surface.vertices) {
            index[i] = std::uint32_t(vertices_.size());
            vertices_.push_back(sorted_unique[i]);
        }
        for (const Vec<T, 3>& v : vertices_)
            for (std::size_t a = 0; a < 3; ++a)
                largest_ = std::max(largest_, std::fabs(double(v[a])));
        if (vertices_.size() < climb_threshold) return;
        if (surface.dimension == 3)
            build_from_triangles(surface.triangles, index);
        else if (surface.dimension == 2)
            build_ring(ring, index);
        if (!first_.empty()) build_starts();
    }

    std::span<const Vec<T, 3>> vertices() const { return vertices_; }
    std::size_t size() const { return vertices_.size(); }
    bool empty() const { return vertices_.empty(); }
    /// Whether queries climb the graph (false: they scan).
    bool climbs() const { return !first_.empty(); }
    /// The neighbours of vertex i on the hull's surface (empty when the queries scan).
    std::span<const std::uint32_t> neighbours(std::uint32_t i) const {
        if (first_.empty()) return {};
        return std::span<const std::uint32_t>(adjacent_).subspan(first_[i],
                                                                 first_[i + 1] - first_[i]);
    }
    /// Whether vertex i lies inside a flat facet of the hull (all its neighbours in one plane).
    bool inside_facet(std::uint32_t i) const { return !flat_.empty() && flat_[i] != 0; }

    /// The index of a vertex whose exact d . x is the largest over the vertices. `hint`: a vertex
    /// to start from (the previous answer, say), or `none`. A zero d gives any vertex; a d with a
    /// NaN or an infinity gives the start vertex. The hull must not be empty.
    std::uint32_t support_index(const Vec<T, 3>& dir, std::uint32_t hint = none) const {
        const Vec<double, 3> d(dir);
        if (!is_finite(d)) return hint < vertices_.size() ? hint : 0;
        const double tie = tie_width(d);
        if (first_.empty()) return exact_scan(d, tie);
        std::uint32_t start = starts_[cell(d)];
        if (hint < vertices_.size() && hint != start && value(d, hint) > value(d, start)) {
            const std::uint32_t found = climb(d, hint, tie);
            if (found != none) return found;
        }
        return climb(d, start, tie);  // an unmarked start: never `none`
    }
    const Vec<T, 3>& support(const Vec<T, 3>& d, std::uint32_t hint = none) const {
        return vertices_[support_index(d, hint)];
    }

  private:
    double value(const Vec<double, 3>& d, std::uint32_t i) const {
        const Vec<T, 3>& x = vertices_[i];
        return d[0] * double(x[0]) + d[1] * double(x[1]) + d[2] * double(x[2]);
    }

    /// Twice a bound on the rounding of value(d, i), so a difference of two values beyond it has
    /// the sign of the exact difference. Each of the three products rounds by at most u = 2^-53
    /// relative (exact for float input) or 2^-1075 absolute where it underflows, and the two sums
    /// by u of their result: |value - d . x| <= 3u (|d|_1 m) + 3 * 2^-1075 (below 2^-1073) with m
    /// the largest |coordinate|. The difference of two values rounds by u of itself, which the
    /// factor 2.02 (against 2 (1 + u)) covers with room. An infinite bound sends every comparison
    /// to the exact test.
    double tie_width(const Vec<double, 3>& d) const {
        constexpr double u = 0x1p-53;
        const double norm1 = std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]);
        return 2.02 * (3 * u * (norm1 * largest_) + 0x1p-1073);
    }

    /// The exact comparison of d . x_i against d . x_j: > 0 when x_i is strictly better.
    int compare(const Vec<double, 3>& d, std::uint32_t i, std::uint32_t j) const {
        return support_detail::dot_difference_sign(d, Vec<double, 3>(vertices_[i]),
                                                   Vec<double, 3>(vertices_[j]));
    }

    /// The exact maximiser by a scan: the best by rounded values (a branch-light pass), then,
    /// only if another vertex lies within the tie width of it, exact comparisons among those.
    std::uint32_t exact_scan(const Vec<double, 3>& d, double tie) const {
        std::uint32_t best = 0;
        double best_value = value(d, 0);
        for (std::uint32_t i = 1; i < vertices_.size(); ++i) {
            const double v = value(d, i);
            if (v > best_value) {
                best_value = v;
                best = i;
            }
        }
        const double floor = best_value - tie;
        std::size_t near = 0;
        for (std::uint32_t i = 0; i < vertices_.size(); ++i) near += value(d, i) >= floor;
        if (near > 1) {
            // Every vertex below `floor` is certainly below the first best, hence below the
            // exact maximum; the rest are compared exactly.
            const std::uint32_t first = best;
            for (std::uint32_t i = 0; i < vertices_.size(); ++i)
                if (i != first && value(d, i) >= floor && compare(d, i, best) > 0) best = i;
        }
        return best;
    }

    /// The climb from `at`; `none` when it never moved, every neighbour tied and `at` lies inside
    /// a flat facet (d may be the facet's inward normal: the caller restarts elsewhere).
    std::uint32_t climb(const Vec<double, 3>& d, std::uint32_t at, double tie) const {
        double at_value = value(d, at);
        bool moved = false;
        for (;;) {
            const std::uint32_t* begin = adjacent_.data() + first_[at];
            const std::uint32_t* end = adjacent_.data() + first_[at + 1];
            std::uint32_t best = at;
            double best_value = at_value;
            const double floor = at_value - tie;
            bool near = false;  // some neighbour not certainly worse
            for (const std::uint32_t* p = begin; p != end; ++p) {
                const double v = value(d, *p);
                near |= v >= floor;
                if (v > best_value) {
                    best_value = v;
                    best = *p;
                }
            }
            if (best_value - at_value > tie) {  // certainly better
                at = best;
                at_value = best_value;
                moved = true;
                continue;
            }
            if (!near) return at;  // every neighbour certainly worse: the usual end
            // No neighbour is certainly better: the ones within the tie width are decided
            // exactly.
            std::uint32_t next = none;
            bool all_tie = true;
            for (const std::uint32_t* p = begin; p != end; ++p) {
                if (value(d, *p) - at_value < -tie) {
                    all_tie = false;
                    continue;
                }
                const int s = compare(d, *p, at);
                if (s > 0) {
                    next = *p;
                    break;
                }
                if (s < 0) all_tie = false;
            }
            if (next != none) {
                at = next;
                at_value = value(d, at);
                moved = true;
                continue;
            }
            if (!moved && all_tie && flat_[at]) return none;
            return at;
        }
    }

    /// The cube-map cell of a finite direction (the zero direction gets cell 0).
    static std::size_t cell(const Vec<double, 3>& d) {
        const double ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
        const std::size_t axis = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
        const double big = std::fabs(d[axis]);
        if (!(big > 0)) return 0;
        const std::size_t u = (axis + 1) % 3, v = (axis + 2) % 3;
        const auto slot = [big](double c) {
            // c / big lies in [-1, 1]: the cell along that edge of the face.
            const int k = int((c / big + 1) * (grid / 2.0));
            return std::size_t(std::clamp(k, 0, grid - 1));
        };
        const std::size_t face = 2 * axis + (d[axis] < 0 ? 1 : 0);
        return (face * grid + slot(d[u])) * grid + slot(d[v]);
    }

    /// The neighbours from the triangles, after checking that they form a closed surface that is
    /// convex at every edge (exactly); otherwise the graph stays empty and the queries scan.
    void build_from_triangles(const std::vector<std::array<std::uint32_t, 3>>& triangles,
                              const std::vector<std::uint32_t>& index) {
        struct HalfEdge {
            std::uint32_t from, to, opposite;  // `opposite`: the triangle's third vertex
        };
        std::vector<HalfEdge> edges;
        edges.reserve(3 * triangles.size());
        for (const auto& t : triangles) {
            const std::uint32_t a = index[t[0]], b = index[t[1]], c = index[t[2]];
            if (a == none || b == none || c == none) return;
            edges.push_back({a, b, c});
            edges.push_back({b, c, a});
            edges.push_back({c, a, b});
        }
        const auto before = [](const HalfEdge& x, const HalfEdge& y) {
            return x.from < y.from || (x.from == y.from && x.to < y.to);
        };
        std::sort(edges.begin(), edges.end(), before);
        const std::size_t n = vertices_.size();
        // A vertex is inside a flat facet when every edge at it joins two coplanar triangles.
        std::vector<std::uint8_t> flat(n, 1);
        for (std::size_t k = 0; k < edges.size(); ++k) {
            const HalfEdge& e = edges[k];
            if (k > 0 && !before(edges[k - 1], e)) return;  // an edge twice: not a closed surface
            const HalfEdge twin{e.to, e.from, 0};
            const auto it = std::lower_bound(edges.begin(), edges.end(), twin, before);
            if (it == edges.end() || it->from != e.to || it->to != e.from) return;
            // The twin's third vertex must not be above this triangle's plane (the triangle is
            // e.from, e.to, e.opposite, counterclockwise from outside).
            const int side = orient3d_sign(vertices_[e.from], vertices_[e.to],
                                           vertices_[e.opposite], vertices_[it->opposite]);
            if (side > 0) return;
            if (side != 0) flat[e.from] = flat[e.to] = 0;
        }
        first_.assign(n + 1, 0);
        for (const HalfEdge& e : edges) ++first_[e.from + 1];
        for (std::size_t i = 0; i < n; ++i) first_[i + 1] += first_[i];
        adjacent_.resize(edges.size());
        for (std::size_t k = 0; k < edges.size(); ++k) adjacent_[k] = edges[k].to;  // sorted
        for (std::size_t i = 0; i < n; ++i)
            if (first_[i] == first_[i + 1]) {  // a vertex on no triangle: cannot be reached
                first_.clear();
                adjacent_.clear();
                return;
            }
        flat_ = std::move(flat);
    }

    /// A convex polygon (in order round it): each vertex's two neighbours on the ring. Every
    /// corner is strict, so none lies inside a flat facet.
    void build_ring(const std::vector<std::uint32_t>& ring,
                    const std::vector<std::uint32_t>& index) {
        const std::size_t n = vertices_.size();
        if (ring.size() != n) return;
        first_.resize(n + 1);
        adjacent_.resize(2 * n);
        for (std::size_t i = 0; i <= n; ++i) first_[i] = std::uint32_t(2 * i);
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t at = index[ring[k]];
            adjacent_[2 * at] = index[ring[(k + n - 1) % n]];
            adjacent_[2 * at + 1] = index[ring[(k + 1) % n]];
        }
        flat_.assign(n, 0);
    }

    /// Each cell's start: the best vertex for the cell centre's direction (by rounded values; a
    /// start needs to be good, not exact) among the vertices not inside a flat facet, which exist
    /// (the hull's corners).
    void build_starts() {
        for (std::size_t face = 0; face < 6; ++face)
            for (int i = 0; i < grid; ++i)
                for (int j = 0; j < grid; ++j) {
                    const std::size_t axis = face / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
                    Vec<double, 3> d{};
                    d[axis] = face % 2 == 0 ? 1.0 : -1.0;
                    d[u] = (2.0 * i + 1) / grid - 1;
                    d[v] = (2.0 * j + 1) / grid - 1;
                    std::uint32_t best = none;
                    double best_value = -std::numeric_limits<double>::infinity();
                    for (std::uint32_t k = 0; k < vertices_.size(); ++k) {
                        if (flat_[k]) continue;
                        const double x = value(d, k);
                        if (best == none || x > best_value) {
                            best = k;
                            best_value = x;
                        }
                    }
                    if (best == none) {  // no corner: impossible for a convex surface
                        first_.clear();
                        adjacent_.clear();
                        flat_.clear();
                        return;
                    }
                    starts_[(face * grid + std::size_t(i)) * grid + std::size_t(j)] = best;
                }
    }

    std::vector<Vec<T, 3>> vertices_;
    std::vector<std::uint32_t> first_;     // CSR offsets: the neighbours of i are
    std::vector<std::uint32_t> adjacent_;  // adjacent_[first_[i] .. first_[i + 1])
    std::vector<std::uint8_t> flat_;       // 1: inside a flat facet
    std::array<std::uint32_t, 6 * grid * grid> starts_{};
    double largest_ = 0;  // the largest |coordinate| of a vertex
};

}  // namespace bvhkit
