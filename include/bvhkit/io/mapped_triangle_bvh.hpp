#pragma once
// MappedTriangleBvh<T>: a saved TriangleBvh queried where its file lies, without copying its
// arrays. map_triangle_bvh() maps the file (io/mapped_file.hpp); view_triangle_bvh() reads bytes
// the caller keeps alive (a buffer, or a mapping of its own). The nodes, slot indices, triangles
// and skipped list are the file's sections themselves, read in place: the format pads every section
// to 8 bytes (docs/serialization.md), which aligns each record for its type.
//
// It answers closest_hit, any_hit, all_hits, trace and occluded as the TriangleBvh that
// load_triangle_bvh makes of the same file does, bit for bit, by the same paths
// (query/wide_triangle_rays.hpp): a file of version 2 holds the wide ray layout, read in place
// too when the bytes lie aligned for it (always in a mapping, which starts on a page; a caller's
// buffer that is not gets a copy of the wide sections). Where the file holds no wide layout of the
// width this CPU walks (a file of version 1, or one written where AVX2 was present and read where
// it is not), rays walk the binary tree, as a TriangleBvh with RayLayout::Binary would: the same
// hits, t, barycentrics and normals as the wide walk, but where two triangles are hit at the same
// t, which one is reported may differ (docs/serialization.md).
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
#include "bvhkit/io/wide_ray_sections.hpp"
#include "bvhkit/query/triangle_rays.hpp"
#include "bvhkit/query/wide_triangle_rays.hpp"

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

    Hit<T> closest_hit(const Ray<T, 3>& ray) const { return closest_hit(ray, NoStats{}); }
    template <class Stats>
    Hit<T> closest_hit(const Ray<T, 3>& ray, Stats&& stats) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (ray_width() > 2) return wide_rays().closest_hit(ray, stats);
#endif
        return rays_.closest_hit(ray, stats);
    }
    bool any_hit(const Ray<T, 3>& ray) const {
        return any_hit(ray, NoStats{});
    }
    template <class Stats>
    bool any_hit(const Ray<T, 3>& ray, Stats&& stats) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (ray_width() > 2) return wide_rays().any_hit(ray, stats);
#endif
        return rays_.any_hit(ray, stats);
    }
    /// on_hit(const Hit<T>&) -> bool (true to go on); hits come in no particular order.
    template <class OnHit, class Stats = NoStats>
    void all_hits(const Ray<T, 3>& ray, OnHit&& on_hit, Stats&& stats = {}) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (ray_width() > 2) return wide_rays().all_hits(ray, on_hit, stats);
#endif
        rays_.all_hits(ray, on_hit, stats);
    }

    // Batches: trace() and occluded(), from RayBatches (query/triangle_rays.hpp), which run these
    // two on chunks of rays.

    /// hits[i] = closest_hit(rays[i]) for every ray, on the calling thread.
    void trace_on_calling_thread(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (ray_width() > 2) {
                this->check_lengths(rays.size(), hits.size(), "trace_on_calling_thread: hits");
                wide_rays().trace_on_calling_thread(rays, hits);
                return;
            }
#endif
        RayBatches<MappedTriangleBvh<T>, T>::trace_on_calling_thread(rays, hits);
    }
    /// occluded[i] = any_hit(rays[i]) (1 or 0) for every ray, on the calling thread.
    void occluded_stream(std::span<const Ray<T, 3>> rays, std::span<std::uint8_t> occluded) const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (ray_width() > 2) {
                this->check_lengths(rays.size(), occluded.size(), "occluded_stream: occluded");
                wide_rays().occluded_stream(rays, occluded);
                return;
            }
#endif
        RayBatches<MappedTriangleBvh<T>, T>::occluded_stream(rays, occluded);
    }

    /// The tree, in place in the file.
    BvhView<Aabb<T, 3>> bvh() const {
        return rays_.bvh();
    }
    /// Triangles left out of the tree for non-finite coordinates, by mesh index.
    std::span<const std::uint32_t> skipped() const {
        return skipped_;
    }
    std::size_t triangle_count() const {
        return triangle_count_;
    }
    TriangleTest triangle_test() const {
        return rays_.triangle_test();
    }
    /// The width of the tree rays walk: 8 or 4 (the file's wide layout), or 2 (the binary tree).
    int ray_width() const {
        return !wide8_.empty() ? 8 : !wide4_.empty() ? 4 : 2;
    }
    /// The bytes of the wide ray layout rays walk (0 for the binary tree).
    std::size_t ray_layout_bytes() const {
        return wide8_.empty() ? wide4_.bytes() : wide8_.bytes();
    }
    /// As TriangleBvh's (query/wide_triangle_rays.hpp).
    RayBatchPath batch_path() const {
        return batch_path_;
    }
    void set_batch_path(RayBatchPath path) {
        check_batch_path(path, ray_width(), "MappedTriangleBvh::set_batch_path");
        batch_path_ = path;
    }
    /// Whether the wide sections are read where they lie in the file (false: none are walked,
    /// or the caller's bytes were not aligned for them and they were copied).
    bool wide_layout_in_place() const {
        return ray_width() > 2 && copied4_.empty() && copied8_.empty();
    }
    /// The bytes the tree is read from (the whole file).
    std::span<const std::uint8_t> bytes() const {
        return bytes_;
    }

  private:
    friend struct serial_detail::MappedTriangleBvhAccess;

