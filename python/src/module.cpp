// The extension module bvhkit._bvhkit: bvhkit::Error becomes ValueError (FileNotFoundError becomes
// MissingFileError, a FileNotFoundError and a ValueError), load_mesh, read_file, and the scene,
// collision, dynamic tree and instanced scene classes (scene.cpp, collision.cpp, dynamic.cpp,
// instanced_scene.cpp). The public API with
// argument checks and defaults is the Python package around it (python/bvhkit/).
#include <string>

#include "bvhkit/io/file_access.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/version.hpp"
#include "common.hpp"

namespace nb = nanobind;
using namespace bvhkit::python;

NB_MODULE(_bvhkit, m) {
    m.doc() = "bvhkit's compiled core; use the bvhkit package, which checks arguments.";
    // A missing file is both FileNotFoundError (what Python users catch for a missing file) and
    // ValueError (what every other bad input is).
    nb::object missing_file = nb::steal(PyErr_NewExceptionWithDoc(
        "bvhkit.MissingFileError", "A file named as input does not exist.",
        nb::make_tuple(nb::handle(PyExc_FileNotFoundError), nb::handle(PyExc_ValueError)).ptr(),
        nullptr));
    m.attr("MissingFileError") = missing_file;
    nb::register_exception_translator(
        [](const std::exception_ptr& p, void* missing) {
            try {
                std::rethrow_exception(p);
            } catch (const bvhkit::FileNotFoundError& e) {
                PyErr_SetString(static_cast<PyObject*>(missing), e.what());
            } catch (const bvhkit::Error& e) {
                PyErr_SetString(PyExc_ValueError, e.what());
            }
        },
        missing_file.ptr());
    m.def(
        "read_file",
        [](const std::string& path) {
            std::string bytes;
            {
                nb::gil_scoped_release release;
                bytes = bvhkit::file_detail::read_regular_file<std::string>(path, "file");
            }
            return nb::bytes(bytes.data(), bytes.size());
        },
        nb::arg("path"),
        "The bytes of a regular file; ValueError for a device, FIFO or directory (which may never "
        "end or never deliver), MissingFileError for a missing file.");
    m.def(
        "write_file",
        [](const std::string& path, nb::bytes data) {
            const auto* first = static_cast<const unsigned char*>(data.data());
            const std::span<const unsigned char> bytes(first, data.size());
            nb::gil_scoped_release release;
            bvhkit::file_detail::write_file(path, bytes, "file");
        },
        nb::arg("path"), nb::arg("data"),
        "Writes `data` to `path` beside it and renamed into place (in place for a device or FIFO), "
        "every write, flush and close checked; ValueError naming the path on failure, and no "
        "partial file left.");
    m.def(
        "load_mesh",
        [](const std::string& file_or_spec) {
            bvhkit::TriangleMesh mesh;
            {
                nb::gil_scoped_release release;
                mesh = bvhkit::load_mesh(file_or_spec);
            }
            std::vector<float> v(3 * mesh.vertices.size());
            for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
                for (int a = 0; a < 3; ++a) v[3 * i + a] = mesh.vertices[i][a];
            std::vector<std::int64_t> f(3 * mesh.triangles.size());
            for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
                for (int a = 0; a < 3; ++a) f[3 * i + a] = mesh.triangles[i][a];
            const std::size_t nv = mesh.vertices.size(), nf = mesh.triangles.size();
            return nb::make_tuple(owned_array(std::move(v), nv, 3),
                                  owned_array(std::move(f), nf, 3));
        },
        nb::arg("file_or_spec"),
        "Reads an OBJ, PLY or STL file, or generates a mesh from a spec such as "
        "'sphere:subdiv=6'; returns (vertices float32 (n, 3), faces int64 (m, 3)).");
    m.attr("version") = bvhkit::version_string;
    bind_convex(m);  // convex shapes, GJK distance and EPA depth (convex.cpp)
    bind_scene(m);
    bind_collision32(m);
    bind_collision64(m);
    bind_dynamic(m);
    bind_instanced_scene(m);
    bind_solid(m);  // closed meshes as solids: penetration depth (solid.cpp)
}
