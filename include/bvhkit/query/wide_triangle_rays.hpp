#pragma once
// WideTriangleRays: every ray path of a float tree with the watertight test that walks a wide
// layout, over arrays it does not own. TriangleBvh<float> runs it on its own arrays and
// MappedTriangleBvh<float> (io/mapped_triangle_bvh.hpp) on a mapped file's sections, so both take
// the same path for the same ray and answer alike.
//
// The paths: a ray the wide walk does not serve (query/ray_wide.hpp, wide_ray_usable) takes the
// binary tree; one that misses the tree's bounds is a miss without a walk; the others walk the
// wide layout, four or eight wide. Batches on the eight-wide layout may walk several rays at once
// (streams, query/ray_stream.hpp; octant streams for occlusion and packets of coherent rays for
// closest hits, query/ray_octant_stream.hpp), chosen by the layout's size (tuning.hpp) and, for
// packets, by the rays themselves (query/ray_coherence.hpp), or forced by RayBatchPath. Every
// path gives the one-ray calls' answers, bit for bit.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/query/ray_coherence.hpp"
#include "bvhkit/query/ray_octant_stream.hpp"
#include "bvhkit/query/ray_stream.hpp"
#include "bvhkit/query/ray_wide.hpp"
#include "bvhkit/query/triangle_rays.hpp"

namespace bvhkit {

/// Which walk the batch calls (trace, occluded and their _stream forms) take on the eight-wide
/// layout. Every choice answers as the one-ray calls do, bit for bit; the choice is for tests,
/// which must run every path whatever the mesh's size, and for measuring.
enum class RayBatchPath {
    Auto,           // trace batches: each run of 32 rays (8 or more at a batch's end) that
                    // coherent_rays accepts as a packet, the others one by one, or in streams
                    // from 2 MB of layout on (tuning.hpp); occlusion
                    // batches in octant streams below 8 MB and in streams above
    OneByOne,       // each ray walks alone, as closest_hit / any_hit
    Streams,        // eight rays in flight (query/ray_stream.hpp); needs the eight-wide layout
    OctantStreams,  // occlusion batches in octant streams (query/ray_octant_stream.hpp), trace
                    // batches one by one or in streams as Auto chooses for rays it finds
                    // incoherent (no packets); needs the eight-wide layout
    Packets,        // trace and occlusion batches in octant streams, whatever the rays (for
                    // coherent rays: query/ray_octant_stream.hpp); needs the eight-wide layout
};

/// The name of a RayBatchPath, for messages.
inline const char* batch_path_name(RayBatchPath path) {
    switch (path) {
        case RayBatchPath::Auto:
            return "Auto";
        case RayBatchPath::OneByOne:
            return "OneByOne";
        case RayBatchPath::Streams:
            return "Streams";
        case RayBatchPath::OctantStreams:
            return "OctantStreams";
        case RayBatchPath::Packets:
            return "Packets";
    }
    return "?";
}

/// An Error unless a tree whose rays walk `ray_width` wide can take `path`: the streams need the
/// eight-wide layout (RayLayout Auto or Wide8 on a CPU with AVX2).
inline void check_batch_path(RayBatchPath path, int ray_width, const char* what) {
    if (path != RayBatchPath::Auto && path != RayBatchPath::OneByOne && ray_width != 8)
        throw Error(std::string(what) + ": RayBatchPath::" + batch_path_name(path) +
                    " needs the eight-wide ray layout, and this tree's rays walk " +
                    std::to_string(ray_width) +
                    " wide (the eight-wide walk needs a CPU with AVX2, the watertight test and "
                    "RayLayout Auto or Wide8)");
}

#if defined(__SSE2__)
class WideTriangleRays {
  public:
    WideTriangleRays() = default;
    /// `binary` walks the tree (watertight, over corners) for the rays the wide walk does not
    /// serve; at most one of `wide4` and `wide8` is non-empty, and an eight-wide one needs
    /// cpu_has_avx2(). check_batch_path(path, width()) must hold.
    WideTriangleRays(const TriangleRays<float>& binary, WideRayView<4> wide4, WideRayView<8> wide8,
                     RayBatchPath path)
        : binary_(binary), wide4_(wide4), wide8_(wide8), path_(path) {}

