// libFuzzer target: read_stl on arbitrary bytes.
#include "bvhkit/io/stl.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return bvhkit::fuzz::check_reader(data, size, "fuzz.stl",
                                      [](std::string_view bytes, std::string_view name) {
                                          return bvhkit::read_stl(bytes, name);
                                      });
}
