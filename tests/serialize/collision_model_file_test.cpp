// CollisionModel files: for every volume type, a saved model loads to the same nodes, slots,
// triangles, vertex ids, skipped list and scale, saves again to the same bytes, and answers
// collide (every contact, segments included) and distance bit for bit on 10^4 poses; malformed
// files are Errors, and a volume shrunk by a corruption fails validate().
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <limits>

#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "byte_flips.hpp"
#include "test_support.hpp"

using namespace bvhkit;
using namespace bvhkit::test;

namespace {

template <class T>
Transform<T> random_pose(SplitMix64& rng, double reach) {
    const double w = rng.uniform(-1, 1), x = rng.uniform(-1, 1), y = rng.uniform(-1, 1),
                 z = rng.uniform(-1, 1);
    const double n = std::sqrt(w * w + x * x + y * y + z * z) + 1e-300;
    Transform<T> pose;
    pose.rotation = Mat3<T>(rotation_from_quaternion(w / n, x / n, y / n, z / n));
    pose.translation = Vec<T, 3>(rng.unit_vector() * rng.uniform(0, reach));
    return pose;
}

template <class V>
void expect_same_model(const CollisionModel<V>& got, const CollisionModel<V>& want) {
    const auto &g = got.bvh(), &w = want.bvh();
    ASSERT_EQ(g.nodes.size(), w.nodes.size());
    if (!w.nodes.empty()) {
        EXPECT_EQ(0, std::memcmp(g.nodes.data(), w.nodes.data(),
                                 w.nodes.size() * sizeof(w.nodes.front())));
    }
    EXPECT_EQ(g.primitive_indices, w.primitive_indices);
    ASSERT_EQ(got.slot_triangles().size(), want.slot_triangles().size());
    if (!want.slot_triangles().empty()) {
        EXPECT_EQ(0, std::memcmp(got.slot_triangles().data(), want.slot_triangles().data(),
                                 want.slot_triangles().size_bytes()));
        EXPECT_EQ(0, std::memcmp(got.slot_vertex_ids().data(), want.slot_vertex_ids().data(),
                                 want.slot_vertex_ids().size_bytes()));
    }
    EXPECT_EQ(got.skipped(), want.skipped());
    EXPECT_EQ(got.triangle_count(), want.triangle_count());
    EXPECT_TRUE(same_bits(got.scale(), want.scale()));
}

// collide (all pairs, with segments), collides and distance of (a, b) against (a2, b2).
template <class V>
void expect_same_answers(const CollisionModel<V>& a, const CollisionModel<V>& b,
                         const CollisionModel<V>& a2, const CollisionModel<V>& b2,
                         std::size_t poses, double reach) {
    using T = typename V::Scalar;
    SplitMix64 rng(7);
    CollideResult<T> r1, r2;
    std::size_t colliding = 0;
    for (std::size_t i = 0; i < poses; ++i) {
        const Transform<T> pose = random_pose<T>(rng, reach);
        collide(a, b, pose, {}, r1);
        collide(a2, b2, pose, {}, r2);
        ASSERT_EQ(r1.colliding, r2.colliding) << i;
        ASSERT_EQ(r1.contacts.size(), r2.contacts.size()) << i;
        for (std::size_t c = 0; c < r1.contacts.size(); ++c) {
            const Contact<T>&x = r1.contacts[c], &y = r2.contacts[c];
            ASSERT_TRUE(x.triangle_a == y.triangle_a && x.triangle_b == y.triangle_b &&
                        same_bits(x.p, y.p) && same_bits(x.q, y.q) && x.coplanar == y.coplanar)
                << i;
        }
        colliding += r1.colliding;
        ASSERT_EQ(collides(a, b, pose), collides(a2, b2, pose)) << i;
        const DistanceResult<T> d1 = distance(a, b, pose), d2 = distance(a2, b2, pose);
        ASSERT_TRUE(same_bits(d1.distance, d2.distance) && same_bits(d1.point_a, d2.point_a) &&
                    same_bits(d1.point_b, d2.point_b) && d1.triangle_a == d2.triangle_a &&
                    d1.triangle_b == d2.triangle_b)
            << i;
    }
    // The poses must test something: some collide, some do not.
    if (poses >= 50 && !a.slot_triangles().empty() && !b.slot_triangles().empty()) {
        EXPECT_GT(colliding, 0u);
        EXPECT_LT(colliding, poses);
    }
}

template <class V>
void round_trip(const TriangleMesh& mesh_a, const TriangleMesh& mesh_b, double reach,
                const std::string& what) {
    SCOPED_TRACE(what);
    const CollisionModel<V> a(mesh_a), b(mesh_b);
    const std::vector<std::uint8_t> bytes_a = to_bytes(a), bytes_b = to_bytes(b);
    for (const bool validate : {true, false}) {
        const CollisionModel<V> a2 = collision_model_from_bytes<V>(bytes_a, {validate});
        const CollisionModel<V> b2 = collision_model_from_bytes<V>(bytes_b, {validate});
        expect_same_model(a2, a);
        expect_same_model(b2, b);
        EXPECT_EQ(to_bytes(a2), bytes_a);
        EXPECT_EQ(to_bytes(b2), bytes_b);
        expect_same_answers(a, b, a2, b2, validate ? scaled(10000, 20) / 8 : 100, reach);
    }
}

template <class V>
void round_trip_all(const std::string& what) {
    const TriangleMesh sphere = make_sphere(2), terrain = make_procedural("terrain:n=8");
    round_trip<V>(sphere, terrain, 1.5, what + " sphere/terrain");
    // Triangles left out (non-finite), one degenerate, and the empty model.
    TriangleMesh holes = make_sphere(1);
    holes.vertices.push_back({std::numeric_limits<float>::quiet_NaN(), 0, 0});
    holes.triangles.push_back({0, 1, std::uint32_t(holes.vertices.size() - 1)});
    holes.triangles.push_back({2, 2, 2});
    round_trip<V>(holes, sphere, 3.0, what + " skipped and degenerate");
    round_trip<V>(TriangleMesh{}, sphere, 1.5, what + " empty");
    // Far from the origin, where the volumes' rounding is large next to the mesh: validate() must
    // still accept the fitted volumes.
    TriangleMesh far = make_sphere(2, 0.3f);
    for (auto& v : far.vertices) v = v * 0.01f + Vec3f(1000, -500, 250);
    const CollisionModel<V> model(far);
    expect_same_model(collision_model_from_bytes<V>(to_bytes(model)), model);
}

// The collide/distance answers of 8 volume types x 2 validate settings: 10^4 poses in all in
// the Release run (the acceptance count), fewer under the sanitizers.
TEST(CollisionModelFile, RoundTripsEveryVolume) {
    round_trip_all<Aabb<float, 3>>("aabb float");
    round_trip_all<Sphere<float>>("sphere float");
    round_trip_all<Obb<float>>("obb float");
    round_trip_all<Rss<float>>("rss float");
    round_trip_all<ObbRss<float>>("obbrss float");
    round_trip_all<Kdop<float, 14>>("kdop14 float");
    round_trip_all<Kdop<float, 18>>("kdop18 float");
    round_trip_all<Kdop<float, 26>>("kdop26 float");
    round_trip_all<ConvexHull<float>>("hull float");
}

TEST(CollisionModelFile, RoundTripsDouble) {
    round_trip_all<Obb<double>>("obb double");
    round_trip_all<ObbRss<double>>("obbrss double");
    round_trip_all<Kdop<double, 18>>("kdop18 double");
    round_trip_all<Aabb<double, 3>>("aabb double");
}

// Models of degenerate triangles only (points, segments, collinear corners): their fitted volumes
// are flat or points, and must still pass validate().
template <class V>
void degenerate_round_trip() {
    TriangleMesh mesh;
    for (int i = 0; i < 40; ++i) {
        const float x = float(i % 7) * 0.3f, y = float(i % 5) * 0.2f, z = float(i % 3) * 0.1f;
        const auto at = std::uint32_t(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), {{x, y, z}, {x + 0.1f, y, z}, {x + 0.2f, y, z}});
        if (i % 3 == 0) mesh.triangles.push_back({at, at, at});          // a point
        if (i % 3 == 1) mesh.triangles.push_back({at, at + 1, at + 1});  // a segment
        if (i % 3 == 2) mesh.triangles.push_back({at, at + 1, at + 2});  // collinear
    }
    const CollisionModel<V> model(mesh);
    ASSERT_EQ(model.slot_triangles().size(), 40u);
    for (const bool validate : {true, false})
        expect_same_model(collision_model_from_bytes<V>(to_bytes(model), {validate}), model);
}

