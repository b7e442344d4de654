#include "bvhkit/io/ray_files.hpp"

#include <bit>
#include <cstring>

#include "bvhkit/error.hpp"
#include "bvhkit/io/file_access.hpp"

namespace bvhkit {
namespace {

static_assert(std::endian::native == std::endian::little,
              "ray and hit files are little-endian; add byte swapping for this machine");

std::vector<char> read_all(const std::filesystem::path& path, std::size_t record,
                           const char* what) {
    std::vector<char> bytes =
        file_detail::read_regular_file<std::vector<char>>(path, std::string(what) + " file");
    if (bytes.size() % record != 0)
        throw Error(path.string() + ": " + std::to_string(bytes.size()) +
                    " bytes is not a whole number of " + what + " records (" +
                    std::to_string(record) + " bytes each)");
    return bytes;
}

void write_all(const std::filesystem::path& path, const void* data, std::size_t size) {
    file_detail::write_file(path, {static_cast<const unsigned char*>(data), size});
}

}  // namespace

std::vector<Ray3f> read_rays(const std::filesystem::path& path) {
    const std::vector<char> bytes = read_all(path, 32, "ray");
    std::vector<Ray3f> rays(bytes.size() / 32);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        float f[8];
        std::memcpy(f, bytes.data() + 32 * i, 32);
        rays[i] = Ray3f({f[0], f[1], f[2]}, {f[3], f[4], f[5]}, f[6], f[7]);
    }
    return rays;
}

void write_rays(const std::filesystem::path& path, const std::vector<Ray3f>& rays) {
    std::vector<float> f;
    f.reserve(rays.size() * 8);
    for (const auto& r : rays)
        f.insert(f.end(), {r.origin[0], r.origin[1], r.origin[2], r.direction[0], r.direction[1],
                           r.direction[2], r.tmin, r.tmax});
    write_all(path, f.data(), f.size() * sizeof(float));
}

std::vector<FileHit> read_hits(const std::filesystem::path& path) {
    const std::vector<char> bytes = read_all(path, 8, "hit");
    std::vector<FileHit> hits(bytes.size() / 8);
    for (std::size_t i = 0; i < hits.size(); ++i) {
        std::memcpy(&hits[i].t, bytes.data() + 8 * i, 4);
        std::memcpy(&hits[i].primitive, bytes.data() + 8 * i + 4, 4);
    }
    return hits;
}

void write_hits(const std::filesystem::path& path, const std::vector<FileHit>& hits) {
    std::vector<char> bytes(hits.size() * 8);
    for (std::size_t i = 0; i < hits.size(); ++i) {
        std::memcpy(bytes.data() + 8 * i, &hits[i].t, 4);
        std::memcpy(bytes.data() + 8 * i + 4, &hits[i].primitive, 4);
    }
    write_all(path, bytes.data(), bytes.size());
}

}  // namespace bvhkit
