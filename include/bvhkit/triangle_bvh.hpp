#pragma once
// TriangleBvh<T>: what a raycasting user wants in one object. Build it from a triangle mesh, then
// ask closest_hit, any_hit or all_hits. It owns a Bvh and a copy of the triangles laid out in leaf
// order (edges and normal precomputed), so a leaf's triangles are contiguous in memory.
//
// Hit::primitive is the triangle's index in the mesh, Hit::normal its geometric normal (p1 - p0) x
// (p2 - p0), not normalized. Triangles with a NaN or infinite coordinate are left out (see
// BuildReport / skipped()); degenerate (zero-area) triangles stay in the tree and are never hit.
// A ray with a NaN or infinite component or a zero direction misses without walking the tree.
//
// Batches of rays: trace() and occluded() over spans, on every core with oneTBB;
// trace_on_calling_thread() and occluded_stream() on the calling thread. On the eight-wide layout a
// batch walks several rays at once (query/ray_stream.hpp; occlusion rays below 8 MB in octant
// streams, query/ray_octant_stream.hpp; runs of coherent rays as packets, query/ray_coherence.hpp,
// and every run with trace_packets()), or as RayBatchPath forces: the one-by-one calls' answers,
// bit for bit. The float paths are query/wide_triangle_rays.hpp's, shared with MappedTriangleBvh.
//
// The triangle test is TriangleBvhOptions::triangle_test: watertight by default (no ray slips
// through a shared edge or vertex of a closed mesh), or the fast Moller-Trumbore test, which can
// (see primitives/triangle.hpp).
//
// TriangleBvhOptions::spatial_splits builds the high-quality tree (build/spatial_splits.hpp): its
// leaves may hold parts of one triangle in several places, which queries never show (all_hits
// reports each triangle once). refit() keeps such a tree correct, with each leaf's box grown to
// its triangles' whole boxes; a tree with spatial splits cannot be saved
// (io/triangle_bvh_file.hpp).
//
// Threads: the const queries may run on many threads at once. refit() needs the tree to itself: it
// rewrites (and may reallocate) what the queries read. Debug builds (!NDEBUG) catch the misuse, as
// the dynamic tree's walk counter does: refit() throws bvhkit::Error while a query runs, and a
// query that starts during a refit() throws. Release builds check nothing (an atomic count per
// query would cost the many-thread case its scaling): a query overlapping refit() is undefined
// behaviour (wrong hits, or a crash on freed memory).
#include <atomic>
#include <span>
#include <unordered_set>

#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/build/spatial_split_choice.hpp"
#include "bvhkit/build/spatial_splits.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"
#include "bvhkit/query/ray.hpp"
#include "bvhkit/query/ray_wide.hpp"
#include "bvhkit/query/triangle_rays.hpp"
#include "bvhkit/query/wide_triangle_rays.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

namespace serial_detail {
struct TriangleBvhAccess;  // io/triangle_bvh_file.hpp: saves and loads the private arrays
}

namespace detail {

/// Debug builds: who uses a tree now, queries (counted) or refit() (a flag), so that refit() and
/// the queries can refuse to overlap instead of corrupting memory. Release builds never touch it;
/// the member is there in both, so that code built with and without NDEBUG agrees on the layout.
/// A copied or moved tree starts unused.
class QueryExclusion {
  public:
    QueryExclusion() = default;
    QueryExclusion(const QueryExclusion&) noexcept {}
    QueryExclusion& operator=(const QueryExclusion&) noexcept { return *this; }

    /// Held by a query for its duration (nested queries count again).
    class Reading {
      public:
#if !defined(NDEBUG)
        explicit Reading(const QueryExclusion& e) : e_(e) {
            if (e_.state_.fetch_add(1, std::memory_order_acquire) & kRefitting) {
                e_.state_.fetch_sub(1, std::memory_order_relaxed);
                throw Error(
                    "TriangleBvh: a query started while refit() runs on the same tree (refit "
                    "needs the tree to itself; in a release build this is undefined behaviour)");
            }
        }
        ~Reading() {
            e_.state_.fetch_sub(1, std::memory_order_release);
        }
        Reading(const Reading&) = delete;
        Reading& operator=(const Reading&) = delete;

      private:
        const QueryExclusion& e_;
#else
        explicit Reading(const QueryExclusion&) {}
#endif
    };

