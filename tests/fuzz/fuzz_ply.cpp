// libFuzzer target: read_ply on arbitrary bytes.
#include "bvhkit/io/ply.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return bvhkit::fuzz::check_reader(data, size, "fuzz.ply",
                                      [](std::string_view bytes, std::string_view name) {
                                          return bvhkit::read_ply(bytes, name);
                                      });
}
