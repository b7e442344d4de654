#pragma once
// Model<V>: a CollisionModel<V> for Python, with collision, contacts and distance over a batch of
// poses (one pose per item, spread over threads) and self-intersection. Instantiated per scalar
// type in collision32.cpp and collision64.cpp, so the two compile side by side.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>

#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/query/contact_manifold.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/query/self_collision.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/obb_rss.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"
#include "common.hpp"

#include <nanobind/stl/optional.h>

namespace bvhkit::python {

/// Rotations ((k, 3, 3) or one (3, 3)) or translations ((k, 3) or one (3,)), float32 or float64
/// whatever the model's type: a planner's float64 poses reach a float32 model without a numpy
/// conversion per call.
using PoseArray = nb::ndarray<nb::ro, nb::c_contig, Cpu>;

/// A PoseArray's values as T, each rounded as numpy's astype would round it (the Python layer
/// has checked the shape and the dtype, not the values).
template <class T>
class PoseValues {
  public:
    PoseValues() = default;
    /// `dims`: 1 for translations ((k, 3) or (3,)), 2 for rotations ((k, 3, 3) or (3, 3)). The
    /// Python layer hands over only those shapes; the checks here keep a direct call of the
    /// extension from reading past the array.
    PoseValues(const PoseArray& a, std::size_t dims, const char* name)
        : data_(a.data()),
          f64_(a.dtype() == nb::dtype<double>()),
          count_(a.ndim() == dims  ? 1
                 : a.ndim() > dims ? a.shape(0)
                                   : 0) {
        if (!f64_ && a.dtype() != nb::dtype<float>())
            throw Error(std::string(name) + ": dtype must be float32 or float64");
        bool shaped = a.ndim() == dims || a.ndim() == dims + 1;
        for (std::size_t d = a.ndim() - dims; shaped && d < a.ndim(); ++d) shaped = a.shape(d) == 3;
        if (!shaped)
            throw Error(std::string(name) +
                        (dims == 1 ? ": must be (k, 3) or (3,)" : ": must be (k, 3, 3) or (3, 3)"));
    }
    explicit operator bool() const { return data_ != nullptr; }
    std::size_t count() const { return count_; }
    T operator[](std::size_t j) const {
        return f64_ ? T(static_cast<const double*>(data_)[j])
                    : T(static_cast<const float*>(data_)[j]);
    }
    Vec<T, 3> row(std::size_t j) const {
        return {(*this)[3 * j], (*this)[3 * j + 1], (*this)[3 * j + 2]};
    }
    Mat3<T> matrix(std::size_t i) const {
        Mat3<T> m;
        for (std::size_t r = 0; r < 3; ++r) m.row[r] = row(3 * i + r);
        return m;
    }

  private:
    const void* data_ = nullptr;
    bool f64_ = false;
    std::size_t count_ = 0;
};

/// Whether the pose is finite and (when `check_rotation`) rigid by check_rigid_pose's rule (its
/// tolerance is the 1e-4 the messages below state).
template <class T>
bool valid(const Transform<T>& pose, bool check_rotation) {
    bool finite = true;
    for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(pose.translation[a]);
    if (!check_rotation || !finite) return finite;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) finite = finite && std::isfinite(pose.rotation.row[i][j]);
    return finite && rigid_deviation(pose.rotation) <= rigid_tolerance<T>();
}

/// Throws the Error the Python layer documents for the first bad value of the poses, in its
/// order of checks: a non-finite translation, then a non-finite rotation entry, then a rotation
/// that is not rigid (r is empty when no rotations were given).
template <class T>
void check_poses(const PoseValues<T>& r, const PoseValues<T>& t) {
    for (std::size_t i = 0; i < 3 * t.count(); ++i)
        if (!std::isfinite(t[i])) throw_bad_translation(i / 3);
    if (!r) return;
    for (std::size_t i = 0; i < 9 * r.count(); ++i)
        if (!std::isfinite(r[i])) throw_bad_rotation_entry(i / 9);
    for (std::size_t i = 0; i < r.count(); ++i)
        if (!(rigid_deviation(r.matrix(i)) <= rigid_tolerance<T>())) throw_not_a_rotation(i);
}