    /// 8 or 4 (the wide layout's width), or 2 when there is none.
    int width() const { return !wide8_.empty() ? 8 : !wide4_.empty() ? 4 : 2; }
    std::size_t layout_bytes() const { return wide8_.empty() ? wide4_.bytes() : wide8_.bytes(); }

    /// Whether trace batches walk streams.
    bool streams_traces() const {
#if BVHKIT_RAY_AVX2
        if (wide8_.empty() || path_ == RayBatchPath::OneByOne) return false;
        return path_ == RayBatchPath::Streams || detail::stream_pays(wide8_);
#else
        return false;
#endif
    }

    template <class Stats>
    Hit<float> closest_hit(const Ray<float, 3>& ray, Stats&& stats) const {
        detail::SlabConstants k;
        const Route route = width() > 2 ? route_wide(ray, k) : Route::Binary;
        if (route == Route::Miss) return Hit<float>{};
        if (route == Route::Binary) return binary_.closest_hit(ray, stats);
        const WatertightRay<float> prep(ray, WatertightRay<float>::KnownValid{});
        const auto trace = [&](auto wide) {
            TriangleHit<float> h;
            const typename decltype(wide)::Group* group;
            int lane;
            if (!closest_hit_wide(wide, ray, k, prep, h, group, lane, stats)) return Hit<float>{};
            return wide_hit(h, *group, lane);
        };
        return wide8_.empty() ? trace(wide4_) : trace(wide8_);
    }

    template <class Stats>
    bool any_hit(const Ray<float, 3>& ray, Stats&& stats) const {
        if (width() == 2 || !wide_ray_usable(ray)) return binary_.any_hit(ray, stats);
        const WatertightRay<float> prep(ray, WatertightRay<float>::KnownValid{});
        return wide8_.empty() ? any_hit_wide(wide4_, ray, prep, stats)
                              : any_hit_wide(wide8_, ray, prep, stats);
    }

    /// on_hit(const Hit<float>&) -> bool (true to go on) for every hit in the ray's range, in no
    /// particular order; the hits of the binary walk's all_hits (the same watertight test).
    template <class OnHit, class Stats>
    void all_hits(const Ray<float, 3>& ray, OnHit&& on_hit, Stats&& stats) const {
        detail::SlabConstants k;
        const Route route = width() > 2 ? route_wide(ray, k) : Route::Binary;
        if (route == Route::Miss) return;
        if (route == Route::Binary) {
            binary_.all_hits(ray, on_hit, stats);
            return;
        }
        const WatertightRay<float> prep(ray, WatertightRay<float>::KnownValid{});
        const auto walk = [&](auto wide) {
            all_hits_wide(
                wide, ray, k, prep,
                [&](const auto& group, int lane, const TriangleHit<float>& h) {
                    return bool(on_hit(wide_hit(h, group, lane)));
                },
                stats);
        };
        if (wide8_.empty())
            walk(wide4_);
        else
            walk(wide8_);
    }

    /// hits[i] = closest_hit(rays[i]); the spans are of one length. On the eight-wide layout,
    /// Auto walks each run of octant_stream_size rays that coherent_rays accepts as a packet
    /// (query/ray_octant_stream.hpp), the others as before; `packets` (or RayBatchPath::Packets)
    /// walks every run as packets.
    void trace_on_calling_thread(std::span<const Ray<float, 3>> rays, std::span<Hit<float>> hits,
                                 bool packets = false) const {
#if BVHKIT_RAY_AVX2
        if (!wide8_.empty() &&
            (packets || path_ == RayBatchPath::Packets || path_ == RayBatchPath::Auto)) {
            trace_in_packets(rays, hits, packets || path_ == RayBatchPath::Packets);
            return;
        }
#endif
        trace_one_way(rays, hits);
    }

