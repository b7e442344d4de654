// libFuzzer target: the TriangleBvh loader on arbitrary bytes, as they come and again with the
// checksum recomputed (random bytes almost never carry a valid checksum, and the checks behind it
// are the ones worth fuzzing). A load may throw bvhkit::Error; a tree it accepts, with or without
// validate(), must answer rays with indices in range (ASan and UBSan watch the traversal).
#include <cstdlib>
#include <span>
#include <vector>

#include "bvhkit/io/triangle_bvh_file.hpp"

namespace {

template <class T>
void load_and_query(std::span<const std::uint8_t> bytes) {
    for (const bool validate : {true, false}) {
        try {
            const bvhkit::TriangleBvh<T> tree =
                bvhkit::triangle_bvh_from_bytes<T>(bytes, bvhkit::LoadOptions{validate});
            const bvhkit::Vec<T, 3> origins[] = {{T(-2), T(0.1), T(0.2)}, {T(0.3), T(0.2), T(0.1)}};
            const bvhkit::Vec<T, 3> directions[] = {{T(1), T(0), T(0)}, {T(0.1), T(-1), T(0.3)}};
            for (const auto& o : origins)
                for (const auto& d : directions) {
                    const bvhkit::Ray<T, 3> ray(o, d);
                    const bvhkit::Hit<T> hit = tree.closest_hit(ray);
                    if (hit && hit.primitive >= tree.triangle_count()) std::abort();
                    (void)tree.any_hit(ray);
                    tree.all_hits(ray, [&](const bvhkit::Hit<T>& h) {
                        if (h.primitive >= tree.triangle_count()) std::abort();
                        return true;
                    });
                }
            for (const std::uint32_t s : tree.skipped())
                if (s >= tree.triangle_count()) std::abort();
        } catch (const bvhkit::Error&) {
            // Rejected cleanly.
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> raw(data, size);
    load_and_query<float>(raw);
    std::vector<std::uint8_t> resealed(raw.begin(), raw.end());
    bvhkit::serial_detail::reseal_tree_file(resealed);
    // Byte 16 is the scalar type: load as the file says, so the fuzzer gets past that check.
    if (size > 16 && data[16] == 2)
        load_and_query<double>(resealed);
    else
        load_and_query<float>(resealed);
    return 0;
}
