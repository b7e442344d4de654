#pragma once
// A thin owner of an Embree 3 scene over one triangle mesh, for same-run comparisons and
// cross-check tests. Compiled only when Embree is found (BVHKIT_HAVE_EMBREE).
#if BVHKIT_HAVE_EMBREE
#include <embree3/rtcore.h>

#include <algorithm>
#include <cstdint>
#include <span>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::bench {

class EmbreeScene {
  public:
    /// Builds with RTC_BUILD_QUALITY_MEDIUM (or, with `high`, RTC_BUILD_QUALITY_HIGH: spatial
    /// splits) on a device limited to `threads` threads (0: every core). A limited device limits
    /// every oneTBB call of the process while it lives (Embree 3 sets a global_control), bvhkit's
    /// included.
    explicit EmbreeScene(const TriangleMesh& mesh, int threads = 1, bool high = false);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// Rebuilds the scene from scratch (for timing builds).
    void build(const TriangleMesh& mesh);

    Hit<float> closest_hit(const Ray3f& ray) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh = ray_hit(ray);
        rtcIntersect1(scene_, &context, &rh);
        return hit_of(rh);
    }

    /// Embree's stream calls (rtcIntersect1M, rtcOccluded1M) on the rays of `rays` (at most
    /// stream_chunk at a time), flagged incoherent: found[i] = 1 when ray i hits.
    static constexpr std::size_t stream_chunk = 256;
    void stream_hits(std::span<const Ray3f> rays, bool occlusion, std::uint8_t* found) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        RTCRayHit chunk[stream_chunk];
        for (std::size_t b = 0; b < rays.size(); b += stream_chunk) {
            const std::size_t n = std::min(stream_chunk, rays.size() - b);
            for (std::size_t j = 0; j < n; ++j) chunk[j] = ray_hit(rays[b + j]);
            if (occlusion) {
                // RTCRayHit starts with its RTCRay: the stride steps over the hits.
                rtcOccluded1M(scene_, &context, &chunk[0].ray, unsigned(n), sizeof(RTCRayHit));
                for (std::size_t j = 0; j < n; ++j) found[b + j] = chunk[j].ray.tfar < 0;
            } else {
                rtcIntersect1M(scene_, &context, chunk, unsigned(n), sizeof(RTCRayHit));
                for (std::size_t j = 0; j < n; ++j)
                    found[b + j] = chunk[j].hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
        }
    }

    bool any_hit(const Ray3f& ray) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r = ray_of(ray);
        rtcOccluded1(scene_, &context, &r);
        return r.tfar < 0;  // Embree sets tfar to -inf when occluded
    }

  private:
    static RTCRay ray_of(const Ray3f& ray) {
        RTCRay r;
        r.org_x = ray.origin[0];
        r.org_y = ray.origin[1];
        r.org_z = ray.origin[2];
        r.dir_x = ray.direction[0];
        r.dir_y = ray.direction[1];
        r.dir_z = ray.direction[2];
        r.tnear = ray.tmin;
        r.tfar = ray.tmax;
        r.time = 0;
        r.mask = 0xFFFFFFFFu;
        r.id = 0;
        r.flags = 0;
        return r;
    }
    static RTCRayHit ray_hit(const Ray3f& ray) {
        RTCRayHit rh;
        rh.ray = ray_of(ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        return rh;
    }
    static Hit<float> hit_of(const RTCRayHit& rh) {
        Hit<float> h;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            h.t = rh.ray.tfar;
            h.primitive = rh.hit.primID;
            h.u = rh.hit.u;
            h.v = rh.hit.v;
            h.normal = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
        }
        return h;
    }

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    bool high_ = false;
};

}  // namespace bvhkit::bench
#endif
