#pragma once
// Saving and loading a TriangleBvh (format: docs/serialization.md). The file holds exactly what the
// tree holds: nodes, slot -> triangle indices, the triangles in slot order in the layout of the
// tree's triangle test (corners for the watertight test, p0/edges/normal for the fast one), and the
// skipped triangles. Nothing is rebuilt on load, so a loaded tree answers bit for bit as the saved
// one, and saving it again gives the same bytes.
//
// Loading trusts nothing: the envelope (size, checksum) is checked first, every count against the
// bytes there are before anything is allocated, then the tree's shape and every index
// (check_tree_structure), always; then validate() unless LoadOptions::validate is false. Any
// failure is a bvhkit::Error.
//
// Thread safety: saving reads the tree only (const queries may run at the same time); loading
// touches only its input and the tree it returns.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/triangle_bvh.hpp"

namespace bvhkit {

struct LoadOptions {
    /// Run validate() on the loaded tree (each node encloses its children and its triangles, each
    /// triangle once, finite boxes, skipped triangles absent). When false, the loader still checks
    /// the tree's shape and every index, so queries stay in range: only the geometry is trusted.
    bool validate = true;
};

namespace serial_detail {

// Layout byte of a TriangleBvh file: which triangle records the payload holds.
enum class TriangleLayout : std::uint8_t { Corners = 1, Precomputed = 2 };

struct TriangleBvhAccess {
    static constexpr const char* what = "TriangleBvh file";

    template <class T>
    static std::vector<std::uint8_t> save(const TriangleBvh<T>& tree) {
        const auto& bvh = tree.bvh_;
        const bool fast = tree.triangle_test_ == TriangleTest::Fast;
        ByteWriter w;
        w.reserve(bvh.nodes.size() * (6 * sizeof(T) + 8) +
                  bvh.primitive_indices.size() * (4 + 12 * sizeof(T)) + 32);
        const auto vec = [&](const Vec<T, 3>& v) {
            for (std::size_t a = 0; a < 3; ++a) w.scalar(v[a]);
        };
        for (const auto& n : bvh.nodes) {
            vec(n.bounds.min);
            vec(n.bounds.max);
            w.u32(n.first);
            w.u32(n.count);
        }
        w.pad(8);
        for (const std::uint32_t p : bvh.primitive_indices) w.u32(p);
        w.pad(8);
        if (fast)
            for (const auto& t : tree.fast_) vec(t.p0), vec(t.e1), vec(t.e2), vec(t.n);
        else
            for (const auto& t : tree.exact_) vec(t.p0), vec(t.p1), vec(t.p2);
        w.pad(8);
        for (const std::uint32_t p : tree.report_.skipped) w.u32(p);
        w.pad(8);
        TreeFileHeader h;
        h.kind = FileKind::TriangleBvh;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = std::uint8_t(fast ? TriangleLayout::Precomputed : TriangleLayout::Corners);
        h.counts = {bvh.nodes.size(), bvh.primitive_indices.size(), tree.report_.skipped.size(),
                    tree.triangle_count_};
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static TriangleBvh<T> load(std::span<const std::uint8_t> file, const LoadOptions& options) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::TriangleBvh, what);
        const TreeFileHeader& h = f.header;
        const auto fail = [](const std::string& m) { throw Error(std::string(what) + ": " + m); };
        if (h.scalar != scalar_code<T>())
            fail(std::string("the file holds a ") + scalar_name(std::uint8_t(h.scalar)) +
                 " tree, loaded as " + scalar_name(std::uint8_t(scalar_code<T>())));
        if (h.volume != VolumeCode::Aabb3)
            fail("unknown bounding volume " + std::to_string(int(h.volume)));
        const auto layout = TriangleLayout(h.layout);
        if (layout != TriangleLayout::Corners && layout != TriangleLayout::Precomputed)
            fail("unknown triangle layout " + std::to_string(int(h.layout)));
        const bool fast = layout == TriangleLayout::Precomputed;
        const auto [node_count, slot_count, skipped_count, triangle_count] = h.counts;

