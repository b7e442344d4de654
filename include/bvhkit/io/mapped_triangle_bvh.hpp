#pragma once
// MappedTriangleBvh<T>: a saved TriangleBvh queried where its file lies, without copying its
// arrays. map_triangle_bvh() maps the file (io/mapped_file.hpp); view_triangle_bvh() reads bytes
// the caller keeps alive (a buffer, or a mapping of its own). The nodes, slot indices, triangles
// and skipped list are the file's sections themselves, read in place: the format pads every section
// to 8 bytes (docs/serialization.md), which aligns each record for its type.
//
// It answers closest_hit, any_hit, all_hits, trace and occluded as a TriangleBvh with
// RayLayout::Binary loaded from the same file does, bit for bit: rays walk the binary tree, because
// the wide layout is derived, not stored, and deriving it would copy the tree into memory. Against
// a tree that traces wide (the default) the hits, t, barycentrics and normals are the same; where
// two triangles are hit at the same t, which one is reported may differ (docs/serialization.md).
//
// Loading trusts the file no more than load_triangle_bvh does: the envelope and checksum, every
// count, the tree's shape and every index always, validate() unless LoadOptions::validate is false.
// These checks read every page once, so the file's pages are resident after the load; they are
// the page cache's, shared between processes, not this process's heap.
//
// Thread safety: queries are const and may run on any number of threads at once.
#include <bit>
#include <cstddef>
#include <filesystem>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "bvhkit/io/mapped_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/query/triangle_rays.hpp"

namespace bvhkit {

namespace serial_detail {
struct MappedTriangleBvhAccess;
}

template <class T>
class MappedTriangleBvh : public RayBatches<MappedTriangleBvh<T>, T> {
  public:
    MappedTriangleBvh() = default;  // no tree: every ray misses
    // Move-only; a moved-from tree is empty (its views go with the mapping).
    MappedTriangleBvh(MappedTriangleBvh&& other) noexcept { take(other); }
    MappedTriangleBvh& operator=(MappedTriangleBvh&& other) noexcept {
        if (this != &other) take(other);
        return *this;
    }

    Hit<T> closest_hit(const Ray<T, 3>& ray) const { return rays_.closest_hit(ray); }
    template <class Stats>
    Hit<T> closest_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        return rays_.closest_hit(ray, stats);
    }
    bool any_hit(const Ray<T, 3>& ray) const { return rays_.any_hit(ray); }
    template <class Stats>
    bool any_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        return rays_.any_hit(ray, stats);
    }
    /// on_hit(const Hit<T>&) -> bool (true to go on); hits come in no particular order.
    template <class OnHit, class Stats = NoStats>
    void all_hits(const Ray<T, 3>& ray, OnHit&& on_hit, Stats&& stats = {}) const {
        rays_.all_hits(ray, on_hit, stats);
    }

    // Batches: trace() and occluded(), from RayBatches (query/triangle_rays.hpp).

    /// The tree, in place in the file.
    BvhView<Aabb<T, 3>> bvh() const { return rays_.bvh(); }
    /// Triangles left out of the tree for non-finite coordinates, by mesh index.
    std::span<const std::uint32_t> skipped() const { return skipped_; }
    std::size_t triangle_count() const { return triangle_count_; }
    TriangleTest triangle_test() const { return rays_.triangle_test(); }
    /// Always 2: rays walk the binary tree.
    static constexpr int ray_width() { return 2; }
    /// The bytes the tree is read from (the whole file).
    std::span<const std::uint8_t> bytes() const { return bytes_; }

  private:
    friend struct serial_detail::MappedTriangleBvhAccess;

    void take(MappedTriangleBvh& other) noexcept {
        file_ = std::move(other.file_);
        bytes_ = std::exchange(other.bytes_, {});
        rays_ = std::exchange(other.rays_, {});
        skipped_ = std::exchange(other.skipped_, {});
        triangle_count_ = std::exchange(other.triangle_count_, 0);
    }

    MappedFile file_;  // empty for a view of the caller's bytes
    std::span<const std::uint8_t> bytes_;
    TriangleRays<T> rays_;
    std::span<const std::uint32_t> skipped_;
    std::size_t triangle_count_ = 0;
};