    /// Held by refit() for its duration.
    class Writing {
      public:
#if !defined(NDEBUG)
        Writing(QueryExclusion& e, const char* where) : e_(e) {
            std::uint32_t idle = 0;
            if (!e_.state_.compare_exchange_strong(idle, kRefitting, std::memory_order_acquire))
                throw Error(std::string(where) + ": called while " +
                            ((idle & kRefitting) ? std::string("another refit()")
                                                 : std::to_string(idle) + " queries") +
                            " run on the same tree (refit needs the tree to itself; in a release "
                            "build this is undefined behaviour)");
        }
        ~Writing() {
            e_.state_.fetch_sub(kRefitting, std::memory_order_release);
        }
        Writing(const Writing&) = delete;
        Writing& operator=(const Writing&) = delete;

      private:
        QueryExclusion& e_;
#else
        Writing(QueryExclusion&, const char*) {}
#endif
    };

  private:
    static constexpr std::uint32_t kRefitting = 0x80000000u;
    mutable std::atomic<std::uint32_t> state_{0};
};

}  // namespace detail

/// Which tree rays walk. The wide layouts serve float trees with the watertight test, on x86
/// (query/ray_wide.hpp); anything else walks the binary tree.
enum class RayLayout {
    Auto,  // eight wide when the CPU has AVX2, else four wide (the default)
    // Kept one release, its value (1) too: saved files carry it.
    Wide8 [[deprecated("use Auto: Wide8 always behaved as Auto")]],
    Wide4,   // four wide (SSE2)
    Binary,  // the binary tree only
};

/// How a TriangleBvh is built (every BuildOptions member), which triangle test its queries run and
/// on which layout. Converts from BuildOptions, so `TriangleBvh<float>(mesh, build_options)` keeps
/// working.
struct TriangleBvhOptions : BuildOptions {
    TriangleTest triangle_test = TriangleTest::Watertight;
    RayLayout ray_layout = RayLayout::Auto;
    /// Which walk batches take on the eight-wide layout (query/wide_triangle_rays.hpp): Streams
    /// and OctantStreams are an Error unless the tree's rays walk eight wide.
    RayBatchPath batch_path = RayBatchPath::Auto;
    /// The high-quality build: binned SAH with spatial splits (Stich et al. 2009), `spatial` its
    /// parameters. Serial, several times the default build's time, and up to spatial.budget more
    /// triangle references; needs Builder::BinnedSah and no optimize (else bvhkit::Error).
    bool spatial_splits = false;
    /// Spatial splits where they pay: the default build, then, if its child_overlap reaches
    /// tuning::spatial_splits_from_overlap (build/spatial_split_choice.hpp: rooms, triangle soups,
    /// not scans), the spatial-split build again with `spatial`; has_split_references() says
    /// whether it was kept. Only with Builder::BinnedSah and no optimize (else the default build
    /// alone). Off by default: that build takes several times as long, and such a tree cannot be
    /// saved.
    bool auto_spatial_splits = false;
    SpatialSplitOptions spatial{};

    TriangleBvhOptions() = default;
    TriangleBvhOptions(const BuildOptions& build) : BuildOptions(build) {}  // NOLINT: implicit
};

template <class T>
class TriangleBvh : public RayBatches<TriangleBvh<T>, T> {
  public:
    TriangleBvh() = default;

    template <IndexedTriangleMesh M>
    explicit TriangleBvh(const M& mesh, const TriangleBvhOptions& options = {})
        : triangle_test_(options.triangle_test), ray_layout_(options.ray_layout) {
        check_triangle_indices(mesh);
        build([&](std::size_t i) { return triangle_at<T>(mesh, i); }, mesh.triangle_count(),
              options);
    }

    explicit TriangleBvh(const std::vector<Triangle<T>>& triangles,
                         const TriangleBvhOptions& options = {})
        : triangle_test_(options.triangle_test), ray_layout_(options.ray_layout) {
        build([&](std::size_t i) { return triangles[i]; }, triangles.size(), options);
    }

