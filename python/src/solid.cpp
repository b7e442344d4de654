// Solid<V>: a closed mesh as a solid for Python (query/solid_model.hpp), and the penetration depth
// and signed distance between two solids over a batch of poses, without the GIL
// (query/mesh_penetration.hpp; the pose loop is collision.hpp's run_poses).
#include "bvhkit/query/mesh_penetration.hpp"
#include "collision.hpp"

namespace bvhkit::python {
namespace {

template <class V>
class Solid {
  public:
    using T = typename V::Scalar;

    Solid(const Rows<T, 3>& vertices, const Faces& faces, unsigned threads) {
        const BasicTriangleMesh<T> mesh = make_mesh<T>(vertices, faces);
        BuildOptions options = collision_build_options();
        options.threads = threads;
        nb::gil_scoped_release release;
        solid_.emplace(mesh, options);
    }

    void signed_distance(const Solid& b, const std::optional<PoseArray>& rotations,
                         const PoseArray& translations, OutColumn<T> dist, OutRows<T, 3> point_a,
                         OutRows<T, 3> point_b, OutRows<T, 3> normal, OutColumn<bool> exact,
                         OutColumn<bool> contained, unsigned threads) const {
        const PoseValues<T> t(translations, 1, "translations");
        const PoseValues<T> r =
            rotations ? PoseValues<T>(*rotations, 2, "rotations") : PoseValues<T>();
        const std::size_t k = pose_count(r, t);
        expect_rows(dist, k, "signed_distance");
        expect_rows(point_a, k, "point_a");
        expect_rows(point_b, k, "point_b");
        expect_rows(normal, k, "normal");
        expect_rows(exact, k, "exact");
        expect_rows(contained, k, "contained");
        T *d = dist.data(), *pa = point_a.data(), *pb = point_b.data(), *n = normal.data();
        bool *ex = exact.data(), *in = contained.data();
        nb::gil_scoped_release release;
        run_poses(r, t, 1, threads, [&](std::size_t i, const Transform<T>& pose) {
            const MeshSignedDistance<T> s = signed_distance_between(*solid_, *b.solid_, pose);
            d[i] = s.signed_distance;
            for (int a = 0; a < 3; ++a) {
                pa[3 * i + a] = s.point_a[a];
                pb[3 * i + a] = s.point_b[a];
                n[3 * i + a] = s.normal[a];
            }
            ex[i] = s.quality == DepthQuality::Exact;
            in[i] = s.contained;
        });
    }

    bool convex() const { return solid_->convex(); }
    std::size_t triangle_count() const { return solid_->collision().triangle_count(); }

  private:
    std::optional<SolidModel<V>> solid_;  // immutable once built: shared by threads freely
};

template <class V>
void bind_solid_type(nb::module_& m, const char* name) {
    using S = Solid<V>;
    using T = typename V::Scalar;
    nb::class_<S>(m, name, "A closed mesh as a solid (see bvhkit.Solid).")
        .def(nb::init<const Rows<T, 3>&, const Faces&, unsigned>(), nb::arg("vertices"),
             nb::arg("faces"), nb::arg("threads"),
             "Checks the mesh is closed, builds its trees and hull.")
        .def("signed_distance", &S::signed_distance, nb::arg("b"), nb::arg("rotations").none(),
             nb::arg("translations"), nb::arg("signed_distance"), nb::arg("point_a"),
             nb::arg("point_b"), nb::arg("normal"), nb::arg("exact"), nb::arg("contained"),
             nb::arg("threads"),
             "Distance, or minus the penetration depth, to b at each pose (this solid's frame).")
        .def_prop_ro("convex", &S::convex, "Whether the mesh is convex.")
        .def_prop_ro("triangle_count", &S::triangle_count, "Number of faces.");
}

}  // namespace

void bind_solid(nb::module_& m) {
    bind_solid_type<Obb<float>>(m, "Solid_obb_f32");
    bind_solid_type<Obb<double>>(m, "Solid_obb_f64");
    bind_solid_type<Rss<float>>(m, "Solid_rss_f32");
    bind_solid_type<Rss<double>>(m, "Solid_rss_f64");
}

}  // namespace bvhkit::python
