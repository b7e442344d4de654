#pragma once
// convex_signed_distance: the distance between two posed convex shapes when they are apart, minus
// the penetration depth when they overlap, with witness points and the normal. The penetration
// depth is the length of the shortest translation of B that separates the shapes: the distance from
// the origin to the boundary of D = A - B, min over unit n of h_D(n), h_D the support function.
//
// Apart: GJK (convex/distance.hpp). Overlapping: the expanding polytope algorithm (EPA, van den
// Bergen 2001, "Proximity queries and penetration depth computation on 3D game objects"): start
// from a tetrahedron of D's points holding the origin (GJK's last simplex, completed by support
// points when GJK stopped on a smaller one), then repeatedly take the face nearest the origin, add
// D's support point along its normal, and replace the faces that point sees by a cone to the
// horizon. The nearest face's distance bounds the depth from below and h_D along its normal from
// above; EPA stops when they agree within a relative tolerance, or at the vertex capacity.
//
// EPA runs on the cores, like GJK: the depth of (core + ball) is the core's depth plus the margins,
// since h of a set swept by a ball of radius r is h + r. A core difference with no interior (two
// sphere centres, two crossing capsule axes, a flat hull and a sphere's centre) has depth 0 along
// the normal of the smallest flat it lies in; the margins give the whole depth then.
//
// The depth returned is h_D along the normal returned (computed, so up to rounding): moving B by
// slightly more than the depth along the normal separates the shapes, by slightly less does not.
//
// Storage: a fixed-capacity polytope (EpaPolytope, ~25 KB on the stack), no allocation.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>

#include "bvhkit/convex/distance.hpp"

namespace bvhkit {

/// The answer of convex_signed_distance (world frame).
template <class T>
struct ConvexSignedDistance {
    /// The distance when apart (> 0), minus the penetration depth when overlapping (<= 0).
    T signed_distance = 0;
    /// Apart: the closest points. Overlapping: the deepest points, point_a on A's boundary and
    /// point_b on B's, such that B moved by depth * normal brings point_b to point_a. Always
    /// point_b - point_a = signed_distance * normal (to rounding).
    Vec<T, 3> point_a{}, point_b{};
    /// The unit direction from A to B: apart, along the closest points; overlapping, the
    /// direction B must move (by the depth) to separate.
    Vec<T, 3> normal{};
    int gjk_iterations = 0;
    int epa_iterations = 0;
    /// False when EPA stopped at its capacity or on a rounding-broken polytope before its bounds
    /// met: the answer is then the best upper bound of the depth it found (still separating).
    bool converged = true;
};

namespace convex_detail {

inline constexpr std::size_t epa_max_vertices = 128;
inline constexpr std::size_t epa_max_faces = 2 * epa_max_vertices;  // a closed triangulated sphere
inline constexpr std::uint16_t epa_none = 0xffff;

/// EPA's relative tolerance between the depth's lower and upper bounds.
template <class T>
constexpr T epa_relative_tolerance() {
    return sizeof(T) > sizeof(float) ? T(1e-10) : T(1e-5);
}

template <class T>
struct EpaFace {
    std::array<std::uint16_t, 3> v{};                 // counterclockwise seen from outside
    std::array<std::uint16_t, 3> nb{};                // the face across edge (v[i], v[i + 1])
    Vec<T, 3> normal{};                               // unit, outward; zero for a face without area
    T distance = std::numeric_limits<T>::infinity();  // normal . v[0]; infinity without area
    std::uint32_t mark = 0;
    bool alive = false;
};

struct EpaHorizonEdge {
    std::uint16_t from, to, across, across_edge;
};

/// The expanding polytope in fixed-capacity arrays (no allocation).
template <class T>
struct EpaPolytope {
    std::array<Vec<T, 3>, epa_max_vertices> w{}, a{};  // points of D, and of A behind them
    std::size_t vertex_count = 0;
    std::array<EpaFace<T>, epa_max_faces> faces{};
    std::size_t face_slots = 0;  // slots used so far; dead ones go on the free list
    std::array<std::uint16_t, epa_max_faces> free_list{};
    std::size_t free_count = 0;
    std::array<std::uint16_t, epa_max_vertices> starts{};
    std::array<std::uint16_t, epa_max_faces> stack{}, visible{};
    std::array<EpaHorizonEdge, epa_max_faces> horizon{};
    std::uint32_t round = 0;
};

/// The result of EPA on a core pair (working frame).
template <class T>
struct EpaResult {
    T depth = 0;
    Vec<T, 3> normal{};
    // A point of A's core; the core point of B is witness_a - depth * normal.
    Vec<T, 3> witness_a{};
    int iterations = 0;
    bool converged = true;
};

template <class T>
class Epa {
  public:
    Epa(const ShapePair<T>& pair, EpaPolytope<T>& poly) : p_(pair), s_(poly) {}