    Hit<T> closest_hit(const Ray<T, 3>& ray) const { return closest_hit(ray, NoStats{}); }
    template <class Stats>
    Hit<T> closest_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        const Reading reading(exclusion_);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (traces_wide()) return wide_rays().closest_hit(ray, stats);
#endif
        return binary_rays().closest_hit(ray, stats);
    }

    bool any_hit(const Ray<T, 3>& ray) const {
        return any_hit(ray, NoStats{});
    }
    template <class Stats>
    bool any_hit(const Ray<T, 3>& ray, Stats&& stats) const {
        const Reading reading(exclusion_);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (traces_wide()) return wide_rays().any_hit(ray, stats);
#endif
        return binary_rays().any_hit(ray, stats);
    }

    /// on_hit(const Hit<T>&) -> bool (true to go on); hits come in no particular order.
    template <class OnHit, class Stats = NoStats>
    void all_hits(const Ray<T, 3>& ray, OnHit&& on_hit, Stats&& stats = {}) const {
        const Reading reading(exclusion_);
        // The walk rays take (the wide layout's gives the binary walk's hits, the same test).
        const auto walk = [&](auto&& report) {
#if defined(__SSE2__)
            if constexpr (std::is_same_v<T, float>)
                if (traces_wide()) return wide_rays().all_hits(ray, report, stats);
#endif
            binary_rays().all_hits(ray, report, stats);
        };
        if (!split_references_) {
            walk(on_hit);
            return;
        }
        // A triangle split by the build can be met in several leaves: reported the first time.
        std::unordered_set<std::uint32_t> seen;
        walk([&](const Hit<T>& h) {
            return seen.insert(h.primitive).second ? bool(on_hit(h)) : true;
        });
    }

    // Batches: trace() and occluded(), from RayBatches (query/triangle_rays.hpp), which run these
    // two on chunks of rays.

    /// hits[i] = closest_hit(rays[i]) for every ray, on the calling thread (an Error when the
    /// spans differ in length).
    void trace_on_calling_thread(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits) const {
        const Reading reading(exclusion_);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (traces_wide()) {
                this->check_lengths(rays.size(), hits.size(), "trace_on_calling_thread: hits");
                wide_rays().trace_on_calling_thread(rays, hits);
                return;
            }
#endif
        RayBatches<TriangleBvh<T>, T>::trace_on_calling_thread(rays, hits);
    }
    /// hits[i] = closest_hit(rays[i]) for a batch its caller knows to be coherent (camera rays,
    /// shadow rays towards one light), on `threads` threads as trace(): on the eight-wide layout
    /// every run of 32 consecutive rays walks the tree as one packet (query/ray_octant_stream.hpp),
    /// whatever batch_path(); elsewhere as trace(). The answers are trace()'s, bit for bit; only
    /// the speed depends on the order. Camera rays pay best in tiles: 32 consecutive rays an 8x4
    /// block of pixels (or two rows of a 16x16 tile, or 32 pixels of one row).
    void trace_packets(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits,
                       unsigned threads = 0) const {
        trace_packets(rays, hits, Executor(threads));
    }
    void trace_packets(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits,
                       const Executor& exec) const {
        this->for_each(rays, hits, exec, "trace_packets: hits", [&](auto chunk, auto out) {
#if defined(__SSE2__)
            if constexpr (std::is_same_v<T, float>)
                if (traces_wide()) {
                    const Reading reading(exclusion_);
                    wide_rays().trace_on_calling_thread(chunk, out, true);
                    return;
                }
#endif
            trace_on_calling_thread(chunk, out);
        });
    }
    /// occluded[i] = any_hit(rays[i]) (1 or 0) for every ray, on the calling thread.
    void occluded_stream(std::span<const Ray<T, 3>> rays, std::span<std::uint8_t> occluded) const {
        const Reading reading(exclusion_);
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>)
            if (traces_wide()) {
                this->check_lengths(rays.size(), occluded.size(), "occluded_stream: occluded");
                wide_rays().occluded_stream(rays, occluded);
                return;
            }
