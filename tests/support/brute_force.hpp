#pragma once
// The search reference of the ray tests: each ray against every triangle, with the same triangle
// test the tree uses (so t agrees exactly, and only the search differs). Whether the triangle test
// itself is right is judged separately, against an independent long-double reference
// (exact_ray_reference.hpp).
#include <gtest/gtest.h>

#include "bvhkit/triangle_bvh.hpp"

namespace bvhkit::test {

template <class T>
class BruteForce {
  public:
    BruteForce(const std::vector<Triangle<T>>& tris, const std::vector<Ray<T, 3>>& rays,
               TriangleTest test = TriangleTest::Watertight)
        : tris_(tris), test_(test) {
        for (const auto& t : tris) fast_.emplace_back(t);
        closest_.resize(rays.size());
        for (std::size_t r = 0; r < rays.size(); ++r) {
            Hit<T> best;
            for (std::uint32_t i = 0; i < tris.size(); ++i) {
                const auto h = intersect(i, rays[r]);
                if (h && h->t < best.t) best = {h->t, i, h->u, h->v};
            }
            closest_[r] = best;
        }
    }

    std::optional<TriangleHit<T>> intersect(std::uint32_t i, const Ray<T, 3>& ray) const {
        if (test_ == TriangleTest::Watertight) return tris_[i].intersect_watertight(ray);
        TriangleHit<T> h;
        if (fast_[i].intersect(ray, ray.tmax, h)) return h;
        return std::nullopt;
    }

    const Hit<T>& closest(std::size_t r) const { return closest_[r]; }

    /// Closest hit and any hit of `bvh` for every ray against the reference.
    void check(const TriangleBvh<T>& bvh, const std::vector<Ray<T, 3>>& rays) const {
        std::size_t hits = 0, ties = 0;
        for (std::size_t r = 0; r < rays.size(); ++r) {
            const Hit<T>& want = closest_[r];
            const Hit<T> got = bvh.closest_hit(rays[r]);
            ASSERT_EQ(bool(got), bool(want)) << "ray " << r;
            if (want) {
                ASSERT_EQ(got.normal, tris_[got.primitive].normal()) << "ray " << r;
            }
            ASSERT_EQ(bvh.any_hit(rays[r]), bool(want)) << "ray " << r;
            if (!want) continue;
            ++hits;
            ASSERT_NEAR(got.t, want.t, T(1e-5) * std::max(T(1), std::fabs(want.t))) << "ray " << r;
            if (got.primitive != want.primitive) {
                // Allowed only for a tie: the triangle we got must be hit at the same t.
                const auto other = intersect(got.primitive, rays[r]);
                ASSERT_TRUE(other && other->t == want.t)
                    << "ray " << r << ": got triangle " << got.primitive << ", want "
                    << want.primitive;
                ++ties;
            } else {
                ASSERT_EQ(got.u, want.u);
                ASSERT_EQ(got.v, want.v);
            }
        }
        EXPECT_GT(hits, rays.size() / 50) << "too few rays hit: the test would prove little";
        EXPECT_LE(ties, rays.size() / 100);
    }

  private:
    const std::vector<Triangle<T>>& tris_;
    std::vector<PrecomputedTriangle<T>> fast_;
    TriangleTest test_;
    std::vector<Hit<T>> closest_;
};

}  // namespace bvhkit::test
