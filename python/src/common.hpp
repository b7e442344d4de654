#pragma once
// What every part of the extension shares: the array types it accepts and returns, the mesh built
// from numpy arrays, and run_batch (batch.hpp), which spreads a batch over threads.
//
// The Python layer (python/bvhkit/) checks shapes and dtypes, names the argument at fault and hands
// over C-contiguous arrays of the scene's scalar type, so the functions here take them as they are
// (no copy) and only read or fill them. Everything that does work releases the GIL.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "batch.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::python {

namespace nb = nanobind;

using Cpu = nb::device::cpu;
/// (k, D) rows of T, read only.
template <class T, std::size_t D>
using Rows = nb::ndarray<const T, nb::shape<-1, D>, nb::c_contig, Cpu>;
/// (k, D) rows of T, written by the call.
template <class T, std::size_t D>
using OutRows = nb::ndarray<T, nb::shape<-1, D>, nb::c_contig, Cpu>;
/// (k,) values, read only / written.
template <class T>
using Column = nb::ndarray<const T, nb::shape<-1>, nb::c_contig, Cpu>;
template <class T>
using OutColumn = nb::ndarray<T, nb::shape<-1>, nb::c_contig, Cpu>;
/// Faces: (m, 3) int32 or int64, chosen at run time.
using Faces = nb::ndarray<nb::ro, nb::shape<-1, 3>, nb::c_contig, Cpu>;

/// Throws bvhkit::Error (ValueError in Python) unless `a` has `rows` rows.
template <class A>
void expect_rows(const A& a, std::size_t rows, const char* name) {
    if (a.shape(0) != rows)
        throw Error(std::string(name) + ": " + std::to_string(a.shape(0)) + " rows, expected " +
                    std::to_string(rows));
}

/// The errors of a bad pose in row i, worded as bvhkit/_collision.py documents them.
[[noreturn]] inline void throw_bad_translation(std::size_t i) {
    throw Error("translations: row " + std::to_string(i) + " has a NaN or infinite coordinate");
}
[[noreturn]] inline void throw_bad_rotation_entry(std::size_t i) {
    throw Error("rotations: rotation " + std::to_string(i) + " has a NaN or infinite entry");
}
[[noreturn]] inline void throw_not_a_rotation(std::size_t i) {
    throw Error("rotations: rotation " + std::to_string(i) +
                " is not a rotation matrix (R^T R must be the identity and det R = +1, to 1e-4)");
}

/// A batch of rays' [tmin, tmax]: one array each, or one pair for every ray (the one-ray calls'
/// usual form, which then converts no array for them).
template <class T>
struct PerRayLimits {
    const T *t0, *t1;
    T tmin(std::size_t i) const { return t0[i]; }
    T tmax(std::size_t i) const { return t1[i]; }
};
template <class T>
struct SharedLimits {
    T t0, t1;
    T tmin(std::size_t) const { return t0; }
    T tmax(std::size_t) const { return t1; }
};

/// The vertices and faces as the library's mesh (one copy: the library keeps its own).
template <class T>
BasicTriangleMesh<T> make_mesh(const Rows<T, 3>& vertices, const Faces& faces) {
    BasicTriangleMesh<T> mesh;
    const std::size_t nv = vertices.shape(0), nf = faces.shape(0);
    mesh.vertices.resize(nv);
    const T* v = vertices.data();
    for (std::size_t i = 0; i < nv; ++i) mesh.vertices[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
    mesh.triangles.resize(nf);
    const auto copy = [&](const auto* f) {
        for (std::size_t i = 0; i < 3 * nf; ++i) {
            const auto k = f[i];
            if (k < 0 || std::uint64_t(k) >= nv)
                throw Error("faces: face " + std::to_string(i / 3) + " names vertex " +
                            std::to_string(k) + " of " + std::to_string(nv));
            mesh.triangles[i / 3][i % 3] = std::uint32_t(k);
        }
    };
    if (faces.dtype() == nb::dtype<std::int32_t>())
        copy(static_cast<const std::int32_t*>(faces.data()));
    else if (faces.dtype() == nb::dtype<std::int64_t>())
        copy(static_cast<const std::int64_t*>(faces.data()));
    else
        throw Error("faces: dtype must be int32 or int64");
    return mesh;
}

/// run_batch in the shape of an Executor's parallel_for, for the library's own parallel steps
/// (spatial_order); `threads` as run_batch's.
struct BatchExecutor {
    unsigned threads;
    template <class Body>
    void parallel_for(std::size_t count, std::size_t grain, Body&& body) const {
        run_batch(count, grain, threads, body);
    }
};

/// A (rows, cols) numpy array that owns `values` (rows * cols of them).
template <class X>
nb::ndarray<nb::numpy, X> owned_array(std::vector<X>&& values, std::size_t rows, std::size_t cols) {
    auto* heap = new std::vector<X>(std::move(values));
    heap->reserve(1);  // a valid data pointer for an empty array
    nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<X>*>(p); });
    if (cols == 0) return nb::ndarray<nb::numpy, X>(heap->data(), {rows}, owner);
    return nb::ndarray<nb::numpy, X>(heap->data(), {rows, cols}, owner);
}

/// Gives `vertices` the (n, 3) rows at `rows` and calls refit(). When refit throws (a non-finite
/// coordinate in a triangle of the tree), the old vertices go back, so the object stays as it was,
/// and the Error names the argument.
template <class T, class Refit>
void refit_vertices(std::vector<Vec<T, 3>>& vertices, const T* rows, Refit&& refit) {
    std::vector<Vec<T, 3>> moved(vertices.size());
    for (std::size_t i = 0; i < moved.size(); ++i)
        moved[i] = {rows[3 * i], rows[3 * i + 1], rows[3 * i + 2]};
    vertices.swap(moved);
    try {
        refit();
    } catch (const Error& e) {
        vertices.swap(moved);
        throw Error(std::string("vertices: ") + e.what());
    }
}

void bind_scene(nb::module_& m);
void bind_convex(nb::module_& m);
void bind_collision32(nb::module_& m);
void bind_collision64(nb::module_& m);
void bind_dynamic(nb::module_& m);
void bind_instanced_scene(nb::module_& m);
void bind_solid(nb::module_& m);

}  // namespace bvhkit::python
