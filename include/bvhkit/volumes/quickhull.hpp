#pragma once
// The vertices of the convex hull of a point set, by Quickhull (Barber, Dobkin and Huhdanpaa 1996):
// start from a tetrahedron of extreme points; give every point outside a face to that face; then,
// while a face has points outside it, take the farthest one (the eye), remove the faces it sees,
// close the hole with a cone of new faces from the eye to the horizon, and hand the removed faces'
// points to the new faces they are outside of (the others are inside the hull now).
//
// Every "is this point outside that face" is decided exactly (orient3d_sign), so the hull's
// vertices hold every input point in their convex hull, whatever the rounding; only the choice of
// the farthest point uses floating point. Points that are all coplanar get a hull in their plane
// (Andrew's monotone chain on a projection that keeps the plane's orientations, decided exactly by
// orient2d_sign); collinear points get their two ends.
//
// Input: points sorted and without duplicates (quickhull_vertices sorts a copy). Output: indices
// into the input, in no particular order. Memory O(n); no recursion.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "bvhkit/math/predicates.hpp"
#include "bvhkit/math/vec.hpp"
#include "bvhkit/math/wide_length.hpp"

namespace bvhkit {

/// The hull's surface as Quickhull leaves it, indices into the input points. `dimension` 3: the
/// vertices and the triangles of a closed surface, each triangle counterclockwise seen from
/// outside, every input point on or inside every triangle's plane (decided exactly), so the
/// surface is convex, though neighbouring triangles may be coplanar and a vertex may lie inside a
/// flat facet. 2: the vertices of a convex polygon in order round it, each a strict corner, no
/// triangles. 0: the vertices only (three points or fewer, collinear points, or the fallback that
/// keeps every point).
struct HullSurface {
    int dimension = 0;
    std::vector<std::uint32_t> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

namespace hull_detail {

template <class T>
class Quickhull {
  public:
    explicit Quickhull(std::span<const Vec<T, 3>> points) : p_(points) {}

    HullSurface surface() {
        HullSurface out;
        const std::size_t n = p_.size();
        if (n <= 3) {
            out.vertices = all();
            return out;
        }
        std::array<std::uint32_t, 4> s{};
        const int dimension = initial_simplex(s);
        if (dimension == 1) {
            out.vertices = {s[0], s[1]};
            return out;
        }
        if (dimension == 2) {
            out.dimension = 2;
            out.vertices = planar_hull(s);
            return out;
        }
        build_tetrahedron(s);
        std::vector<std::uint32_t> rest;
        rest.reserve(n);
        for (std::uint32_t i = 0; i < n; ++i)
            if (i != s[0] && i != s[1] && i != s[2] && i != s[3]) rest.push_back(i);
        distribute(rest, 0);
        expand();
        if (broken_) {  // cannot happen with exact tests; all points stay correct
            out.vertices = all();
            return out;
        }
        out.dimension = 3;
        std::vector<char> used(n, 0);
        for (const Face& f : faces_)
            if (f.alive) {
                out.triangles.push_back(f.v);
                for (std::uint32_t v : f.v)
                    if (!used[v]) {
                        used[v] = 1;
                        out.vertices.push_back(v);
                    }
            }
        return out;
    }

  private:
    struct Face {
        std::array<std::uint32_t, 3> v;   // counterclockwise seen from outside
        std::array<std::uint32_t, 3> nb;  // the face across edge (v[i], v[i + 1])
        Vec<double, 3> normal;            // unnormalized, for choosing the farthest point only
        std::vector<std::uint32_t> outside;
        bool alive = true;
    };

    std::vector<std::uint32_t> all() const {
        std::vector<std::uint32_t> out(p_.size());
        for (std::uint32_t i = 0; i < out.size(); ++i) out[i] = i;
        return out;
    }
    Vec<double, 3> point(std::uint32_t i) const { return Vec<double, 3>(p_[i]); }
    bool outside(const Face& f, std::uint32_t i) const {
        return orient3d_sign(p_[f.v[0]], p_[f.v[1]], p_[f.v[2]], p_[i]) > 0;
    }
    double height(const Face& f, std::uint32_t i) const {
        return dot(f.normal, point(i) - point(f.v[0]));
    }

