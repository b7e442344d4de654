// BSP building: splitting, area preservation, no polygon lost or duplicated, statistics, options
// and degenerate input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bsp_reference.hpp"
#include "random_geometry.hpp"

namespace bvhkit::test {
namespace {

using V = Vec<double, 3>;

TEST(BspSplit, SquareAcrossAPlaneTilesExactly) {
    const std::vector<V> square = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
    const auto plane = Plane<double>::axis_aligned(0, 0.5);
    ASSERT_EQ((classify_polygon<double, 3>)(square, plane, 1e-9), Side::Spanning);
    std::vector<V> f, b;
    split_polygon<double, 3>(square, plane, 1e-9, f, b);
    ASSERT_EQ(f.size(), 4u);
    ASSERT_EQ(b.size(), 4u);
    EXPECT_DOUBLE_EQ(polygon_area<double>(f), 3.0);
    EXPECT_DOUBLE_EQ(polygon_area<double>(b), 1.0);
    for (const auto& p : f) EXPECT_GE(p[0], 0.5);
    for (const auto& p : b) EXPECT_LE(p[0], 0.5);
    // Within the thick plane: coplanar, or on one side without a split.
    EXPECT_EQ((classify_polygon<double, 3>)(square, Plane<double>::axis_aligned(2, 1e-10), 1e-9),
              Side::Coplanar);
    EXPECT_EQ((classify_polygon<double, 3>)(square, Plane<double>::axis_aligned(0, 1e-10), 1e-9),
              Side::Front);
    EXPECT_EQ(
        (classify_polygon<double, 3>)(square, Plane<double>::axis_aligned(0, 2 - 1e-10), 1e-9),
        Side::Back);
}

TEST(BspSplit, ThroughAVertexMakesTwoTriangles) {
    const std::vector<V> tri = {{0, 0, 0}, {2, 0, 0}, {1, 2, 0}};
    std::vector<V> f, b;
    split_polygon<double, 3>(tri, Plane<double>::axis_aligned(0, 1.0), 1e-9, f, b);
    EXPECT_EQ(f.size(), 3u);
    EXPECT_EQ(b.size(), 3u);
    EXPECT_DOUBLE_EQ(polygon_area<double>(f) + polygon_area<double>(b), 2.0);
}

TEST(BspSplit, AVertexInsideTheThickPlaneIsTheCutPoint) {
    // The apex lies 1e-12 off the plane: it becomes the chord's end, no crossing point beside it.
    const std::vector<V> tri = {{0, 0, 0}, {2, 0, 0}, {1 + 1e-12, 2, 0}};
    std::vector<V> f, b;
    split_polygon<double, 3>(tri, Plane<double>::axis_aligned(0, 1.0), 1e-9, f, b);
    ASSERT_EQ(f.size(), 3u);
    ASSERT_EQ(b.size(), 3u);
    EXPECT_NE(std::find(f.begin(), f.end(), tri[2]), f.end());
    EXPECT_NE(std::find(b.begin(), b.end(), tri[2]), b.end());
    EXPECT_NEAR(polygon_area<double>(f) + polygon_area<double>(b), 2.0, 1e-15);
}

struct Variant {
    const char* name;
    BspOptions options;
};

std::vector<Variant> variants() {
    std::vector<Variant> v;
    v.push_back({"default", {}});
    BspOptions balance;
    balance.split_weight = 0.1;
    balance.candidate_count = 16;
    v.push_back({"balanced", balance});
    BspOptions axes;
    axes.candidates = BspCandidates::AxisAligned;
    axes.leaf_size = 4;
    v.push_back({"axis-aligned", axes});
    BspOptions shallow;
    shallow.max_depth = 6;
    shallow.candidates = BspCandidates::Both;
    v.push_back({"shallow", shallow});
    BspOptions thick;
    thick.epsilon = 1e-7;  // a thousand times the default plane thickness
    v.push_back({"thick", thick});
    return v;
}

// Every source triangle's parts: areas sum to its own, and points sampled on it lie in exactly one.
void check_parts(const TriangleMesh& mesh, const BspTree<double>& tree, const std::string& what) {
    const auto tris = ld_triangles(mesh);
    const auto& pool = tree.polygons();
    std::vector<LD> area(tris.size(), 0);
    std::vector<std::vector<std::uint32_t>> parts(tris.size());
    for (std::uint32_t i = 0; i < pool.size(); ++i) {
        const auto src = pool.polygons[i].source;
        ASSERT_LT(src, tris.size()) << what;
        area[src] += LD(pool.area(i));
        parts[src].push_back(i);
    }
    Random rng(7);
    std::size_t checked = 0;
    for (std::size_t s = 0; s < tris.size(); ++s) {
        const LD want = ld_area(tris[s]);
        ASSERT_FALSE(parts[s].empty()) << what << ": triangle " << s << " lost";
        ASSERT_LE(std::fabs(area[s] - want), 1e-9 * want)
            << what << ": triangle " << s << " parts sum to " << double(area[s]) << ", not "
            << double(want);
        if (s % 7) continue;  // point sampling on a seventh of the triangles
        const VL n = normalize(cross(tris[s].p[1] - tris[s].p[0], tris[s].p[2] - tris[s].p[0]));
        const LD size = std::sqrt(want);
        for (int k = 0; k < 8; ++k) {
            LD u = rng.uniform(), v = rng.uniform();
            if (u + v > 1) u = 1 - u, v = 1 - v;
            const VL p = tris[s].p[0] + (tris[s].p[1] - tris[s].p[0]) * u +
                         (tris[s].p[2] - tris[s].p[0]) * v;
            int inside = 0;
            bool unsure = false;
            for (const auto i : parts[s]) {
                const LD m = ld_inside_margin(pool.vertices_of(i), n, p);
                if (m > 1e-9 * size)
                    ++inside;
                else if (m > -1e-9 * size)
                    unsure = true;
            }
            if (unsure) continue;
            ASSERT_EQ(inside, 1) << what << ": a point of triangle " << s << " lies in " << inside
                                 << " of its " << parts[s].size() << " parts";
            ++checked;
        }
    }
    EXPECT_GT(checked, tris.size() / 7) << what;
}

void check_statistics(const BspTree<double>& tree, const BspOptions& o, const std::string& what) {
    const BspStatistics& s = tree.statistics();
    EXPECT_EQ(s.nodes, tree.nodes().size()) << what;
    EXPECT_EQ(s.nodes, 2 * s.interior_nodes + 1) << what;
    EXPECT_EQ(s.leaves, s.interior_nodes + 1) << what;
    EXPECT_EQ(s.polygons, tree.polygons().size()) << what;
    EXPECT_EQ(s.polygons, s.input_triangles - s.dropped_degenerate + s.splits) << what;
    EXPECT_EQ(s.polygons, s.polygons_at_nodes + s.polygons_in_leaves) << what;
    EXPECT_LE(s.depth, o.max_depth) << what;
    // Runs: a node's polygons follow one another, nodes cover the pool once.
    std::vector<int> owner(tree.polygons().size(), 0);
    std::size_t max_depth_seen = 0;
    std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0, 0}};
    while (!stack.empty()) {
        const auto [k, depth] = stack.back();
        stack.pop_back();
        max_depth_seen = std::max(max_depth_seen, depth);
        const auto& n = tree.nodes()[k];
        for (std::uint32_t i = n.first; i < n.first + n.count; ++i) ++owner[i];
        if (n.is_leaf()) {
            if (depth < o.max_depth) {
                EXPECT_LE(n.count, o.leaf_size) << what;
            }
            continue;
        }
        if (!n.axis_aligned) {
            EXPECT_GE(n.count, 1u) << what;  // its splitter's own polygon at least
        }
        EXPECT_LE(n.front_facing, n.count) << what;
        // Polygons at the node lie in its thick plane and face as listed.
        for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
            for (const auto& p : tree.polygons().vertices_of(i))
                EXPECT_LE(std::fabs(n.plane.distance(p)), tree.epsilon()) << what;
            const double facing = dot(tree.polygons().plane_of(i).normal, n.plane.normal);
            EXPECT_EQ(facing >= 0, i < n.first + n.front_facing) << what;
        }
        stack.push_back({n.front, depth + 1});
        stack.push_back({n.back, depth + 1});
    }
    EXPECT_EQ(max_depth_seen, s.depth) << what;
    for (std::size_t i = 0; i < owner.size(); ++i)
        ASSERT_EQ(owner[i], 1) << what << " polygon " << i;
}