TEST(CollisionModelFile, DegenerateTrianglesRoundTrip) {
    degenerate_round_trip<Aabb<float, 3>>();
    degenerate_round_trip<Sphere<float>>();
    degenerate_round_trip<Obb<float>>();
    degenerate_round_trip<Rss<float>>();
    degenerate_round_trip<ObbRss<float>>();
    degenerate_round_trip<Kdop<float, 14>>();
    degenerate_round_trip<Kdop<float, 18>>();
    degenerate_round_trip<Kdop<float, 26>>();
    degenerate_round_trip<ConvexHull<float>>();
    degenerate_round_trip<Obb<double>>();
    degenerate_round_trip<Rss<double>>();
}

// A model refitted to moved vertices saves and loads (with validate) like a built one.
TEST(CollisionModelFile, RefittedModelRoundTrips) {
    TriangleMesh mesh = make_sphere(2, 0.2f);
    CollisionModel<Rss<float>> model(mesh);
    for (auto& v : mesh.vertices) v = v * 1.5f + Vec3f(0.25f, 0, 0);
    model.refit(mesh);
    const auto loaded = collision_model_from_bytes<Rss<float>>(to_bytes(model));
    expect_same_model(loaded, model);
}

TEST(CollisionModelFile, SavesAndLoadsFiles) {
    const CollisionModel<Obb<float>> model(make_sphere(2));
    const auto path = std::filesystem::temp_directory_path() /
                      ("bvhkit_collision_model_" + std::to_string(::getpid()) + ".bvh");
    save(model, path);
    const auto loaded = load_collision_model<Obb<float>>(path);
    std::filesystem::remove(path);
    expect_same_model(loaded, model);
    try {
        (void)load_collision_model<Obb<float>>(path);
        ADD_FAILURE() << "a missing file loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
}

std::vector<std::uint8_t> small_model_file() {
    return to_bytes(CollisionModel<Obb<float>>(make_sphere(1)));  // 80 triangles
}

template <class V>
void expect_error(std::span<const std::uint8_t> bytes, const std::string& what,
                  const std::string& message_part = "", bool validate = true) {
    try {
        (void)collision_model_from_bytes<V>(bytes, {validate});
        ADD_FAILURE() << what << ": loaded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos)
            << what << ": " << e.what();
    }
}

TEST(CollisionModelFile, EveryTruncationIsAnError) {
    const std::vector<std::uint8_t> file = small_model_file();
    ASSERT_NO_THROW((void)collision_model_from_bytes<Obb<float>>(file));
    for (std::size_t n = 0; n < file.size(); ++n)
        expect_error<Obb<float>>(std::span(file).first(n), "truncated to " + std::to_string(n));
    std::vector<std::uint8_t> longer = file;
    longer.push_back(0);
    expect_error<Obb<float>>(longer, "one byte appended", "payload bytes");
}

TEST(CollisionModelFile, WrongKindVolumeOrScalarIsAnError) {
    const std::vector<std::uint8_t> file = small_model_file();
    expect_error<Aabb<float, 3>>(file, "as aabb", "bounding volume Obb");
    expect_error<ObbRss<float>>(file, "as obbrss", "bounding volume Obb");
    expect_error<Kdop<float, 14>>(file, "as kdop14", "bounding volume Obb");
    expect_error<Obb<double>>(file, "as double", "float");
    EXPECT_THROW((void)triangle_bvh_from_bytes<float>(file), Error);
    expect_error<Obb<float>>(to_bytes(TriangleBvh<float>(make_sphere(1))), "a TriangleBvh file",
                             "kind 1");
    const auto k18 = to_bytes(CollisionModel<Kdop<float, 18>>(make_sphere(1)));
    expect_error<Kdop<float, 26>>(k18, "kdop18 as kdop26", "Kdop18");
}

// FNV-1a changes with any one-byte change; resealed, the flips reach the other checks: a load is
// an Error or a model that answers queries with indices in range.
TEST(CollisionModelFile, ByteFlipsAreErrorsOrUsableModels) {
    const std::vector<std::uint8_t> file = small_model_file();
    const CollisionModel<Obb<float>> other(make_sphere(1));
    SplitMix64 rng(11);
    const std::size_t rounds = full_scale() ? 100000 : scaled(10000, 10);
    std::size_t loaded[2] = {0, 0};
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)collision_model_from_bytes<Obb<float>>(bad), Error) << round;
        serial_detail::reseal_tree_file(bad);
        for (const bool validate : {true, false}) {
            try {
                const auto model = collision_model_from_bytes<Obb<float>>(bad, {validate});
                ++loaded[validate];
                SplitMix64 poses(round);
                CollideResult<float> result;
                for (int i = 0; i < 4; ++i) {
                    const Transform<float> pose = random_pose<float>(poses, 1.0);
                    collide(model, other, pose, {}, result);
                    for (const auto& c : result.contacts)
                        ASSERT_TRUE(c.triangle_a < model.triangle_count());
                    const auto d = distance(model, other, pose);
                    ASSERT_TRUE(!(d.distance < std::numeric_limits<float>::infinity()) ||
                                d.triangle_a < model.triangle_count());
                }
            } catch (const Error&) {
            }
        }
    }
    RecordProperty("resealed_loaded", std::to_string(loaded[1]) + " of " + std::to_string(rounds));
    EXPECT_LT(loaded[1], rounds);
    EXPECT_LE(loaded[1], loaded[0]);
}