    /// Two points far apart, a third far from their line, a fourth far from their plane; returns
    /// the dimension of the set (1: collinear, 2: coplanar, 3).
    int initial_simplex(std::array<std::uint32_t, 4>& s) const {
        // The points are sorted: the first and last are the ends of the set along x (then y, z).
        s[0] = 0;
        s[1] = std::uint32_t(p_.size() - 1);
        double best = 0;
        const Vec<double, 3> a = point(s[0]), ab = point(s[1]) - a;
        for (std::uint32_t i = 1; i + 1 < p_.size(); ++i) {
            const double d = length_squared(cross(ab, point(i) - a));
            if (d > best) {
                best = d;
                s[2] = i;
            }
        }
        // The rounded cross product of exactly collinear points need not be zero (the
        // differences round), so the pick is checked exactly: a collinear s[2] while another
        // point is off the line would make every orientation below zero and the set "flat".
        if ((best == 0 || !off_line(s, s[2])) && !find_off_line(s)) return 1;
        const Vec<double, 3> n = cross(ab, point(s[2]) - a);
        best = -1;
        for (std::uint32_t i = 0; i < p_.size(); ++i) {
            const double d = std::fabs(dot(n, point(i) - a));
            if (d > best && i != s[0] && i != s[1] && i != s[2]) {
                best = d;
                s[3] = i;
            }
        }
        if (orient3d_sign(p_[s[0]], p_[s[1]], p_[s[2]], p_[s[3]]) != 0) return 3;
        // The farthest by rounding may be coplanar while another point is not: look exactly.
        for (std::uint32_t i = 0; i < p_.size(); ++i)
            if (orient3d_sign(p_[s[0]], p_[s[1]], p_[s[2]], p_[i]) != 0) {
                s[3] = i;
                return 3;
            }
        return 2;
    }
    /// Whether point i is off the line through s[0] and s[1], exactly.
    bool off_line(const std::array<std::uint32_t, 4>& s, std::uint32_t i) const {
        for (int axis = 0; axis < 3; ++axis)
            if (projected_orientation(s[0], s[1], i, axis) != 0) return true;
        return false;
    }
    /// The sign of triangle (a, b, c) projected along `axis`, exactly.
    int projected_orientation(std::uint32_t a, std::uint32_t b, std::uint32_t c, int axis) const {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        return orient2d_sign(p_[a][u], p_[a][v], p_[b][u], p_[b][v], p_[c][u], p_[c][v]);
    }
    /// The rounded distance said "on the line"; an exact look for a point off it.
    bool find_off_line(std::array<std::uint32_t, 4>& s) const {
        for (std::uint32_t i = 1; i + 1 < p_.size(); ++i)
            if (off_line(s, i)) {
                s[2] = i;
                return true;
            }
        return false;
    }

    /// Coplanar points: the hull in the plane, on the projection along the normal's largest
    /// component (an affine map that is one-to-one on the plane, so the orientations are kept).
    std::vector<std::uint32_t> planar_hull(const std::array<std::uint32_t, 4>& s) const {
        // The rounded normal of a nearly collinear s[0], s[1], s[2] may be largest along an axis
        // the plane holds (a projection along it flattens the plane to a line): only axes whose
        // projection keeps the triangle's area, decided exactly, are candidates.
        const Vec<double, 3> n = cross(point(s[1]) - point(s[0]), point(s[2]) - point(s[0]));
        std::size_t drop = 3;
        for (std::size_t axis = 0; axis < 3; ++axis)
            if (projected_orientation(s[0], s[1], s[2], int(axis)) != 0 &&
                (drop == 3 || std::fabs(n[axis]) > std::fabs(n[drop])))
                drop = axis;
        const std::size_t u = (drop + 1) % 3, v = (drop + 2) % 3;
        std::vector<std::uint32_t> order = all();
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            return p_[a][u] < p_[b][u] || (p_[a][u] == p_[b][u] && p_[a][v] < p_[b][v]);
        });
        // Andrew's monotone chain: lower then upper chain, keeping strict left turns only.
        std::vector<std::uint32_t> hull(2 * order.size());
        std::size_t k = 0;
        auto left_turn = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
            return orient2d_sign(p_[a][u], p_[a][v], p_[b][u], p_[b][v], p_[c][u], p_[c][v]) > 0;
        };
        for (std::uint32_t i : order) {
            while (k >= 2 && !left_turn(hull[k - 2], hull[k - 1], i)) --k;
            hull[k++] = i;
        }
        const std::size_t lower = k + 1;
        for (std::size_t j = order.size() - 1; j-- > 0;) {
            while (k >= lower && !left_turn(hull[k - 2], hull[k - 1], order[j])) --k;
            hull[k++] = order[j];
        }
        hull.resize(k - 1);  // the last point repeats the first
        return hull;
    }

