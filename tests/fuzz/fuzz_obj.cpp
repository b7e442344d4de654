// libFuzzer target: read_obj on arbitrary bytes.
#include "bvhkit/io/obj.hpp"
#include "fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return bvhkit::fuzz::check_reader(data, size, "fuzz.obj",
                                      [](std::string_view bytes, std::string_view name) {
                                          return bvhkit::read_obj(bytes, name);
                                      });
}
