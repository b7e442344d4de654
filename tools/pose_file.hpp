#pragma once
// Pose files (docs/workloads.md): 12 float32 per pose, a row-major 3x3 rotation R then a
// translation t; and the little-endian byte writer the result files share.
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/math/transform.hpp"

namespace bvhkit::tools {

inline std::vector<Transform<float>> read_pose_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot open pose file " + path);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
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
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) throw Error("cannot write " + path);
}

}  // namespace bvhkit::tools
