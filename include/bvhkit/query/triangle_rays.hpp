#pragma once
// TriangleRays<T>: closest hit, any hit and all hits on a binary tree over triangles stored in leaf
// slot order, read in place. It owns nothing: TriangleBvh walks its own arrays with it when rays
// take the binary tree, and MappedTriangleBvh (io/mapped_triangle_bvh.hpp) walks a mapped file's.
//
// The triangles are either their corners (the watertight test, Woop, Benthin and Wald 2013) or
// p0, edges and normal (the fast Moller-Trumbore test); see primitives/triangle.hpp.
#include <span>
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "bvhkit/query/ray.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

enum class TriangleTest {
    Watertight,  // Woop, Benthin, Wald 2013: never misses through a shared edge (default)
    Fast,        // Moller-Trumbore on precomputed edges: a ray can slip through a shared edge
};

template <class T>
class TriangleRays {
  public:
    TriangleRays() = default;
    /// Watertight test over corners, `corners[slot]` the triangle in leaf slot `slot`.
    TriangleRays(BvhView<Aabb<T, 3>> bvh, std::span<const Triangle<T>> corners)
        : bvh_(bvh), corners_(corners.data()), test_(TriangleTest::Watertight) {}
    /// Fast test over precomputed triangles, by leaf slot.
    TriangleRays(BvhView<Aabb<T, 3>> bvh, std::span<const PrecomputedTriangle<T>> precomputed)
        : bvh_(bvh), precomputed_(precomputed.data()), test_(TriangleTest::Fast) {}

    template <class Stats = NoStats>
    Hit<T> closest_hit(const Ray<T, 3>& ray, Stats&& stats = {}) const {
        if (test_ == TriangleTest::Watertight)
            return bvhkit::closest_hit(bvh_, ray, WatertightTest{corners_, ray}, stats);
        return bvhkit::closest_hit(bvh_, ray, FastTest{precomputed_}, stats);
    }
    template <class Stats = NoStats>
    bool any_hit(const Ray<T, 3>& ray, Stats&& stats = {}) const {
        if (test_ == TriangleTest::Watertight)
            return bvhkit::any_hit(bvh_, ray, WatertightTest{corners_, ray}, stats);
        return bvhkit::any_hit(bvh_, ray, FastTest{precomputed_}, stats);
    }
    /// on_hit(const Hit<T>&) -> bool (true to go on); hits come in no particular order.
    template <class OnHit, class Stats = NoStats>
    void all_hits(const Ray<T, 3>& ray, OnHit&& on_hit, Stats&& stats = {}) const {
        if (test_ == TriangleTest::Watertight)
            bvhkit::all_hits(bvh_, ray, WatertightTest{corners_, ray}, on_hit, stats);
        else
            bvhkit::all_hits(bvh_, ray, FastTest{precomputed_}, on_hit, stats);
    }

    BvhView<Aabb<T, 3>> bvh() const { return bvh_; }
    TriangleTest triangle_test() const { return test_; }

  private:
    // The leaf tests (query/ray.hpp): the watertight one carries its per-ray constants, made once
    // per query.
    struct WatertightTest {
        const Triangle<T>* tris;
        WatertightRay<T> prepared;
        WatertightTest(const Triangle<T>* t, const Ray<T, 3>& ray) : tris(t), prepared(ray) {}
        bool operator()(std::uint32_t slot, const Ray<T, 3>& ray, TriangleHit<T>& h) const {
            const Triangle<T>& tri = tris[slot];
            return intersect_watertight(prepared, tri.p0, tri.p1, tri.p2, ray.tmin, ray.tmax, h);
        }
        Vec<T, 3> normal(std::uint32_t slot) const { return tris[slot].normal(); }
    };
    struct FastTest {
        const PrecomputedTriangle<T>* tris;
        bool operator()(std::uint32_t slot, const Ray<T, 3>& ray, TriangleHit<T>& h) const {
            return tris[slot].intersect(ray, ray.tmax, h);
        }
        // n = (p0 - p1) x (p2 - p0) = -(p1 - p0) x (p2 - p0).
        Vec<T, 3> normal(std::uint32_t slot) const { return tris[slot].n * T(-1); }
    };

