#pragma once
// SceneGeometry<T>: one triangle mesh of a Scene (scene.hpp), shared by every instance of it. It
// keeps a copy of the mesh, the vertices of the mesh's convex hull (computed once, for the
// instances' world boxes) and the bottom-level trees, each built the first time a query family
// needs it: a TriangleBvh for rays, a ClosestPointMesh for closest points, a CollisionModel for
// collision. The lazy builds are guarded by std::call_once, so const queries on many threads may
// trigger them at once; prepare() builds all three up front.
//
// World boxes: an instance's box is the box of its hull vertices under its pose, x' = R x + t,
// rounded outward, then padded by pose_pad() for the rounding of the queries' transforms. The
// hull's extent along each axis is the geometry's (a linear map's extreme over a convex set is at
// a vertex), so a rotated instance gets the tightest box there is, not the box of its rotated
// local box. The extremes come from six support queries on the hull (rows of R, and their
// negations), each climbing over the hull's neighbours (volumes/hull_support.hpp) instead of a
// pass over every vertex: a pose change costs a few neighbourhoods per axis.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/closest_point.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/scene/geometry_solid.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/hull_support.hpp"
#include "bvhkit/volumes/obb_rss.hpp"

namespace bvhkit {

namespace scene_detail {

/// x rounded to T toward -inf (down) or +inf (up). A value beyond T's finite range becomes the
/// infinity on its side (or T's largest finite value, rounding toward zero): the conversion itself
/// is only defined within the range, so the range is checked first.
template <class T, class W>
T round_down(W x) {
    constexpr W big = W(std::numeric_limits<T>::max());
    if (x > big) return std::numeric_limits<T>::max();
    if (x < -big) return -std::numeric_limits<T>::infinity();
    T r = T(x);
    if (W(r) > x) r = std::nextafter(r, -std::numeric_limits<T>::infinity());
    return r;
}
template <class T, class W>
T round_up(W x) {
    constexpr W big = W(std::numeric_limits<T>::max());
    if (x > big) return std::numeric_limits<T>::infinity();
    if (x < -big) return -std::numeric_limits<T>::max();
    T r = T(x);
    if (W(r) < x) r = std::nextafter(r, std::numeric_limits<T>::infinity());
    return r;
}
/// x rounded to T to nearest, or the infinity on its side when beyond T's finite range (NaN stays
/// NaN): the narrowing conversion without its undefined case.
template <class T, class W>
T narrow(W x) {
    constexpr W big = W(std::numeric_limits<T>::max());
    if (x > big) return std::numeric_limits<T>::infinity();
    if (x < -big) return -std::numeric_limits<T>::infinity();
    return T(x);
}

/// The box grown by `by` on every side, in W and rounded outward (by = 0 gives the box itself).
template <class T>
Aabb<T, 3> grown(const Aabb<T, 3>& box, T by) {
    Aabb<T, 3> r = box;
    for (std::size_t i = 0; i < 3; ++i)
        r.min[i] = round_down<T>(AccurateScalar<T>(box.min[i]) - AccurateScalar<T>(by)),
        r.max[i] = round_up<T>(AccurateScalar<T>(box.max[i]) + AccurateScalar<T>(by));
    return r;
}

/// The rotation nearest to R (in the Frobenius norm: R's orthogonal polar factor), computed in W
/// and rounded to T. Newton's iteration for the polar factor, X <- (X + X^-T) / 2, from X = R:
/// it converges quadratically (a deviation e from orthogonality becomes about e^2 / 2), so from
/// the 1e-4 that check_rigid_pose accepts it is below W's epsilon within four steps. The polar
/// factor rather than Gram-Schmidt: it treats the three axes alike (Gram-Schmidt keeps the first
/// column's direction and pushes all of the error into the others) and it is the nearest
/// orthogonal matrix, so no point of a mesh moves by more than R's own distance from it. det R
/// near +1 keeps X away from singular matrices, and the factor is then a proper rotation. A
/// rotation that is already exact (the identity, a signed permutation) comes back unchanged.
template <class W, class T>
Mat3<T> nearest_rotation(const Mat3<T>& rotation) {
    Mat3<W> x(rotation);
    for (int step = 0; step < 8; ++step) {
        // X^-T = cofactor(X) / det X; the cofactor matrix's rows are cross products of X's rows.
        const Vec<W, 3> c0 = cross(x.row[1], x.row[2]), c1 = cross(x.row[2], x.row[0]),
                        c2 = cross(x.row[0], x.row[1]);
        const W det = dot(x.row[0], c0);
        const Vec<W, 3> c[3] = {c0, c1, c2};
        W change = 0;
        for (std::size_t i = 0; i < 3; ++i)
            for (std::size_t j = 0; j < 3; ++j) {
                const W next = (x.row[i][j] + c[i][j] / det) / W(2);
                change = std::max(change, W(std::fabs(next - x.row[i][j])));
                x.row[i][j] = next;
            }
        if (change <= W(4) * std::numeric_limits<W>::epsilon()) break;
    }
    return Mat3<T>(x);
}

/// The pose as a Scene stores it: the translation as given, the rotation replaced by the nearest
/// rotation (so R^T is R's inverse to T's rounding, and a relative pose R_a^T R_b is as rigid).
/// A rotation already orthonormal to a few units of T's rounding (what a rotation computed in T
/// from angles or quaternions is) is kept as given: its polar factor, rounded to T, would differ
/// from it by about as much, and the Newton steps in the wider type cost more than the rest of a
/// pose change. The pad of the world box (pose_pad) measures the stored rotation's deviation
/// either way.
template <class T>
Transform<T> rigid_pose(const Transform<T>& pose) {
    if (rigid_deviation(pose.rotation) <= 8 * double(std::numeric_limits<T>::epsilon()))
        return pose;
    return {nearest_rotation<AccurateScalar<T>>(pose.rotation), pose.translation};
}

/// R x + t in W.
template <class W, class T>
Vec<W, 3> apply_wide(const Transform<T>& pose, const Vec<T, 3>& x) {
    Vec<W, 3> r;
    for (std::size_t i = 0; i < 3; ++i)
        r[i] = W(pose.rotation[i][0]) * W(x[0]) + W(pose.rotation[i][1]) * W(x[1]) +
               W(pose.rotation[i][2]) * W(x[2]) + W(pose.translation[i]);
    return r;
}

/// R^T (x - t) in W, rounded to T once: a world point in the instance's frame.
template <class W, class T>
Vec<T, 3> to_local_point(const Transform<T>& pose, const Vec<T, 3>& x) {
    const W d[3] = {W(x[0]) - W(pose.translation[0]), W(x[1]) - W(pose.translation[1]),
                    W(x[2]) - W(pose.translation[2])};
    Vec<T, 3> r;
    for (std::size_t j = 0; j < 3; ++j)
        r[j] = narrow<T>(W(pose.rotation[0][j]) * d[0] + W(pose.rotation[1][j]) * d[1] +
                         W(pose.rotation[2][j]) * d[2]);
    return r;
}

/// R^T v in W, rounded to T once: a world direction in the instance's frame.
template <class W, class T>
Vec<T, 3> to_local_vector(const Transform<T>& pose, const Vec<T, 3>& v) {
    Vec<T, 3> r;
    for (std::size_t j = 0; j < 3; ++j)
        r[j] = narrow<T>(W(pose.rotation[0][j]) * W(v[0]) + W(pose.rotation[1][j]) * W(v[1]) +
                         W(pose.rotation[2][j]) * W(v[2]));
    return r;
}

/// R v in W, rounded to T once.
template <class W, class T>
Vec<T, 3> to_world_vector(const Transform<T>& pose, const Vec<T, 3>& v) {
    Vec<T, 3> r;
    for (std::size_t i = 0; i < 3; ++i)
        r[i] = narrow<T>(W(pose.rotation[i][0]) * W(v[0]) + W(pose.rotation[i][1]) * W(v[1]) +
                         W(pose.rotation[i][2]) * W(v[2]));
    return r;
}

/// The pose of b in a's frame, inverse(a) * b, in W and rounded to T once: R_a^T R_b and
/// R_a^T (t_b - t_a). Two instances far from the origin and near each other get a relative
/// translation as exact as their own.
template <class W, class T>
Transform<T> relative_pose(const Transform<T>& a, const Transform<T>& b) {
    Transform<T> r;
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j)
            r.rotation[i][j] = T(W(a.rotation[0][i]) * W(b.rotation[0][j]) +
                                 W(a.rotation[1][i]) * W(b.rotation[1][j]) +
                                 W(a.rotation[2][i]) * W(b.rotation[2][j]));
    r.translation = to_local_point<W>(a, b.translation);
    return r;
}

}  // namespace scene_detail

