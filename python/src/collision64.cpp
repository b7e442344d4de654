// The collision models over double (see collision.hpp).
#include "collision.hpp"

namespace bvhkit::python {

void bind_collision64(nb::module_& m) {
    bind_model<Aabb<double, 3>>(m, "Model_aabb_f64");
    bind_model<Sphere<double>>(m, "Model_sphere_f64");
    bind_model<Obb<double>>(m, "Model_obb_f64");
    bind_model<Rss<double>>(m, "Model_rss_f64");
    bind_model<ObbRss<double>>(m, "Model_obbrss_f64");
    bind_model<Kdop<double, 18>>(m, "Model_kdop18_f64");
    bind_model<ConvexHull<double>>(m, "Model_hull_f64");
}

}  // namespace bvhkit::python