/// The number of poses: the translations' rows, which the rotations (when given) must match.
template <class T>
std::size_t pose_count(const PoseValues<T>& r, const PoseValues<T>& t) {
    const std::size_t k = t.count();
    if (r && r.count() != k) {
        check_poses(r, t);
        throw Error("translations: " + std::to_string(k) + " rows, rotations has " +
                    std::to_string(r.count()));
    }
    return k;
}

/// Calls per_pose(i, pose) for every pose, `grain` poses a chunk over `threads` threads (the
/// caller has released the GIL). Each pose is checked where it is used, so a batch reads its
/// poses once; a bad pose stops the batch, and the poses are then scanned in order for the error
/// bvhkit/_collision.py documents (check_poses).
template <class T, class PerPose>
void run_poses(const PoseValues<T>& r, const PoseValues<T>& t, std::size_t grain, unsigned threads,
               PerPose&& per_pose) {
    std::atomic<bool> bad{false};
    run_batch(t.count(), grain, threads, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end && !bad.load(std::memory_order_relaxed); ++i) {
            Transform<T> pose;  // the identity rotation where none was given
            if (r) pose.rotation = r.matrix(i);
            pose.translation = t.row(i);
            if (!valid(pose, bool(r))) {
                bad.store(true, std::memory_order_relaxed);
                return;
            }
            per_pose(i, pose);
        }
    });
    if (bad.load()) {
        check_poses(r, t);
        // Only another thread writing the arrays during the call gets here: a pose read as bad
        // was good when scanned again. The outputs are not whole, so the call fails.
        throw Error("translations: the poses changed while the call read them");
    }
}

template <class V>
class Model {
  public:
    using T = typename V::Scalar;

    Model(const Rows<T, 3>& vertices, const Faces& faces, unsigned threads)
        : mesh_(make_mesh<T>(vertices, faces)) {
        BuildOptions options = collision_build_options();
        options.threads = threads;
        nb::gil_scoped_release release;
        model_ = CollisionModel<V>(mesh_, options);
    }

    /// A model from the parts state() gave (bvhkit/_collision.py holds them in one container):
    /// the model is loaded from its file, checked as every load is, never rebuilt, and must be
    /// the model of exactly this mesh: the same face count, each slot's vertex ids and corners
    /// those of its face, and each face left out a face with a non-finite corner. Any failure is
    /// a bvhkit::Error (ValueError).
    Model(const Rows<T, 3>& vertices, const Faces& faces, const nb::bytes& model)
        : mesh_(make_mesh<T>(vertices, faces)) {
        // The bytes object stays referenced by the caller and is immutable: safe without the GIL.
        const std::span<const std::uint8_t> bytes(
            reinterpret_cast<const std::uint8_t*>(model.c_str()), model.size());
        nb::gil_scoped_release release;
        model_ = collision_model_from_bytes<V>(bytes);
        const auto fail = [](const std::string& m) { throw Error("model: " + m); };
        if (model_.triangle_count() != mesh_.triangles.size())
            fail("covers " + std::to_string(model_.triangle_count()) + " faces, the mesh has " +
                 std::to_string(mesh_.triangles.size()));
        const auto tris = model_.slot_triangles();
        const auto ids = model_.slot_vertex_ids();
        for (std::uint32_t s = 0; s < tris.size(); ++s) {
            const std::uint32_t f = model_.triangle_id(s);
            const Triangle<T> t = triangle_at<T>(mesh_, f);
            if (ids[s] != mesh_.triangles[f] || std::memcmp(&t, &tris[s], sizeof(t)) != 0)
                fail("slot " + std::to_string(s) + " does not hold face " + std::to_string(f) +
                     " of the mesh");
        }
        for (const std::uint32_t f : model_.skipped()) {
            const Triangle<T> t = triangle_at<T>(mesh_, f);
            bool finite = true;
            for (const Vec<T, 3>& p : {t.p0, t.p1, t.p2})
                for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(p[a]);
            if (finite) fail("face " + std::to_string(f) + " is finite but left out");
        }
    }

