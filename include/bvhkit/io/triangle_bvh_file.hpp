#pragma once
// Saving and loading a TriangleBvh (format: docs/serialization.md). The file holds exactly what the
// tree holds: nodes, slot -> triangle indices, the triangles in slot order in the layout of the
// tree's triangle test (corners for the watertight test, p0/edges/normal for the fast one), the
// skipped triangles, and the ray layout it was built with (RayLayout, in the layout byte's high
// half). Nothing is rebuilt on load but the wide ray layout, derived from the loaded tree by the
// code a build uses (storing it does not pay: docs/serialization.md), so a loaded tree answers bit
// for bit as the saved one (on a CPU of the same kind: RayLayout::Auto picks by AVX2), and saving
// it again gives the same bytes.
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

#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_sections.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/triangle_bvh.hpp"

namespace bvhkit {

namespace serial_detail {

// Layout byte of a TriangleBvh file: the low half says which triangle records the payload holds,
// the high half the tree's RayLayout (0 Auto, 1 Wide8, 2 Wide4, 3 Binary), so that a tree built
// to trace with another layout than the default traces (and breaks ties) with it after a load.
enum class TriangleLayout : std::uint8_t { Corners = 1, Precomputed = 2 };

// What the header of a TriangleBvh file says, every count checked against the payload.
struct TriangleBvhFileHeader {
    OpenedTreeFile file;
    bool fast = false;  // precomputed triangles (the fast test) rather than corners
    RayLayout ray_layout = RayLayout::Auto;
};

template <class T>
TriangleBvhFileHeader open_triangle_bvh_file(std::span<const std::uint8_t> bytes,
                                             const char* what) {
    TriangleBvhFileHeader out{open_tree_file(bytes, FileKind::TriangleBvh, what)};
    const TreeFileHeader& h = out.file.header;
    check_scalar_and_volume<T>(h, what);
    const auto layout = TriangleLayout(h.layout & 0x0f);
    const int ray_layout = h.layout >> 4;
    if ((layout != TriangleLayout::Corners && layout != TriangleLayout::Precomputed) ||
        ray_layout > int(RayLayout::Binary))
        throw Error(std::string(what) + ": unknown triangle layout " +
                    std::to_string(int(h.layout)));
    out.fast = layout == TriangleLayout::Precomputed;
    out.ray_layout = RayLayout(ray_layout);
    check_tree_counts(h, node_record_bytes<T>, (out.fast ? 12 : 9) * sizeof(T), 0, what);
    return out;
}

// The checks on a loaded tree, wherever its arrays lie: shape and indices always, then validate()
// unless opted out. The fast layout keeps no corners (p0 - e1 need not round back to p1): there a
// triangle's box is its leaf's, and a leaf's enclosure of its triangles goes unchecked.
template <class T>
void check_loaded_triangle_tree(const TriangleRays<T>& rays, std::span<const Triangle<T>> corners,
                                std::uint64_t triangle_count,
                                std::span<const std::uint32_t> skipped, const LoadOptions& options,
                                const char* what) {
    check_tree_structure(rays.bvh(), triangle_count, what);
    check_skipped(skipped, triangle_count, what);
    if (options.validate)
        validate_loaded(
            rays.bvh(), std::size_t(triangle_count), skipped,
            [&](std::uint32_t s, const auto& leaf) {
                return rays.triangle_test() == TriangleTest::Fast ? leaf.bounds
                                                                  : corners[s].bounds();
            },
            what);
}

struct TriangleBvhAccess {
    static constexpr const char* what = "TriangleBvh file";

    template <class T>
    static std::vector<std::uint8_t> save(const TriangleBvh<T>& tree) {
        // The format holds each triangle once (its loader checks that); a tree with spatial
        // splits would need the references' clipped boxes checked instead.
        if (tree.split_references_)
            throw Error(std::string(what) +
                        ": a tree built with spatial splits cannot be saved; save the mesh and "
                        "rebuild, or build without spatial_splits");
        const auto& bvh = tree.bvh_;
        const bool fast = tree.triangle_test_ == TriangleTest::Fast;
        ByteWriter w;
        w.reserve(bvh.nodes.size() * node_record_bytes<T> +
                  bvh.primitive_indices.size() * (4 + 12 * sizeof(T)) + 32);
        put_nodes(w, bvh);
        put_u32s(w, bvh.primitive_indices);
        if (fast) {
            for (const auto& t : tree.fast_)
                put_vec(w, t.p0), put_vec(w, t.e1), put_vec(w, t.e2), put_vec(w, t.n);
            w.pad(8);
        } else {
            put_corners<T>(w, tree.exact_);
        }
        put_u32s(w, tree.report_.skipped);
        TreeFileHeader h;
        h.kind = FileKind::TriangleBvh;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = std::uint8_t(
            std::uint8_t(fast ? TriangleLayout::Precomputed : TriangleLayout::Corners) |
            std::uint8_t(std::uint8_t(tree.ray_layout_) << 4));
        h.counts = {bvh.nodes.size(), bvh.primitive_indices.size(), tree.report_.skipped.size(),
                    tree.triangle_count_};
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static TriangleBvh<T> load(std::span<const std::uint8_t> file, const LoadOptions& options) {
        const TriangleBvhFileHeader f = open_triangle_bvh_file<T>(file, what);
        const bool fast = f.fast;
        const auto [node_count, slot_count, skipped_count, triangle_count] = f.file.header.counts;

        ByteReader r(f.file.payload, what);
        TriangleBvh<T> tree;
        tree.triangle_test_ = fast ? TriangleTest::Fast : TriangleTest::Watertight;
        tree.ray_layout_ = f.ray_layout;
        tree.triangle_count_ = std::size_t(triangle_count);
        auto& bvh = tree.bvh_;
        get_nodes(r, bvh, node_count);
        get_u32s(r, bvh.primitive_indices, slot_count);
        if (fast) {
            tree.fast_.resize(std::size_t(slot_count));
            for (auto& t : tree.fast_)
                t.p0 = get_vec<T>(r), t.e1 = get_vec<T>(r), t.e2 = get_vec<T>(r),
                t.n = get_vec<T>(r);
            r.skip_padding(8);
        } else {
            get_corners(r, tree.exact_, slot_count);
        }
        auto& skipped = tree.report_.skipped;
        get_u32s(r, skipped, skipped_count);

        check_loaded_triangle_tree<T>(tree.binary_rays(), tree.exact_, triangle_count, skipped,
                                      options, what);
        tree.make_ray_layout();  // derived, not stored: the structure was checked above
        return tree;
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
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return triangle_bvh_from_bytes<T>(bytes, options);
    });
}

}  // namespace bvhkit