template <class T>
class SceneGeometry {
  public:
    using W = AccurateScalar<T>;

    template <IndexedTriangleMesh M>
    explicit SceneGeometry(const M& mesh) {
        check_triangle_indices(mesh);
        mesh_.vertices.resize(mesh.vertex_count());
        for (std::size_t k = 0; k < mesh.vertex_count(); ++k)
            mesh_.vertices[k] = Vec<T, 3>(mesh.vertex(k));
        mesh_.triangles.resize(mesh.triangle_count());
        for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
            const auto& ids = mesh.triangle(i);
            mesh_.triangles[i] = {std::uint32_t(ids[0]), std::uint32_t(ids[1]),
                                  std::uint32_t(ids[2])};
        }
        // The hull of the corners of the triangles whose three corners are finite: a stray vertex
        // bounds nothing, and neither does a finite corner of a triangle that the queries skip
        // (one with a NaN or infinite corner).
        std::vector<Vec<T, 3>> used;
        used.reserve(3 * mesh_.triangles.size());
        for (const auto& tri : mesh_.triangles) {
            const auto& v = mesh_.vertices;
            if (!(is_finite(v[tri[0]]) && is_finite(v[tri[1]]) && is_finite(v[tri[2]]))) continue;
            for (const std::uint32_t k : tri) used.push_back(v[k]);
        }
        used = hull_detail::sorted_unique(std::move(used));
        if (!used.empty()) hull_ = HullSupport<T>(std::span<const Vec<T, 3>>(used));
        for (const Vec<T, 3>& v : hull_.vertices())
            for (std::size_t a = 0; a < 3; ++a) extent_ = std::max(extent_, W(std::fabs(W(v[a]))));
    }
    SceneGeometry(const SceneGeometry&) = delete;
    SceneGeometry& operator=(const SceneGeometry&) = delete;

    const BasicTriangleMesh<T>& mesh() const { return mesh_; }
    std::size_t triangle_count() const { return mesh_.triangles.size(); }
    /// The hull's vertices (empty when no triangle has finite corners).
    std::span<const Vec<T, 3>> hull_vertices() const { return hull_.vertices(); }
    /// The hull's vertices with their neighbours, for support queries.
    const HullSupport<T>& hull() const { return hull_; }
    bool has_extent() const { return !hull_.empty(); }

    /// The box of the geometry under `pose`, `pad` added on every side: rounded outward, never
    /// smaller than the exact extent of R x + t over the hull. A geometry without finite
    /// triangles gets the point box at t.
    Aabb<T, 3> world_box(const Transform<T>& pose, W pad) const {
        if (hull_.empty()) return Aabb<T, 3>(pose.translation, pose.translation);
        // The vertices that reach farthest along -/+ each world axis: the exact maximisers of
        // -/+ R_a . x (R_a the rotation's row a, negated exactly), so the extremes of R x + t over
        // the whole hull are these vertices' values, each off only by its own rounding.
        std::array<std::uint32_t, 6> extreme;
        for (std::size_t a = 0; a < 3; ++a) {
            extreme[2 * a] = hull_.support_index(-pose.rotation[a]);
            extreme[2 * a + 1] = hull_.support_index(pose.rotation[a]);
        }
        Vec<W, 3> lo, hi;
        if (!extremes_in_double(pose, extreme, lo, hi)) {  // beyond double's range: in W
            for (std::size_t a = 0; a < 3; ++a) {
                lo[a] = scene_detail::apply_wide<W>(pose, hull_.vertices()[extreme[2 * a]])[a];
                hi[a] = scene_detail::apply_wide<W>(pose, hull_.vertices()[extreme[2 * a + 1]])[a];
            }
        }
        Aabb<T, 3> box;
        for (std::size_t a = 0; a < 3; ++a) {
            box.min[a] = scene_detail::round_down<T>(lo[a] - pad);
            box.max[a] = scene_detail::round_up<T>(hi[a] + pad);
        }
        return box;
    }

    /// The extremes of R x + t over the hull (coordinate a from the vertices extreme[2a], the
    /// lowest, and extreme[2a + 1], the highest), each widened by a bound on its rounding,
    /// computed in double: long double (W for a double mesh) costs several times double's
    /// arithmetic. For a float mesh every product is exact in double and the two sums and t
    /// round by at most 2 eps_d of 3.01 e + |t| (e the hull's largest |coordinate|, |R_ab| <= 1 +
    /// 1e-4); for a double mesh the three products add one rounding each: 4 eps_d of the same.
    /// The bound holds for each vertex's own value, and these vertices' exact values are the
    /// exact extremes, so the widened values hold the exact extremes. False (nothing written)
    /// where a value leaves double's range.
    bool extremes_in_double(const Transform<T>& pose, const std::array<std::uint32_t, 6>& extreme,
                            Vec<W, 3>& lo_out, Vec<W, 3>& hi_out) const {
        const double eps = std::numeric_limits<double>::epsilon();
        for (std::size_t a = 0; a < 3; ++a) {
            const Vec<double, 3> r(pose.rotation[a]);
            const double t = double(pose.translation[a]);
            const Vec<double, 3> x_lo(hull_.vertices()[extreme[2 * a]]),
                x_hi(hull_.vertices()[extreme[2 * a + 1]]);
            const double lo = r[0] * x_lo[0] + r[1] * x_lo[1] + r[2] * x_lo[2] + t;
            const double hi = r[0] * x_hi[0] + r[1] * x_hi[1] + r[2] * x_hi[2] + t;
            const double slack = 4 * eps * (3.01 * double(extent_) + std::fabs(t));
            if (!(std::isfinite(lo) && std::isfinite(hi) && std::isfinite(slack))) return false;
            lo_out[a] = W(lo) - W(slack);
            hi_out[a] = W(hi) + W(slack);
        }
        return true;
    }

    /// The pad for a pose: what the roundings of the box and of the queries' transforms can move
    /// a point of the geometry by, so that the walks over the world boxes lose no instance that
    /// the query in the instance's frame would find. With E = extent_ (the hull's largest
    /// |coordinate|, so |x| <= sqrt(3) E for every point x of the mesh), tau = max |t_i|,
    /// d = rigid_deviation(R) (a few eps_T for a stored pose: nearest_rotation) and eps_T, eps_W
    /// the epsilons of T and of the wider type W:
    ///
    ///   pad = 16 eps_T E + 8 eps_W (tau + 2 E) + 6 d E.
    ///
    /// Why it suffices. (a) The box: its extremes are the values of the exact extreme vertices
    /// (world_box), so only their own rounding counts: extremes_in_double adds its bound on it;
    /// beyond double's range each coordinate of R x + t is two products and three sums in W of
    /// terms at most sqrt(3) E and tau, off by at most 3 eps_W (sqrt(3) E + tau) from the exact
    /// value, which the second term covers; rounding outward to T only grows the box. (b) The
    /// queries: a world point p goes to p' = R^T (p - t), the difference and the products taken
    /// in W (off by at most 3 eps_W |p - t|: relative to the local distance, not to |t|, because
    /// t is subtracted first) and rounded to T once (eps_T / 2 of each coordinate). A point
    /// found in the instance's frame within the instance's reach (local coordinates within 4 E:
    /// the query point, or the stretch of a ray's segment, near the instance, which is where a
    /// hit or a nearest point on it is decided) is off from the exact image of the world point by
    /// at most eps_T / 2 * sqrt(3) * 4 E per rounded point, twice for a ray (its origin and its
    /// direction times t): under 7 eps_T E, and the triangle tests' own rounding of the local
    /// coordinates stays within the rest of the first term. (c) R^T differs from R's inverse by
    /// (I - R^T R) R^-1, of norm at most 3 d (1 + 3 d), so mapping back moves a point at
    /// |x| <= sqrt(3) E by under 6 d E: the third term. Where W is no wider than T (long double
    /// is double on some platforms), eps_W = eps_T and the second term is 8 eps_T (tau + 2 E),
    /// the |t| term such a platform needs. The pad no longer grows with eps_T |t|: far from the
    /// origin the box is as tight as T's spacing there allows. A query from farther out than
    /// 4 E carries its own rounding, eps_T / 2 of its local coordinates, which the queries
    /// already document as their accuracy.
    W pose_pad(const Transform<T>& pose) const {
        W tau = 0;
        for (std::size_t a = 0; a < 3; ++a)
            tau = std::max(tau, W(std::fabs(W(pose.translation[a]))));
        const W eps_t = W(std::numeric_limits<T>::epsilon());
        const W eps_w = std::numeric_limits<W>::epsilon();
        const W d = W(rigid_deviation(pose.rotation));
        return W(16) * eps_t * extent_ + W(8) * eps_w * (tau + W(2) * extent_) + W(6) * d * extent_;
    }

    const TriangleBvh<T>& ray_tree() const {
        std::call_once(rays_once_, [&] { rays_ = std::make_unique<TriangleBvh<T>>(mesh_); });
        return *rays_;
    }
    const ClosestPointMesh<T>& closest_point_tree() const {
        std::call_once(points_once_,
                       [&] { points_ = std::make_unique<ClosestPointMesh<T>>(mesh_); });
        return *points_;
    }
    /// OBB+RSS volumes (as FCL's OBBRSS): the OBB test for collision, the rectangle-swept-sphere
    /// bound for distance, both tight for the rotated relative poses that instances meet (an
    /// axis-aligned box's distance bound loosens as the pose turns, docs/benchmarks.md C2).
    const CollisionModel<ObbRss<T>>& collision_model() const {
        std::call_once(collision_once_,
                       [&] { collision_ = std::make_unique<CollisionModel<ObbRss<T>>>(mesh_); });
        return *collision_;
    }
    /// The signed distance and inside/outside structures (scene/geometry_solid.hpp), built at
    /// their first use, not by prepare().
    const SignedDistanceMesh<T>& signed_distance_mesh() const {
        return solid_.signed_distance_mesh(mesh_);
    }
    const WindingNumberMesh<T>& winding_number_mesh() const {
        return solid_.winding_number_mesh(mesh_);
    }
    bool is_closed() const { return solid_.closed(mesh_); }
    /// Builds the three trees now rather than at the first query of each family.
    void prepare() const {
        (void)ray_tree();
        (void)closest_point_tree();
        (void)collision_model();
    }

  private:
    BasicTriangleMesh<T> mesh_;
    HullSupport<T> hull_;
    W extent_ = 0;  // the hull's largest |coordinate|
    mutable std::once_flag rays_once_, points_once_, collision_once_;
    mutable std::unique_ptr<TriangleBvh<T>> rays_;
    mutable std::unique_ptr<ClosestPointMesh<T>> points_;
    mutable std::unique_ptr<CollisionModel<ObbRss<T>>> collision_;
    scene_detail::GeometrySolid<T> solid_;
};

}  // namespace bvhkit
