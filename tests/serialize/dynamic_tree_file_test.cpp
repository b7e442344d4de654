// DynamicTree files: a saved tree loads to one that saves to the same bytes, answers every query
// as the original, and goes on through the same moves, destroys and pair steps with the same pair
// events (a rollback); truncated, corrupted and hand-made hostile files are Errors, and a corrupted
// file that was resealed either loads to a tree that validates and keeps working, or is an Error.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <vector>

#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/math/random.hpp"
#include "byte_flips.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

template <class T, std::size_t N>
Aabb<T, N> random_box(SplitMix64& rng, T world) {
    Vec<T, N> lo, size;
    for (std::size_t a = 0; a < N; ++a) {
        lo[a] = T(rng.uniform() * world);
        size[a] = T(rng.uniform() * 2);
    }
    return Aabb<T, N>(lo, lo + size);
}

/// One step of a game: moves, a few creates and destroys, an enlarge, a pair step; returns the pair
/// events and what a query and a ray cast see, so two trees can be compared step by step.
template <class Tree>
std::vector<long long> play(Tree& t, SplitMix64& rng, std::vector<ProxyId>& live) {
    using T = typename Tree::Scalar;
    constexpr std::size_t N = Tree::dimension;
    std::vector<long long> seen;
    for (int k = 0; k < 200 && !live.empty(); ++k) {
        const ProxyId id = live[rng.below(std::uint32_t(live.size()))];
        const auto box = random_box<T, N>(rng, T(60));
        if (k % 17 == 0)
            t.enlarge(id, box);
        else
            t.move(id, box, typename Tree::VecT(T(0.5)));
    }
    for (int k = 0; k < 5; ++k) live.push_back(t.create(random_box<T, N>(rng, T(60)), rng.next()));
    for (int k = 0; k < 3; ++k) {
        const std::size_t i = rng.below(std::uint32_t(live.size()));
        t.destroy(live[i]);
        live.erase(live.begin() + std::ptrdiff_t(i));
    }
    if (rng.below(4) == 0) t.rebuild(false);
    t.update_pairs([&](ProxyId a, ProxyId b) { seen.push_back(1000000LL * a + b); },
                   [&](ProxyId a, ProxyId b) { seen.push_back(-1000000LL * a - b); });
    seen.push_back(-1);
    t.query(random_box<T, N>(rng, T(60)), [&](ProxyId id) {
        seen.push_back(id);
        return true;
    });
    typename Tree::VecT dir(T(0));
    dir[0] = T(1);
    t.ray_cast(typename Tree::VecT(T(1)), dir, T(50), [&](ProxyId id, T) {
        seen.push_back(id);
        return T(-1);
    });
    seen.push_back(t.height());
    return seen;
}

template <class T, std::size_t N, class U>
void check_round_trip(const DynamicTreeOptions<T>& options, const char* what) {
    SCOPED_TRACE(what);
    SplitMix64 rng(5);
    DynamicTree<T, N, U> tree(options);
    std::vector<ProxyId> live;
    const std::size_t count = test::scaled(3000, 10);
    for (std::size_t i = 0; i < count; ++i)
        live.push_back(tree.create(random_box<T, N>(rng, T(60)), U(i)));
    for (int step = 0; step < 3; ++step) play(tree, rng, live);
    std::vector<ProxyPair> pairs;
    tree.find_pairs(pairs);  // leaves the persistent set stale: saved as such
    play(tree, rng, live);
    for (int k = 0; k < 10; ++k) tree.move(live[k], random_box<T, N>(rng, T(60)));  // buffered

    const std::vector<std::uint8_t> bytes = to_bytes(tree);
    DynamicTree<T, N, U> loaded = dynamic_tree_from_bytes<T, N, U>(bytes);
    EXPECT_EQ(to_bytes(loaded), bytes);
    EXPECT_EQ(loaded.size(), tree.size());
    for (const ProxyId id : live) {
        EXPECT_EQ(loaded.box(id), tree.box(id));
        EXPECT_EQ(loaded.fat_box(id), tree.fat_box(id));
        EXPECT_EQ(loaded.user_data(id), tree.user_data(id));
    }
    // Both go on alike: the same events and answers at every step, the same bytes at the end.
    SplitMix64 a_rng(9), b_rng(9);
    std::vector<ProxyId> a_live = live, b_live = live;
    for (int step = 0; step < 6; ++step)
        ASSERT_EQ(play(tree, a_rng, a_live), play(loaded, b_rng, b_live)) << step;
    EXPECT_EQ(to_bytes(loaded), to_bytes(tree));

    const auto path = std::filesystem::temp_directory_path() /
                      ("bvhkit_dynamic_" + std::to_string(::getpid()) + ".bin");
    save(tree, path);
    EXPECT_EQ(to_bytes(load_dynamic_tree<T, N, U>(path)), to_bytes(tree));
    std::filesystem::remove(path);
}