// Offsets of the sections of small_model_file() (docs/serialization.md).
constexpr std::size_t header = 72;
constexpr std::size_t obb_node = 15 * 4 + 8;

template <class F>
std::vector<std::uint8_t> edited(std::vector<std::uint8_t> file, F&& edit) {
    edit(file);
    serial_detail::reseal_tree_file(file);
    return file;
}
void put_u64(std::vector<std::uint8_t>& f, std::size_t at, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) f[at + i] = std::uint8_t(v >> (8 * i));
}
void put_f32(std::vector<std::uint8_t>& f, std::size_t at, float v) {
    std::memcpy(f.data() + at, &v, 4);
}
float get_f32(const std::vector<std::uint8_t>& f, std::size_t at) {
    float v;
    std::memcpy(&v, f.data() + at, 4);
    return v;
}

TEST(CollisionModelFile, HostileHeadersAreErrors) {
    const std::vector<std::uint8_t> file = small_model_file();
    using O = Obb<float>;
    // Counts that claim more than the file holds, before anything is allocated.
    for (int c = 0; c < 3; ++c)
        for (const std::uint64_t n : {std::uint64_t(1) << 62, ~std::uint64_t(0), std::uint64_t(1)})
            expect_error<O>(edited(file, [&](auto& f) { put_u64(f, 24 + 8 * c, n); }),
                            "count " + std::to_string(c) + " = " + std::to_string(n));
    expect_error<O>(edited(file, [&](auto& f) { put_u64(f, 48, 81); }), "triangle count",
                    "triangle count");
    expect_error<O>(edited(file, [&](auto& f) { f[17] = 42; }), "unknown volume", "unknown");
    expect_error<O>(edited(file, [&](auto& f) { f[18] = 2; }), "layout", "layout");
    expect_error<O>(edited(file, [&](auto& f) { f[19] = 1; }), "reserved", "reserved");
    expect_error<O>(edited(file, [&](auto& f) { f[8] = 2; }), "version", "version");
    // A cycle: the root's first child is the root.
    expect_error<O>(edited(file, [&](auto& f) { std::memset(f.data() + header + 60, 0, 4); }),
                    "root points at itself", "", false);
    // The scale: negative or NaN always, another value under validate().
    const std::size_t scale_at = file.size() - 8;
    const float scale = get_f32(file, scale_at);
    ASSERT_GT(scale, 1.0f);
    for (const float bad : {-1.0f, std::numeric_limits<float>::quiet_NaN()})
        expect_error<O>(edited(file, [&](auto& f) { put_f32(f, scale_at, bad); }), "scale", "scale",
                        false);
    expect_error<O>(edited(file, [&](auto& f) { put_f32(f, scale_at, scale * 2); }),
                    "another scale", "scale");
    EXPECT_NO_THROW((void)collision_model_from_bytes<O>(
        edited(file, [&](auto& f) { put_f32(f, scale_at, scale * 2); }), {false}));
}

