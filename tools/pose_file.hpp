#pragma once
// Pose files (docs/workloads.md): 12 float32 per pose, a row-major 3x3 rotation R then a
// translation t; and the writer the result files share (file_access.hpp: beside and renamed, every
// step checked).
#include <cstring>
#include <string>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/io/file_access.hpp"
#include "bvhkit/math/transform.hpp"

namespace bvhkit::tools {

inline std::vector<Transform<float>> read_pose_file(const std::string& path) {
    const auto bytes = file_detail::read_regular_file<std::vector<char>>(path, "pose file");
    if (bytes.size() % 48 != 0)
        throw Error("pose file " + path + ": " + std::to_string(bytes.size()) +
                    " bytes is not a whole number of 48-byte poses");
    std::vector<Transform<float>> poses(bytes.size() / 48);
    for (std::size_t i = 0; i < poses.size(); ++i) {
        float f[12];
        std::memcpy(f, bytes.data() + 48 * i, 48);
        for (int r = 0; r < 3; ++r) poses[i].rotation[r] = {f[3 * r], f[3 * r + 1], f[3 * r + 2]};
        poses[i].translation = {f[9], f[10], f[11]};
        for (float x : f)
            if (!std::isfinite(x))
                throw Error("pose file " + path + ": pose " + std::to_string(i) +
                            " has a non-finite value");
    }
    return poses;
}

inline void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
    file_detail::write_file(path, bytes, "output file");
}

}  // namespace bvhkit::tools