#endif
        RayBatches<TriangleBvh<T>, T>::occluded_stream(rays, occluded);
    }

    TriangleTest triangle_test() const {
        return triangle_test_;
    }
    /// The width of the tree rays walk: 8 or 4 (a wide layout), or 2 (the binary tree).
    int ray_width() const {
        return !wide8_.empty() ? 8 : !wide4_.empty() ? 4 : 2;
    }
    bool traces_wide() const {
        return ray_width() > 2;
    }
    /// The bytes of the wide ray layout (0 when rays walk the binary tree).
    std::size_t ray_layout_bytes() const {
        return wide8_.empty() ? wide4_.bytes() : wide8_.bytes();
    }
    /// Whether trace batches walk their incoherent rays several at once (query/ray_stream.hpp):
    /// on the eight-wide layout once it is 2 MB or more (about 45,000 triangles), or as
    /// batch_path() says. Coherent runs walk as packets on any eight-wide layout, whatever this
    /// says (RayBatchPath::Auto and Packets, trace_packets).
    /// Occlusion batches on the eight-wide layout do unless batch_path() is OneByOne: in octant
    /// streams below 8 MB (query/ray_octant_stream.hpp), as trace batches above.
    bool streams_rays() const {
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) return wide_rays().streams_traces();
#endif
        return false;
    }
    /// Which walk batches take on the eight-wide layout (query/wide_triangle_rays.hpp).
    RayBatchPath batch_path() const {
        return batch_path_;
    }
    /// Forces the batches' walk (for tests and measuring; answers stay the same): an Error for
    /// Streams or OctantStreams unless ray_width() is 8. Not while queries run on the tree.
    void set_batch_path(RayBatchPath path) {
        check_batch_path(path, ray_width(), "TriangleBvh::set_batch_path");
        batch_path_ = path;
    }

    /// After the mesh's vertices moved (same triangles, same order): refit the boxes, one pass.
    /// A triangle of the tree with a NaN or infinite coordinate is an Error, and the tree is left
    /// as it was (its boxes would be NaN, and rays would miss it without a word); triangles left
    /// out at the build stay out. No query may run on the tree meanwhile (debug builds throw
    /// bvhkit::Error on either side; see the top of this file).
    template <IndexedTriangleMesh M>
    void refit(const M& mesh) {
        const detail::QueryExclusion::Writing writing(exclusion_, "TriangleBvh::refit");
        if (mesh.triangle_count() != triangle_count_)
            throw Error("TriangleBvh::refit: the mesh has " +
                        std::to_string(mesh.triangle_count()) +
                        " triangles, the tree was built over " + std::to_string(triangle_count_));
        check_triangle_indices(mesh);
        const auto triangle = [&](std::size_t i) { return triangle_at<T>(mesh, i); };
        for (const std::uint32_t t : bvh_.primitive_indices)
            if (!triangle(t).bounds().is_finite())
                throw Error("TriangleBvh::refit: triangle " + std::to_string(t) +
                            " has a non-finite coordinate (a new tree would leave it out)");
        bvhkit::refit(bvh_, [&](std::uint32_t i) { return triangle(i).bounds(); });
        lay_out(triangle);
    }

    const AabbBvh<T, 3>& bvh() const {
        return bvh_;
    }
    /// Triangles left out of the tree for non-finite coordinates, by mesh index.
    const std::vector<std::uint32_t>& skipped() const {
        return report_.skipped;
    }
    std::size_t triangle_count() const {
        return triangle_count_;
    }
    /// Whether the build split triangles (spatial splits): then bvh() names some in several leaves.
    bool has_split_references() const {
        return split_references_;
    }

  private:
    friend struct serial_detail::TriangleBvhAccess;
    using Reading = detail::QueryExclusion::Reading;

    // The binary walk over this tree's own arrays.
    TriangleRays<T> binary_rays() const {
        if (triangle_test_ == TriangleTest::Watertight)
            return TriangleRays<T>(bvh_view(bvh_), std::span<const Triangle<T>>(exact_));
        return TriangleRays<T>(bvh_view(bvh_), std::span<const PrecomputedTriangle<T>>(fast_));
    }

#if defined(__SSE2__)
    // Every ray path of a float tree over this tree's own arrays (made per call: a few spans;
    // called for float trees only).
    WideTriangleRays wide_rays() const {
        return WideTriangleRays(binary_rays(), wide4_, wide8_, batch_path_);
    }
