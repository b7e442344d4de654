// `bvhkit closest --out` for points whose squared distance float32 cannot hold (issue 38): the
// default record (format 2) carries the distance in float64, finite for every finite point;
// --format 1 still writes the earlier record. The references are analytic: points straight above
// a triangle in the plane z = 0, whose distance is their height.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <vector>

#include "run_cli.hpp"

namespace {

using bvhkit::test::run_cli;
using bvhkit::test::ScratchFile;

std::vector<char> read_bytes(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct ClosestRun {
    ScratchFile mesh{"closest_test", "mesh.obj"}, points{"closest_test", "points.bin"},
        out{"closest_test", "out.bin"};
    std::vector<float> heights = {1e-30f, 1e-20f, 1.0f, 1e10f, 1e20f, 1e30f, 3e38f};
    // A triangle 4 units across in z = 0 (index 0), a second one far off (index 1), and one point
    // above (1, 1) at each height, then a point with a NaN coordinate.
    ClosestRun() {
        std::ofstream(mesh.path()) << "v 0 0 0\nv 4 0 0\nv 0 4 0\nv 100 100 -50\nv 104 100 "
                                      "-50\nv 100 104 -50\nf 1 2 3\nf 4 5 6\n";
        std::vector<float> p;
        for (const float h : heights) p.insert(p.end(), {1.0f, 1.0f, h});
        p.insert(p.end(), {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f});
        std::ofstream(points.path(), std::ios::binary)
            .write(reinterpret_cast<const char*>(p.data()), std::streamsize(p.size() * 4));
    }
    std::vector<char> run(const std::string& extra) {
        const auto o = run_cli("closest " + mesh.string() + " --points " + points.string() +
                               " --out " + out.string() + extra);
        EXPECT_EQ(o.status, 0) << o.output;
        return read_bytes(out.path());
    }
};

// Before format 2 the file held float32 squared distances: inf from 1.8e19 on and 0 below 1e-23.
TEST(ClosestCommand, DistancesInFloat64AtEveryScale) {
    ClosestRun r;
    const std::vector<char> bytes = r.run("");
    ASSERT_EQ(bytes.size(), (r.heights.size() + 1) * 24);
    for (std::size_t i = 0; i <= r.heights.size(); ++i) {
        const char* rec = bytes.data() + 24 * i;
        float point[3];
        std::uint32_t triangle;
        double distance;
        std::memcpy(point, rec, 12);
        std::memcpy(&triangle, rec + 12, 4);
        std::memcpy(&distance, rec + 16, 8);
        if (i == r.heights.size()) {  // the NaN point: none
            EXPECT_EQ(triangle, 0xFFFFFFFFu);
            EXPECT_EQ(distance, std::numeric_limits<double>::infinity());
            continue;
        }
        const double h = r.heights[i];
        SCOPED_TRACE("height " + std::to_string(h));
        // docs/accuracy.md's bound in double (the triangle's longest edge is 5.7).
        const double eps = std::numeric_limits<double>::epsilon(), bound = 96 * eps * (h + 5.7);
        EXPECT_EQ(triangle, 0u);
        EXPECT_NEAR(point[0], 1.0f, 1e-6f);
        EXPECT_NEAR(point[1], 1.0f, 1e-6f);
        EXPECT_NEAR(point[2], 0.0, bound);
        ASSERT_TRUE(std::isfinite(distance));
        EXPECT_GT(distance, 0.0);
        EXPECT_NEAR(distance, h, 4 * eps * h + bound);
    }
}

TEST(ClosestCommand, FormatOneIsTheEarlierRecord) {
    ClosestRun r;
    const std::vector<char> bytes = r.run(" --format 1");
    ASSERT_EQ(bytes.size(), (r.heights.size() + 1) * 20);
    for (std::size_t i = 0; i < r.heights.size(); ++i) {
        float squared;
        std::uint32_t triangle;
        std::memcpy(&squared, bytes.data() + 20 * i + 12, 4);
        std::memcpy(&triangle, bytes.data() + 20 * i + 16, 4);
        const float h = r.heights[i];
        EXPECT_EQ(triangle, 0u);
        // inf and 0 where float32 cannot hold the square.
        if (std::isinf(h * h) || h * h == 0.0f)
            EXPECT_EQ(squared, h * h) << "height " << h;
        else
            EXPECT_NEAR(squared, h * h, 1e-6f * h * h + 1e-44f) << "height " << h;
    }
    EXPECT_NE(run_cli("closest " + r.mesh.string() + " --points " + r.points.string() + " --out " +
                      r.out.string() + " --format 3")
                  .status,
              0);
}

}  // namespace