    Face make_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
        Face f;
        f.v = {a, b, c};
        f.nb = {0, 0, 0};
        f.normal = cross(point(b) - point(a), point(c) - point(a));
        return f;
    }

    void build_tetrahedron(std::array<std::uint32_t, 4> s) {
        // Outward faces need the fourth corner below the first face.
        if (orient3d_sign(p_[s[0]], p_[s[1]], p_[s[2]], p_[s[3]]) > 0) std::swap(s[1], s[2]);
        const std::uint32_t a = s[0], b = s[1], c = s[2], d = s[3];
        faces_ = {make_face(a, b, c), make_face(a, d, b), make_face(b, d, c), make_face(c, d, a)};
        // Neighbours: the face holding the reversed edge.
        for (std::uint32_t f = 0; f < 4; ++f)
            for (int e = 0; e < 3; ++e) {
                const std::uint32_t from = faces_[f].v[e], to = faces_[f].v[(e + 1) % 3];
                for (std::uint32_t g = 0; g < 4; ++g)
                    for (int k = 0; k < 3; ++k)
                        if (faces_[g].v[k] == to && faces_[g].v[(k + 1) % 3] == from)
                            faces_[f].nb[e] = g;
            }
    }

    /// Gives each point to the first face (from `first_face` on) it is outside of.
    void distribute(const std::vector<std::uint32_t>& points, std::size_t first_face) {
        for (std::uint32_t i : points)
            for (std::size_t f = first_face; f < faces_.size(); ++f)
                if (faces_[f].alive && outside(faces_[f], i)) {
                    faces_[f].outside.push_back(i);
                    break;
                }
    }

    void expand() {
        std::vector<std::uint32_t> visible, stack, orphans;
        std::vector<std::uint32_t> starts(p_.size(), UINT32_MAX);
        // The round that last reached each face: clearing a flag per face every round made the
        // rounds quadratic in the faces ever made.
        std::vector<std::size_t> seen;
        // Each round makes one more hull vertex, so the rounds are at most the points; more would
        // mean a broken hull, answered by keeping every point.
        for (std::size_t f = 0, rounds = 0; f < faces_.size(); ++f) {
            if (!faces_[f].alive || faces_[f].outside.empty()) continue;
            if (++rounds > p_.size()) {
                broken_ = true;
                return;
            }
            const std::uint32_t eye = farthest(faces_[f]);
            // The faces the eye sees form one connected patch around face f.
            seen.resize(faces_.size(), 0);
            visible.clear();
            stack.assign(1, std::uint32_t(f));
            seen[f] = rounds;
            while (!stack.empty()) {
                const std::uint32_t g = stack.back();
                stack.pop_back();
                visible.push_back(g);
                for (std::uint32_t h : faces_[g].nb)
                    if (seen[h] != rounds && outside(faces_[h], eye)) {
                        seen[h] = rounds;
                        stack.push_back(h);
                    }
            }
            // The cone: one new face per horizon edge (visible on one side only).
            const std::size_t first_new = faces_.size();
            for (std::uint32_t g : visible)
                for (int e = 0; e < 3; ++e) {
                    const std::uint32_t across = faces_[g].nb[e];
                    if (seen[across] == rounds) continue;
                    const std::uint32_t a = faces_[g].v[e], b = faces_[g].v[(e + 1) % 3];
                    Face nf = make_face(a, b, eye);
                    nf.nb[0] = across;
                    for (auto& back : faces_[across].nb)
                        if (back == g) back = std::uint32_t(faces_.size());
                    if (starts[a] != UINT32_MAX) broken_ = true;  // the horizon is not one loop
                    starts[a] = std::uint32_t(faces_.size());
                    faces_.push_back(std::move(nf));
                }
            // Link the cone: across (b, eye) is the new face starting at b, across (eye, a) the
            // one ending at a.
            for (std::size_t g = first_new; g < faces_.size(); ++g) {
                const std::uint32_t b = faces_[g].v[1];
                if (broken_ || starts[b] == UINT32_MAX) {
                    broken_ = true;
                    return;
                }
                faces_[g].nb[1] = starts[b];
                faces_[starts[b]].nb[2] = std::uint32_t(g);
            }
            for (std::size_t g = first_new; g < faces_.size(); ++g)
                starts[faces_[g].v[0]] = UINT32_MAX;
            orphans.clear();
            for (std::uint32_t g : visible) {
                faces_[g].alive = false;
                for (std::uint32_t i : faces_[g].outside)
                    if (i != eye) orphans.push_back(i);
                faces_[g].outside.clear();
                faces_[g].outside.shrink_to_fit();
            }
            distribute(orphans, first_new);
        }
    }

    std::uint32_t farthest(const Face& f) const {
        std::uint32_t best = f.outside[0];
        double best_h = height(f, best);
        for (std::uint32_t i : f.outside) {
            const double h = height(f, i);
            if (h > best_h) {
                best_h = h;
                best = i;
            }
        }
        return best;
    }

    std::span<const Vec<T, 3>> p_;
    std::vector<Face> faces_;
    bool broken_ = false;
};

}  // namespace hull_detail