// validate(): a volume shrunk (so it would cull a pair that meets) fails; grown, it loads (it
// only costs time); axes that are not orthonormal and negative sizes fail.
TEST(CollisionModelFile, CorruptedVolumesFailValidate) {
    const std::vector<std::uint8_t> file = small_model_file();
    using O = Obb<float>;
    const CollisionModel<O> model = collision_model_from_bytes<O>(file);
    const std::size_t nodes = model.bvh().nodes.size();
    ASSERT_GT(nodes, 4u);
    std::size_t caught = 0;
    for (std::size_t n = 0; n < nodes; ++n) {
        const std::size_t extents = header + n * obb_node + 12 * 4;  // after centre and axes
        for (int a = 0; a < 3; ++a) {
            const float e = get_f32(file, extents + 4 * a);
            const auto shrunk =
                edited(file, [&](auto& f) { put_f32(f, extents + 4 * a, e * 0.999f - 1e-4f); });
            expect_error<O>(shrunk, "node " + std::to_string(n) + " shrunk", "node ");
            EXPECT_NO_THROW((void)collision_model_from_bytes<O>(shrunk, {false}));
            EXPECT_NO_THROW((void)collision_model_from_bytes<O>(
                edited(file, [&](auto& f) { put_f32(f, extents + 4 * a, e * 1.5f); })));
            ++caught;
        }
    }
    EXPECT_EQ(caught, 3 * nodes);
    const std::size_t root_axes = header + 3 * 4;
    expect_error<O>(edited(file, [&](auto& f) { put_f32(f, root_axes, 2.0f); }), "long axis",
                    "orthonormal");
    expect_error<O>(edited(file, [&](auto& f) { put_f32(f, header + 12 * 4, -1); }),
                    "negative extent", "negative size");
    // A triangle moved outside its leaf, and a triangle in two slots.
    const std::size_t slots_at = header + (nodes * obb_node + 7) / 8 * 8;
    const std::size_t tris_at = slots_at + (model.slot_triangles().size() * 4 + 7) / 8 * 8;
    expect_error<O>(edited(file, [&](auto& f) { put_f32(f, tris_at, 5.0f); }), "moved triangle",
                    "");
    // Coordinates the exact triangle tests cannot take: an Error even without validate().
    for (const float bad :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()})
        expect_error<O>(edited(file, [&](auto& f) { put_f32(f, tris_at + 8, bad); }),
                        "non-finite corner", "not finite", false);
    expect_error<O>(
        edited(file,
               [&](auto& f) { std::memcpy(f.data() + slots_at, f.data() + slots_at + 4, 4); }),
        "triangle twice", "two slots");
}

