#pragma once
// ConvexHull<T, Cap>: the tightest bounding volume of the classic list, the convex hull of a node's
// vertices, with at most Cap vertices so that every node has the same size.
//
// Fitting. A node with at most Cap distinct vertices keeps them all: its volume is their exact
// hull. A larger node takes the vertices of its hull (Quickhull, volumes/quickhull.hpp, exact
// orientation tests), keeps Cap of them, and is swept by a sphere of radius `margin` that covers
// what was dropped: the volume is conv(kept) + ball(margin), with margin the largest distance of a
// dropped hull vertex to conv(kept). That covers every vertex of the node: the distance to a
// convex set is a convex function, so over conv(hull vertices) it is largest at a vertex. The kept
// vertices are chosen greedily, each time the one farthest from the hull of those kept so far
// (starting from the extremes along x, y and z), which keeps margin small. Distances come from
// GJK in double and are rounded up, so the volume is conservative.
//
// Tests. Two hulls are apart when some direction v separates them by more than both margins and
// the slack: min over A of v.a - max over B of v.b > (margin_a + margin_b + slack) |v|. GJK
// (Gilbert, Johnson and Keerthi 1988; volumes/gjk.hpp) searches the direction, but the decision is
// taken on the support values alone with a bound on their rounding, so no rounding in GJK can make
// two meeting volumes "apart". A bounding-sphere test goes first. The same support values give the
// distance lower bound. Under a pose, B's points are moved on the fly (B's directions are taken
// into B's frame once per step: v . (R b + t) = (R^T v) . b + v . t).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <span>
#include <vector>

#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/volumes/bounding_volume.hpp"
#include "bvhkit/volumes/gjk.hpp"
#include "bvhkit/volumes/quickhull.hpp"

namespace bvhkit {

template <class T, std::size_t Cap = 16>
struct ConvexHull {
    static_assert(Cap >= 4, "a hull needs room for a tetrahedron");
    using Scalar = T;
    static constexpr std::size_t capacity = Cap;

    std::array<Vec<T, 3>, Cap> points{};  // the kept vertices; the first `count` are used
    std::uint32_t count = 0;              // 0: empty (meets nothing)
    T margin = 0;                         // radius of the sphere swept over conv(points)
    Vec<T, 3> center{};                   // centre of the points' box
    T reach = 0;  // half the points' box diagonal + margin: a bounding sphere's radius

    bool is_empty() const { return count == 0; }
    std::span<const Vec<T, 3>> vertices() const { return {points.data(), count}; }
};

namespace hull_detail {

/// Whether q lies in the tetrahedron of the simplex's four points of A, exactly (a flat one
/// counts as "not known").
inline bool certainly_inside(const GjkSimplex<double>& simplex, const Vec<double, 3>& q) {
    if (simplex.size() != 4) return false;
    static constexpr int faces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};
    for (const auto& f : faces) {
        const auto& a = simplex.point_a(std::size_t(f[0]));
        const auto& b = simplex.point_a(std::size_t(f[1]));
        const auto& c = simplex.point_a(std::size_t(f[2]));
        const int opposite = orient3d_sign(a, b, c, simplex.point_a(std::size_t(f[3])));
        if (opposite == 0) return false;
        const int side = orient3d_sign(a, b, c, q);
        if (side != 0 && side != opposite) return false;
    }
    return true;
}

/// An upper bound of the distance from p to conv(s), by GJK in double: every step's nearest point
/// is a convex combination of s, so its distance can only be too large (the rounding of the
/// combination is added); the least of them is returned. GJK stops when the support point adds
/// nothing (within rounding, or a vertex it holds already: rounding would otherwise make it cycle).
template <class T>
double distance_to_hull(const Vec<T, 3>& p, std::span<const Vec<T, 3>> s) {
    const Vec<double, 3> q(p);
    double scale = length(q);
    for (const auto& a : s) scale = std::max(scale, length(Vec<double, 3>(a)));
    const double pad = 16 * std::numeric_limits<double>::epsilon() * scale;
    // The distance to the point the simplex's weights (clamped, normalised) give.
    const auto measured = [&](const GjkSimplex<double>& simplex) {
        Vec<double, 3> x{};
        double total = 0;
        const auto weights = simplex.weights();
        for (std::size_t i = 0; i < weights.size(); ++i) {
            const double l = std::max(weights[i], 0.0);
            x += simplex.point_a(i) * l;
            total += l;
        }
        if (!(total > 0)) return std::numeric_limits<double>::infinity();
        return length(q - x * (1 / total)) * (1 + 1e-15) + pad;
    };
    GjkSimplex<double> simplex;
    Vec<double, 3> v = Vec<double, 3>(s[0]) - q;
    double best = length(v) * (1 + 1e-15) + pad;
    for (int step = 0; step < 64; ++step) {
        std::size_t pick = 0;
        double low = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < s.size(); ++i) {
            const double d = dot(v, Vec<double, 3>(s[i]));
            if (d < low) {
                low = d;
                pick = i;
            }
        }
        const Vec<double, 3> a(s[pick]);
        const Vec<double, 3> w = a - q;
        const double v2 = length_squared(v);
        if (step > 0 && (v2 - dot(v, w) <= 1e-10 * v2 || simplex.holds(w))) break;
        simplex.add(w, a);
        bool inside = false;
        v = simplex.nearest(inside);
        // The rounded face tests of a tetrahedron with a needle-thin face can put the origin
        // inside while the point lies outside by far more than `pad` (seen: 1e-10 at a scale of
        // 600 in double): only an exact test may return pad; otherwise the least distance
        // measured so far stays the (conservative) answer.
        if (inside) return certainly_inside(simplex, q) ? pad : best;
        best = std::min(best, measured(simplex));
        if (length_squared(v) == 0) break;
    }
    return best;
}

