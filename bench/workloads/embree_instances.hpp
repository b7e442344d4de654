#pragma once
// Embree 3's two-level instancing over one triangle mesh, for workload S3 (instanced rays): the
// mesh in a scene of its own, and a top scene of RTC_GEOMETRY_TYPE_INSTANCE geometries, one per
// pose, each placed with rtcSetGeometryTransform. Compiled only when Embree is found
// (BVHKIT_HAVE_EMBREE).
#if BVHKIT_HAVE_EMBREE
#include <embree3/rtcore.h>

#include <span>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/math/transform.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::bench {

class EmbreeInstances {
  public:
    /// One hit: the instance is the pose's index, face the triangle's index in the mesh.
    struct Result {
        unsigned instance = RTC_INVALID_GEOMETRY_ID;
        unsigned face = RTC_INVALID_GEOMETRY_ID;
        float t = 0, u = 0, v = 0;
        explicit operator bool() const { return instance != RTC_INVALID_GEOMETRY_ID; }
    };

    /// Both levels built with RTC_BUILD_QUALITY_MEDIUM (Embree's default, a binned SAH build, as
    /// bvhkit's default TriangleBvh is) on a device of `threads` threads (0: every core; a limited
    /// device limits every oneTBB call of the process while it lives).
    EmbreeInstances(const TriangleMesh& mesh, std::span<const Transform<float>> poses,
                    int threads = 1);
    ~EmbreeInstances();
    EmbreeInstances(const EmbreeInstances&) = delete;
    EmbreeInstances& operator=(const EmbreeInstances&) = delete;

    /// Both scenes again from scratch (for timing builds).
    void build(const TriangleMesh& mesh, std::span<const Transform<float>> poses);

    Result closest_hit(const Ray3f& ray) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh;
        rh.ray = ray_of(ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(top_, &context, &rh);
        Result r;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            r.instance = rh.hit.instID[0];
            r.face = rh.hit.primID;
            r.t = rh.ray.tfar;
            r.u = rh.hit.u;
            r.v = rh.hit.v;
        }
        return r;
    }

    bool any_hit(const Ray3f& ray) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r = ray_of(ray);
        rtcOccluded1(top_, &context, &r);
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
    void release();

    RTCDevice device_ = nullptr;
    RTCScene mesh_ = nullptr;
    RTCScene top_ = nullptr;
};

}  // namespace bvhkit::bench
#endif
