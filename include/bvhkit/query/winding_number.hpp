#pragma once
// Generalized winding number of a triangle mesh at a point (Jacobson, Kavan and Sorkine-Hornung
// 2013, "Robust inside-outside segmentation using generalized winding numbers"): the sum of the
// signed solid angles of the triangles seen from the point, over 4 pi. 1 inside and 0 outside a
// closed outward-oriented mesh; for a mesh with holes, a smooth value that is still near 1 deep
// inside and near 0 far outside, so w > 1/2 is a robust inside test where the pseudonormal sign
// (signed_distance.hpp) fails.
//
// Exact: every triangle's solid angle (Van Oosterom and Strackee 1983), linear in the mesh size.
// Fast: the hierarchical approximation of Barill et al. 2018 ("Fast winding numbers for soups and
// clouds"): a node whose triangles all lie within radius r of their area-weighted centre c, seen
// from a point farther than beta * r from c, counts as its Taylor expansion; nearer nodes are
// opened (leaves summed exactly). Order 1 is the dipole,
//     w_node = (c - q) . sum(a_i n_i) / (4 pi |c - q|^3);
// order 2 adds the first moment M = sum(a_i (centroid_i - c) (x) n_i) against the Jacobian of
// r / |r|^3: (tr M / |r|^3 - 3 r.M.r / |r|^5) / (4 pi), r = c - q; order 3 (the default, Barill
// et al.'s second order, libigl's default) adds the second moment
// S_jki = sum over triangles of n_i * integral of (x - c)_j (x - c)_k dA against the Hessian:
// (1/2) H_ijk S_jki / (4 pi), H_ijk = -3 (d_ij r_k + d_ik r_j + d_jk r_i) / |r|^5
// + 15 r_i r_j r_k / |r|^7. A triangle's integral is exact: area * ((g - c)(g - c)^T +
// sum over corners (v - g)(v - g)^T / 12), g its centroid.
// Measured against exact() on spot for 3,000 points within 1% of the diagonal from the surface,
// beta = 2 (tests/proximity/winding_accuracy_test.cpp prints these): order 1 mean error 0.027,
// max 0.065, 92% of points off by more than 1e-2; order 2 mean 0.010, max 0.036, 46%; order 3:
// see docs/accuracy.md. Far from the surface the error falls off fast. A larger beta is more
// exact and slower; beta must be at least 1.
//
// Range: both are right for every finite mesh and point. The solid angles are evaluated in double
// (for a double mesh beyond 2^±300, on the normalized directions), and each node's expansion is
// kept in units of a power of two near its half-extent (the moments grow like the fourth power
// of the coordinates) and evaluated on (c - q) in those units, so nothing overflows or
// underflows (tests/proximity/winding_scale_test.cpp: 1e-30 to 1e30 in float, 1e-300 to 1e300
// in double, off the origin).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <type_traits>

#include "bvhkit/build/build.hpp"
#include "bvhkit/bvh/traverse.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/query/point_order.hpp"