/// Rounds a non-negative double up to T.
template <class T>
T round_up(double x) {
    return round_up_to<T>(x);
}

/// `cap` of the hull vertices `hull`: the extremes along the axes, then greedily the vertex
/// farthest from the hull of those kept (distances only shrink as vertices are kept, so a stale
/// distance is an upper bound and the candidates wait in a max-heap until their turn). Adds the
/// largest distance of a vertex left out to `margin`.
template <class T>
std::vector<std::uint32_t> select_farthest_as_given(std::span<const Vec<T, 3>> points,
                                                    const std::vector<std::uint32_t>& hull,
                                                    std::size_t cap, double& margin);

/// The distances square coordinates in double, which overflows for a double model beyond about
/// 1e154 and sinks below 1e-154: there the points are divided by a power of two first (exact but
/// for coordinates far below the rest, which move by less than the fit's pads) and the margin
/// multiplied back.
template <class T>
std::vector<std::uint32_t> select_farthest(std::span<const Vec<T, 3>> points,
                                           const std::vector<std::uint32_t>& hull, std::size_t cap,
                                           double& margin) {
    if constexpr (sizeof(T) > sizeof(float)) {
        double m = 0;
        for (std::uint32_t i : hull)
            for (std::size_t a = 0; a < 3; ++a) m = std::max(m, std::fabs(double(points[i][a])));
        if (const int k = squaring_exponent(m); k != 0) {
            std::vector<Vec<T, 3>> scaled(points.size());
            const T unit = T(std::ldexp(1.0, -k));
            for (std::uint32_t i : hull) scaled[i] = points[i] * unit;
            double added = 0;
            std::vector<std::uint32_t> keep =
                select_farthest_as_given<T>(std::span<const Vec<T, 3>>(scaled), hull, cap, added);
            margin += std::ldexp(added, k);
            return keep;
        }
    }
    return select_farthest_as_given<T>(points, hull, cap, margin);
}

template <class T>
std::vector<std::uint32_t> select_farthest_as_given(std::span<const Vec<T, 3>> points,
                                                    const std::vector<std::uint32_t>& hull,
                                                    std::size_t cap, double& margin) {
    std::vector<std::uint32_t> keep;
    std::vector<Vec<T, 3>> kept;
    auto take = [&](std::uint32_t i) {
        if (keep.size() == cap || std::find(keep.begin(), keep.end(), i) != keep.end()) return;
        keep.push_back(i);
        kept.push_back(points[i]);
    };
    for (std::size_t axis = 0; axis < 3; ++axis) {
        auto [lo, hi] = std::minmax_element(hull.begin(), hull.end(), [&](auto a, auto b) {
            return points[a][axis] < points[b][axis];
        });
        take(*lo);
        take(*hi);
    }
    using Entry = std::pair<double, std::uint32_t>;
    std::priority_queue<Entry> heap;
    // First bounds: the distance to the nearest kept vertex (no less than to their hull).
    for (std::uint32_t i : hull) {
        if (std::find(keep.begin(), keep.end(), i) != keep.end()) continue;
        double nearest = std::numeric_limits<double>::infinity();
        for (const Vec<T, 3>& k : kept)
            nearest = std::min(nearest, length(Vec<double, 3>(points[i]) - Vec<double, 3>(k)));
        heap.push({nearest * (1 + 1e-12), i});
    }
    // A vertex within rounding of the kept hull is not worth keeping; its distance still counts.
    double size = 0;
    for (std::uint32_t i : hull) size = std::max(size, length(Vec<double, 3>(points[i])));
    const double negligible = 64 * std::numeric_limits<double>::epsilon() * size;
    double worst = 0;
    while (keep.size() < cap && !heap.empty()) {
        const std::uint32_t i = heap.top().second;
        heap.pop();
        const double d = distance_to_hull<T>(points[i], kept);
        if (d <= negligible) {
            worst = std::max(worst, d);
            continue;
        }
        if (heap.empty() || d >= heap.top().first)
            take(i);
        else
            heap.push({d, i});
    }
    // The largest distance left out: stale values bound the true ones from above, so the scan
    // stops at the first one no larger than the largest found.
    while (!heap.empty() && heap.top().first > worst) {
        worst = std::max(worst, distance_to_hull<T>(points[heap.top().second], kept));
        heap.pop();
    }
    margin += worst;
    return keep;
}

