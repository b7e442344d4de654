#pragma once
// A thin owner of an Embree 3 scene over one triangle mesh, for same-run comparisons and
// cross-check tests. Compiled only when Embree is found (BVHKIT_HAVE_EMBREE).
#if BVHKIT_HAVE_EMBREE
#include <embree3/rtcore.h>

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
        RTCRayHit rh;
        rh.ray.org_x = ray.origin[0];
        rh.ray.org_y = ray.origin[1];
        rh.ray.org_z = ray.origin[2];
        rh.ray.dir_x = ray.direction[0];
        rh.ray.dir_y = ray.direction[1];
        rh.ray.dir_z = ray.direction[2];
        rh.ray.tnear = ray.tmin;
        rh.ray.tfar = ray.tmax;
        rh.ray.time = 0;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &context, &rh);
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

    bool any_hit(const Ray3f& ray) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
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
        rtcOccluded1(scene_, &context, &r);
        return r.tfar < 0;  // Embree sets tfar to -inf when occluded
    }

  private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    bool high_ = false;
};

}  // namespace bvhkit::bench
#endif