        // Every count against the payload before any allocation; then the exact total.
        const std::uint64_t limit = h.payload_size;
        const std::uint64_t expected =
            section_bytes(node_count, 6 * sizeof(T) + 8, limit, what, "node") +
            section_bytes(slot_count, 4, limit, what, "slot") +
            section_bytes(slot_count, (fast ? 12 : 9) * sizeof(T), limit, what, "triangle") +
            section_bytes(skipped_count, 4, limit, what, "skipped");
        if (expected != h.payload_size)
            fail("the counts need " + std::to_string(expected) + " payload bytes, the file has " +
                 std::to_string(h.payload_size));
        if (node_count > 0xffffffffu || slot_count > 0xffffffffu)
            fail("more than 2^32 - 1 nodes or slots");
        if (triangle_count != slot_count + skipped_count)
            fail("triangle count " + std::to_string(triangle_count) + " is not slots (" +
                 std::to_string(slot_count) + ") + skipped (" + std::to_string(skipped_count) +
                 ")");

        ByteReader r(f.payload, what);
        const auto vec = [&] {
            Vec<T, 3> v;
            for (std::size_t a = 0; a < 3; ++a) v[a] = r.scalar<T>();
            return v;
        };
        TriangleBvh<T> tree;
        tree.triangle_test_ = fast ? TriangleTest::Fast : TriangleTest::Watertight;
        tree.triangle_count_ = std::size_t(triangle_count);
        auto& bvh = tree.bvh_;
        bvh.nodes.resize(std::size_t(node_count));
        for (auto& n : bvh.nodes) {
            n.bounds.min = vec();
            n.bounds.max = vec();
            n.first = r.u32();
            n.count = r.u32();
        }
        r.skip_padding(8);
        bvh.primitive_indices.resize(std::size_t(slot_count));
        for (std::uint32_t& p : bvh.primitive_indices) p = r.u32();
        r.skip_padding(8);
        if (fast) {
            tree.fast_.resize(std::size_t(slot_count));
            for (auto& t : tree.fast_) t.p0 = vec(), t.e1 = vec(), t.e2 = vec(), t.n = vec();
        } else {
            tree.exact_.resize(std::size_t(slot_count));
            for (auto& t : tree.exact_) t.p0 = vec(), t.p1 = vec(), t.p2 = vec();
        }
        r.skip_padding(8);
        auto& skipped = tree.report_.skipped;
        skipped.resize(std::size_t(skipped_count));
        for (std::uint32_t& p : skipped) p = r.u32();
        r.skip_padding(8);

        check_tree_structure(bvh, triangle_count, what);
        for (std::size_t i = 0; i < skipped.size(); ++i)
            if (skipped[i] >= triangle_count || (i && skipped[i] <= skipped[i - 1]))
                fail("skipped triangles out of range or not ascending");
        if (options.validate) validate_geometry(tree, fast);
        return tree;
    }

    // validate() against each triangle's box. The fast layout keeps no corners (p0 - e1 need not
    // round back to p1), so there a triangle's box is its leaf's: its own enclosure goes unchecked.
    template <class T>
    static void validate_geometry(const TriangleBvh<T>& tree, bool fast) {
        const auto& bvh = tree.bvh_;
        std::vector<Aabb<T, 3>> boxes(tree.triangle_count_);  // absent ones stay empty
        for (const auto& n : bvh.nodes)
            if (n.is_leaf())
                for (std::uint32_t s = n.first; s < n.first + n.count; ++s)
                    boxes[bvh.primitive_indices[s]] = fast ? n.bounds : tree.exact_[s].bounds();
        try {
            validate(bvh, boxes, tree.report_.skipped);
        } catch (const Error& e) {
            throw Error(std::string(what) + ": " + e.what());
        }
    }
};

}  // namespace serial_detail

/// The tree as a file's bytes (to write elsewhere, or to pickle).
template <class T>
std::vector<std::uint8_t> to_bytes(const TriangleBvh<T>& tree) {
    return serial_detail::TriangleBvhAccess::save(tree);
}

template <class T>
void save(const TriangleBvh<T>& tree, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(tree));
}

/// A tree from bytes written by to_bytes / save; the scalar type must match the file's.
template <class T>
TriangleBvh<T> triangle_bvh_from_bytes(std::span<const std::uint8_t> bytes,
                                       const LoadOptions& options = {}) {
    return serial_detail::TriangleBvhAccess::load<T>(bytes, options);
}

template <class T>
TriangleBvh<T> load_triangle_bvh(const std::filesystem::path& path,
                                 const LoadOptions& options = {}) {
    const std::vector<std::uint8_t> bytes = serial_detail::read_file_bytes(path);
    try {
        return triangle_bvh_from_bytes<T>(bytes, options);
    } catch (const Error& e) {
        throw Error(path.string() + ": " + e.what());
    }
}

}  // namespace bvhkit
