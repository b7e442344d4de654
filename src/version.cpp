#include "bvhkit/version.hpp"

namespace bvhkit {
// Anchors the version in the compiled library so a consumer can check what it linked.
const char* linked_version() {
    return version_string;
}
}  // namespace bvhkit
