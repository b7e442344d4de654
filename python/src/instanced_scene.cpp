// The binding of InstancedScene<T> (instanced_scene.hpp, instanced_scene_pairs.hpp) as
// bvhkit._bvhkit.InstancedScene32/64, wrapped by bvhkit.Scene (python/bvhkit/_instances.py,
// _scene_pairs.py).
#include "instanced_scene.hpp"
#include "instanced_scene_pairs.hpp"

namespace bvhkit::python {
namespace {

template <class T>
void bind_instanced_type(nb::module_& m, const char* name) {
    using S = InstancedScene<T>;
    nb::class_<S>(m, name, "Posed instances of shared meshes (see bvhkit.Scene).")
        .def(nb::init<>())
        .def("add_mesh", &S::add_mesh, nb::arg("vertices"), nb::arg("faces"))
        .def("add_instances", &S::add_instances, nb::arg("geometry"), nb::arg("rotations"),
             nb::arg("translations"), nb::arg("user_data"), nb::arg("group"), nb::arg("mask"),
             nb::arg("margin"), nb::arg("ids"))
        .def("set_poses", &S::set_poses, nb::arg("ids"), nb::arg("rotations"),
             nb::arg("translations"))
        .def("set_options", &S::set_options, nb::arg("ids"), nb::arg("user_data"), nb::arg("group"),
             nb::arg("mask"), nb::arg("margin"), nb::arg("given"))
        .def("remove", &S::remove, nb::arg("ids"))
        .def("__len__", &S::size)
        .def("geometry_count", &S::geometry_count)
        .def("contains", &S::contains, nb::arg("id"))
        .def("ids", &S::ids)
        .def("describe", &S::describe, nb::arg("ids"), nb::arg("geometry"), nb::arg("user_data"),
             nb::arg("group"), nb::arg("mask"), nb::arg("margin"), nb::arg("rotations"),
             nb::arg("translations"))
        .def("bounds", &S::bounds)
        .def("validate", &S::validate)
        .def("prepare", &S::prepare)
        .def("intersect", &S::intersect, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("t"), nb::arg("instance"), nb::arg("geometry"),
             nb::arg("face"), nb::arg("barycentric"), nb::arg("normal"), nb::arg("threads"))
        .def("intersect_shared", &S::intersect_shared, nb::arg("origins"), nb::arg("directions"),
             nb::arg("tmin"), nb::arg("tmax"), nb::arg("t"), nb::arg("instance"),
             nb::arg("geometry"), nb::arg("face"), nb::arg("barycentric"), nb::arg("normal"),
             nb::arg("threads"))
        .def("occluded", &S::occluded, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("out"), nb::arg("threads"))
        .def("list_intersections", &S::list_intersections, nb::arg("origins"),
             nb::arg("directions"), nb::arg("tmin"), nb::arg("tmax"), nb::arg("threads"))
        .def("closest_point", &S::closest_point, nb::arg("points"), nb::arg("distance"),
             nb::arg("point"), nb::arg("instance"), nb::arg("geometry"), nb::arg("face"),
             nb::arg("barycentric"), nb::arg("threads"))
        .def("signed_distance", &S::signed_distance, nb::arg("points"), nb::arg("sign"),
             nb::arg("distance"), nb::arg("point"), nb::arg("instance"), nb::arg("geometry"),
             nb::arg("face"), nb::arg("barycentric"), nb::arg("threads"))
        .def("contains_points", &S::contains_points, nb::arg("points"), nb::arg("out"),
             nb::arg("threads"))
        .def("colliding_pairs", &instance_pairs::colliding_pairs<T>, nb::arg("ignore"))
        .def("any_collision", &instance_pairs::any_collision<T>, nb::arg("ignore"))
        .def("colliding_instances", &instance_pairs::colliding_instances<T>, nb::arg("geometry"),
             nb::arg("rotation"), nb::arg("translation"), nb::arg("group"), nb::arg("mask"),
             nb::arg("margin"), nb::arg("stop_at_first"))
        .def("colliding_pairs_with", &instance_pairs::colliding_pairs_with<T>, nb::arg("other"),
             nb::arg("ignore"))
        .def("any_collision_with", &instance_pairs::any_collision_with<T>, nb::arg("other"),
             nb::arg("ignore"))
        .def("colliding_faces", &instance_pairs::colliding_faces<T>, nb::arg("ignore"))
        .def("colliding_faces_with", &instance_pairs::colliding_faces_with<T>, nb::arg("other"),
             nb::arg("ignore"))
        .def("colliding_pairs_at", &instance_pairs::colliding_pairs_at<T>, nb::arg("ids"),
             nb::arg("rotations"), nb::arg("translations"), nb::arg("ignore"))
        .def("any_collisions_at", &instance_pairs::any_collisions_at<T>, nb::arg("ids"),
             nb::arg("rotations"), nb::arg("translations"), nb::arg("ignore"), nb::arg("threads"))
        .def("to_bytes", &S::to_bytes)
        .def("load_bytes", &S::load_bytes, nb::arg("data"))
        .def("closest_pair", &instance_pairs::closest_pair<T>, nb::arg("ignore"))
        .def("closest_pair_with", &instance_pairs::closest_pair_with<T>, nb::arg("other"),
             nb::arg("ignore"))
        .def("pairs_within", &instance_pairs::pairs_within<T>, nb::arg("threshold"),
             nb::arg("ignore"))
        .def("pairs_within_with", &instance_pairs::pairs_within_with<T>, nb::arg("other"),
             nb::arg("threshold"), nb::arg("ignore"))
        .def("closest_instance", &instance_pairs::closest_instance<T>, nb::arg("geometry"),
             nb::arg("rotation"), nb::arg("translation"), nb::arg("group"), nb::arg("mask"),
             nb::arg("margin"));
}

}  // namespace

void bind_instanced_scene(nb::module_& m) {
    bind_instanced_type<float>(m, "InstancedScene32");
    bind_instanced_type<double>(m, "InstancedScene64");
}

}  // namespace bvhkit::python
