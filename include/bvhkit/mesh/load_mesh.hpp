#pragma once
// load_mesh: what command-line tools and benchmarks call with a user's mesh argument. An existing
// file is read (read_mesh: .obj, .ply, .stl); otherwise a generator spec ("sphere:subdiv=6") is
// generated (make_procedural); anything else is a bvhkit::Error saying it is neither.
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

TriangleMesh load_mesh(std::string_view file_or_spec);

}  // namespace bvhkit