    /// What the loading constructor takes: (vertices, faces int64, model file bytes). One
    /// consistent snapshot.
    nb::tuple state() const {
        std::vector<T> v;
        std::vector<std::int64_t> f;
        std::vector<std::uint8_t> file;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            v.reserve(3 * mesh_.vertices.size());
            for (const auto& p : mesh_.vertices) v.insert(v.end(), {p[0], p[1], p[2]});
            f.reserve(3 * mesh_.triangles.size());
            for (const auto& t : mesh_.triangles) f.insert(f.end(), {t[0], t[1], t[2]});
            file = to_bytes(model_);
        }
        const std::size_t nv = mesh_.vertices.size(), nf = mesh_.triangles.size();
        return nb::make_tuple(owned_array(std::move(v), nv, 3), owned_array(std::move(f), nf, 3),
                              nb::bytes(reinterpret_cast<const char*>(file.data()), file.size()));
    }

    void refit(const Rows<T, 3>& vertices) {
        if (vertices.shape(0) != mesh_.vertices.size())
            throw Error("vertices: " + std::to_string(vertices.shape(0)) + " rows, the model has " +
                        std::to_string(mesh_.vertices.size()));
        const T* v = vertices.data();
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        refit_vertices(mesh_.vertices, v, [&] { model_.refit(mesh_); });
        const std::lock_guard<std::mutex> contact_lock(contact_mutex_);
        contact_.reset();  // rebuilt from the new vertices when next asked for
    }

    /// Calls per_pose(i, pose) for every pose of B in A's frame (this is A), without the GIL
    /// (run_poses). `rotations` is (k, 3, 3) or None for the identity, `translations` (k, 3); a
    /// single pose may also come as (3, 3) and (3,).
    template <class PerPose>
    void poses(const Model& b, const std::optional<PoseArray>& rotations,
               const PoseArray& translations, unsigned threads, PerPose&& per_pose) const {
        const PoseValues<T> t(translations, 1, "translations");
        const PoseValues<T> r =
            rotations ? PoseValues<T>(*rotations, 2, "rotations") : PoseValues<T>();
        pose_count(r, t);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock_a(mutex_);
        std::shared_lock<std::shared_mutex> lock_b;
        if (&b != this) lock_b = std::shared_lock<std::shared_mutex>(b.mutex_);
        run_poses(r, t, 1, threads, per_pose);
    }

    /// Calls per_pose(i, pose, model) for every pose of one more object (a convex shape:
    /// convex.cpp) in this model's frame, without the GIL, under this model's shared lock.
    template <class PerPose>
    void shape_poses(const std::optional<PoseArray>& rotations, const PoseArray& translations,
                     unsigned threads, PerPose&& per_pose) const {
        const PoseValues<T> t(translations, 1, "translations");
        const PoseValues<T> r =
            rotations ? PoseValues<T>(*rotations, 2, "rotations") : PoseValues<T>();
        pose_count(r, t);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        run_poses(r, t, 1, threads,
                  [&](std::size_t i, const Transform<T>& pose) { per_pose(i, pose, model_); });
    }

    void collides(const Model& b, const std::optional<PoseArray>& rotations,
                  const PoseArray& translations, OutColumn<bool> out, unsigned threads) const {
        expect_rows(out, PoseValues<T>(translations, 1, "translations").count(), "out");
        bool* o = out.data();
        poses(b, rotations, translations, threads, [&](std::size_t i, const Transform<T>& pose) {
            o[i] = bvhkit::collides(model_, b.model_, pose);
        });
    }

    /// Every intersecting face pair at every pose: (pairs (p, 2), offsets (k + 1)); pose i's
    /// pairs are rows offsets[i] .. offsets[i + 1], sorted.
    nb::tuple contacts(const Model& b, const std::optional<PoseArray>& rotations,
                       const PoseArray& translations, unsigned threads) const {
        const std::size_t k = PoseValues<T>(translations, 1, "translations").count();
        std::vector<std::vector<std::array<std::int64_t, 2>>> per(k);
        poses(b, rotations, translations, threads, [&](std::size_t i, const Transform<T>& pose) {
            CollideResult<T> result;
            const CollideOptions options{CollideMode::AllPairs, DescentRule::Larger, false};
            bvhkit::collide(model_, b.model_, pose, options, result);
            for (const Contact<T>& c : result.contacts)
                per[i].push_back({c.triangle_a, c.triangle_b});
            std::sort(per[i].begin(), per[i].end());
        });
        std::vector<std::int64_t> pairs, offsets(k + 1, 0);
        for (std::size_t i = 0; i < k; ++i) {
            offsets[i + 1] = offsets[i] + std::int64_t(per[i].size());
            for (const auto& p : per[i]) pairs.insert(pairs.end(), p.begin(), p.end());
        }
        const std::size_t p = pairs.size() / 2;
        return nb::make_tuple(owned_array(std::move(pairs), p, 2),
                              owned_array(std::move(offsets), k + 1, 0));
    }

    /// The contact manifold at every pose (query/contact_manifold.hpp): (faces (p, 2), points
    /// (p, 3), normals (p, 3), depths (p,), regions (p,), kinds (p,), offsets (k + 1)); pose i's
    /// contacts are rows offsets[i] .. offsets[i + 1], region by region, each deepest first.
    nb::tuple manifold(const Model& b, const std::optional<PoseArray>& rotations,
                       const PoseArray& translations, std::uint32_t max_points,
                       bool inside_vertices, bool walk_inside, unsigned threads) const {
        const std::size_t k = PoseValues<T>(translations, 1, "translations").count();
        std::vector<std::vector<ContactPoint<T>>> per(k);
        ContactOptions options;
        options.max_points_per_region = max_points;
        options.inside_vertices = inside_vertices;
        options.walk_inside = walk_inside;
        poses(b, rotations, translations, threads, [&](std::size_t i, const Transform<T>& pose) {
            // One result a thread, kept across calls: its workspace grows to the largest meshes
            // once instead of being allocated and cleared at every pose.
            thread_local ContactManifold<T> result;
            contact_manifold(model_, contact_mesh(), b.model_, b.contact_mesh(), pose, options,
                             result);
            per[i] = result.points;
        });
        std::size_t total = 0;
        for (const auto& v : per) total += v.size();
        std::vector<std::int64_t> faces, regions, offsets(k + 1, 0);
        std::vector<T> points, normals, depths;
        std::vector<std::int8_t> kinds;
        faces.reserve(2 * total);
        points.reserve(3 * total);
        normals.reserve(3 * total);
        for (std::size_t i = 0; i < k; ++i) {
            offsets[i + 1] = offsets[i] + std::int64_t(per[i].size());
            for (const ContactPoint<T>& c : per[i]) {
                faces.insert(faces.end(), {c.triangle_a, c.triangle_b});
                points.insert(points.end(), {c.point[0], c.point[1], c.point[2]});
                normals.insert(normals.end(), {c.normal[0], c.normal[1], c.normal[2]});
                depths.push_back(c.depth);
                regions.push_back(c.region);
                kinds.push_back(std::int8_t(c.kind));
            }
        }
        return nb::make_tuple(
            owned_array(std::move(faces), total, 2), owned_array(std::move(points), total, 3),
            owned_array(std::move(normals), total, 3), owned_array(std::move(depths), total, 0),
            owned_array(std::move(regions), total, 0), owned_array(std::move(kinds), total, 0),
            owned_array(std::move(offsets), k + 1, 0));
    }

    void distance(const Model& b, const std::optional<PoseArray>& rotations,
                  const PoseArray& translations, T absolute_tolerance, T relative_tolerance,
                  OutColumn<T> dist, OutRows<T, 3> point_a, OutRows<T, 3> point_b,
                  OutColumn<std::int64_t> face_a, OutColumn<std::int64_t> face_b,
                  unsigned threads) const {
        const std::size_t k = PoseValues<T>(translations, 1, "translations").count();
        expect_rows(dist, k, "distance");
        expect_rows(point_a, k, "point_a");
        expect_rows(point_b, k, "point_b");
        expect_rows(face_a, k, "face_a");
        expect_rows(face_b, k, "face_b");
        T *d = dist.data(), *pa = point_a.data(), *pb = point_b.data();
        std::int64_t *fa = face_a.data(), *fb = face_b.data();
        DistanceOptions<T> options;
        options.absolute_tolerance = absolute_tolerance;
        options.relative_tolerance = relative_tolerance;
        poses(b, rotations, translations, threads, [&](std::size_t i, const Transform<T>& pose) {
            const DistanceResult<T> r = bvhkit::distance(model_, b.model_, pose, options);
            const bool found = r.distance < std::numeric_limits<T>::infinity();
            d[i] = r.distance;
            for (int a = 0; a < 3; ++a) {
                pa[3 * i + a] = found ? r.point_a[a] : std::numeric_limits<T>::quiet_NaN();
                pb[3 * i + a] = found ? r.point_b[a] : std::numeric_limits<T>::quiet_NaN();
            }
            fa[i] = found ? std::int64_t(r.triangle_a) : -1;
            fb[i] = found ? std::int64_t(r.triangle_b) : -1;
        });
    }

    /// Intersecting face pairs of the mesh with itself that share no vertex, (p, 2), sorted.
    nb::ndarray<nb::numpy, std::int64_t> self_intersections() const {
        std::vector<std::int64_t> pairs;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            std::vector<Contact<T>> contacts;
            self_collide(model_, contacts);
            for (const Contact<T>& c : contacts) {
                pairs.push_back(c.triangle_a);
                pairs.push_back(c.triangle_b);
            }
        }
        const std::size_t p = pairs.size() / 2;
        return owned_array(std::move(pairs), p, 2);
    }

    std::size_t triangle_count() const { return model_.triangle_count(); }
    std::size_t node_count() const { return model_.bvh().nodes.size(); }

  private:
    /// The model's ContactMesh, built at its first use (the caller holds mutex_, shared or not).
    const ContactMesh<T>& contact_mesh() const {
        const std::lock_guard<std::mutex> lock(contact_mutex_);
        if (!contact_) contact_ = std::make_unique<ContactMesh<T>>(mesh_);
        return *contact_;
    }

    BasicTriangleMesh<T> mesh_;
    CollisionModel<V> model_;
    mutable std::shared_mutex mutex_;
    mutable std::mutex contact_mutex_;
    mutable std::unique_ptr<ContactMesh<T>> contact_;
};