namespace bvhkit {

namespace serial_detail {
struct WindingNumberMeshAccess;  // io/winding_number_mesh_file.hpp: saves and loads the arrays
}

namespace winding_detail {

/// The type solid angles and expansions are evaluated in: double for float and double meshes
/// (a float mesh's products of up to five coordinates fit in double's exponent range).
template <class T>
using Wide = std::conditional_t<(sizeof(T) > sizeof(double)), T, double>;

/// Van Oosterom and Strackee (1983) on the directions of A, B, C alone: each vector is divided
/// by its largest component, then by its length, so no product overflows or underflows whatever
/// the scale. A zero vector (q on a corner) gives 0; a non-finite one NaN.
template <class W>
W solid_angle_of_directions(const Vec<W, 3>* v) {
    Vec<W, 3> u[3];
    for (int k = 0; k < 3; ++k) {
        const W m = max_component(abs(v[k]));
        if (!(m > W(0) && m <= std::numeric_limits<W>::max()))
            return m == W(0) ? W(0) : std::numeric_limits<W>::quiet_NaN();
        u[k] = v[k] / m;
        u[k] = u[k] / length(u[k]);
    }
    const W num = dot(u[0], cross(u[1], u[2]));
    const W den = W(1) + dot(u[0], u[1]) + dot(u[1], u[2]) + dot(u[2], u[0]);
    return W(2) * std::atan2(num, den);
}

/// solid_angle() where a squared length lies outside the range its fast path needs: in W, on the
/// normalized directions where W's range needs it too.
template <class T>
[[gnu::noinline]] T solid_angle_careful(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c,
                                        const Vec<T, 3>& q) {
    using W = Wide<T>;
    const Vec<W, 3> qw(q);
    Vec<W, 3> v[3] = {Vec<W, 3>(a) - qw, Vec<W, 3>(b) - qw, Vec<W, 3>(c) - qw};
    const W la2 = length_squared(v[0]), lb2 = length_squared(v[1]), lc2 = length_squared(v[2]);
    // With every squared length in [2^-600, 2^600] the products of three lengths below neither
    // overflow nor underflow in W; a float mesh's are always there in double, save a zero vector.
    constexpr W lo = W(0x1p-600), hi = W(0x1p600);
    if (la2 >= lo && lb2 >= lo && lc2 >= lo && la2 <= hi && lb2 <= hi && lc2 <= hi) {
        const W la = std::sqrt(la2), lb = std::sqrt(lb2), lc = std::sqrt(lc2);
        const W num = dot(v[0], cross(v[1], v[2]));
        const W den =
            la * lb * lc + dot(v[0], v[1]) * lc + dot(v[1], v[2]) * la + dot(v[2], v[0]) * lb;
        return T(W(2) * std::atan2(num, den));
    }
    const Vec<T, 3>* corners[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k)
        if (!is_finite(v[k]))  // a - q overflowed: the halves' difference has its direction
            v[k] = Vec<W, 3>(*corners[k]) * W(0.5) - qw * W(0.5);
    return T(solid_angle_of_directions(v));
}

}  // namespace winding_detail

/// Solid angle of triangle (a, b, c) seen from q, signed: positive when q sees its back (the side
/// opposite to (b - a) x (c - a)). Van Oosterom and Strackee (1983): in T where the products of
/// three lengths stay in T's normal range, else in double, on the normalized directions where
/// double's range needs it too: right for every finite input.
template <class T>
T solid_angle(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& q) {
    constexpr T lo = std::is_same_v<T, float> ? T(0x1p-80) : T(0x1p-600);
    constexpr T hi = std::is_same_v<T, float> ? T(0x1p80) : T(0x1p600);
    const Vec<T, 3> A = a - q, B = b - q, C = c - q;
    const T la2 = length_squared(A), lb2 = length_squared(B), lc2 = length_squared(C);
    if (std::min(la2, std::min(lb2, lc2)) >= lo && std::max(la2, std::max(lb2, lc2)) <= hi)
        [[likely]] {
        const T la = std::sqrt(la2), lb = std::sqrt(lb2), lc = std::sqrt(lc2);
        const T num = dot(A, cross(B, C));
        const T den = la * lb * lc + dot(A, B) * lc + dot(B, C) * la + dot(C, A) * lb;
        return T(2) * std::atan2(num, den);
    }
    return winding_detail::solid_angle_careful(a, b, c, q);
}

template <class T>
class WindingNumberMesh {
  public:
    template <IndexedTriangleMesh M>
    explicit WindingNumberMesh(const M& mesh, const BuildOptions& options = {}) {
        std::vector<Aabb<T, 3>> boxes(mesh.triangle_count());
        std::vector<Vec<T, 3>> centroids(mesh.triangle_count());
        std::vector<Triangle<T>> tris(mesh.triangle_count());
        check_triangle_indices(mesh);
        for (std::size_t i = 0; i < tris.size(); ++i) {
            tris[i] = triangle_at<T>(mesh, i);
            boxes[i] = tris[i].bounds();
            centroids[i] = boxes[i].centroid();
        }
        bvh_ = build_bvh<T, 3>(boxes, centroids, options);
        for (std::uint32_t i : bvh_.primitive_indices) tris_.push_back(tris[i]);
        derive_dipoles();
    }

  private:
    friend struct serial_detail::WindingNumberMeshAccess;
    WindingNumberMesh() = default;  // for the loader, which fills bvh_ and tris_

    using W = winding_detail::Wide<T>;

