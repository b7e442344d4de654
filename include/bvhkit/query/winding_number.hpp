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

#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

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

/// Solid angle of triangle (a, b, c) seen from q, signed: positive when q sees its back (the side
/// opposite to (b - a) x (c - a)).
template <class T>
T solid_angle(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& q) {
    const Vec<T, 3> A = a - q, B = b - q, C = c - q;
    const T la = length(A), lb = length(B), lc = length(C);
    const T num = dot(A, cross(B, C));
    const T den = la * lb * lc + dot(A, B) * lc + dot(B, C) * la + dot(C, A) * lb;
    return T(2) * std::atan2(num, den);
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

    /// What derive_dipoles() keeps per node, in double, for the node's parent.
    struct NodeMoments {
        Vec<double, 3> an{};               // sum of area-weighted normals
        Vec<double, 3> weighted_centre{};  // sum of area * centroid
        double area = 0;
        Vec<double, 3> centre{};          // weighted_centre / area (the box's centre if no area)
        std::array<double, 9> first{};    // sum a_i (centroid_i - centre) (x) n_i
        std::array<double, 27> second{};  // S[9 * j + 3 * k + i]
    };

    // The dipoles from bvh_ and tris_ alone (a loaded file derives them so): per node the sum of
    // area-weighted normals, the area-weighted centre, the first and second moments about it, and
    // a radius, children before parents (reverse array order). Sums in double.
    void derive_dipoles() {
        const std::size_t n = bvh_.nodes.size();
        dipoles_.resize(n);
        std::vector<NodeMoments> moments(n);
        for (std::size_t k = n; k-- > 0;) {
            const auto& node = bvh_.nodes[k];
            NodeMoments& m = moments[k];
            if (node.is_leaf()) {
                leaf_area_and_centre(node, m);
            } else {
                for (std::uint32_t c : {node.left(), node.right()}) {
                    m.an += moments[c].an;
                    m.weighted_centre += moments[c].weighted_centre;
                    m.area += moments[c].area;
                }
            }
            m.centre =
                m.area > 0 ? m.weighted_centre / m.area : Vec<double, 3>(node.bounds.centroid());
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
        double sum = 0;
        // Its own walk, not traverse_depth_first (bvh/traverse.hpp): that one, entering the right
        // child first so the sum keeps its order, took 1.6% more instructions (63.8M against
        // 62.8M for 4000 points about a 36,864-triangle torus, callgrind). Both children are
        // pushed, so the stack holds one more than the depth.
        FixedStack<std::uint32_t, max_bvh_depth + 1> stack;
        stack.push(0);
        while (!stack.empty()) {
            const std::uint32_t k = stack.pop();
            const auto& node = bvh_.nodes[k];
            const Dipole& d = dipoles_[k];
            const Vec<T, 3> r = d.centre - q;
            const T dist = length(r);
            if (dist > beta * d.radius) {
                // g(r) = r / |r|^3 integrated over the node: g(r) . an, then (order 2) its
                // Jacobian I / |r|^3 - 3 r r^T / |r|^5 against the first moment.
                const double rr = double(dist) * dist, inv3 = 1.0 / (rr * dist);
                sum += double(dot(r, d.an)) * inv3;
                if (order >= 2) {
                    const Vec<double, 3> rd(r);
                    double trace = 0, rmr = 0;
                    for (int i = 0; i < 3; ++i) {
                        trace += double(d.moment[4 * i]);
                        for (int j = 0; j < 3; ++j)
                            rmr += rd[i] * double(d.moment[3 * i + j]) * rd[j];
                    }
                    sum += trace * inv3 - 3.0 * rmr * inv3 / rr;
                }
                if (order == 3) sum += second_order_term(d, Vec<double, 3>(r), rr, inv3);
                continue;
            }
            if (node.is_leaf()) {
                for (const LeafSlot s : leaf_slots(node)) {  // tris_ is in leaf order
                    const Triangle<T>& t = tris_[s.value];
                    sum += double(solid_angle(t.p0, t.p1, t.p2, q));
                }
                continue;
            }
            stack.push(node.left());
            stack.push(node.right());
        }
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
        T radius = 0;
        Vec<T, 3> an;      // sum of area * unit normal
        T moment[9] = {};  // sum of area * (centroid - centre) (x) unit normal, row-major
        // The second moment S_jki for the six (j <= k) pairs (00, 01, 02, 11, 12, 22), then i,
        // the off-diagonal pairs doubled (they stand for jk and kj); and
        // traces_j = 2 sum_i S_jii + sum_i S_iij.
        T second[18] = {};
        T traces[3] = {};
    };
    /// (1/2) H_ijk(r) S_jki (see the top of the file): with S symmetric in j, k it is
    /// (1/2) (-3 r.traces / |r|^5 + 15 r_i r_j r_k S_jki / |r|^7). rr = |r|^2, inv3 = 1 / |r|^3.
    static double second_order_term(const Dipole& d, const Vec<double, 3>& r, double rr,
                                    double inv3) {
        const double rjrk[6] = {r[0] * r[0], r[0] * r[1], r[0] * r[2],
                                r[1] * r[1], r[1] * r[2], r[2] * r[2]};
        double rS = 0;
        for (int u = 0; u < 6; ++u)
            rS += rjrk[u] * (r[0] * double(d.second[3 * u]) + r[1] * double(d.second[3 * u + 1]) +
                             r[2] * double(d.second[3 * u + 2]));
        const double rt =
            r[0] * double(d.traces[0]) + r[1] * double(d.traces[1]) + r[2] * double(d.traces[2]);
        const double inv5 = inv3 / rr;
        return 0.5 * inv5 * (15.0 * rS / rr - 3.0 * rt);
    }

    void leaf_area_and_centre(const BvhNode<Aabb<T, 3>>& node, NodeMoments& m) const {
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
            const Triangle<T>& t = tris_[s];
            const Vec<double, 3> nrm = Vec<double, 3>(t.normal()) * 0.5;
            const double a = length(nrm);
            m.an += nrm;
            m.weighted_centre += Vec<double, 3>(t.centroid()) * a;
            m.area += a;
        }
    }

    static void add_outer(std::array<double, 9>& m, const Vec<double, 3>& x,
                          const Vec<double, 3>& y) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) m[3 * i + j] += x[i] * y[j];
    }
    // sm += (x (x) y) (x) z, the first two indices symmetric by construction or by use.
    static void add_outer3(std::array<double, 27>& sm, const Vec<double, 3>& x,
                           const Vec<double, 3>& y, const Vec<double, 3>& z) {
        for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l)
                for (int i = 0; i < 3; ++i) sm[9 * j + 3 * l + i] += x[j] * y[l] * z[i];
    }

    /// A leaf's first and second moments about m.centre, from its triangles: each triangle's
    /// centroid term plus its own spread (the vertices' offsets from the centroid, over 12).
    void add_leaf_moments(const BvhNode<Aabb<T, 3>>& node, NodeMoments& m) const {
        const Vec<double, 3> c = m.centre;
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
            const Triangle<T>& t = tris_[s];
            const Vec<double, 3> g(t.centroid()), area_n = Vec<double, 3>(t.normal()) * 0.5;
            add_outer(m.first, g - c, area_n);
            add_outer3(m.second, g - c, g - c, area_n);
            for (const Vec<T, 3>& v : {t.p0, t.p1, t.p2}) {
                const Vec<double, 3> e = Vec<double, 3>(v) - g;
                add_outer3(m.second, e, e, area_n / 12.0);
            }
        }
    }

    /// A child's moments moved from its centre c' to the parent's c: x - c = (x - c') + d.
    static void add_child_moments(const NodeMoments& child, NodeMoments& m) {
        const Vec<double, 3> dc = child.centre - m.centre;
        for (int i = 0; i < 9; ++i) m.first[i] += child.first[i];
        add_outer(m.first, dc, child.an);
        for (int i = 0; i < 27; ++i) m.second[i] += child.second[i];
        for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l)
                for (int i = 0; i < 3; ++i)
                    m.second[9 * j + 3 * l + i] += dc[j] * child.first[3 * l + i] +
                                                   dc[l] * child.first[3 * j + i] +
                                                   dc[j] * dc[l] * child.an[i];
    }

    /// The node's Dipole in T: the symmetric second moment packed, its traces, and a radius (the
    /// farthest corner of the node's box bounds every triangle below it).
    static void store_dipole(const BvhNode<Aabb<T, 3>>& node, const NodeMoments& m, Dipole& d) {
        const auto& sm = m.second;
        for (int j = 0, u = 0; j < 3; ++j)
            for (int kk = j; kk < 3; ++kk, ++u)
                for (int i = 0; i < 3; ++i)
                    d.second[3 * u + i] = T(sm[9 * j + 3 * kk + i] * (j == kk ? 1.0 : 2.0));
        for (int j = 0; j < 3; ++j) {
            double su = 0, sv = 0;
            for (int i = 0; i < 3; ++i) su += sm[9 * j + 3 * i + i], sv += sm[9 * i + 3 * i + j];
            d.traces[j] = T(2 * su + sv);
        }
        d.an = Vec<T, 3>(m.an);
        d.centre = Vec<T, 3>(m.centre);
        for (int i = 0; i < 9; ++i) d.moment[i] = T(m.first[i]);
        double r2 = 0;
        for (int corner = 0; corner < 8; ++corner) {
            Vec<double, 3> p;
            for (int a = 0; a < 3; ++a)
                p[a] = (corner >> a & 1) ? node.bounds.max[a] : node.bounds.min[a];
            r2 = std::max(r2, length_squared(p - m.centre));
        }
        d.radius = T(std::sqrt(r2));
    }

    AabbBvh<T, 3> bvh_;
    std::vector<Triangle<T>> tris_;  // leaf-slot order
    std::vector<Dipole> dipoles_;
};

}  // namespace bvhkit
