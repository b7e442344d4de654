#include "embree_instances.hpp"
#if BVHKIT_HAVE_EMBREE
#include <cstring>
#include <string>

#include "bvhkit/error.hpp"

namespace bvhkit::bench {

EmbreeInstances::EmbreeInstances(const TriangleMesh& mesh, std::span<const Transform<float>> poses,
                                 int threads) {
    const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw Error("Embree: rtcNewDevice failed");
    build(mesh, poses);
}

EmbreeInstances::~EmbreeInstances() {
    release();
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeInstances::release() {
    if (top_) rtcReleaseScene(top_);
    if (mesh_) rtcReleaseScene(mesh_);
    top_ = mesh_ = nullptr;
}

void EmbreeInstances::build(const TriangleMesh& mesh, std::span<const Transform<float>> poses) {
    release();
    mesh_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(mesh_, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry triangles = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(triangles, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.vertices.size()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(triangles, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    std::memcpy(vertices, mesh.vertices.data(), mesh.vertices.size() * 3 * sizeof(float));
    std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(unsigned));
    rtcSetGeometryBuildQuality(triangles, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitGeometry(triangles);
    rtcAttachGeometry(mesh_, triangles);
    rtcReleaseGeometry(triangles);
    rtcCommitScene(mesh_);

    top_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(top_, RTC_BUILD_QUALITY_MEDIUM);
    for (std::size_t i = 0; i < poses.size(); ++i) {
        RTCGeometry instance = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(instance, mesh_);
        // 3x4 column major: R's three columns, then t.
        const Transform<float>& p = poses[i];
        float xfm[12];
        for (std::size_t c = 0; c < 3; ++c)
            for (std::size_t r = 0; r < 3; ++r) xfm[3 * c + r] = p.rotation[r][c];
        for (std::size_t r = 0; r < 3; ++r) xfm[9 + r] = p.translation[r];
        rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
        rtcCommitGeometry(instance);
        // Attached by id: the hit's instID[0] is the pose's index.
        rtcAttachGeometryByID(top_, instance, unsigned(i));
        rtcReleaseGeometry(instance);
    }
    rtcCommitScene(top_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw Error("Embree: instance build failed");
}

}  // namespace bvhkit::bench
#endif
