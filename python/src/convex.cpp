// Convex shapes for Python: one ConvexShape<double> per object (Convex), and convex_distance /
// convex_signed_distance over a batch of poses of B in A's frame, spread over the pool without the
// GIL. The Python layer (bvhkit/_convex.py) checks the shapes' parameters and the arrays' shapes
// and types; the poses' values are checked here as they are read, with the messages of collide and
// distance (collision.hpp: PoseValues, valid, check_poses).
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "bvhkit/convex/penetration.hpp"
#include "bvhkit/query/convex_mesh.hpp"
#include "collision.hpp"

#include <nanobind/stl/optional.h>

namespace bvhkit::python {
namespace {

using Shape = ConvexShape<double>;

/// One convex shape, immutable once made: queries read it from any thread without a lock.
class Convex {
  public:
    explicit Convex(Shape shape) : shape_(std::move(shape)) {}

    static Convex sphere(double radius) { return Convex(SphereShape<double>(radius)); }
    static Convex box(double x, double y, double z) {
        return Convex(BoxShape<double>(Vec<double, 3>{x, y, z}));
    }
    static Convex capsule(double radius, double half_length) {
        return Convex(CapsuleShape<double>(radius, half_length));
    }
    static Convex cylinder(double radius, double half_height) {
        return Convex(CylinderShape<double>(radius, half_height));
    }
    static Convex cone(double radius, double height) {
        return Convex(ConeShape<double>(radius, height));
    }
    /// The hull of the points, built twice: the second hull, of the first one's vertices, is what
    /// hull(vertices()) gives again, vertex order included. The support point at a tie is the
    /// first vertex in that order, so an unpickled hull (made from vertices()) answers bit for bit
    /// as this one does.
    static Convex hull(const Rows<double, 3>& points) {
        std::vector<Vec<double, 3>> p(points.shape(0));
        const double* d = points.data();
        for (std::size_t i = 0; i < p.size(); ++i) p[i] = {d[3 * i], d[3 * i + 1], d[3 * i + 2]};
        nb::gil_scoped_release release;
        const ConvexPolytope<double> first{std::span<const Vec<double, 3>>(p)};
        return Convex(ConvexPolytope<double>(first.vertices()));
    }

    const Shape& shape() const { return shape_; }
    int kind() const { return int(shape_.kind()); }
    double bounding_radius() const { return shape_.bounding_radius(); }
    /// A hull's vertices (n, 3); (0, 3) for the other shapes.
    nb::ndarray<nb::numpy, double> vertices() const {
        std::vector<double> v;
        if (const auto* hull = std::get_if<ConvexPolytope<double>>(&shape_.variant()))
            for (const Vec<double, 3>& p : hull->vertices()) v.insert(v.end(), {p[0], p[1], p[2]});
        const std::size_t n = v.size() / 3;
        return owned_array(std::move(v), n, 3);
    }