    /// What derive_dipoles() keeps per node for the node's parent. Every sum is in units of the
    /// node's scale s, a power of two near its box's half-extent (area / s^2, first moment / s^3,
    /// second / s^4), so none overflows or underflows at any coordinate scale, and rescaling by
    /// a child's s / s' is exact.
    struct NodeMoments {
        Vec<W, 3> origin{};  // the box's centre
        W scale = 1, inv_scale = 1;
        Vec<W, 3> an{};               // sum of area-weighted normals
        Vec<W, 3> weighted_centre{};  // sum of area * (centroid - origin)
        W area = 0;
        Vec<W, 3> centre{};          // area-weighted centre rounded to T (absolute): the moments
                                     // are about the point the walk reads
        Vec<W, 3> centre_n{};        // (centre - origin) / scale
        std::array<W, 9> first{};    // sum a_i (centroid_i - centre) (x) n_i
        std::array<W, 27> second{};  // S[9 * j + 3 * k + i]
    };

    // The dipoles from bvh_ and tris_ alone (a loaded file derives them so): per node the sum of
    // area-weighted normals, the area-weighted centre, the first and second moments about it, and
    // a radius, children before parents (reverse array order). Sums in W.
    void derive_dipoles() {
        const std::size_t n = bvh_.nodes.size();
        dipoles_.resize(n);
        std::vector<NodeMoments> moments(n);
        for (std::size_t k = n; k-- > 0;) {
            const auto& node = bvh_.nodes[k];
            NodeMoments& m = moments[k];
            set_frame(node.bounds, m);
            if (node.is_leaf()) {
                leaf_area_and_centre(node, m);
            } else {
                for (std::uint32_t ch : {node.left(), node.right()}) {
                    const NodeMoments& c = moments[ch];
                    const W rho2 = square(c.scale * m.inv_scale);
                    m.an += c.an * rho2;
                    m.area += c.area * rho2;
                    m.weighted_centre += (c.centre - m.origin) * (m.inv_scale * c.area * rho2);
                }
            }
            const Vec<W, 3> c = m.area > W(0) ? m.weighted_centre / m.area : Vec<W, 3>(W(0));
            m.centre = Vec<W, 3>(Vec<T, 3>(m.origin + c * m.scale));
            m.centre_n = (m.centre - m.origin) * m.inv_scale;
            if (node.is_leaf()) {
                add_leaf_moments(node, m);
            } else {
                for (std::uint32_t ch : {node.left(), node.right()})
                    add_child_moments(moments[ch], m);
            }
            store_dipole(node, m, dipoles_[k]);
        }
    }

  public:
    /// The exact winding number: every triangle's solid angle.
    T exact(const Vec<T, 3>& q) const {
        double sum = 0;
        for (const auto& t : tris_) sum += double(solid_angle(t.p0, t.p1, t.p2, q));
        return T(sum / (4 * std::numbers::pi));
    }

    /// Barill et al.'s approximation; `beta` (>= 1, +inf allowed: exact) trades accuracy for
    /// speed. Throws Error for a beta below 1 or NaN: nearer than its radius a node's expansion
    /// does not converge.
    T fast(const Vec<T, 3>& q, T beta = T(2), int order = 3) const {
        check_beta(beta);
        check_order(order);
        if (bvh_.empty()) return T(0);
        const Vec<W, 3> qw(q);
        if (!is_finite(qw)) return std::numeric_limits<T>::quiet_NaN();
        const W beta2 = W(beta) * W(beta);
        W sum = 0;
        // Depth first, the right child first (the order the sum has always been taken in): a
        // node far enough for its expansion is summed and not entered.
        const auto enter = [&](std::uint32_t k) {
            const Dipole& d = dipoles_[k];
            const Vec<T, 3> r = d.centre - q;
            const T rr = length_squared(r);
            if (rr >= safe_lo && rr <= safe_hi) [[likely]] {
                // |r|^2 neither overflowed nor lost precision to underflow: decide in T as ever
                // (radius is rounded up, so a node is never taken for farther than it is).
                const T dist = std::sqrt(rr);
                if (dist > beta * d.radius) {
                    const W inv_dist = W(1) / W(dist);
                    sum += expansion(d, Vec<W, 3>(r) * inv_dist, d.scale * inv_dist, order);
                    return false;
                }
            } else if (far_in_scale_units(d, qw, beta2, order, sum)) {
                return false;
            }
            return true;
        };
        const auto on_leaf = [&](std::uint32_t k) {
            for (const LeafSlot s : leaf_slots(bvh_.nodes[k])) {  // tris_ is in leaf order
                const Triangle<T>& t = tris_[s.value];
                sum += W(solid_angle(t.p0, t.p1, t.p2, q));
            }
            return true;
        };
        TraversalStack stack;
        walk_depth_first(BvhNodes<BvhNode<Aabb<T, 3>>>{bvh_.nodes.data()}, stack, enter, on_leaf,
                         FirstChild::Right);
        return T(sum / (4 * std::numbers::pi));
    }