TEST(BspBuild, PartsTileEveryTriangleAndStatisticsAddUp) {
    for (const auto& [name, mesh] : bsp_test_meshes()) {
        for (const auto& var : variants()) {
            const std::string what = name + "/" + var.name;
            const BspTree<double> tree(mesh, var.options);
            EXPECT_EQ(tree.statistics().dropped_degenerate, 0u) << what;
            if (name != "sphere") {  // a convex mesh's planes split nothing
                EXPECT_GT(tree.statistics().splits, 0u) << what;
            }
            check_statistics(tree, var.options, what);
            check_parts(mesh, tree, what);
            const bool expect_solid = var.options.leaf_size == 0 &&
                                      var.options.candidates == BspCandidates::PolygonPlanes;
            if (expect_solid) {
                EXPECT_TRUE(tree.is_solid()) << what;
            }
            if (var.options.leaf_size > 0) {
                EXPECT_FALSE(tree.is_solid()) << what;
            }
        }
    }
}

TEST(BspBuild, PolygonSoupWithManySplits) {
    // Random overlapping triangles: many spanning polygons, every split checked by area.
    const auto soup = random_soup<double>(scaled(600, 4), 3);
    TriangleMesh mesh;
    for (const auto& t : soup) {
        const auto k = std::uint32_t(mesh.vertices.size());
        mesh.vertices.push_back(Vec3f(t.p0));
        mesh.vertices.push_back(Vec3f(t.p1));
        mesh.vertices.push_back(Vec3f(t.p2));
        mesh.triangles.push_back({k, k + 1, k + 2});
    }
    BspOptions o;
    o.split_weight = 0.5;
    const BspTree<double> tree(mesh, o);
    check_statistics(tree, o, "soup");
    // Needle triangles of the soup may be dropped: only the kept ones must tile.
    EXPECT_GT(tree.statistics().splits, soup.size() / 10);
    if (tree.statistics().dropped_degenerate == 0) check_parts(mesh, tree, "soup");
}