    /// occluded[i] = any_hit(rays[i]) (1 or 0); the spans are of one length.
    void occluded_stream(std::span<const Ray<float, 3>> rays,
                         std::span<std::uint8_t> occluded) const {
#if BVHKIT_RAY_AVX2
        if (!wide8_.empty() && path_ != RayBatchPath::OneByOne) {
            const bool octants =
                path_ == RayBatchPath::OctantStreams || path_ == RayBatchPath::Packets ||
                (path_ == RayBatchPath::Auto && detail::octant_streams_pay(wide8_));
            if (octants)
                occlude_in_octants(rays, occluded);
            else
                stream<true>(
                    rays, [&](const detail::StreamRay& s) { occluded[s.index] = s.found ? 1 : 0; },
                    [&](std::size_t i) { occluded[i] = any_hit(rays[i], NoStats{}) ? 1 : 0; });
            return;
        }
#endif
        for (std::size_t i = 0; i < rays.size(); ++i)
            occluded[i] = any_hit(rays[i], NoStats{}) ? 1 : 0;
    }

  private:
    /// The trace batch's rays in streams (when streams_traces()) or one by one.
    void trace_one_way(std::span<const Ray<float, 3>> rays, std::span<Hit<float>> hits) const {
        if (rays.empty()) return;
#if BVHKIT_RAY_AVX2
        if (streams_traces()) {
            stream<false>(
                rays,
                [&](const detail::StreamRay& s) {
                    hits[s.index] =
                        s.hit_group ? wide_hit(s.best, *s.hit_group, s.hit_lane) : Hit<float>{};
                },
                [&](std::size_t i) { hits[i] = closest_hit(rays[i], NoStats{}); });
            return;
        }
#endif
        for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest_hit(rays[i], NoStats{});
    }

    /// A wide walk's hit as a Hit: the group holds the triangle's index and a copy of its corners
    /// (the same normal as the binary walk's, from the line just tested).
    template <class Group>
    static Hit<float> wide_hit(const TriangleHit<float>& h, const Group& group, int lane) {
        return Hit<float>{h.t, group.slot[lane], h.u, h.v, group.triangle(lane).normal()};
    }

    /// Where a wide walk sends `ray`: to the binary walk (the wide walk does not serve it),
    /// nowhere (it misses the tree's bounds: no hit) or down the wide layout, with its slab
    /// constants in `k` (which also served the bounds test).
    enum class Route { Binary, Miss, Walk };
    Route route_wide(const Ray<float, 3>& ray, detail::SlabConstants& k) const {
        if (!wide_ray_usable(ray)) return Route::Binary;
        k = detail::SlabConstants(ray);
        return k.meets(binary_.bvh().nodes[0].bounds, ray.tmin, ray.tmax) ? Route::Walk
                                                                          : Route::Miss;
    }

#if BVHKIT_RAY_AVX2
    /// The rays through the eight-wide layout in a stream (query/ray_stream.hpp): finish(s) takes
    /// each walked ray; a ray the wide walk does not serve goes to alone(i) (the one-ray call,
    /// which walks the binary tree), one that misses the bounds is a miss without a walk.
    template <bool AnyHit, class Finish, class Alone>
    void stream(std::span<const Ray<float, 3>> rays, Finish&& finish, Alone&& alone) const {
        std::size_t next = 0;
        const auto start = [&](detail::StreamRay& s) {
            while (next < rays.size()) {
                const std::size_t i = next++;
                const Ray<float, 3>& ray = rays[i];
                const Route route = route_wide(ray, s.k);
                if (route == Route::Binary) {
                    alone(i);
                    continue;
                }
                s.index = i;
                s.ray = ray;
                if (route == Route::Miss) {
                    finish(s);  // no hit: stream8 cleared the slot's hit
                    continue;
                }
                s.prep = WatertightRay<float>(ray, WatertightRay<float>::KnownValid{});
                return true;
            }
            return false;
        };
        detail::StreamRay slots[detail::stream_width];
        detail::stream8<AnyHit>(wide8_, slots, start, finish);
    }

    // Closest hits in packets of one octant (query/ray_octant_stream.hpp), a run of
    // octant_stream_size rays at a time: every run (`every_run`), or those packet_run accepts,
    // the others as trace_one_way. The rays the wide walk does not take go one by one.
    void trace_in_packets(std::span<const Ray<float, 3>> rays, std::span<Hit<float>> hits,
                          bool every_run) const {
        // The streams are made at the first packet: a batch of a few rays, or of incoherent
        // ones, makes none.
        for (std::size_t b = 0; b < rays.size(); b += detail::octant_stream_size)
            if (every_run || packet_run(rays, b)) {
                trace_one_way(rays.first(b), hits.first(b));
                trace_packets_from(rays, hits, b, every_run);
                return;
            }
        trace_one_way(rays, hits);
    }