    /// fast() for many points (in parallel with oneTBB; the same values as serial).
    void fast(std::span<const Vec<T, 3>> points, std::span<T> out, T beta = T(2),
              unsigned threads = 0, int order = 3) const {
        fast(points, out, beta, Executor(threads), order);
    }
    /// fast() for many points, on `exec`.
    void fast(std::span<const Vec<T, 3>> points, std::span<T> out, T beta, const Executor& exec,
              int order = 3) const {
        check_beta(beta);
        check_order(order);
        if (out.size() < points.size())
            throw Error("WindingNumberMesh::fast: " + std::to_string(points.size()) +
                        " points but room for " + std::to_string(out.size()));
        for_point_chunks(points, exec, 512, [&](std::span<const std::uint32_t> chunk) {
            for (const std::uint32_t i : chunk) out[i] = fast(points[i], beta, order);
        });
    }

    bool inside(const Vec<T, 3>& q, T beta = T(2)) const { return fast(q, beta) > T(0.5); }

  private:
    static void check_beta(T beta) {
        if (!(beta >= T(1)))
            throw Error("WindingNumberMesh::fast: beta must be at least 1 (or +inf), got " +
                        std::to_string(double(beta)));
    }
    static void check_order(int order) {
        if (order < 1 || order > 3)
            throw Error("WindingNumberMesh::fast: order must be 1, 2 or 3, got " +
                        std::to_string(order));
    }
    struct Dipole {
        Vec<T, 3> centre;  // area-weighted centre (first: the walk reads it and radius first)
        T radius = 0;      // rounded up to T (+inf where T cannot hold it)
        W scale = 1;       // s, the node's scale (NodeMoments), a power of two
        T radius2 = 0;     // (radius / s)^2
        // The expansion's terms in units of s (NodeMoments), so that they stay in T's range:
        Vec<T, 3> an;      // sum of area * unit normal, / s^2
        T moment[9] = {};  // sum of area * (centroid - centre) (x) unit normal, row-major, / s^3
        // The second moment S_jki / s^4 for the six (j <= k) pairs (00, 01, 02, 11, 12, 22),
        // then i, the off-diagonal pairs doubled (they stand for jk and kj); and
        // traces_j = 2 sum_i S_jii + sum_i S_iij.
        T second[18] = {};
        T traces[3] = {};
    };
    static W square(W x) { return x * x; }
    // The squared distances at which the walk decides in T: T's rounding is still relative
    // there (no underflow), and nothing overflows.
    static constexpr T safe_lo = std::is_same_v<T, float> ? T(0x1p-100) : T(0x1p-900);
    static constexpr T safe_hi = std::is_same_v<T, float> ? T(0x1p100) : T(0x1p900);
    /// The node's expansion seen from q, for c - q = |c - q| e and inv = s / |c - q| (distances
    /// in units of the node's scale s, see NodeMoments): g(r) = r / |r|^3 integrated over the
    /// node is e . an / |r|^2, then (order 2) its Jacobian against the first moment,
    /// (tr M - 3 e.M.e) / |r|^3, then (order 3) the second-moment term / |r|^4.
    static W expansion(const Dipole& d, const Vec<W, 3>& e, W inv, int order) {
        W series = 0;
        if (order >= 2) {
            W trace = 0, eme = 0;
            for (int i = 0; i < 3; ++i) {
                trace += W(d.moment[4 * i]);
                for (int j = 0; j < 3; ++j) eme += e[i] * W(d.moment[3 * i + j]) * e[j];
            }
            series = trace - W(3) * eme;
            if (order == 3) series += second_order_term(d, e) * inv;
        }
        return (dot(e, Vec<W, 3>(d.an)) + series * inv) * (inv * inv);
    }
    /// The walk's test where |c - q|^2 is beyond T's safe range: in units of s throughout, in W.
    /// Adds the node's expansion to `sum` and returns true if the node is far (beta = +inf makes
    /// the product NaN or inf, so opens).
    [[gnu::noinline]] static bool far_in_scale_units(const Dipole& d, const Vec<W, 3>& qw, W beta2,
                                                     int order, W& sum) {
        const Vec<W, 3> u = (Vec<W, 3>(d.centre) - qw) / d.scale;
        const W uu = length_squared(u);
        if (!(uu > beta2 * W(d.radius2))) return false;
        // Beyond W's range the node adds less than |an| / |u|^2, below W's least value.
        if (!(uu <= std::numeric_limits<W>::max())) return true;
        const W inv = W(1) / std::sqrt(uu);
        sum += expansion(d, u * inv, inv, order);
        return true;
    }
    /// (1/2) H_ijk(r) S_jki |r|^4 (see the top of the file) for r = |r| e: with S symmetric in
    /// j, k it is (1/2) (15 e_i e_j e_k S_jki - 3 e.traces).
    static W second_order_term(const Dipole& d, const Vec<W, 3>& e) {
        const W ejek[6] = {e[0] * e[0], e[0] * e[1], e[0] * e[2],
                           e[1] * e[1], e[1] * e[2], e[2] * e[2]};
        W eS = 0;
        for (int u = 0; u < 6; ++u)
            eS += ejek[u] * (e[0] * W(d.second[3 * u]) + e[1] * W(d.second[3 * u + 1]) +
                             e[2] * W(d.second[3 * u + 2]));
        const W et = e[0] * W(d.traces[0]) + e[1] * W(d.traces[1]) + e[2] * W(d.traces[2]);
        return W(0.5) * (W(15) * eS - W(3) * et);
    }