  private:
    Shape shape_;
};

/// Calls per_pose(i, pose) for every pose of B in A's frame, over `threads` threads without the
/// GIL (collision.hpp's run_poses, as Model::poses).
template <class PerPose>
void each_pose(const std::optional<PoseArray>& rotations, const PoseArray& translations,
               unsigned threads, PerPose&& per_pose) {
    const PoseValues<double> t(translations, 1, "translations");
    const PoseValues<double> r =
        rotations ? PoseValues<double>(*rotations, 2, "rotations") : PoseValues<double>();
    pose_count(r, t);
    nb::gil_scoped_release release;
    // A query is a few microseconds: chunks of several poses keep the shared counter off the
    // critical path. Each pose is still answered by one thread alone.
    run_poses(r, t, 16, threads, per_pose);
}

void put(double* out, std::size_t i, const Vec<double, 3>& v) {
    for (int a = 0; a < 3; ++a) out[3 * i + a] = v[a];
}

void distance_batch(const Convex& a, const Convex& b, const std::optional<PoseArray>& rotations,
                    const PoseArray& translations, OutColumn<double> dist,
                    OutRows<double, 3> point_a, OutRows<double, 3> point_b,
                    OutRows<double, 3> normal, unsigned threads) {
    const std::size_t k = PoseValues<double>(translations, 1, "translations").count();
    expect_rows(dist, k, "distance");
    expect_rows(point_a, k, "point_a");
    expect_rows(point_b, k, "point_b");
    expect_rows(normal, k, "normal");
    double *d = dist.data(), *pa = point_a.data(), *pb = point_b.data(), *n = normal.data();
    const Transform<double> identity = Transform<double>::identity();
    each_pose(rotations, translations, threads, [&](std::size_t i, const Transform<double>& pose) {
        const ConvexDistance<double> c = convex_distance(a.shape(), identity, b.shape(), pose);
        d[i] = c.distance;
        put(pa, i, c.point_a);
        put(pb, i, c.point_b);
        put(n, i, c.normal);
    });
}

void signed_distance_batch(const Convex& a, const Convex& b,
                           const std::optional<PoseArray>& rotations, const PoseArray& translations,
                           OutColumn<double> dist, OutRows<double, 3> point_a,
                           OutRows<double, 3> point_b, OutRows<double, 3> normal,
                           OutColumn<bool> converged, unsigned threads) {
    const std::size_t k = PoseValues<double>(translations, 1, "translations").count();
    expect_rows(dist, k, "signed_distance");
    expect_rows(point_a, k, "point_a");
    expect_rows(point_b, k, "point_b");
    expect_rows(normal, k, "normal");
    expect_rows(converged, k, "converged");
    double *d = dist.data(), *pa = point_a.data(), *pb = point_b.data(), *n = normal.data();
    bool* ok = converged.data();
    const Transform<double> identity = Transform<double>::identity();
    each_pose(rotations, translations, threads, [&](std::size_t i, const Transform<double>& pose) {
        const ConvexSignedDistance<double> c =
            convex_signed_distance(a.shape(), identity, b.shape(), pose);
        d[i] = c.signed_distance;
        put(pa, i, c.point_a);
        put(pb, i, c.point_b);
        put(n, i, c.normal);
        ok[i] = c.converged;
    });
}

/// The shape at each pose in the mesh model's frame: distance, overlap, closest points (the
/// model's frame) and the mesh's face; with `collides_only`, only overlap (stopping at the first
/// triangle met) and the other outputs untouched.
template <class V>
void mesh_batch(const Model<V>& mesh, const Convex& shape,
                const std::optional<PoseArray>& rotations, const PoseArray& translations,
                OutColumn<double> dist, OutColumn<bool> overlap, OutRows<double, 3> point_shape,
                OutRows<double, 3> point_mesh, OutColumn<std::int64_t> face, bool collides_only,
                unsigned threads) {
    const std::size_t k = PoseValues<double>(translations, 1, "translations").count();
    expect_rows(overlap, k, "overlap");
    if (!collides_only) {
        expect_rows(dist, k, "distance");
        expect_rows(point_shape, k, "point_shape");
        expect_rows(point_mesh, k, "point_mesh");
        expect_rows(face, k, "face");
    }
    const Transform<double> identity = Transform<double>::identity();
    mesh.shape_poses(rotations, translations, threads,
                     [&](std::size_t i, const Transform<double>& pose, const CollisionModel<V>& m) {
                         if (collides_only) {
                             overlap.data()[i] =
                                 convex_mesh_collides(shape.shape(), pose, m, identity);
                             return;
                         }
                         const ConvexMeshDistance<double> c =
                             convex_mesh_distance(shape.shape(), pose, m, identity);
                         const bool found = c.face != ConvexMeshDistance<double>{}.face;
                         dist.data()[i] = c.distance;
                         overlap.data()[i] = c.overlap;
                         const double nan = std::numeric_limits<double>::quiet_NaN();
                         put(point_shape.data(), i, found ? c.point_shape : Vec<double, 3>(nan));
                         put(point_mesh.data(), i, found ? c.point_mesh : Vec<double, 3>(nan));
                         face.data()[i] = found ? std::int64_t(c.face) : -1;
                     });
}

template <class V>
void bind_mesh_batch(nb::module_& m) {
    m.def("convex_mesh", &mesh_batch<V>, nb::arg("mesh"), nb::arg("shape"),
          nb::arg("rotations").none(), nb::arg("translations"), nb::arg("distance"),
          nb::arg("overlap"), nb::arg("point_shape"), nb::arg("point_mesh"), nb::arg("face"),
          nb::arg("collides_only"), nb::arg("threads"),
          "The shape at each pose in the mesh's frame against the mesh: into the arrays.");
}

}  // namespace

void bind_convex(nb::module_& m) {
    nb::class_<Convex>(m, "Convex", "One convex shape (see bvhkit.ConvexShape).")
        .def_static("sphere", &Convex::sphere, nb::arg("radius"))
        .def_static("box", &Convex::box, nb::arg("x"), nb::arg("y"), nb::arg("z"))
        .def_static("capsule", &Convex::capsule, nb::arg("radius"), nb::arg("half_length"))
        .def_static("cylinder", &Convex::cylinder, nb::arg("radius"), nb::arg("half_height"))
        .def_static("cone", &Convex::cone, nb::arg("radius"), nb::arg("height"))
        .def_static("hull", &Convex::hull, nb::arg("points"),
                    "The hull of (n, 3) float64 points, n >= 1, all finite.")
        .def_prop_ro("kind", &Convex::kind,
                     "0 sphere, 1 box, 2 capsule, 3 cylinder, 4 cone, 5 hull.")
        .def_prop_ro("bounding_radius", &Convex::bounding_radius,
                     "The largest distance of a point of the shape from its origin.")
        .def("vertices", &Convex::vertices, "A hull's vertices (n, 3); (0, 3) otherwise.");
    m.def("convex_distance", &distance_batch, nb::arg("a"), nb::arg("b"),
          nb::arg("rotations").none(), nb::arg("translations"), nb::arg("distance"),
          nb::arg("point_a"), nb::arg("point_b"), nb::arg("normal"), nb::arg("threads"),
          "GJK distance of b at each pose (in a's frame) from a, into the given arrays.");
    m.def("convex_signed_distance", &signed_distance_batch, nb::arg("a"), nb::arg("b"),
          nb::arg("rotations").none(), nb::arg("translations"), nb::arg("signed_distance"),
          nb::arg("point_a"), nb::arg("point_b"), nb::arg("normal"), nb::arg("converged"),
          nb::arg("threads"),
          "Signed distance (minus the EPA penetration depth when overlapping) of b at each pose.");
    bind_mesh_batch<Aabb<double, 3>>(m);
    bind_mesh_batch<Sphere<double>>(m);
    bind_mesh_batch<Obb<double>>(m);
    bind_mesh_batch<Rss<double>>(m);
    bind_mesh_batch<ObbRss<double>>(m);
    bind_mesh_batch<Kdop<double, 18>>(m);
    bind_mesh_batch<ConvexHull<double>>(m);
}

}  // namespace bvhkit::python