/// The hull volume of `points` (sorted, unique; `hull_vertices`: already all extreme), swept by
/// at least `margin`.
template <class T, std::size_t Cap>
ConvexHull<T, Cap> hull_of(std::span<const Vec<T, 3>> points, double margin,
                           bool hull_vertices = false) {
    ConvexHull<T, Cap> v;
    if (points.empty()) return v;
    std::vector<std::uint32_t> keep;
    if (points.size() <= Cap) {
        for (std::uint32_t i = 0; i < points.size(); ++i) keep.push_back(i);
    } else {
        std::vector<std::uint32_t> hull;
        if (hull_vertices)
            for (std::uint32_t i = 0; i < points.size(); ++i) hull.push_back(i);
        else
            hull = quickhull_vertices(points);
        keep = hull.size() <= Cap ? hull : select_farthest<T>(points, hull, Cap, margin);
    }
    Aabb<T, 3> box;
    for (std::uint32_t i : keep) {
        v.points[v.count++] = points[i];
        box.grow(points[i]);
    }
    v.margin = margin > 0 ? round_up<T>(margin) : T(0);
    for (std::size_t a = 0; a < 3; ++a) v.center[a] = midpoint_of(box.min[a], box.max[a]);
    // The box's half diagonal, which never shrinks when volumes merge (so size() grows from child
    // to parent), or, when the centre's rounding (far from the origin) leaves a vertex farther,
    // that vertex's distance: the sphere holds every kept vertex.
    // Lengths without squaring (wide_length): squares overflow double for a model at 1e155.
    double half = wide_length(Vec<double, 3>(box.max) - Vec<double, 3>(box.min)) * 0.5;
    for (std::uint32_t i = 0; i < v.count; ++i)
        half = std::max(half, wide_length(Vec<double, 3>(v.points[i]) - Vec<double, 3>(v.center)));
    v.reach = round_up<T>((half + double(v.margin)) * (1 + 1e-12)) * (T(1) + detail::fit_pad<T>);
    return v;
}

/// Sorted, unique copy of `points`, without the non-finite ones: a NaN breaks the sort's
/// ordering and the exact predicates' expansions (merge() of a volume holding one overflowed a
/// stack buffer in orient3d), and such a point bounds nothing (CollisionModel skips those
/// triangles too).
template <class T>
std::vector<Vec<T, 3>> sorted_unique(std::vector<Vec<T, 3>> points) {
    std::erase_if(points, [](const Vec<T, 3>& p) { return !is_finite(p); });
    std::sort(points.begin(), points.end(),
              [](const Vec<T, 3>& a, const Vec<T, 3>& b) { return lexicographic_less(a, b); });
    points.erase(std::unique(points.begin(), points.end()), points.end());
    return points;
}

}  // namespace hull_detail

template <class T, std::size_t Cap>
struct VolumeTraits<ConvexHull<T, Cap>> {
    using V = ConvexHull<T, Cap>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = false;