    /// The node's frame: its box's centre and a power of two s with s <= half-extent < 2 s
    /// (clamped so that s and 1 / s are normal; 1 for a box that is a point).
    static void set_frame(const Aabb<T, 3>& box, NodeMoments& m) {
        W half = 0;
        for (int a = 0; a < 3; ++a) {
            const W lo = W(box.min[a]), hi = W(box.max[a]);
            m.origin[a] = lo * W(0.5) + hi * W(0.5);  // halves first: no overflow
            half = std::max(half, hi * W(0.5) - lo * W(0.5));
        }
        constexpr int emax = std::numeric_limits<W>::max_exponent - 4;
        const int e = half > W(0) ? std::clamp(std::ilogb(half), -emax, emax) : 0;
        m.scale = std::ldexp(W(1), e);
        m.inv_scale = std::ldexp(W(1), -e);
    }
    /// Corner v of a triangle in the node's frame.
    static Vec<W, 3> in_frame(const Vec<T, 3>& v, const NodeMoments& m) {
        return (Vec<W, 3>(v) - m.origin) * m.inv_scale;
    }

    void leaf_area_and_centre(const BvhNode<Aabb<T, 3>>& node, NodeMoments& m) const {
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
            const Triangle<T>& t = tris_[s];
            const Vec<W, 3> v0 = in_frame(t.p0, m), v1 = in_frame(t.p1, m), v2 = in_frame(t.p2, m);
            const Vec<W, 3> nrm = cross(v1 - v0, v2 - v0) * W(0.5);
            const W a = length(nrm);
            m.an += nrm;
            m.weighted_centre += (v0 + v1 + v2) * (a / W(3));
            m.area += a;
        }
    }