#if defined(__SSE2__)
    // Every ray path of a float tree over the file's sections (made per call: a few spans;
    // called for float trees only).
    WideTriangleRays wide_rays() const {
        return WideTriangleRays(rays_, wide4_, wide8_, batch_path_);
    }
#endif

    // The views stay valid: a moved mapping and moved vectors keep their addresses.
    void take(MappedTriangleBvh& other) noexcept {
        file_ = std::move(other.file_);
        bytes_ = std::exchange(other.bytes_, {});
        rays_ = std::exchange(other.rays_, {});
        skipped_ = std::exchange(other.skipped_, {});
        triangle_count_ = std::exchange(other.triangle_count_, 0);
        wide4_ = std::exchange(other.wide4_, {});
        wide8_ = std::exchange(other.wide8_, {});
        copied4_ = std::move(other.copied4_);
        copied8_ = std::move(other.copied8_);
        other.copied4_ = {};
        other.copied8_ = {};
        batch_path_ = std::exchange(other.batch_path_, RayBatchPath::Auto);
    }

    MappedFile file_;  // empty for a view of the caller's bytes
    std::span<const std::uint8_t> bytes_;
    TriangleRays<T> rays_;
    std::span<const std::uint32_t> skipped_;
    std::size_t triangle_count_ = 0;
    WideRayView<4> wide4_;  // at most one is non-empty: the file's sections, or copied*_
    WideRayView<8> wide8_;
    WideRayBvh<4> copied4_;  // the wide sections, when the bytes were not aligned for them
    WideRayBvh<8> copied8_;
    RayBatchPath batch_path_ = RayBatchPath::Auto;
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
           std::is_trivially_copyable_v<RayNode<8>> && std::is_trivially_copyable_v<RayGroup<8>> &&
           std::is_trivially_copyable_v<RayNode<4>> && std::is_trivially_copyable_v<RayGroup<4>> &&
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
            const WideSectionHeader wide = open_wide_sections<T>(f, r, what);
            check_loaded_triangle_tree<T>(rays, corners, triangle_count, skipped, options, what);
            if (wide.width == 4) open_wide<4>(tree, r, wide, f, bvh, corners, options);
            if (wide.width == 8) open_wide<8>(tree, r, wide, f, bvh, corners, options);
            tree.bytes_ = bytes;
            tree.rays_ = rays;
            tree.skipped_ = skipped;
            tree.triangle_count_ = std::size_t(triangle_count);
        }
    }

    // The wide sections in place (or copied where the bytes are not aligned for them), checked as
    // load_triangle_bvh checks them; walked only when of the width this CPU walks.
    template <int W, class T>
    static void open_wide(MappedTriangleBvh<T>& tree, ByteReader& r, const WideSectionHeader& h,
                          const TriangleBvhFileHeader& f, BvhView<Aabb<T, 3>> bvh,
                          std::span<const Triangle<T>> corners, const LoadOptions& options) {
        WideRayBvh<W> copied;
        const WideRayView<W> view = read_wide_layout(r, h, copied);
        const std::uint64_t triangle_count = f.file.header.counts[3];
        check_wide_structure<W>(view, triangle_count, what);
        if (W != f.wide_width_here<T>()) return;
        if constexpr (std::is_same_v<T, float>) {
            if (options.validate) {
                // The layout a load derives, from a copy of the tree, compared and dropped.
                Bvh<Aabb<float, 3>> tree_copy;
                tree_copy.nodes.assign(bvh.nodes.begin(), bvh.nodes.end());
                tree_copy.primitive_indices.assign(bvh.primitive_indices.begin(),
                                                   bvh.primitive_indices.end());
                const WideRayBvh<W> derived = make_wide_ray_bvh<W>(
                    tree_copy, [&](std::uint32_t s) { return corners[s]; },
                    [&](std::uint32_t s) { return bvh.primitive_indices[s]; });
                // A layout stored in the collapse's own lane order is checked with the order for
                // occlusion rays applied, and walked as it lies (the same answers).
                WideRayBvh<W> held;
                const bool reorder = h.lane_order == wide_lane_order_collapse;
                if (!same_wide_layout<W>(derived, ordered_as_now(view, reorder, held)))
                    throw Error(std::string(what) +
                                ": the stored wide ray layout is not the one the tree derives");
            }
            if constexpr (W == 4) {
                tree.copied4_ = std::move(copied);
                tree.wide4_ = view;
            } else {
                tree.copied8_ = std::move(copied);
                tree.wide8_ = view;
            }
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