template <class V>
void bind_model(nb::module_& m, const char* name) {
    using M = Model<V>;
    using T = typename V::Scalar;
    nb::class_<M>(m, name, "A mesh ready for collision and distance (see bvhkit.CollisionModel).")
        .def(nb::init<const Rows<T, 3>&, const Faces&, unsigned>(), nb::arg("vertices"),
             nb::arg("faces"), nb::arg("threads"), "Builds the model's tree.")
        .def(nb::init<const Rows<T, 3>&, const Faces&, const nb::bytes&>(), nb::arg("vertices"),
             nb::arg("faces"), nb::arg("model"),
             "Loads the model from the parts state() gave (nothing is rebuilt).")
        .def("state", &M::state, "The mesh and the model's file, for saving.")
        .def("refit", &M::refit, nb::arg("vertices"), "New vertex positions, same faces.")
        .def("collides", &M::collides, nb::arg("b"), nb::arg("rotations").none(),
             nb::arg("translations"), nb::arg("out"), nb::arg("threads"),
             "Whether b, placed at each pose, intersects this model.")
        .def("contacts", &M::contacts, nb::arg("b"), nb::arg("rotations").none(),
             nb::arg("translations"), nb::arg("threads"),
             "(pairs (p, 2), offsets (k + 1)): the intersecting face pairs at each pose.")
        .def("manifold", &M::manifold, nb::arg("b"), nb::arg("rotations").none(),
             nb::arg("translations"), nb::arg("max_points"), nb::arg("inside_vertices"),
             nb::arg("walk_inside"), nb::arg("threads"),
             "(faces, points, normals, depths, regions, kinds, offsets): the contact manifold "
             "at each pose.")
        .def("distance", &M::distance, nb::arg("b"), nb::arg("rotations").none(),
             nb::arg("translations"), nb::arg("absolute_tolerance"), nb::arg("relative_tolerance"),
             nb::arg("distance"), nb::arg("point_a"), nb::arg("point_b"), nb::arg("face_a"),
             nb::arg("face_b"), nb::arg("threads"),
             "Distance to b at each pose, with the closest points in this model's frame.")
        .def("self_intersections", &M::self_intersections,
             "Intersecting face pairs that share no vertex, (p, 2).")
        .def_prop_ro("triangle_count", &M::triangle_count, "Number of faces.")
        .def_prop_ro("node_count", &M::node_count, "Number of tree nodes.");
}

}  // namespace bvhkit::python