    static void add_outer(std::array<W, 9>& m, const Vec<W, 3>& x, const Vec<W, 3>& y) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) m[3 * i + j] += x[i] * y[j];
    }
    // sm += (x (x) y) (x) z, the first two indices symmetric by construction or by use.
    static void add_outer3(std::array<W, 27>& sm, const Vec<W, 3>& x, const Vec<W, 3>& y,
                           const Vec<W, 3>& z) {
        for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l)
                for (int i = 0; i < 3; ++i) sm[9 * j + 3 * l + i] += x[j] * y[l] * z[i];
    }

    /// A leaf's first and second moments about its centre, from its triangles: each triangle's
    /// centroid term plus its own spread (the vertices' offsets from the centroid, over 12).
    void add_leaf_moments(const BvhNode<Aabb<T, 3>>& node, NodeMoments& m) const {
        const Vec<W, 3> c = m.centre_n;
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
            const Triangle<T>& t = tris_[s];
            const Vec<W, 3> v[3] = {in_frame(t.p0, m), in_frame(t.p1, m), in_frame(t.p2, m)};
            const Vec<W, 3> g = (v[0] + v[1] + v[2]) / W(3);
            const Vec<W, 3> area_n = cross(v[1] - v[0], v[2] - v[0]) * W(0.5);
            add_outer(m.first, g - c, area_n);
            add_outer3(m.second, g - c, g - c, area_n);
            for (const Vec<W, 3>& vk : v) add_outer3(m.second, vk - g, vk - g, area_n / W(12));
        }
    }

    /// A child's moments moved from its centre c' to the parent's c, x - c = (x - c') + d, and
    /// from its scale to the parent's (an exact power of two, rho = s' / s).
    static void add_child_moments(const NodeMoments& child, NodeMoments& m) {
        const W rho = child.scale * m.inv_scale, rho2 = rho * rho, rho3 = rho2 * rho;
        const Vec<W, 3> dc = (child.centre - m.centre) * m.inv_scale;
        const Vec<W, 3> an = child.an * rho2;
        std::array<W, 9> first;
        for (int i = 0; i < 9; ++i) first[i] = child.first[i] * rho3;
        for (int i = 0; i < 9; ++i) m.first[i] += first[i];
        add_outer(m.first, dc, an);
        for (int i = 0; i < 27; ++i) m.second[i] += child.second[i] * (rho3 * rho);
        for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l)
                for (int i = 0; i < 3; ++i)
                    m.second[9 * j + 3 * l + i] +=
                        dc[j] * first[3 * l + i] + dc[l] * first[3 * j + i] + dc[j] * dc[l] * an[i];
    }

    /// The node's Dipole in T: the symmetric second moment packed, its traces, and a radius (the
    /// farthest corner of the node's box bounds every triangle below it), all in units of s.
    static void store_dipole(const BvhNode<Aabb<T, 3>>& node, const NodeMoments& m, Dipole& d) {
        const auto& sm = m.second;
        for (int j = 0, u = 0; j < 3; ++j)
            for (int kk = j; kk < 3; ++kk, ++u)
                for (int i = 0; i < 3; ++i)
                    d.second[3 * u + i] = T(sm[9 * j + 3 * kk + i] * (j == kk ? W(1) : W(2)));
        for (int j = 0; j < 3; ++j) {
            W su = 0, sv = 0;
            for (int i = 0; i < 3; ++i) su += sm[9 * j + 3 * i + i], sv += sm[9 * i + 3 * i + j];
            d.traces[j] = T(2 * su + sv);
        }
        d.an = Vec<T, 3>(m.an);
        d.centre = Vec<T, 3>(m.centre);
        d.scale = m.scale;
        for (int i = 0; i < 9; ++i) d.moment[i] = T(m.first[i]);
        W r2 = 0;
        for (int corner = 0; corner < 8; ++corner) {
            Vec<T, 3> p;
            for (int a = 0; a < 3; ++a)
                p[a] = (corner >> a & 1) ? node.bounds.max[a] : node.bounds.min[a];
            r2 = std::max(r2, length_squared(in_frame(p, m) - m.centre_n));
        }
        d.radius2 = T(r2);
        const W radius = std::sqrt(r2) * m.scale;
        d.radius = radius <= W(std::numeric_limits<T>::max()) ? T(radius)
                                                              : std::numeric_limits<T>::infinity();
        if (W(d.radius) < radius)
            d.radius = std::nextafter(d.radius, std::numeric_limits<T>::infinity());
    }

    AabbBvh<T, 3> bvh_;
    std::vector<Triangle<T>> tris_;  // leaf-slot order
    std::vector<Dipole> dipoles_;
};

}  // namespace bvhkit