    /// `simplex`: GJK's last simplex, whose hull holds the origin (within the tolerance);
    /// `fallback`: the normal's direction when D has no interior.
    EpaResult<T> run(const GjkSimplex<T>& simplex, const Vec<T, 3>& fallback) {
        EpaResult<T> r;
        if (!initial_tetrahedron(simplex, fallback, r)) return r;
        T best_upper = std::numeric_limits<T>::infinity();
        const T rel = epa_relative_tolerance<T>(), tol = p_.abs_tolerance;
        for (;; ++r.iterations) {
            const std::uint16_t f = nearest_face();
            if (f == epa_none) {
                r.converged = false;
                break;
            }
            const EpaFace<T>& face = s_.faces[f];
            const Vec<T, 3> n = face.normal;
            const auto [w, a] = p_.support(n);
            const T upper = dot(n, w);
            if (upper < best_upper) {
                best_upper = upper;
                r.depth = upper;
                r.normal = n;
                r.witness_a = on_support_plane(face_witness(face), n, a);
            }
            // Converged: this face's answer, even when an earlier face's upper bound was lower
            // (by less than the tolerance): an early, large face's witness may lie deep inside a
            // curved shape, this one's lies within the tolerance of the boundary.
            if (upper - face.distance <= rel * std::fabs(upper) + tol || s_.w[face.v[0]] == w ||
                s_.w[face.v[1]] == w || s_.w[face.v[2]] == w) {
                r.depth = upper;
                r.normal = n;
                r.witness_a = on_support_plane(face_witness(face), n, a);
                break;
            }
            if (s_.vertex_count == epa_max_vertices || !expand(f, w, a)) {
                r.converged = false;
                break;
            }
        }
        // A depth below zero is the rounding of an origin on the boundary.
        if (r.depth < T(0)) r.depth = T(0);
        return r;
    }

  private:
    std::uint16_t add_vertex(const Vec<T, 3>& w, const Vec<T, 3>& a) {
        s_.w[s_.vertex_count] = w;
        s_.a[s_.vertex_count] = a;
        return std::uint16_t(s_.vertex_count++);
    }

