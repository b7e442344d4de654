// DynamicTree calls made from inside its own callbacks. A structural call (create, destroy, move,
// enlarge, rebuild, optimize, clear, shift_origin, shrink_to_fit, find_pairs, update_pairs) from a
// query, cast, for_each_node or pair callback would reallocate or relink the nodes being walked;
// it must throw bvhkit::Error, leave the tree valid and release the tree once the walk unwinds.
// Read-only calls (nested queries, user_data) stay allowed.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "test_geometry.hpp"
#include "test_support.hpp"

namespace {

using bvhkit::Aabb2f;
using bvhkit::DynamicTree;
using bvhkit::ProxyId;
using bvhkit::Vec2f;
using Tree = DynamicTree<float, 2>;

using bvhkit::test::box2;

/// Eight overlapping proxies: 15 nodes in a pool of 16, so a create() needing two more nodes
/// grows (moves) the pool.
Tree make_tree(std::vector<ProxyId>& ids) {
    Tree t;
    for (int i = 0; i < 8; ++i) ids.push_back(t.create(box2(float(i) * 0.25f, 0)));
    return t;
}

/// Runs `walk(mutation)`; the mutation, called from the callback, must throw an Error that names
/// the call, and the tree must come out valid and usable.
template <class Walk>
void expect_refused(Tree& t, const char* call, Walk&& walk) {
    const std::size_t before = t.size();
    try {
        walk();
        ADD_FAILURE() << call << " from a callback was accepted";
    } catch (const bvhkit::Error& e) {
        EXPECT_NE(std::string(e.what()).find(call), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("callback"), std::string::npos) << e.what();
    }
    t.validate();
    EXPECT_EQ(t.size(), before);
    const ProxyId extra = t.create(box2(50, 50));  // the walk has ended: mutation works again
    t.destroy(extra);
    t.validate();
}

TEST(DynamicTreeReentry, CreateInQueryCallbackIsRefused) {
    std::vector<ProxyId> ids;
    Tree t = make_tree(ids);
    expect_refused(t, "DynamicTree::create", [&] {
        t.query(box2(0, 0, 3, 1), [&](ProxyId) {
            for (int k = 0; k < 64; ++k) t.create(box2(float(k), 2));  // would grow the pool
            return true;
        });
    });
}

TEST(DynamicTreeReentry, DestroyAndMoveInEveryQueryAreRefused) {
    std::vector<ProxyId> ids;
    Tree t = make_tree(ids);
    expect_refused(t, "DynamicTree::destroy", [&] {
        t.query_point(Vec2f{0.5f, 0.5f}, [&](ProxyId id) { return t.destroy(id), true; });
    });
    expect_refused(t, "DynamicTree::move", [&] {
        t.ray_cast(Vec2f{-1, 0.5f}, Vec2f{10, 0}, 1.0f, [&](ProxyId id, float) {
            t.move(id, box2(30, 30));
            return -1.0f;
        });
    });
    expect_refused(t, "DynamicTree::enlarge", [&] {
        t.box_cast(box2(-2, 0), Vec2f{10, 0}, 1.0f, [&](ProxyId id, float) {
            t.enlarge(id, box2(30, 30));
            return -1.0f;
        });
    });
    expect_refused(t, "DynamicTree::rebuild", [&] {
        t.for_each_node([&](const Aabb2f&, int, bool, ProxyId) { t.rebuild(); });
    });
    expect_refused(t, "DynamicTree::optimize",
                   [&] { t.query(box2(0, 0), [&](ProxyId) { return t.optimize(4), true; }); });
    expect_refused(t, "DynamicTree::clear",
                   [&] { t.query(box2(0, 0), [&](ProxyId) { return t.clear(), true; }); });
    expect_refused(t, "DynamicTree::shift_origin", [&] {
        t.query(box2(0, 0), [&](ProxyId) { return t.shift_origin(Vec2f{1, 1}), true; });
    });
}

TEST(DynamicTreeReentry, FindPairsFromCallbacksIsRefused) {
    std::vector<ProxyId> ids;
    Tree t = make_tree(ids);
    std::vector<bvhkit::ProxyPair> pairs;
    expect_refused(t, "DynamicTree::find_pairs", [&] {
        t.find_pairs([&](ProxyId, ProxyId) { t.find_pairs([&](ProxyId, ProxyId) {}); });
    });
    expect_refused(t, "DynamicTree::find_pairs", [&] {
        t.query(box2(0, 0), [&](ProxyId) { return t.find_pairs(pairs), true; });
    });
    // A destroy from a pair callback would leave later pairs naming a dead proxy: refused too.
    t.move(ids[1], box2(0.3f, 0));
    expect_refused(t, "DynamicTree::destroy",
                   [&] { t.find_pairs([&](ProxyId a, ProxyId) { t.destroy(a); }); });
}

TEST(DynamicTreeReentry, QueryTreeLocksBothTrees) {
    std::vector<ProxyId> ids, other_ids;
    Tree t = make_tree(ids);
    Tree other = make_tree(other_ids);
    expect_refused(other, "DynamicTree::create", [&] {
        t.query_tree(other, [&](ProxyId, ProxyId) { return other.create(box2(9, 9)), true; });
    });
    expect_refused(t, "DynamicTree::destroy", [&] {
        t.query_tree(other, [&](ProxyId mine, ProxyId) { return t.destroy(mine), true; });
    });
}

TEST(DynamicTreeReentry, ReadOnlyCallsInsideCallbacksWork) {
    std::vector<ProxyId> ids;
    Tree t = make_tree(ids);
    int outer = 0, inner = 0;
    t.query(box2(0, 0, 3, 1), [&](ProxyId id) {
        ++outer;
        t.user_data(id) = 5;  // user data is not structure
        t.query(t.box(id), [&](ProxyId) { return ++inner, true; });
        return true;
    });
    EXPECT_EQ(outer, 8);
    EXPECT_GT(inner, outer);
    EXPECT_EQ(t.user_data(ids[3]), 5u);
    // A tree copied during a walk starts unlocked.
    t.query(box2(0, 0), [&](ProxyId) {
        Tree copy = t;
        copy.create(box2(7, 7));
        copy.validate();
        return false;
    });
}

}  // namespace
