#include <cstdio>

#include "bvhkit/version.hpp"
#include "commands.hpp"

namespace bvhkit::tools {

int version_command(int, char**) {
    std::printf("bvhkit %s\n", bvhkit::version_string);
    return 0;
}

}  // namespace bvhkit::tools
