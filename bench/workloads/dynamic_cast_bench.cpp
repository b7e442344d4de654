// D4: closest-hit ray casts on a 2D dynamic tree (D1's boxes at their start positions), long rays
// across the world and short ones, against Box2D 2.4.1's b2DynamicTree::RayCast in the same
// process. Both libraries get the same callback work: the entry fraction of the ray into the
// proxy's tight box by one shared slab test, returned to clip the ray (closest hit).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "dynamic_bench.hpp"
#include "dynamic_motion.hpp"

#ifdef BVHKIT_HAVE_BOX2D
#include <box2d/b2_dynamic_tree.h>
#endif

namespace bvhkit::bench {
namespace {

using namespace dynamic_workload;

struct CastRay {
    float o[2], d[2];  // the segment o + s d, s in [0, 1]
};

/// Entry fraction of the segment into the unit box at `lo` (0 when o is inside), or -1 on a miss
/// or beyond max_fraction.
inline float tight_entry(const float* lo, const CastRay& r, float max_fraction) {
    float t0 = 0, t1 = max_fraction;
    for (int a = 0; a < 2; ++a) {
        const float inv = 1.0f / r.d[a];
        float n = (lo[a] - r.o[a]) * inv, f = (lo[a] + 1.0f - r.o[a]) * inv;
        if (n > f) std::swap(n, f);
        t0 = std::max(t0, n);
        t1 = std::min(t1, f);
    }
    return t0 <= t1 ? t0 : -1.0f;
}

std::vector<CastRay> make_rays(const Motion& m, int count, float length, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> pos(0.0f, m.side), angle(0.0f, 6.2831853f);
    std::vector<CastRay> rays(static_cast<std::size_t>(count));
    for (auto& r : rays) {
        const float a = angle(rng);
        r = {{pos(rng), pos(rng)}, {length * std::cos(a), length * std::sin(a)}};
    }
    return rays;
}

struct CastResult {
    std::vector<float> fraction;  // the closest hit's fraction per ray, 2 (no hit) past the end
    double nodes_per_ray = 0;
};

CastResult cast_bvhkit(const DynamicTree<float, 2>& tree, const Motion& m,
                       const std::vector<CastRay>& rays, bool count_nodes) {
    CastResult r;
    r.fraction.resize(rays.size());
    QueryStats stats;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const CastRay& ray = rays[i];
        float best = 2.0f;
        tree.ray_cast(
            Vec2f{ray.o[0], ray.o[1]}, Vec2f{ray.d[0], ray.d[1]}, 1.0f,
            [&](ProxyId id, float max_fraction) {
                const float f =
                    tight_entry(&m.start[std::size_t(id.index()) * 3], ray, max_fraction);
                if (f >= 0) best = std::min(best, f);
                return f;
            },
            count_nodes ? &stats : nullptr);
        r.fraction[i] = best;
    }
    r.nodes_per_ray = double(stats.nodes_visited) / double(std::max<std::size_t>(1, rays.size()));
    return r;
}

#ifdef BVHKIT_HAVE_BOX2D
struct Box2dCaster {
    const Motion* m;
    const CastRay* ray;
    float best;
    float RayCastCallback(const b2RayCastInput& input, int32 proxy) {
        const float f = tight_entry(&m->start[std::size_t(proxy_index[std::size_t(proxy)]) * 3],
                                    *ray, input.maxFraction);
        if (f >= 0) best = std::min(best, f);
        return f;
    }
    std::vector<std::int32_t> proxy_index;  // Box2D's proxy id -> the box's index
};

CastResult cast_box2d(const b2DynamicTree& tree, Box2dCaster& caster,
                      const std::vector<CastRay>& rays) {
    CastResult r;
    r.fraction.resize(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const CastRay& ray = rays[i];
        caster.ray = &ray;
        caster.best = 2.0f;
        b2RayCastInput in;
        in.p1.Set(ray.o[0], ray.o[1]);
        in.p2.Set(ray.o[0] + ray.d[0], ray.o[1] + ray.d[1]);
        in.maxFraction = 1.0f;
        tree.RayCast(&caster, in);
        r.fraction[i] = caster.best;
    }
    return r;
}
#endif

}  // namespace

void dynamic_ray_casts(const DynamicBenchConfig& c, std::FILE* log, std::vector<Row>& rows) {
    const Motion m = make_motion(c.n, 2, 1, 1001);
    const int count = 20000;
    std::fprintf(log, "D4: %d boxes, %d long (world-wide) and %d short (10-unit) rays each\n", c.n,
                 count, count);
    DynamicTreeOptions<float> o;
    o.margin_absolute = 0.1f;  // Box2D 2.4.1's b2_aabbExtension
    DynamicTree<float, 2> tree(o);
    for (int i = 0; i < m.n; ++i) {
        const Vec2f lo{m.start[std::size_t(i) * 3], m.start[std::size_t(i) * 3 + 1]};
        tree.create(Aabb2f(lo, lo + Vec2f(1.0f)), std::uint64_t(i));
    }
#ifdef BVHKIT_HAVE_BOX2D
    b2DynamicTree box2d;
    Box2dCaster caster{&m, nullptr, 0, {}};
    for (int i = 0; i < m.n; ++i) {
        b2AABB b;
        b.lowerBound.Set(m.start[std::size_t(i) * 3], m.start[std::size_t(i) * 3 + 1]);
        b.upperBound.Set(b.lowerBound.x + 1.0f, b.lowerBound.y + 1.0f);
        const int32 id = box2d.CreateProxy(b, nullptr);
        if (std::size_t(id) >= caster.proxy_index.size())
            caster.proxy_index.resize(std::size_t(id) + 1, -1);
        caster.proxy_index[std::size_t(id)] = i;
    }
#endif
    for (const auto& [name, length] :
         {std::pair{"D4-long", m.side}, std::pair{"D4-short", 10.0f}}) {
        const auto rays = make_rays(m, count, length, name[3] == 'l' ? 41 : 42);
        const CastResult ours = cast_bvhkit(tree, m, rays, true);
        CastResult theirs_result;
        std::vector<std::function<void()>> runs{[&] { cast_bvhkit(tree, m, rays, false); }};
#ifdef BVHKIT_HAVE_BOX2D
        runs.push_back([&] { theirs_result = cast_box2d(box2d, caster, rays); });
#endif
        const std::vector<double> ms = median_ms_interleaved(c.reps, runs);
        Row row;
        row.set("workload", std::string(name)).set("library", std::string("bvhkit"));
        row.set("step_ms", ms[0]).set("speedup", std::string("-"));
        row.set("pairs", (long long)std::count_if(ours.fraction.begin(), ours.fraction.end(),
                                                  [](float f) { return f <= 1.0f; }));
        row.set("nodes_per_ray", ours.nodes_per_ray);
        rows.push_back(row);
#ifdef BVHKIT_HAVE_BOX2D
        Row peer;
        peer.set("workload", std::string(name)).set("library", std::string("box2d-2.4.1"));
        peer.set("step_ms", ms[1]).set("speedup", ms[1] / ms[0]);
        peer.set("agree", std::string(theirs_result.fraction == ours.fraction ? "yes" : "NO"));
        rows.push_back(peer);
#else
        std::fprintf(log, "%s: Box2D not built in (libbox2d-dev missing); skipped\n", name);
#endif
    }
}

}  // namespace bvhkit::bench
