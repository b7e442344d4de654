// The collision models over float (see collision.hpp).
#include "collision.hpp"

namespace bvhkit::python {

void bind_collision32(nb::module_& m) {
    bind_model<Aabb<float, 3>>(m, "Model_aabb_f32");
    bind_model<Sphere<float>>(m, "Model_sphere_f32");
    bind_model<Obb<float>>(m, "Model_obb_f32");
    bind_model<Rss<float>>(m, "Model_rss_f32");
    bind_model<ObbRss<float>>(m, "Model_obbrss_f32");
    bind_model<Kdop<float, 18>>(m, "Model_kdop18_f32");
    bind_model<ConvexHull<float>>(m, "Model_hull_f32");
}

}  // namespace bvhkit::python