TEST(BspBuild, Deterministic) {
    const auto mesh = make_torus(24, 12);
    const BspTree<double> a(mesh), b(mesh);
    ASSERT_EQ(a.nodes().size(), b.nodes().size());
    for (std::size_t k = 0; k < a.nodes().size(); ++k) {
        EXPECT_EQ(a.nodes()[k].plane.normal, b.nodes()[k].plane.normal);
        EXPECT_EQ(a.nodes()[k].count, b.nodes()[k].count);
    }
}

TEST(BspBuild, SplitWeightTradesSplitsForBalance) {
    const auto mesh = make_torus(48, 24);
    BspOptions few_splits, balanced;
    few_splits.split_weight = 1.0;
    balanced.split_weight = 0.0;
    const BspTree<double> a(mesh, few_splits), b(mesh, balanced);
    EXPECT_LT(a.statistics().splits, b.statistics().splits);
    EXPECT_LT(b.statistics().depth, a.statistics().depth);
}

TEST(BspBuild, HaltsByLeafSizeAndDepth) {
    const auto mesh = make_sphere(3);
    BspOptions o;
    o.leaf_size = 16;
    const BspTree<double> leafy(mesh, o);
    check_statistics(leafy, o, "leaf_size 16");
    EXPECT_GT(leafy.statistics().polygons_in_leaves, 0u);
    o = {};
    o.max_depth = 3;
    const BspTree<double> shallow(mesh, o);
    check_statistics(shallow, o, "max_depth 3");
    EXPECT_EQ(shallow.statistics().depth, 3u);
    EXPECT_FALSE(shallow.is_solid());
    EXPECT_LE(shallow.statistics().interior_nodes, 7u);
}

// Degenerate input: each has a documented answer.

TEST(BspDegenerate, EmptyMesh) {
    const BspTree<double> tree{TriangleMesh{}};
    EXPECT_EQ(tree.statistics().nodes, 1u);
    EXPECT_EQ(tree.statistics().polygons, 0u);
    EXPECT_TRUE(tree.is_solid());
    EXPECT_FALSE(closest_hit(tree, Ray<double, 3>({0, 0, 0}, {1, 0, 0})));
    EXPECT_EQ(classify_point(tree, V{0, 0, 0}), PointLocation::Outside);
    int visited = 0;
    for_each_front_to_back(tree, V{0, 0, 0}, [&](std::uint32_t) { ++visited; });
    EXPECT_EQ(visited, 0);
}

