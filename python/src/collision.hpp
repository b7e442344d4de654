#pragma once
// Model<V>: a CollisionModel<V> for Python, with collision, contacts and distance over a batch of
// poses (one pose per item, spread over threads) and self-intersection. Instantiated per scalar
// type in collision32.cpp and collision64.cpp, so the two compile side by side.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <shared_mutex>
#include <span>

#include "bvhkit/io/collision_model_file.hpp"
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

namespace bvhkit::python {

template <class T>
using Rotations = nb::ndarray<const T, nb::shape<-1, 3, 3>, nb::c_contig, Cpu>;

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
    }

    /// Calls per_pose(i, pose) for every pose of B in A's frame (this is A), without the GIL.
    template <class PerPose>
    void poses(const Model& b, const Rotations<T>& rotations, const Rows<T, 3>& translations,
               unsigned threads, PerPose&& per_pose) const {
        const std::size_t k = rotations.shape(0);
        expect_rows(translations, k, "translations");
        const T *r = rotations.data(), *t = translations.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock_a(mutex_);
        std::shared_lock<std::shared_mutex> lock_b;
        if (&b != this) lock_b = std::shared_lock<std::shared_mutex>(b.mutex_);
        run_batch(k, 1, threads, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                Transform<T> pose;
                for (int row = 0; row < 3; ++row)
                    pose.rotation.row[row] = {r[9 * i + 3 * row], r[9 * i + 3 * row + 1],
                                              r[9 * i + 3 * row + 2]};
                pose.translation = {t[3 * i], t[3 * i + 1], t[3 * i + 2]};
                per_pose(i, pose);
            }
        });
    }

    void collides(const Model& b, const Rotations<T>& rotations, const Rows<T, 3>& translations,
                  OutColumn<bool> out, unsigned threads) const {
        expect_rows(out, rotations.shape(0), "out");
        bool* o = out.data();
        poses(b, rotations, translations, threads, [&](std::size_t i, const Transform<T>& pose) {
            o[i] = bvhkit::collides(model_, b.model_, pose);
        });
    }

    /// Every intersecting face pair at every pose: (pairs (p, 2), offsets (k + 1)); pose i's
    /// pairs are rows offsets[i] .. offsets[i + 1], sorted.
    nb::tuple contacts(const Model& b, const Rotations<T>& rotations,
                       const Rows<T, 3>& translations, unsigned threads) const {
        const std::size_t k = rotations.shape(0);
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

    void distance(const Model& b, const Rotations<T>& rotations, const Rows<T, 3>& translations,
                  T absolute_tolerance, T relative_tolerance, OutColumn<T> dist,
                  OutRows<T, 3> point_a, OutRows<T, 3> point_b, OutColumn<std::int64_t> face_a,
                  OutColumn<std::int64_t> face_b, unsigned threads) const {
        const std::size_t k = rotations.shape(0);
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
    BasicTriangleMesh<T> mesh_;
    CollisionModel<V> model_;
    mutable std::shared_mutex mutex_;
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
        .def("collides", &M::collides, nb::arg("b"), nb::arg("rotations"), nb::arg("translations"),
             nb::arg("out"), nb::arg("threads"),
             "Whether b, placed at each pose, intersects this model.")
        .def("contacts", &M::contacts, nb::arg("b"), nb::arg("rotations"), nb::arg("translations"),
             nb::arg("threads"),
             "(pairs (p, 2), offsets (k + 1)): the intersecting face pairs at each pose.")
        .def("distance", &M::distance, nb::arg("b"), nb::arg("rotations"), nb::arg("translations"),
             nb::arg("absolute_tolerance"), nb::arg("relative_tolerance"), nb::arg("distance"),
             nb::arg("point_a"), nb::arg("point_b"), nb::arg("face_a"), nb::arg("face_b"),
             nb::arg("threads"),
             "Distance to b at each pose, with the closest points in this model's frame.")
        .def("self_intersections", &M::self_intersections,
             "Intersecting face pairs that share no vertex, (p, 2).")
        .def_prop_ro("triangle_count", &M::triangle_count, "Number of faces.")
        .def_prop_ro("node_count", &M::node_count, "Number of tree nodes.");
}

}  // namespace bvhkit::python