namespace serial_detail {

// The in-memory records a mapped load reads in place must be the file's records byte for byte.
template <class T>
constexpr bool records_match_the_file() {
    using Box = Aabb<T, 3>;
    using Node = BvhNode<Box>;
    return std::endian::native == std::endian::little && sizeof(Vec<T, 3>) == 3 * sizeof(T) &&
           sizeof(Box) == 6 * sizeof(T) && offsetof(Box, max) == 3 * sizeof(T) &&
           sizeof(Node) == node_record_bytes<T> && offsetof(Node, first) == 6 * sizeof(T) &&
           sizeof(Triangle<T>) == 9 * sizeof(T) &&
           sizeof(PrecomputedTriangle<T>) == 12 * sizeof(T) && std::is_trivially_copyable_v<Node> &&
           std::is_trivially_copyable_v<Triangle<T>> &&
           std::is_trivially_copyable_v<PrecomputedTriangle<T>>;
}

struct MappedTriangleBvhAccess {
    static constexpr const char* what = "TriangleBvh file";

    template <class T>
    static void open(MappedTriangleBvh<T>& tree, std::span<const std::uint8_t> bytes,
                     const LoadOptions& options) {
        if constexpr (!records_match_the_file<T>()) {
            throw Error(std::string(what) +
                        ": this machine's records differ from the file's (a big-endian "
                        "machine?); load it with load_triangle_bvh instead");
        } else {
            const TriangleBvhFileHeader f = open_triangle_bvh_file<T>(bytes, what);
            const auto [node_count, slot_count, skipped_count, triangle_count] =
                f.file.header.counts;
            ByteReader r(f.file.payload, what);
            const BvhView<Aabb<T, 3>> bvh{
                r.records_in_place<BvhNode<Aabb<T, 3>>>(std::size_t(node_count), 8),
                r.records_in_place<std::uint32_t>(std::size_t(slot_count), 8)};
            std::span<const Triangle<T>> corners;
            TriangleRays<T> rays;
            if (f.fast) {
                rays = TriangleRays<T>(
                    bvh, r.records_in_place<PrecomputedTriangle<T>>(std::size_t(slot_count), 8));
            } else {
                corners = r.records_in_place<Triangle<T>>(std::size_t(slot_count), 8);
                rays = TriangleRays<T>(bvh, corners);
            }
            const auto skipped = r.records_in_place<std::uint32_t>(std::size_t(skipped_count), 8);
            check_loaded_triangle_tree<T>(rays, corners, triangle_count, skipped, options, what);
            tree.bytes_ = bytes;
            tree.rays_ = rays;
            tree.skipped_ = skipped;
            tree.triangle_count_ = std::size_t(triangle_count);
        }
    }

    template <class T>
    static MappedTriangleBvh<T> map(const std::filesystem::path& path, const LoadOptions& options) {
        MappedTriangleBvh<T> tree;
        tree.file_ = MappedFile(path);
        try {
            open(tree, tree.file_.bytes(), options);
        } catch (const Error& e) {
            throw Error(path.string() + ": " + e.what());
        }
        return tree;
    }
};

}  // namespace serial_detail

/// Maps the file written by save(const TriangleBvh<T>&, path) and queries it in place; the scalar
/// type must match the file's. Any fault of the file is an Error naming it.
template <class T>
MappedTriangleBvh<T> map_triangle_bvh(const std::filesystem::path& path,
                                      const LoadOptions& options = {}) {
    return serial_detail::MappedTriangleBvhAccess::map<T>(path, options);
}

/// The same over bytes the caller keeps alive and unchanged while the result is used (to_bytes'
/// output, a mapping of its own); their first byte must be aligned for T (an Error otherwise;
/// a std::vector's data always is).
template <class T>
MappedTriangleBvh<T> view_triangle_bvh(std::span<const std::uint8_t> bytes,
                                       const LoadOptions& options = {}) {
    MappedTriangleBvh<T> tree;
    serial_detail::MappedTriangleBvhAccess::open(tree, bytes, options);
    return tree;
}
/// A temporary buffer would be gone before the first query: keep it in a variable.
template <class T>
MappedTriangleBvh<T> view_triangle_bvh(std::vector<std::uint8_t>&& bytes,
                                       const LoadOptions& options = {}) = delete;

}  // namespace bvhkit
