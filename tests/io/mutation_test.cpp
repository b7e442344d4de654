// Randomized mutations of small valid files (bit flips, byte changes, inserts, deletes, duplicated
// and swapped chunks, digits turned into huge numbers): every read must give a usable mesh (all
// indices below the vertex count) or a bvhkit::Error, never another exception or a crash.
#include <gtest/gtest.h>

#include <random>

#include "bvhkit/io/read_mesh.hpp"
#include "mesh_writers.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

std::string mutate(std::string s, std::mt19937& rng) {
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
        const std::size_t at = s.empty() ? 0 : rng() % s.size();
        switch (rng() % 7) {
            case 0:  // flip a bit
                if (!s.empty()) s[at] = static_cast<char>(s[at] ^ (1 << (rng() % 8)));
                break;
            case 1:  // replace a byte
                if (!s.empty()) s[at] = static_cast<char>(rng());
                break;
            case 2:  // insert a byte
                s.insert(s.begin() + static_cast<std::ptrdiff_t>(at), static_cast<char>(rng()));
                break;
            case 3:  // delete a run
                if (!s.empty()) s.erase(at, 1 + rng() % 8);
                break;
            case 4: {  // duplicate a chunk elsewhere
                if (s.empty()) break;
                const std::string chunk = s.substr(at, 1 + rng() % 32);
                s.insert(rng() % (s.size() + 1), chunk);
                break;
            }
            case 5:  // a digit becomes a huge or negative number (header counts, indices)
                for (std::size_t i = at; i < s.size(); ++i)
                    if (s[i] >= '0' && s[i] <= '9') {
                        static const char* big[] = {
                            "4294967295", "1000000000000",        "-1",
                            "0",          "99999999999999999999", "2147483648"};
                        s.replace(i, 1, big[rng() % 6]);
                        break;
                    }
                break;
            default:  // truncate
                s.resize(at);
                break;
        }
    }
    return s;
}

struct Seed {
    std::string bytes;
    std::string name;
};

std::vector<Seed> seed_files() {
    const PolygonMesh mesh = random_polygon_mesh(7, 5, 21);
    const TriangleMesh tris = random_polygon_mesh(6, 3, 22, true).fanned();
    std::vector<Seed> seeds;
    seeds.push_back({write_obj(mesh, {ObjFaceForm::mixed, false, false, true}), "m.obj"});
    seeds.push_back({write_obj(mesh, {ObjFaceForm::with_both, true, true, false}), "m.obj"});
    for (const PlyEncoding e :
         {PlyEncoding::ascii, PlyEncoding::binary_le, PlyEncoding::binary_be}) {
        PlyOptions o;
        o.encoding = e;
        o.extra_elements = true;
        o.shuffle_vertex_properties = true;
        seeds.push_back({write_ply(mesh, o), "m.ply"});
        const std::vector<std::vector<std::int32_t>> strips = {{0, 1, 2, 3, -1, 4, 5, 6, 6, 2}};
        o.count_type = "int";
        seeds.push_back({write_ply(mesh, o, &strips), "m.ply"});
    }
    seeds.push_back({write_stl_ascii(tris), "m.stl"});
    seeds.push_back({write_stl_binary(tris, "solid but binary"), "m.stl"});
    return seeds;
}

TEST(Mutation, ReadersReturnAValidMeshOrThrowError) {
    const std::vector<Seed> seeds = seed_files();
    for (const Seed& s : seeds) ASSERT_NO_THROW(read_mesh(s.bytes, s.name)) << s.name;
    std::mt19937 rng(2024);
    const std::size_t rounds = scaled(10000, 10);
    std::size_t accepted = 0, rejected = 0;
    for (std::size_t round = 0; round < rounds; ++round) {
        for (const Seed& s : seeds) {
            const std::string bytes = mutate(s.bytes, rng);
            try {
                const TriangleMesh m = read_mesh(bytes, s.name);
                for (const auto& t : m.triangles)
                    for (const std::uint32_t i : t)
                        ASSERT_LT(i, m.vertices.size()) << s.name << " round " << round;
                ++accepted;
            } catch (const Error&) {
                ++rejected;
            } catch (const std::exception& e) {
                FAIL() << s.name << " round " << round << ": unexpected exception " << e.what();
            }
        }
    }
    std::printf("  %zu mutated files accepted, %zu rejected with bvhkit::Error\n", accepted,
                rejected);
    EXPECT_GT(rejected, 0u);
}

}  // namespace