    /// The simplex completed to a tetrahedron by support points; false (and `r` set to depth 0)
    /// when D has no interior within the tolerance.
    bool initial_tetrahedron(const GjkSimplex<T>& simplex, const Vec<T, 3>& fallback,
                             EpaResult<T>& r) {
        const T tol = p_.abs_tolerance;
        std::array<Vec<T, 3>, 4> w, a;
        const std::size_t given = simplex.size();
        for (std::size_t i = 0; i < given; ++i) {
            w[i] = simplex.point(i);
            a[i] = simplex.point_a(i);
        }
        r.witness_a = simplex_witness_a(simplex);
        // Second point: the simplex's farthest from the first, else D's along the axes.
        std::size_t have = 1;
        const auto take_farthest = [&](auto&& distance_of, std::size_t slot,
                                       std::initializer_list<Vec<T, 3>> directions) {
            T best = tol;
            bool found = false;
            for (std::size_t i = slot; i < given; ++i) {
                const T d = distance_of(w[i]);
                if (d > best) {
                    best = d;
                    std::swap(w[i], w[slot]);
                    std::swap(a[i], a[slot]);
                    found = true;
                }
            }
            if (found) return true;
            for (const Vec<T, 3>& dir : directions) {
                const auto [sw, sa] = p_.support(dir);
                const T d = distance_of(sw);
                if (d > best) {
                    best = d;
                    w[slot] = sw;
                    a[slot] = sa;
                    found = true;
                }
            }
            return found;
        };
        const Vec<T, 3> x{T(1), T(0), T(0)}, y{T(0), T(1), T(0)}, z{T(0), T(0), T(1)};
        if (!take_farthest([&](const Vec<T, 3>& q) { return length(q - w[0]); }, have,
                           {x, -x, y, -y, z, -z}))
            return flat(r, fallback, Vec<T, 3>{});
        ++have;
        const Vec<T, 3> axis = normalize(w[1] - w[0]);
        const Vec<T, 3> u = normalize(cross(axis, std::fabs(axis[0]) < T(0.6) ? x : y));
        const Vec<T, 3> v = cross(axis, u);
        if (!take_farthest([&](const Vec<T, 3>& q) { return length(cross(q - w[0], axis)); }, have,
                           {u, -u, v, -v, u + v, -u - v, u - v, v - u}))
            return flat(r, fallback, axis);
        ++have;
        const Vec<T, 3> n = normalize(cross(w[1] - w[0], w[2] - w[0]));
        if (!take_farthest([&](const Vec<T, 3>& q) { return std::fabs(dot(q - w[0], n)); }, have,
                           {n, -n}))
            return flat(r, fallback, n, true);
        for (std::size_t i = 0; i < 4; ++i) add_vertex(w[i], a[i]);
        // Outward faces need the fourth corner behind the first face.
        std::uint16_t c0 = 0, c1 = 1, c2 = 2, c3 = 3;
        if (dot(cross(w[1] - w[0], w[2] - w[0]), w[3] - w[0]) > T(0)) std::swap(c1, c2);
        const std::array<std::array<std::uint16_t, 3>, 4> tet{
            {{c0, c1, c2}, {c0, c3, c1}, {c1, c3, c2}, {c2, c3, c0}}};
        for (const auto& t : tet) make_face(t[0], t[1], t[2]);
        for (std::size_t f = 0; f < 4; ++f)
            for (std::size_t e = 0; e < 3; ++e) {
                const std::uint16_t from = s_.faces[f].v[e], to = s_.faces[f].v[(e + 1) % 3];
                for (std::uint16_t g = 0; g < 4; ++g)
                    for (std::size_t k = 0; k < 3; ++k)
                        if (s_.faces[g].v[k] == to && s_.faces[g].v[(k + 1) % 3] == from)
                            s_.faces[f].nb[e] = g;
            }
        return true;
    }

    /// D lies in a flat (a point, a line, a plane) within the tolerance: depth 0, and the normal
    /// perpendicular to the flat, turned towards `fallback` when it can be.
    bool flat(EpaResult<T>& r, const Vec<T, 3>& fallback, const Vec<T, 3>& along,
              bool along_is_normal = false) {
        r.depth = T(0);
        Vec<T, 3> n;
        if (along_is_normal) {
            n = along;
        } else {
            // Perpendicular to `along` (zero for a point): the fallback's part across it.
            n = fallback - along * dot(fallback, along);
            if (!(length_squared(n) > T(0)))
                n = cross(along, std::fabs(along[0]) < T(0.6) ? Vec<T, 3>{T(1), T(0), T(0)}
                                                              : Vec<T, 3>{T(0), T(1), T(0)});
            if (!(length_squared(n) > T(0))) n = {T(0), T(0), T(1)};
            n = normalize(n);
        }
        if (dot(n, fallback) < T(0)) n = -n;
        r.normal = n;
        return false;
    }

    std::uint16_t make_face(std::uint16_t i, std::uint16_t j, std::uint16_t k) {
        std::uint16_t f;
        if (s_.free_count > 0) {
            f = s_.free_list[--s_.free_count];
        } else {
            f = std::uint16_t(s_.face_slots++);
        }
        EpaFace<T>& face = s_.faces[f];
        face.v = {i, j, k};
        face.nb = {epa_none, epa_none, epa_none};
        face.alive = true;
        face.mark = 0;
        const Vec<T, 3> n = cross(s_.w[j] - s_.w[i], s_.w[k] - s_.w[i]);
        const T len = length(n);
        if (len > T(0) && std::isfinite(len)) {
            face.normal = n * (T(1) / len);
            face.distance = dot(face.normal, s_.w[i]);
        } else {
            face.normal = {};
            face.distance = std::numeric_limits<T>::infinity();
        }
        return f;
    }

