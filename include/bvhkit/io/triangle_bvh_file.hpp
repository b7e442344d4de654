#pragma once
// Saving and loading a TriangleBvh (format: docs/serialization.md). The file holds exactly what the
// tree holds: nodes, slot -> triangle indices, the triangles in slot order in the layout of the
// tree's triangle test (corners for the watertight test, p0/edges/normal for the fast one), the
// skipped triangles, the ray layout it was built with (RayLayout, in the layout byte's high half)
// and, from version 2 on, the wide ray layout itself (io/wide_ray_sections.hpp), so that a mapped
// file traces wide (io/mapped_triangle_bvh.hpp). A load uses the stored wide layout when it is
// the width this CPU walks (RayLayout::Auto picks by AVX2) and derives it from the loaded tree by
// the code a build uses otherwise (a file of version 1, or one written on a CPU of another kind).
// A loaded tree answers bit for bit as the saved one, and saving it again gives the same bytes
// (of version 2, and on a CPU of the same kind).
//
// Loading trusts nothing: the envelope (size, checksum) is checked first, every count against the
// bytes there are before anything is allocated, then the tree's shape and every index
// (check_tree_structure) and the wide layout's (check_wide_structure), always; then validate()
// unless LoadOptions::validate is false, which for the wide layout means it must be the one the
// tree derives, byte for byte. Any failure is a bvhkit::Error.
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
#include "bvhkit/io/wide_ray_sections.hpp"
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

    /// Whether the tree's rays can walk a wide layout on some CPU: else the file holds none.
    template <class T>
    bool walks_wide_somewhere() const {
        return std::is_same_v<T, float> && !fast && ray_layout != RayLayout::Binary &&
               file.header.counts[0] > 0;
    }
    /// The width of the wide layout the tree walks on this CPU (TriangleBvh::make_ray_layout's
    /// choice), 0 for none.
    template <class T>
    int wide_width_here() const {
#if defined(__SSE2__)
        if (!walks_wide_somewhere<T>()) return 0;
        return ray_layout != RayLayout::Wide4 && cpu_has_avx2() ? 8 : 4;
#else
        return 0;
#endif
    }
};

template <class T>
TriangleBvhFileHeader open_triangle_bvh_file(std::span<const std::uint8_t> bytes,
                                             const char* what) {
    TriangleBvhFileHeader out{
        open_tree_file(bytes, FileKind::TriangleBvh, what, triangle_bvh_file_version)};
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
    // Version 2: the wide layout's sections follow, checked by get_wide_header.
    check_tree_counts(h, node_record_bytes<T>, (out.fast ? 12 : 9) * sizeof(T),
                      h.version >= 2 ? wide_header_bytes : 0, what, h.version == 1);
    return out;
}

// The wide layout's header of a version-2 file (none in version 1), after the skipped list.
template <class T>
WideSectionHeader open_wide_sections(const TriangleBvhFileHeader& f, ByteReader& r,
                                     const char* what) {
    if (f.file.header.version < 2) return {};
    const WideSectionHeader h = get_wide_header(r);
    if (h.width != 0 && !f.walks_wide_somewhere<T>())
        throw Error(std::string(what) +
                    ": a wide ray layout in a tree whose rays walk the binary tree (a double "
                    "tree, the fast test, RayLayout::Binary or no nodes)");
    return h;
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
        if (!tree.wide8_.empty())
            put_wide_layout<8>(w, tree.wide8_);
        else
            put_wide_layout<4>(w, tree.wide4_);  // width 0 when empty
        TreeFileHeader h;
        h.version = triangle_bvh_file_version;
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
        const WideSectionHeader wide = open_wide_sections<T>(f, r, what);
        // Read in place where the bytes allow (copied only when kept), else copied here.
        WideRayBvh<4> copy4;
        WideRayBvh<8> copy8;
        WideRayView<4> stored4;
        WideRayView<8> stored8;
        if (wide.width == 4) stored4 = read_wide_layout(r, wide, copy4);
        if (wide.width == 8) stored8 = read_wide_layout(r, wide, copy8);

        check_loaded_triangle_tree<T>(tree.binary_rays(), tree.exact_, triangle_count, skipped,
                                      options, what);
        check_wide_structure<4>(stored4, triangle_count, what);
        check_wide_structure<8>(stored8, triangle_count, what);
        // The stored layout where it is the one this CPU walks and is trusted or proved the
        // derived one; else derived from the tree, whose structure was checked above. A layout
        // stored in the collapse's own lane order (written before the order for occlusion rays)
        // is taken with that order applied, and checked so.
        const bool reorder = wide.lane_order == wide_lane_order_collapse;
        if (wide.width != 0 && wide.width == f.wide_width_here<T>() && !options.validate) {
            tree.wide4_.nodes.assign(stored4.nodes.begin(), stored4.nodes.end());
            tree.wide4_.groups.assign(stored4.groups.begin(), stored4.groups.end());
            tree.wide8_.nodes.assign(stored8.nodes.begin(), stored8.nodes.end());
            tree.wide8_.groups.assign(stored8.groups.begin(), stored8.groups.end());
            if (reorder && !tree.wide4_.empty()) order_for_occlusion(tree.wide4_);
            if (reorder && !tree.wide8_.empty()) order_for_occlusion(tree.wide8_);
            return tree;
        }
        tree.make_ray_layout();
        WideRayBvh<4> held4;
        WideRayBvh<8> held8;
        if (wide.width != 0 && wide.width == f.wide_width_here<T>() &&
            !(same_wide_layout<4>(tree.wide4_, ordered_as_now(stored4, reorder, held4)) &&
              same_wide_layout<8>(tree.wide8_, ordered_as_now(stored8, reorder, held8))))
            throw Error(std::string(what) +
                        ": the stored wide ray layout is not the one the tree derives");
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