    /// Whether the run of rays from b walks as a packet when the batch path chooses: 8 rays or
    /// more (a batch's tail, or a batch of one, shares too little to pay) that coherent_rays
    /// accepts.
    bool packet_run(std::span<const Ray<float, 3>> rays, std::size_t b) const {
        const std::size_t n = detail::octant_stream_size;
        const std::size_t count = std::min(n, rays.size() - b);
        return count >= n / 4 &&
               coherent_rays(rays.subspan(b, count), binary_.bvh().nodes[0].bounds);
    }

    /// trace_in_packets from `first`, the start of a run that walks as a packet.
    void trace_packets_from(std::span<const Ray<float, 3>> rays, std::span<Hit<float>> hits,
                            std::size_t first, bool every_run) const {
        const auto done = [&](const detail::OctantStream& s, int r, bool found) {
            hits[s.index[r]] =
                found ? wide_hit(s.best[r], *s.hit_group[r], s.hit_lane[r]) : Hit<float>{};
        };
        detail::OctantStreams<false> streams;
        detail::EightRayConstants eight;
        const Aabb<float, 3>& bounds = binary_.bvh().nodes[0].bounds;
        const std::size_t n = detail::octant_stream_size;
        std::size_t rest = first;  // the first ray neither in a packet nor traced
        for (std::size_t b = first; b < rays.size(); b += n) {
            if (b != first && !every_run && !packet_run(rays, b)) continue;
            trace_one_way(rays.subspan(rest, b - rest), hits.subspan(rest, b - rest));
            const std::size_t count = std::min(n, rays.size() - b);
            rest = b + count;
            // route_wide's routes and the walk's constants, eight rays at a time.
            for (std::size_t i = b; i < b + count; i += 8) {
                const int m = int(std::min<std::size_t>(8, b + count - i));
                detail::make_eight_ray_constants(rays.data() + i, m, bounds, eight);
                streams.add_eight(wide8_, eight, i, done);
                for (unsigned other = ~eight.walk & ((1u << m) - 1); other; other &= other - 1) {
                    const int r = __builtin_ctz(other);
                    const bool usable = (eight.usable >> r) & 1u;  // else the binary walk's
                    hits[i + r] = usable ? Hit<float>{} : binary_.closest_hit(rays[i + r]);
                }
            }
        }
        trace_one_way(rays.subspan(rest), hits.subspan(rest));
        streams.finish(wide8_, done);
    }

    // Occlusion rays in octant streams (query/ray_octant_stream.hpp); those the wide walk does not
    // take go one by one.
    void occlude_in_octants(std::span<const Ray<float, 3>> rays,
                            std::span<std::uint8_t> occluded) const {
        const auto blocked = [&](const detail::OctantStream& s, int r, bool b) {
            occluded[s.index[r]] = b ? 1 : 0;
        };
        detail::OctantStreams<true> streams;
        detail::EightRayConstants eight;
        const Aabb<float, 3>& bounds = binary_.bvh().nodes[0].bounds;
        for (std::size_t i = 0; i < rays.size(); i += 8) {
            const int m = int(std::min<std::size_t>(8, rays.size() - i));
            detail::make_eight_ray_constants(rays.data() + i, m, bounds, eight);
            streams.add_eight(wide8_, eight, i, blocked);
            for (unsigned other = ~eight.walk & ((1u << m) - 1); other; other &= other - 1) {
                const int r = __builtin_ctz(other);
                const bool usable = (eight.usable >> r) & 1u;  // else the binary walk's
                occluded[i + r] = !usable && binary_.any_hit(rays[i + r]) ? 1 : 0;
            }
        }
        streams.finish(wide8_, blocked);
    }
#endif

    TriangleRays<float> binary_;
    WideRayView<4> wide4_;
    WideRayView<8> wide8_;
    RayBatchPath path_ = RayBatchPath::Auto;
};
#endif

}  // namespace bvhkit