    static V fit(std::span<const Triangle<T>> tris) {
        return hull_detail::hull_of<T, Cap>(corners(tris), 0.0);
    }
    /// Every node of a tree (children after their parent in `nodes`), each from the exact hull
    /// vertices of its children: the hull of a union is the hull of the parts' hull vertices, so
    /// no node reads its whole run of triangles again. The volumes are those fit() gives.
    template <class Nodes>
    static void fit_tree(Nodes& nodes, std::span<const Triangle<T>> slot_triangles) {
        std::vector<std::vector<Vec<T, 3>>> hulls(nodes.size());
        for (std::size_t n = nodes.size(); n-- > 0;) {
            auto& node = nodes[n];
            std::vector<Vec<T, 3>> points;
            if (node.is_leaf()) {
                points = corners(slot_triangles.subspan(node.first, node.count));
            } else {
                for (std::size_t child : {std::size_t(node.left()), std::size_t(node.right())}) {
                    points.insert(points.end(), hulls[child].begin(), hulls[child].end());
                    hulls[child] = {};
                }
                points = hull_detail::sorted_unique(std::move(points));
            }
            // `points` is sorted, so the vertices in index order are sorted too.
            std::vector<std::uint32_t> vertices = quickhull_vertices<T>(points);
            std::sort(vertices.begin(), vertices.end());
            for (std::uint32_t i : vertices) hulls[n].push_back(points[i]);
            node.bounds = hull_detail::hull_of<T, Cap>(hulls[n], 0.0, true);
        }
    }
    /// conv(A) + ball(ra) and conv(B) + ball(rb) both lie in conv(A u B) + ball(max(ra, rb)).
    static V merge(const V& a, const V& b) {
        if (a.is_empty()) return b;
        if (b.is_empty()) return a;
        std::vector<Vec<T, 3>> points(a.points.begin(), a.points.begin() + a.count);
        points.insert(points.end(), b.points.begin(), b.points.begin() + b.count);
        points = hull_detail::sorted_unique(std::move(points));
        return hull_detail::hull_of<T, Cap>(points, double(std::max(a.margin, b.margin)));
    }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b) {
        return overlaps(a, b, prepare(Transform<T>::identity(), T(0)));
    }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        if (a.is_empty() || b.is_empty()) return false;
        return search(a, b, p, true) <= T(0);
    }
    static T size(const V& v) { return v.reach * v.reach; }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        if (a.is_empty() || b.is_empty()) return T(0);
        return std::max(T(0), search(a, b, p, false));
    }

  private:
    /// The triangles' corners, sorted, without duplicates.
    static std::vector<Vec<T, 3>> corners(std::span<const Triangle<T>> tris) {
        std::vector<Vec<T, 3>> points;
        points.reserve(3 * tris.size());
        for (const auto& t : tris) {
            points.push_back(t.p0);
            points.push_back(t.p1);
            points.push_back(t.p2);
        }
        return hull_detail::sorted_unique(std::move(points));
    }
    /// The largest certified separation of the two volumes found (<= 0: none). `decide`: stop at
    /// the first positive one, or as soon as the cores are seen to lie closer than the margins.
    static T search(const V& a, const V& b, const Prepared& p, bool decide) {
        constexpr T eps = std::numeric_limits<T>::epsilon();
        const T inflate = a.margin + b.margin + p.slack;
        const Vec<T, 3> cb = p.r * b.center + p.t;
        // A bound on the rounding of every support value below, per unit of |v|.
        const T err =
            T(16) * eps * (length(a.center) + a.reach + length(b.center) + b.reach + length(p.t));
        Vec<T, 3> v = a.center - cb;
        T best = length(v) - a.reach - b.reach - p.slack - err;
        if (decide && best > T(0)) return best;
        if (!(length_squared(v) > T(0))) v = {T(1), T(0), T(0)};
        GjkSimplex<T> simplex;
        for (int step = 0; step < 32; ++step) {
            const Vec<T, 3> u = p.r.transpose_times(v);
            std::uint32_t ia = 0, ib = 0;
            T ha = dot(v, a.points[0]), hb = dot(u, b.points[0]);
            for (std::uint32_t i = 1; i < a.count; ++i) {
                const T d = dot(v, a.points[i]);
                if (d < ha) {
                    ha = d;
                    ia = i;
                }
            }
            for (std::uint32_t j = 1; j < b.count; ++j) {
                const T d = dot(u, b.points[j]);
                if (d > hb) {
                    hb = d;
                    ib = j;
                }
            }
            hb += dot(v, p.t);
            const T len = length(v);
            // The gap along v / |v|, made smaller by every rounding it may hold.
            const T gap = (ha - hb - err * len) / (len * (T(1) + T(8) * eps)) - inflate;
            if (gap > best) {
                best = gap;
                if (decide && best > T(0)) return best;
            }
            const Vec<T, 3> w = a.points[ia] - (p.r * b.points[ib] + p.t);
            const T v2 = len * len;
            // As close as it gets (or a point it holds: rounding would make it cycle).
            if (step > 0 && (v2 - dot(v, w) <= T(1e-4) * v2 || simplex.holds(w))) break;
            simplex.add(w, a.points[ia]);
            bool inside = false;
            v = simplex.nearest(inside);
            if (inside || !(length_squared(v) > T(0))) break;
            // The cores are within the margins of each other: the volumes meet.
            if (decide && length(v) < inflate) break;
        }
        return best;
    }
};

using ConvexHullf = ConvexHull<float, 16>;

}  // namespace bvhkit
