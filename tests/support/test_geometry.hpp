#pragma once
// Small shapes several test files build their cases from.
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::test {

/// The 2D box of corner (x, y), w wide and h high.
inline Aabb2f box2(float x, float y, float w = 1, float h = 1) {
    return {{x, y}, {x + w, y + h}};
}

/// A mesh's bounds in scalar T.
template <class T>
Aabb<T, 3> bounds_as(const TriangleMesh& mesh) {
    const Aabb3f b = mesh.bounds();
    return {Vec<T, 3>(b.min), Vec<T, 3>(b.max)};
}

}  // namespace bvhkit::test
