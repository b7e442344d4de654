#pragma once
// Deterministic procedural meshes for tests and benchmarks: the same arguments and seed give the
// same mesh on every run (the generator uses its own RNG; coordinates that pass through
// std::sin/std::cos may differ in the last bit between C libraries).
//
// make_procedural parses a spec "kind[:key=value,...]":
//   sphere  subdiv=5 (0..10, 20*4^subdiv triangles) or freq=F (20*F^2 triangles), displacement=0
//           (0 <= d < 1, radial bumps), seed=1
//   torus   u=96, v=48 (segments around the ring and the tube, 2*u*v triangles), major=1, minor=0.3
//   terrain n=256 (n x n grid, 2*n^2 triangles), seed=1
//   room    objects=50 (boxes and spheres inside a closed room), seed=1
//   soup    n=100000 (unconnected random triangles in the unit cube), seed=1
// e.g. "sphere", "sphere:subdiv=6,seed=3", "terrain:n=512", "room:objects=200",
// "soup:n=100000,seed=7". An unknown kind or key, a bad value or a mesh above
// max_procedural_triangles is a bvhkit::Error.
#include <cstdint>
#include <string>
#include <string_view>

#include "bvhkit/error.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit {

/// The largest mesh a spec may ask for (about 400 MB of vertices and indices at most).
inline constexpr std::uint64_t max_procedural_triangles = std::uint64_t(1) << 25;

/// A unit sphere from an icosahedron whose faces are split into 4^subdivisions triangles
/// (20 * 4^s triangles, 10 * 4^s + 2 vertices), displaced radially by up to `displacement`
/// (smooth bumps, 0 <= displacement < 1). Closed, triangles counter-clockwise seen from outside.
TriangleMesh make_sphere(std::uint32_t subdivisions, float displacement = 0.0f,
                         std::uint64_t seed = 1);
/// The same sphere with each icosahedron edge split into `frequency` parts (20 * frequency^2
/// triangles), for sizes between the powers of 4.
TriangleMesh make_geodesic_sphere(std::uint32_t frequency, float displacement = 0.0f,
                                  std::uint64_t seed = 1);
/// A torus around the z axis: `u` segments along the ring, `v` around the tube (both >= 3).
/// Closed, counter-clockwise seen from outside.
TriangleMesh make_torus(std::uint32_t u = 96, std::uint32_t v = 48, float major_radius = 1.0f,
                        float minor_radius = 0.3f);
/// A height field over [0,1] x [0,1] in x and z, heights (y) in about [0, 0.25], from fractal value
/// noise; an open surface of 2 * grid_n^2 triangles facing +y.
TriangleMesh make_terrain(std::uint32_t grid_n, std::uint64_t seed = 1);
/// A closed room [0,10] x [0,4] x [0,10] (walls facing inwards) holding `object_count` random boxes
/// and spheres (closed, facing outwards; they may overlap each other).
TriangleMesh make_room(std::uint32_t object_count, std::uint64_t seed = 1);
/// `triangle_count` unconnected triangles in the unit cube, sizes spread from 0.001 to 0.1.
TriangleMesh make_soup(std::uint64_t triangle_count, std::uint64_t seed = 1);

/// A city-like scene over [-15, 75 blocks + 15] in x and z, y up: a ground plane of two
/// triangles, `blocks` x `blocks` blocks of 60 m (plinths between 15 m streets) holding towers of
/// log-normal heights (4 to 400 m, some with setbacks), their walls cut into floors and bays of
/// 1.5 m or 6 m. Triangle sizes range over four orders of magnitude. Towers and plinths have no
/// bottom (they stand on the ground): an open surface facing outwards.
TriangleMesh make_city(std::uint32_t blocks, std::uint64_t seed = 1);

/// Generates the mesh a spec describes (see above).
TriangleMesh make_procedural(std::string_view spec);
/// True when the spec's kind (the text before any ':') is a generator's name.
bool is_procedural_kind(std::string_view spec);
/// One line per kind with its keys and defaults, for help texts and error messages.
std::string procedural_spec_help();

}  // namespace bvhkit
