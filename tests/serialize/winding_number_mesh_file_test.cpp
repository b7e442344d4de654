// WindingNumberMesh files: a saved mesh loads to one whose fast (every order) and exact winding
// numbers equal the original's bit for bit on 10^4 points (the expansions are derived again on
// load), and saves to the same bytes; malformed files are Errors.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "byte_flips.hpp"
#include "random_geometry.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

template <class T>
void round_trip(const WindingNumberMesh<T>& mesh, const Aabb<T, 3>& bounds,
                const std::string& what) {
    SCOPED_TRACE(what);
    const std::vector<std::uint8_t> bytes = to_bytes(mesh);
    const WindingNumberMesh<T> loaded = winding_number_mesh_from_bytes<T>(bytes);
    EXPECT_EQ(to_bytes(loaded), bytes);
    const Vec<T, 3> margin = bounds.extent() * T(0.5);
    const Aabb<T, 3> box(bounds.min - margin, bounds.max + margin);
    Random rng(12);
    const std::size_t count = scaled(10000, 10);
    for (std::size_t i = 0; i < count; ++i) {
        const Vec<T, 3> p = rng.point_in(box);
        const int order = 1 + int(i % 3);
        ASSERT_TRUE(same_bits(loaded.fast(p, T(2), order), mesh.fast(p, T(2), order))) << i;
        if (i % 100 == 0) {
            ASSERT_TRUE(same_bits(loaded.exact(p), mesh.exact(p))) << i;
        }
    }
}

TEST(WindingNumberMeshFile, RoundTrips) {
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh spot = read_mesh(path);
    round_trip(WindingNumberMesh<float>(spot), bounds_as<float>(spot), "spot float");
    round_trip(WindingNumberMesh<double>(spot), bounds_as<double>(spot), "spot double");
    const TriangleMesh terrain = make_procedural("terrain:n=16");  // open
    round_trip(WindingNumberMesh<float>(terrain), bounds_as<float>(terrain), "terrain");
    TriangleMesh holes = make_sphere(2);
    holes.vertices[3][0] = std::numeric_limits<float>::quiet_NaN();  // its triangles left out
    round_trip(WindingNumberMesh<float>(holes), Aabb3f({-1, -1, -1}, {1, 1, 1}), "with NaN");
}

TEST(WindingNumberMeshFile, MalformedFilesAreErrors) {
    const std::vector<std::uint8_t> file = to_bytes(WindingNumberMesh<float>(make_sphere(1)));
    ASSERT_NO_THROW((void)winding_number_mesh_from_bytes<float>(file));
    for (std::size_t n = 0; n < file.size(); ++n)
        EXPECT_THROW((void)winding_number_mesh_from_bytes<float>(std::span(file).first(n)), Error);
    EXPECT_THROW((void)winding_number_mesh_from_bytes<double>(file), Error);
    SplitMix64 rng(10);
    const std::size_t rounds = full_scale() ? 100000 : scaled(10000, 10);
    std::size_t loaded = 0;
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)winding_number_mesh_from_bytes<float>(bad), Error) << round;
        serial_detail::reseal_tree_file(bad);
        for (const bool validate : {true, false}) {
            try {
                const auto m = winding_number_mesh_from_bytes<float>(bad, {validate});
                ++loaded;
                Random points(round);
                for (int i = 0; i < 4; ++i)
                    (void)m.fast(points.point_in(Aabb3f({-2, -2, -2}, {2, 2, 2})));
            } catch (const Error&) {
            }
        }
    }
    RecordProperty("resealed_loaded", std::to_string(loaded) + " of " + std::to_string(2 * rounds));
}

}  // namespace