TEST(BspDegenerate, OnePolygon) {
    TriangleMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.triangles = {{0, 1, 2}};
    const BspTree<double> tree(mesh);
    EXPECT_EQ(tree.statistics().nodes, 3u);
    EXPECT_EQ(tree.statistics().depth, 1u);
    EXPECT_EQ(tree.statistics().splits, 0u);
    const auto hit = closest_hit(tree, Ray<double, 3>({0.25, 0.25, 1}, {0, 0, -1}));
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit.t, 1.0);
    EXPECT_EQ(hit.source, 0u);
    EXPECT_FALSE(closest_hit(tree, Ray<double, 3>({0.75, 0.75, 1}, {0, 0, -1})));
    // One open polygon is a "solid" of a half space: behind it is inside.
    EXPECT_EQ(classify_point(tree, V{0, 0, -1}), PointLocation::Inside);
    EXPECT_EQ(classify_point(tree, V{0, 0, 1}), PointLocation::Outside);
}

TEST(BspDegenerate, AllCoplanar) {
    // A flat grid, half its triangles flipped: one node holds all, split by facing.
    TriangleMesh mesh;
    const int n = 10;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) mesh.vertices.push_back({float(x), float(y), 2.0f});
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const std::uint32_t a = std::uint32_t(y * (n + 1) + x), b = a + 1, c = a + n + 1,
                                d = c + 1;
            mesh.triangles.push_back({a, b, d});
            if ((x + y) % 2)
                mesh.triangles.push_back({a, c, d});  // facing -z
            else
                mesh.triangles.push_back({a, d, c});
        }
    const BspTree<double> tree(mesh);
    const auto& s = tree.statistics();
    EXPECT_EQ(s.nodes, 3u);
    EXPECT_EQ(s.splits, 0u);
    EXPECT_EQ(s.polygons_at_nodes, std::size_t(2 * n * n));
    EXPECT_EQ(tree.root().front_facing, std::uint32_t(2 * n * n - n * n / 2));
    const auto hit = closest_hit(tree, Ray<double, 3>({3.3, 4.6, 5}, {0, 0, -1}));
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit.t, 3.0, 1e-12);
}

TEST(BspDegenerate, ZeroAreaTrianglesAreDroppedAndCounted) {
    TriangleMesh mesh = make_sphere(1);
    const std::size_t n = mesh.triangle_count();
    mesh.vertices.push_back({5, 5, 5});
    const auto k = std::uint32_t(mesh.vertices.size() - 1);
    mesh.triangles.push_back({k, k, k});  // a point
    mesh.triangles.push_back({0, 1, 0});  // an edge twice
    mesh.triangles.push_back({0, k, k});  // a segment
    const BspTree<double> tree(mesh);
    EXPECT_EQ(tree.statistics().input_triangles, n + 3);
    EXPECT_EQ(tree.statistics().dropped_degenerate, 3u);
    for (std::uint32_t i = 0; i < tree.polygons().size(); ++i)
        EXPECT_LT(tree.polygons().polygons[i].source, n);
    EXPECT_TRUE(tree.is_solid());
}

TEST(BspDegenerate, NaNVertexIsAnErrorNamingTheTriangle) {
    TriangleMesh mesh = make_sphere(1);
    mesh.vertices[mesh.triangles[7][1]][2] = std::numeric_limits<float>::quiet_NaN();
    try {
        const BspTree<double> tree(mesh);
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("NaN"), std::string::npos) << m;
        EXPECT_NE(m.find("triangle"), std::string::npos) << m;
    }
    mesh = make_sphere(1);
    mesh.triangles[3][0] = 100000;
    EXPECT_THROW(BspTree<double>{mesh}, Error);
}

TEST(BspDegenerate, BadOptionsAreErrors) {
    const auto mesh = make_sphere(1);
    BspOptions o;
    o.split_weight = 1.5;
    EXPECT_THROW(BspTree<double>(mesh, o), Error);
    o.split_weight = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(BspTree<double>(mesh, o), Error);
    o = {};
    o.candidate_count = 0;
    EXPECT_THROW(BspTree<double>(mesh, o), Error);
    o = {};
    o.epsilon = -1;
    EXPECT_THROW(BspTree<double>(mesh, o), Error);
    o = {};
    o.max_depth = 1u << 25;
    EXPECT_THROW(BspTree<double>(mesh, o), Error);
}

TEST(BspBuild, FloatTreeBuilds) {
    const auto mesh = make_torus(24, 12);
    const BspTree<float> tree(mesh);
    EXPECT_EQ(tree.statistics().polygons, tree.statistics().input_triangles -
                                              tree.statistics().dropped_degenerate +
                                              tree.statistics().splits);
    const auto hit = closest_hit(tree, Ray<float, 3>({0, -1, 2}, {0, 0, -1}));
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit.t, 1.7f, 0.02f);  // the facetted tube's top, near z = 0.3
}

}  // namespace
}  // namespace bvhkit::test