/// The hull's surface over `sorted_unique` (sorted lexicographically, no duplicates): every input
/// point lies in the convex hull of its vertices, exactly.
///
/// The orientation tests are exact only for coordinate differences within 2^±300 (predicates.hpp):
/// a double model beyond about 1e77 or below 1e-77 is divided by a power of two first (an exact,
/// order-keeping scaling), unless that would merge points (coordinates far below the rest sinking
/// into denormals), where the points are taken as they are.
template <class T>
HullSurface quickhull_surface(std::span<const Vec<T, 3>> sorted_unique) {
    if constexpr (sizeof(T) > sizeof(float)) {
        double m = 0;
        for (const Vec<T, 3>& p : sorted_unique)
            for (std::size_t a = 0; a < 3; ++a) m = std::max(m, std::fabs(double(p[a])));
        if (const int k = squaring_exponent(m); k != 0) {
            std::vector<Vec<T, 3>> scaled(sorted_unique.size());
            const T unit = T(std::ldexp(1.0, -k));
            bool distinct = true;
            for (std::size_t i = 0; i < scaled.size(); ++i) {
                scaled[i] = sorted_unique[i] * unit;
                if (i > 0 && scaled[i] == scaled[i - 1]) distinct = false;
            }
            if (distinct)
                return hull_detail::Quickhull<T>(std::span<const Vec<T, 3>>(scaled)).surface();
        }
    }
    return hull_detail::Quickhull<T>(sorted_unique).surface();
}

/// Indices of the hull's vertices among `sorted_unique` (quickhull_surface's vertices).
template <class T>
std::vector<std::uint32_t> quickhull_vertices(std::span<const Vec<T, 3>> sorted_unique) {
    return quickhull_surface<T>(sorted_unique).vertices;
}

/// Lexicographic order, the order quickhull_vertices expects.
template <class T>
bool lexicographic_less(const Vec<T, 3>& a, const Vec<T, 3>& b) {
    return a[0] < b[0] || (a[0] == b[0] && (a[1] < b[1] || (a[1] == b[1] && a[2] < b[2])));
}

}  // namespace bvhkit
