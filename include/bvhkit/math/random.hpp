#pragma once
// A small deterministic random source (SplitMix64, Steele, Lea and Flood 2014, "Fast splittable
// pseudorandom number generators"): the same seed gives the same numbers on every machine and
// standard library, which the benchmark workloads and generators need.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "bvhkit/math/vec.hpp"

namespace bvhkit {

class SplitMix64 {
  public:
    explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1) with 53 random bits.
    double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    /// Uniform in [0, n), by multiplying the top 32 bits (Lemire 2019, without the rejection step:
    /// the bias is below 2^-32 per value for the small n used here).
    std::uint32_t below(std::uint32_t n) {
        return static_cast<std::uint32_t>((next() >> 32) * n >> 32);
    }

    /// Uniform on the unit sphere: z uniform in [-1, 1], the angle uniform (Archimedes' hat-box
    /// theorem makes that uniform in area).
    Vec3d unit_vector() {
        const double z = uniform(-1.0, 1.0);
        const double a = uniform(0.0, 6.283185307179586);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {r * std::cos(a), r * std::sin(a), z};
    }

  private:
    std::uint64_t state_;
};

}  // namespace bvhkit