#endif

    template <class TriangleAt>
    void build(TriangleAt&& triangle, std::size_t count, const TriangleBvhOptions& options) {
        BuildOptions tree_options = options;
        // The wide layouts test a leaf's triangles four or eight abreast: leaves priced in blocks
        // as wide as the walk's groups, so that a node of one block is a leaf without a search (a
        // faster build, the same rays; tuning.hpp). Never above max_leaf_size: nodes between the
        // two would be split at the object median.
        if (tree_options.costs.leaf_block == 0 && wide_layout())
            tree_options.costs.leaf_block = std::min<std::uint32_t>(
                eight_wide() ? tuning::wide8_leaf_block : tuning::wide4_leaf_block,
                tree_options.max_leaf_size);
        if (options.spatial_splits) {
            if (options.builder != Builder::BinnedSah || options.optimize)
                throw Error(
                    "TriangleBvh: spatial_splits needs Builder::BinnedSah and optimize = false");
            bvh_ = build_spatial_split_bvh<T>(triangle, count, tree_options, options.spatial,
                                              &report_);
        } else {
            std::vector<Aabb<T, 3>> boxes;
            std::vector<Vec<T, 3>> centroids;
            boxes.reserve(count);
            centroids.reserve(count);
            for (std::size_t i = 0; i < count; ++i) {
                boxes.push_back(triangle(i).bounds());
                centroids.push_back(boxes.back().centroid());
            }
            bvh_ = build_bvh<T, 3>(boxes, centroids, tree_options, &report_);
            if (options.auto_spatial_splits && options.builder == Builder::BinnedSah &&
                !options.optimize && spatial_splits_pay(child_overlap(bvh_))) {
                report_ = {};
                bvh_ = build_spatial_split_bvh<T>(triangle, count, tree_options, options.spatial,
                                                  &report_);
            }
        }
        split_references_ = bvh_.primitive_indices.size() + report_.skipped.size() != count;
        triangle_count_ = count;
        lay_out(triangle);
        set_batch_path(options.batch_path);
    }

    // Only the chosen test's layout is kept.
    template <class TriangleAt>
    void lay_out(TriangleAt&& triangle) {
        const auto& order = bvh_.primitive_indices;
        fast_.clear();
        exact_.clear();
        if (triangle_test_ == TriangleTest::Watertight) {
            exact_.reserve(order.size());
            for (std::uint32_t i : order) exact_.push_back(triangle(i));
        } else {
            fast_.reserve(order.size());
            for (std::uint32_t i : order) fast_.emplace_back(triangle(i));
        }
        make_ray_layout();
    }

    /// Whether rays walk a wide layout: float, the watertight test, x86, not forced binary.
    bool wide_layout() const {
#if defined(__SSE2__)
        return std::is_same_v<T, float> && ray_layout_ != RayLayout::Binary &&
               triangle_test_ == TriangleTest::Watertight;
#else
        return false;
#endif
    }

    /// Whether the wide layout is the eight-wide one (this CPU has AVX2 and it is not forced to
    /// four wide).
    bool eight_wide() const {
        return ray_layout_ != RayLayout::Wide4 && cpu_has_avx2();
    }

    // The wide ray layout (query/ray_wide_layout.hpp), derived from the tree and the triangles:
    // made after a build, a refit or a load.
    void make_ray_layout() {
        wide4_ = {};
        wide8_ = {};
#if defined(__SSE2__)
        if constexpr (std::is_same_v<T, float>) {
            if (!wide_layout() || bvh_.empty()) return;
            const auto at = [&](std::uint32_t slot) { return exact_[slot]; };
            const auto index = [&](std::uint32_t slot) { return bvh_.primitive_indices[slot]; };
            if (eight_wide())
                wide8_ = make_wide_ray_bvh<8>(bvh_, at, index);
            else
                wide4_ = make_wide_ray_bvh<4>(bvh_, at, index);
        }
#endif
    }

    AabbBvh<T, 3> bvh_;
    std::vector<PrecomputedTriangle<T>> fast_;  // leaf-slot order, only for the fast test
    std::vector<Triangle<T>> exact_;            // leaf-slot order, only for the watertight test
    BuildReport report_;
    std::size_t triangle_count_ = 0;
    bool split_references_ = false;  // some triangle is in more than one leaf
    TriangleTest triangle_test_ = TriangleTest::Watertight;
    RayLayout ray_layout_ = RayLayout::Auto;
    RayBatchPath batch_path_ = RayBatchPath::Auto;  // not saved: a loaded tree starts at Auto
    WideRayBvh<4> wide4_;  // at most one of the two is filled (float, watertight, x86 only)
    WideRayBvh<8> wide8_;
    detail::QueryExclusion exclusion_;  // debug builds: refit() and queries never overlap
};

}  // namespace bvhkit