    BvhView<Aabb<T, 3>> bvh_;
    const Triangle<T>* corners_ = nullptr;
    const PrecomputedTriangle<T>* precomputed_ = nullptr;
    TriangleTest test_ = TriangleTest::Watertight;
};

/// Rays per task of the batch calls: large enough to pay for a task, small enough to balance
/// incoherent rays over the cores.
inline constexpr std::size_t ray_batch_grain = tuning::ray_batch_grain;

/// The batch calls of a tree with closest_hit(ray) and any_hit(ray) (TriangleBvh,
/// MappedTriangleBvh derive from it): trace() sets hits[i] = closest_hit(rays[i]), occluded()
/// sets occluded[i] = any_hit(rays[i]) (1 or 0), on `threads` threads (0 = every core, 1 = the
/// calling thread; several only when bvhkit has oneTBB) or on an Executor. Rays go in fixed chunks
/// of batch_grain and each answer is its ray's alone, so the answers equal the one-by-one calls
/// for any thread count. An Error when the spans differ in length.
template <class Tree, class T>
class RayBatches {
  public:
    static constexpr std::size_t batch_grain = ray_batch_grain;

    void trace(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits,
               unsigned threads = 0) const {
        trace(rays, hits, Executor(threads));
    }
    void trace(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits,
               const Executor& exec) const {
        for_each(rays, hits, exec, "trace: hits",
                 [&](auto chunk, auto out) { tree().trace_on_calling_thread(chunk, out); });
    }
    void occluded(std::span<const Ray<T, 3>> rays, std::span<std::uint8_t> occluded,
                  unsigned threads = 0) const {
        this->occluded(rays, occluded, Executor(threads));
    }
    void occluded(std::span<const Ray<T, 3>> rays, std::span<std::uint8_t> occluded,
                  const Executor& exec) const {
        for_each(rays, occluded, exec, "occluded: occluded",
                 [&](auto chunk, auto out) { tree().occluded_stream(chunk, out); });
    }

    /// trace() on the calling thread: hits[i] = closest_hit(rays[i]). A tree that walks several
    /// rays at once (TriangleBvh) hides this with its own, of the same answers.
    void trace_on_calling_thread(std::span<const Ray<T, 3>> rays, std::span<Hit<T>> hits) const {
        check_lengths(rays.size(), hits.size(), "trace_on_calling_thread: hits");
        for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = tree().closest_hit(rays[i]);
    }
    /// The former name of trace_on_calling_thread, kept for one release.
    [[deprecated("use trace_on_calling_thread")]] void trace_stream(std::span<const Ray<T, 3>> rays,
                                                                    std::span<Hit<T>> hits) const {
        tree().trace_on_calling_thread(rays, hits);
    }
    /// occluded() on the calling thread: occluded[i] = any_hit(rays[i]) (1 or 0).
    void occluded_stream(std::span<const Ray<T, 3>> rays, std::span<std::uint8_t> occluded) const {
        check_lengths(rays.size(), occluded.size(), "occluded_stream: occluded");
        for (std::size_t i = 0; i < rays.size(); ++i)
            occluded[i] = std::uint8_t(tree().any_hit(rays[i]) ? 1 : 0);
    }

  protected:
    static void check_lengths(std::size_t rays, std::size_t out, const char* what) {
        if (rays != out)
            throw Error(std::string(what) + " holds " + std::to_string(out) + " entries for " +
                        std::to_string(rays) + " rays");
    }

    /// Runs chunk(rays, out) over chunks of batch_grain on the executor's threads.
    template <class Out, class Chunk>
    static void for_each(std::span<const Ray<T, 3>> rays, std::span<Out> out, const Executor& exec,
                         const char* what, Chunk&& chunk) {
        check_lengths(rays.size(), out.size(), what);
        exec.parallel_for(rays.size(), batch_grain, [&](std::size_t b, std::size_t e) {
            chunk(rays.subspan(b, e - b), out.subspan(b, e - b));
        });
    }

  private:
    const Tree& tree() const { return static_cast<const Tree&>(*this); }
};

}  // namespace bvhkit