TEST(DynamicTreeFile, RoundTripsAndGoesOnAlike) {
    DynamicTreeOptions<float> f;
    check_round_trip<float, 2, std::uint64_t>(f, "2D float");
    DynamicTreeOptions<double> d;
    d.insertion = InsertionStrategy::BranchAndBound;
    d.margin_relative = 0.1;
    check_round_trip<double, 3, std::uint64_t>(d, "3D double, branch and bound");
    f.rotate = false;
    f.insertion = InsertionStrategy::Greedy;
    check_round_trip<float, 3, std::int32_t>(f, "3D float, greedy, no rotations, int32 data");
}

TEST(DynamicTreeFile, EmptyAndClearedTrees) {
    DynamicTree<float, 2> empty;
    const auto bytes = to_bytes(empty);
    EXPECT_EQ(to_bytes(dynamic_tree_from_bytes<float, 2>(bytes)), bytes);
    DynamicTree<float, 2> t;
    const ProxyId id = t.create(Aabb<float, 2>({0, 0}, {1, 1}));
    t.destroy(id);  // a free slot and a destroyed id waiting in the move buffer
    const auto loaded = dynamic_tree_from_bytes<float, 2>(to_bytes(t));
    EXPECT_EQ(loaded.size(), 0u);
    EXPECT_EQ(loaded.move_buffer_size(), 1u);
}

DynamicTree<float, 2> load_2f(std::span<const std::uint8_t> bytes) {
    return dynamic_tree_from_bytes<float, 2>(bytes);
}

TEST(DynamicTreeFile, MalformedFilesAreErrors) {
    DynamicTree<float, 2> tree;
    SplitMix64 rng(3);
    std::vector<ProxyId> live;
    for (int i = 0; i < 40; ++i) live.push_back(tree.create(random_box<float, 2>(rng, 20.0f)));
    play(tree, rng, live);
    const std::vector<std::uint8_t> file = to_bytes(tree);
    ASSERT_NO_THROW((void)load_2f(file));
    for (std::size_t n = 0; n < file.size(); ++n)
        EXPECT_THROW((void)load_2f(std::span(file).first(n)), Error) << n;
    EXPECT_THROW((void)(dynamic_tree_from_bytes<double, 2>)(file), Error);
    EXPECT_THROW((void)(dynamic_tree_from_bytes<float, 3>)(file), Error);

    // Hand-made: a count that claims far more than the file (the loader must not allocate it),
    // and a node that is its own child (a cycle a query would never leave).
    std::vector<std::uint8_t> huge = file;
    huge[24 + 5] = 0x10;  // counts[0] (nodes), bits 40..47
    serial_detail::reseal_tree_file(huge);
    EXPECT_THROW((void)load_2f(huge), Error);
    const std::size_t state = serial_detail::dynamic_state_bytes<float>;
    const std::size_t node_bytes = serial_detail::dynamic_node_bytes<float, 2>;
    // The root's index: the first int32 after the three options and three flag bytes.
    std::int32_t root = -1;
    std::memcpy(&root, file.data() + serial_detail::tree_file_header_size + 3 * 4 + 3, 4);
    ASSERT_GE(root, 0);
    std::vector<std::uint8_t> cycle = file;
    const std::size_t child1 =
        serial_detail::tree_file_header_size + state + std::size_t(root) * node_bytes + 16 + 4;
    std::memcpy(cycle.data() + child1, &root, 4);
    serial_detail::reseal_tree_file(cycle);
    EXPECT_THROW((void)load_2f(cycle), Error);

    // Random corruption: an Error before resealing (the checksum); after it, a tree that validates
    // and keeps working, or an Error.
    const std::size_t rounds = test::full_scale() ? 100000 : test::scaled(20000, 10);
    std::size_t loaded = 0;
    for (std::size_t round = 0; round < rounds; ++round) {
        std::vector<std::uint8_t> bad = test::with_byte_flips(file, rng);
        if (bad == file) continue;
        ASSERT_THROW((void)load_2f(bad), Error) << round;
        serial_detail::reseal_tree_file(bad);
        try {
            auto t = load_2f(bad);
            ++loaded;
            std::vector<ProxyId> ids;
            for (ProxyId id = 0; id < t.id_bound(); ++id)
                if (t.contains(id)) ids.push_back(id);
            SplitMix64 more(round);
            play(t, more, ids);
            t.validate();
        } catch (const Error&) {
        }
    }
    RecordProperty("resealed_loaded", std::to_string(loaded) + " of " + std::to_string(rounds));
}

}  // namespace
