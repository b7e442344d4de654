#include "embree_scene.hpp"
#if BVHKIT_HAVE_EMBREE
#include <cstring>
#include <string>

#include "bvhkit/error.hpp"

namespace bvhkit::bench {

EmbreeScene::EmbreeScene(const TriangleMesh& mesh, int threads, bool high) : high_(high) {
    // threads=0 leaves Embree's default, every core, and no process-wide limit on oneTBB.
    const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw Error("Embree: rtcNewDevice failed");
    build(mesh);
}

EmbreeScene::~EmbreeScene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::build(const TriangleMesh& mesh) {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = rtcNewScene(device_);
    const RTCBuildQuality quality = high_ ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
    rtcSetSceneBuildQuality(scene_, quality);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.vertices.size()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    std::memcpy(vertices, mesh.vertices.data(), mesh.vertices.size() * 3 * sizeof(float));
    std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(unsigned));
    rtcSetGeometryBuildQuality(geometry, quality);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw Error("Embree: scene build failed");
}

}  // namespace bvhkit::bench
#endif
