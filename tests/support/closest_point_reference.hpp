#pragma once
// The closest-point tests' references and inputs (tests/proximity/nearest_test.cpp,
// closest_point_wide_test.cpp, closest_point_fuzz_test.cpp): the brute force over every triangle,
// query points near and far, moved and scaled meshes, and sliver soups.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>
#include <vector>

#include "bvhkit/query/closest_point_mesh.hpp"
#include "random_geometry.hpp"
#include "test_support.hpp"

namespace bvhkit::test {

/// The brute force's distance: the accurate point-triangle distance ClosestPointMesh measures its
/// candidates with (itself judged against exact arithmetic in closest_point_accuracy_test.cpp), so
/// that these tests check the search: the same answer as every triangle measured alike.
template <class T>
T distance2(const Triangle<T>& t, const Vec<T, 3>& p) {
    return T(distance_squared_accurate(t, p));
}

/// Points near the surface (a random surface point pushed off by up to 1% of the diagonal) and
/// far (uniform in the box grown by half its size on every side).
template <class T>
std::vector<Vec<T, 3>> query_points(const std::vector<Triangle<T>>& tris, std::size_t count,
                                    std::uint64_t seed) {
    test::Random rng(seed);
    Aabb<T, 3> box;
    for (const auto& t : tris) box.grow(t.bounds());
    const Vec<T, 3> e = box.extent();
    const T diag = length(e);
    const Aabb<T, 3> far(box.min - e * T(0.5), box.max + e * T(0.5));
    std::vector<Vec<T, 3>> out;
    for (std::size_t i = 0; i < count; ++i) {
        if (i % 2) {
            out.push_back(rng.point_in(far));
        } else {
            const auto& t = tris[rng.below(std::uint32_t(tris.size()))];
            T a = T(rng.uniform()), b = T(rng.uniform());
            if (a + b > 1) a = 1 - a, b = 1 - b;
            const Vec<T, 3> s = t.p0 + (t.p1 - t.p0) * a + (t.p2 - t.p0) * b;
            out.push_back(s + rng.unit_vector<T>() * (diag * T(0.01 * rng.uniform())));
        }
    }
    return out;
}

template <class T>
void check_against_brute_force(const std::vector<Triangle<T>>& tris, std::size_t point_count,
                               std::uint64_t seed, const BuildOptions& options = {}) {
    const ClosestPointMesh<T> mesh(tris, options);
    const auto points = query_points(tris, point_count, seed);
    NearestScratch<T> scratch;
    std::vector<MeshPoint<T>> knn, inside;
    std::vector<std::pair<T, std::uint32_t>> all(tris.size());
    std::size_t ties = 0;
    for (std::size_t q = 0; q < points.size(); ++q) {
        const Vec<T, 3>& p = points[q];
        for (std::uint32_t i = 0; i < tris.size(); ++i) all[i] = {distance2(tris[i], p), i};
        std::sort(all.begin(), all.end());
        const auto got = mesh.closest_point(p, scratch);
        ASSERT_TRUE(got) << "point " << q;
        const T want = all[0].first;
        ASSERT_NEAR(got.distance_squared, want, T(1e-6) * want + std::numeric_limits<T>::min())
            << "point " << q;
        // And within 1e-6 (relative, in distance) of a brute force by another method: Ericson's
        // closest point in double on the same triangles, moved so that p is the origin (its
        // rounding is then relative to the distance and the triangle's size).
        double ericson = std::numeric_limits<double>::infinity();
        const Vec3d pd(p);
        for (const auto& t : tris) {
            const Triangle<double> w{Vec3d(t.p0) - pd, Vec3d(t.p1) - pd, Vec3d(t.p2) - pd};
            ericson = std::min(ericson, length_squared(closest_point(w, Vec3d(0.0)).point));
        }
        // (Plus 2^-40 of p's magnitude: points on the surface are at distance ~0, and either
        // brute force is off by the rounding of the coordinates there.)
        ASSERT_NEAR(std::sqrt(double(got.distance_squared)), std::sqrt(ericson),
                    1e-6 * std::sqrt(ericson) + 0x1p-40 * double(max_component(abs(p))))
            << "point " << q;
        if (got.triangle != all[0].second) {
            // Allowed for a tie only: the triangle we got is as close as the best.
            ASSERT_EQ(distance2(tris[got.triangle], p), want) << "point " << q;
            ++ties;
        }
        // The point and barycentrics describe the same place on that triangle.
        const Triangle<T>& t = tris[got.triangle];
        const Vec<T, 3> from_uv = t.p0 * (1 - got.u - got.v) + t.p1 * got.u + t.p2 * got.v;
        ASSERT_LE(length(from_uv - got.point), T(1e-4) * (T(1) + length(got.point)));

        // k nearest: the same distances as the k smallest of all.
        const std::size_t k = std::min<std::size_t>(8, tris.size());
        mesh.k_nearest(p, k, knn, scratch);
        ASSERT_EQ(knn.size(), k);
        for (std::size_t j = 0; j < k; ++j)
            ASSERT_EQ(knn[j].distance_squared, all[j].first) << "point " << q << " rank " << j;

        // Within a radius: the same set (the radius between two distances to avoid ties).
        const std::size_t m = std::min<std::size_t>(20, tris.size() - 1);
        const T r2 = (all[m - 1].first + all[m].first) / 2;
        if (!(all[m - 1].first < r2 && r2 < all[m].first)) continue;
        mesh.within_radius(p, std::sqrt(r2), inside);
        std::set<std::uint32_t> got_set, want_set;
        for (const auto& h : inside) got_set.insert(h.triangle);
        for (std::size_t j = 0; j < tris.size() && all[j].first <= r2; ++j)
            if (all[j].first <= std::sqrt(r2) * std::sqrt(r2)) want_set.insert(all[j].second);
        // sqrt(r2)^2 may differ from r2 by an ulp: only a triangle at that very distance may
        // differ, and the radius lies strictly between two distances.
        ASSERT_EQ(got_set, want_set) << "point " << q;
    }
    // Ties are common on meshes (a closest point at a vertex or on an edge belongs to every
    // triangle around it); each one was checked to be exact above.
    ::testing::Test::RecordProperty("ties", int(ties));
}

/// The triangles of a mesh in T, each corner moved by `offset` (added in T).
template <class T>
std::vector<Triangle<T>> moved(const TriangleMesh& mesh, T offset, T scale = T(1)) {
    std::vector<Triangle<T>> out = mesh_triangles<T>(mesh);
    for (auto& t : out)
        for (Vec<T, 3>* v : {&t.p0, &t.p1, &t.p2}) *v = *v * scale + Vec<T, 3>(offset);
    return out;
}

/// Triangles with p0 == p1 != p2 get p1 and p2 swapped (the same segment), so that the soups'
/// segments come with distinct first corners (TriangleWithFirstTwoCornersEqual tests the other
/// form).
template <class T>
std::vector<Triangle<T>> no_equal_first_corners(std::vector<Triangle<T>> tris) {
    for (auto& t : tris)
        if (t.p0 == t.p1) std::swap(t.p1, t.p2);
    return tris;
}

/// A soup made mostly of slivers and degenerate triangles (needles with the sharp corner at any
/// vertex, flat obtuse ones, exactly collinear ones, two or three equal corners) among a sixth of
/// ordinary ones, sizes from tiny to ~0.2 in the unit cube.
template <class T>
std::vector<Triangle<T>> sliver_soup(std::size_t count, std::uint64_t seed) {
    test::Random rng(seed);
    std::vector<Triangle<T>> out;
    while (out.size() < count) {
        const Vec3d c{rng.uniform(), rng.uniform(), rng.uniform()};
        const double size = 0.2 * std::pow(rng.uniform(), 2.0) + 1e-6;
        const Vec3d u = rng.unit_vector<double>();
        Vec3d w = cross(u, rng.unit_vector<double>());
        if (length(w) < 0.1) continue;
        w = normalize(w);
        const double thin = std::pow(10.0, rng.uniform(-8, -2));
        Vec3d v[3];
        switch (rng.below(6)) {
            case 0:  // a needle
                v[0] = c, v[1] = c + u * size, v[2] = c + (u + w * thin) * (size * rng.uniform());
                break;
            case 1:  // flat, the obtuse corner in the middle
                v[0] = c, v[1] = c - u * (size * rng.uniform()), v[2] = c + (u + w * thin) * size;
                break;
            case 2:  // collinear
                v[0] = c, v[1] = c + u * size, v[2] = c + u * (size * rng.uniform(-1, 2));
                break;
            case 3:  // two corners equal: p0 == p2 or p1 == p2 (see the note below)
                v[0] = c, v[1] = c + u * size, v[2] = rng.below(2) ? v[0] : v[1];
                break;
            case 4:  // a point
                v[0] = v[1] = v[2] = c;
                break;
            default:  // an ordinary triangle
                v[0] = c, v[1] = c + u * size, v[2] = c + w * size;
                break;
        }
        const std::uint32_t r = rng.below(3);  // the special corner anywhere
        out.push_back({Vec<T, 3>(v[r]), Vec<T, 3>(v[(r + 1) % 3]), Vec<T, 3>(v[(r + 2) % 3])});
    }
    return no_equal_first_corners(out);
}

}  // namespace bvhkit::test
