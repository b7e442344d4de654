#pragma once
// A small deterministic random source (SplitMix64, Steele, Lea and Flood 2014, "Fast splittable
// pseudorandom number generators"): the same seed gives the same numbers on every machine and
// standard library, which the benchmark workloads and generators need.
#include <cstdint>

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

  private:
    std::uint64_t state_;
};

}  // namespace bvhkit