// Every volume type's checks catch a shrunk root: the first scalar after the centre (or slab 0's
// hi) pulled in.
template <class V>
void expect_shrunk_root_caught(std::size_t at, bool grow_low) {
    const std::vector<std::uint8_t> file = to_bytes(CollisionModel<V>(make_sphere(1)));
    const float x = get_f32(file, header + at * 4);
    expect_error<V>(
        edited(file, [&](auto& f) { put_f32(f, header + at * 4, grow_low ? x + 0.1f : x * 0.9f); }),
        "shrunk root", "does not contain");
}

TEST(CollisionModelFile, ShrunkRootOfEveryVolumeFailsValidate) {
    expect_shrunk_root_caught<Aabb<float, 3>>(3, false);       // max x
    expect_shrunk_root_caught<Aabb<float, 3>>(0, true);        // min x
    expect_shrunk_root_caught<Sphere<float>>(3, false);        // radius
    expect_shrunk_root_caught<Obb<float>>(12, false);          // extents[0]
    expect_shrunk_root_caught<Rss<float>>(14, false);          // radius
    expect_shrunk_root_caught<ObbRss<float>>(15 + 14, false);  // the swept sphere's radius
    expect_shrunk_root_caught<Kdop<float, 14>>(1, false);      // slab 0's hi
    expect_shrunk_root_caught<Kdop<float, 26>>(25, false);     // the last slab's hi
    expect_shrunk_root_caught<ConvexHull<float>>(49, false);   // the margin (80 triangles: capped)
}

}  // namespace
