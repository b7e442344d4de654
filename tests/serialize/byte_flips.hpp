#pragma once
// The random corruption the file tests apply: a copy of a saved file with one to four bytes
// changed.
#include <cstdint>
#include <vector>

#include "bvhkit/math/random.hpp"

namespace bvhkit::test {

/// `file` with 1 to 4 bytes xor-ed with a non-zero value (two flips may cancel: compare the copy
/// with `file` before counting it as corrupted).
inline std::vector<std::uint8_t> with_byte_flips(const std::vector<std::uint8_t>& file,
                                                 SplitMix64& rng) {
    std::vector<std::uint8_t> bad = file;
    const std::uint32_t flips = 1 + rng.below(4);
    for (std::uint32_t f = 0; f < flips; ++f)
        bad[rng.below(std::uint32_t(bad.size()))] ^= std::uint8_t(1 + rng.below(255));
    return bad;
}

}  // namespace bvhkit::test