    std::uint16_t nearest_face() const {
        std::uint16_t best = epa_none;
        T best_distance = std::numeric_limits<T>::infinity();
        for (std::size_t f = 0; f < s_.face_slots; ++f)
            if (s_.faces[f].alive && s_.faces[f].distance < best_distance) {
                best_distance = s_.faces[f].distance;
                best = std::uint16_t(f);
            }
        return best;
    }

    /// The face's point of A moved along n onto A's supporting plane (through A's support point
    /// `a_support`): a no-op on a flat part of A; on a curved one it lifts the point from the
    /// polytope's chord to the tangent plane, and point_b (witness - depth * n) to B's.
    static Vec<T, 3> on_support_plane(const Vec<T, 3>& witness, const Vec<T, 3>& n,
                                      const Vec<T, 3>& a_support) {
        return witness + n * dot(n, a_support - witness);
    }

    /// The barycentric weights of q in face f's triangle (its plane), unclamped.
    std::array<T, 3> weights_in(const EpaFace<T>& face, const Vec<T, 3>& q) const {
        const Vec<T, 3>& p0 = s_.w[face.v[0]];
        const Vec<T, 3> e1 = s_.w[face.v[1]] - p0, e2 = s_.w[face.v[2]] - p0, d = q - p0;
        const T d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
        const T d1 = dot(d, e1), d2 = dot(d, e2);
        const T denominator = d11 * d22 - d12 * d12;
        T l1 = T(1) / T(3), l2 = T(1) / T(3);
        if (denominator > T(0)) {
            l1 = (d22 * d1 - d12 * d2) / denominator;
            l2 = (d11 * d2 - d12 * d1) / denominator;
        }
        return {T(1) - l1 - l2, l1, l2};
    }

    /// The point of A behind the origin's projection q on the face. Faces that nearly tie for
    /// nearest (a flat or straight part of D cut into triangles, coplanar up to rounding or the
    /// curvature between their corners) share q between them, and q may lie just outside this
    /// one: then the point of those faces nearest q (Ericson's closest point on a triangle, by
    /// GjkSimplex) gives the weights.
    Vec<T, 3> face_witness(const EpaFace<T>& face) const {
        const Vec<T, 3> q = face.normal * face.distance;
        const std::array<T, 3> l = weights_in(face, q);
        const T slack = T(-64) * std::numeric_limits<T>::epsilon();
        if (std::min({l[0], l[1], l[2]}) >= slack)
            return s_.a[face.v[0]] * l[0] + s_.a[face.v[1]] * l[1] + s_.a[face.v[2]] * l[2];
        T best = std::numeric_limits<T>::infinity();
        Vec<T, 3> witness{};
        for (std::size_t f = 0; f < s_.face_slots; ++f) {
            const EpaFace<T>& other = s_.faces[f];
            if (!other.alive || dot(other.normal, face.normal) < T(0.5)) continue;
            GjkSimplex<T> triangle;
            for (const std::uint16_t i : other.v) triangle.add(s_.w[i] - q, s_.a[i]);
            bool unused = false;
            const T gap = length_squared(triangle.nearest(unused));
            if (gap < best) {
                best = gap;
                witness = triangle.witness_a();
            }
        }
        return witness;
    }

    bool sees(const EpaFace<T>& face, const Vec<T, 3>& w) const {
        return dot(face.normal, w) - face.distance > T(0);
    }

