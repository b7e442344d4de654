#pragma once
// Convex polygons in 3D (segments in 2D) as the BSP stores them: one shared array of vertices, each
// polygon a run of it, counter-clockwise seen from the front of its source triangle's plane (a
// segment: two vertices). A polygon remembers the input triangle or segment it came from (its
// source), so that the parts a split makes can be traced back.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "bvhkit/bsp/plane.hpp"

namespace bvhkit {

/// A polygon of a PolygonPool: vertices [first, first + count) of the pool, and its source.
struct BspPolygon {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    std::uint32_t source = 0;  // index of the input triangle; its plane is the pool's plane[source]
};

/// Twice the vector area of a planar polygon (its length is twice the area, its direction the
/// normal of the counter-clockwise side); a fan from vertex 0.
template <class T>
Vec<T, 3> polygon_double_area_vector(std::span<const Vec<T, 3>> v) {
    Vec<T, 3> s{};
    for (std::size_t k = 1; k + 1 < v.size(); ++k) s += cross(v[k] - v[0], v[k + 1] - v[0]);
    return s;
}

template <class T>
T polygon_area(std::span<const Vec<T, 3>> v) {
    return length(polygon_double_area_vector(v)) / T(2);
}

/// The measure of a stored polygon: its area in 3D, its length in 2D (a segment).
template <class T, std::size_t N>
T polygon_measure(std::span<const Vec<T, N>> v) {
    if constexpr (N == 3)
        return polygon_area<T>(v);
    else
        return v.size() == 2 ? length(v[1] - v[0]) : T(0);
}

/// The polygons of a BSP (or of its build): vertices, polygons, and the plane of each source
/// triangle, which every part of that triangle shares (a split never tilts a part).
template <class T, std::size_t N = 3>
struct PolygonPool {
    std::vector<Vec<T, N>> vertices;
    std::vector<BspPolygon> polygons;
    std::vector<Plane<T, N>> source_planes;

    std::size_t size() const { return polygons.size(); }
    std::span<const Vec<T, N>> vertices_of(std::size_t i) const {
        const BspPolygon& p = polygons[i];
        return {vertices.data() + p.first, p.count};
    }
    const Plane<T, N>& plane_of(std::size_t i) const { return source_planes[polygons[i].source]; }
    /// Area in 3D, length in 2D.
    T area(std::size_t i) const { return polygon_measure<T, N>(vertices_of(i)); }

    /// Appends a polygon with the given vertices and source; returns its index.
    std::uint32_t add(std::span<const Vec<T, N>> v, std::uint32_t source) {
        BspPolygon p;
        p.first = std::uint32_t(vertices.size());
        p.count = std::uint32_t(v.size());
        p.source = source;
        vertices.insert(vertices.end(), v.begin(), v.end());
        polygons.push_back(p);
        return std::uint32_t(polygons.size() - 1);
    }
};

}  // namespace bvhkit
