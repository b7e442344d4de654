#pragma once
// What the dynamic-tree workloads share: the generated motion of a crowd, the tight boxes that the
// peers' fat pairs are filtered by, and a run's result. Internal to bench/workloads.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace bvhkit::bench::dynamic_workload {

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// The motion of a crowd: unit boxes [p, p + 1] in a cube of side `side`, each step each box moves
/// by its velocity with probability 0.1, bouncing at the walls.
struct Motion {
    int n = 0, dim = 0;
    float side = 0;
    std::vector<float> start;  // n * 3, min corners (unused axes 0)
    struct Move {
        std::int32_t id;
        float p[3];  // new min corner
        float v[3];  // displacement of this move
    };
    std::vector<std::vector<Move>> steps;
};

inline Motion make_motion(int n, int dim, int steps, std::uint64_t seed) {
    Motion m;
    m.n = n;
    m.dim = dim;
    m.side = float(3.0 * std::pow(double(n), 1.0 / dim));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> pos(0.0f, m.side - 1.0f), vel(-0.5f, 0.5f), u(0.0f, 1.0f);
    m.start.assign(std::size_t(n) * 3, 0.0f);
    std::vector<float> v(std::size_t(n) * 3, 0.0f);
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < dim; ++a) m.start[i * 3 + a] = pos(rng), v[i * 3 + a] = vel(rng);
    std::vector<float> p = m.start;
    m.steps.resize(steps);
    for (int s = 0; s < steps; ++s) {
        for (int i = 0; i < n; ++i) {
            if (u(rng) >= 0.1f) continue;
            Motion::Move mv{i, {0, 0, 0}, {0, 0, 0}};
            for (int a = 0; a < dim; ++a) {
                float& x = p[i * 3 + a];
                float& vx = v[i * 3 + a];
                float nx = x + vx;
                if (nx < 0) nx = -nx, vx = -vx;
                if (nx > m.side - 1) nx = 2 * (m.side - 1) - nx, vx = -vx;
                mv.v[a] = nx - x;
                x = nx;
                mv.p[a] = nx;
            }
            m.steps[s].push_back(mv);
        }
    }
    return m;
}

/// The tight boxes of every step, to filter the peers' (fat) pairs: positions after each step.
struct Tight {
    std::vector<float> p;
    explicit Tight(const Motion& m) : p(m.start) {}
    void apply(const std::vector<Motion::Move>& moves) {
        for (const auto& mv : moves)
            for (int a = 0; a < 3; ++a) p[mv.id * 3 + a] = mv.p[a];
    }
    bool overlap(int a, int b, int dim) const {
        for (int k = 0; k < dim; ++k)
            if (std::fabs(p[a * 3 + k] - p[b * 3 + k]) > 1.0f) return false;
        return true;
    }
};

/// A step's pairs summarised: the count and an order-independent hash of the set.
struct PairSummary {
    long long count = 0;
    std::uint64_t hash = 0;
    void add(std::uint32_t a, std::uint32_t b) {
        if (a > b) std::swap(a, b);
        std::uint64_t h = (std::uint64_t(a) << 32 | b) * 0x9E3779B97F4A7C15ull;
        h ^= h >> 29;
        hash += h * 0xBF58476D1CE4E5B9ull;
        ++count;
    }
    bool operator==(const PairSummary&) const = default;
};

struct RunResult {
    double build_ms = 0, step_ms = 0;
    double move_ms = 0;         // the part of step_ms spent moving proxies (the rest finds pairs)
    bool tree_measured = true;  // height, sah and ratio were measured
    long long reported = -1;    // D1-own: events / pairs the library reported (-1: use per_step)
    std::vector<PairSummary> per_step;  // the first entry is the build's pair pass
    int height = 0;
    double sah = 0, ratio = 0;
    long long touched = 0;
};

/// D1 in Box2D's own semantics (dynamic_events_bench.cpp): bvhkit reports pair begin and end events
/// of the tight boxes (update_pairs); Box2D reports the fat-box pairs of its re-inserted proxies.
RunResult run_bvhkit_events(const Motion& m);
#ifdef BVHKIT_HAVE_BOX2D
RunResult run_box2d_own(const Motion& m);
#endif

}  // namespace bvhkit::bench::dynamic_workload