    /// Adds w (a point of D beyond face f) and replaces the faces it sees by a cone to the
    /// horizon. False when rounding broke the polytope (the horizon is not one loop).
    bool expand(std::uint16_t f, const Vec<T, 3>& w, const Vec<T, 3>& a) {
        const std::uint32_t round = ++s_.round;
        std::size_t stack_size = 0, visible_count = 0, horizon_count = 0;
        s_.stack[stack_size++] = f;
        s_.faces[f].mark = round;
        while (stack_size > 0) {
            const std::uint16_t g = s_.stack[--stack_size];
            s_.visible[visible_count++] = g;
            for (std::size_t e = 0; e < 3; ++e) {
                const std::uint16_t h = s_.faces[g].nb[e];
                if (h == epa_none) return false;
                if (s_.faces[h].mark == round) continue;
                if (sees(s_.faces[h], w)) {
                    s_.faces[h].mark = round;
                    s_.stack[stack_size++] = h;
                } else {
                    const std::uint16_t from = s_.faces[g].v[e], to = s_.faces[g].v[(e + 1) % 3];
                    std::uint16_t back = epa_none;
                    for (std::uint16_t k = 0; k < 3; ++k)
                        if (s_.faces[h].v[k] == to && s_.faces[h].v[(k + 1) % 3] == from) back = k;
                    if (back == epa_none) return false;
                    s_.horizon[horizon_count++] = {from, to, h, back};
                }
            }
        }
        // The cone adds horizon_count faces and removes visible_count.
        const std::size_t live = s_.face_slots - s_.free_count;
        if (live - visible_count + horizon_count > epa_max_faces) return false;
        for (std::size_t i = 0; i < visible_count; ++i) {
            s_.faces[s_.visible[i]].alive = false;
            s_.free_list[s_.free_count++] = s_.visible[i];
        }
        const std::uint16_t eye = add_vertex(w, a);
        for (std::size_t i = 0; i < s_.vertex_count; ++i) s_.starts[i] = epa_none;
        std::uint16_t first = epa_none;
        for (std::size_t i = 0; i < horizon_count; ++i) {
            const EpaHorizonEdge& e = s_.horizon[i];
            const std::uint16_t g = make_face(e.from, e.to, eye);
            s_.faces[g].nb[0] = e.across;
            s_.faces[e.across].nb[e.across_edge] = g;
            if (s_.starts[e.from] != epa_none) return false;  // the horizon is not one loop
            s_.starts[e.from] = g;
            if (first == epa_none) first = g;
        }
        // Across (to, eye) is the new face starting at `to`; across (eye, from) the one ending at
        // `from`.
        for (std::size_t i = 0; i < horizon_count; ++i) {
            const std::uint16_t g = s_.starts[s_.horizon[i].from];
            const std::uint16_t next = s_.starts[s_.horizon[i].to];
            if (next == epa_none) return false;
            s_.faces[g].nb[1] = next;
            s_.faces[next].nb[2] = g;
        }
        return first != epa_none;
    }

    const ShapePair<T>& p_;
    EpaPolytope<T>& s_;
};

}  // namespace convex_detail

/// The signed distance between shape `a` at `pose_a` and shape `b` at `pose_b` (rigid poses,
/// world frame): the distance when apart, minus the penetration depth when overlapping, with the
/// witness points and the normal (convex/penetration.hpp's header comment). Throws Error for a
/// pose that is not finite or not rigid.
template <class T>
ConvexSignedDistance<T> convex_signed_distance(const ConvexShape<T>& a, const Transform<T>& pose_a,
                                               const ConvexShape<T>& b,
                                               const Transform<T>& pose_b) {
    const convex_detail::ShapePair<T> pair =
        convex_detail::make_shape_pair(a, pose_a, b, pose_b, true, "convex_signed_distance");
    const convex_detail::GjkRun<T> g = convex_detail::run_gjk(pair);
    ConvexSignedDistance<T> r;
    r.gjk_iterations = g.iterations;
    const T ma = a.margin(), mb = b.margin();
    Vec<T, 3> core_a, n;
    T core_signed;  // the cores' signed distance
    // In the working frame (scaled by a power of two), then back in world units below.
    if (!g.overlap) {
        core_signed = length(g.v);
        n = g.v * (T(-1) / core_signed);
        core_a = g.simplex.witness_a();
    } else {
        convex_detail::EpaPolytope<T> polytope;
        convex_detail::Epa<T> epa(pair, polytope);
        // Without an interior, the normal leans towards B's position from A's.
        const convex_detail::EpaResult<T> e = epa.run(g.simplex, pair.b.offset);
        r.epa_iterations = e.iterations;
        r.converged = e.converged;
        core_signed = -e.depth;
        n = e.normal;
        core_a = e.witness_a;
    }
    core_signed *= pair.unscale;
    core_a = core_a * pair.unscale;
    r.signed_distance = core_signed - ma - mb;
    r.normal = n;
    r.point_a = core_a + n * ma + pair.origin;
    r.point_b = core_a + n * (core_signed - mb) + pair.origin;
    return r;
}

}  // namespace bvhkit
