#pragma once
// The ray and hit files of docs/workloads.md (little-endian, no header):
// rays: 8 float32 per ray (origin xyz, direction xyz, tmin, tmax);
// hits: per ray, float32 t (+inf on a miss) then uint32 primitive index (0xFFFFFFFF on a miss).
#include <filesystem>
#include <vector>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/hit.hpp"

namespace bvhkit {

/// Throws bvhkit::Error naming the file when it cannot be read or its size is not a multiple of 32.
std::vector<Ray3f> read_rays(const std::filesystem::path& path);
void write_rays(const std::filesystem::path& path, const std::vector<Ray3f>& rays);

struct FileHit {
    float t;
    std::uint32_t primitive;
};
std::vector<FileHit> read_hits(const std::filesystem::path& path);
void write_hits(const std::filesystem::path& path, const std::vector<FileHit>& hits);

}  // namespace bvhkit
