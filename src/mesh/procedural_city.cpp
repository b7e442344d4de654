// A city-like scene: what scanned meshes are not. A ground plane of two huge triangles, blocks of
// low plinths between streets, and on them towers whose heights follow a heavy-tailed law (most
// low, a few tall), some with setbacks, their facades cut into a grid of floors and bays. So the
// triangles range over four orders of magnitude in size, most of the surface is axis-aligned and
// coplanar in large groups, and the empty space between towers is wide: the kind of scene where
// a tree tuned on scans places its leaves badly.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"

namespace bvhkit {

namespace {

/// A quad (a, b, c, d, counter-clockwise seen from its front) cut into `along` x `up` cells.
void append_grid_quad(TriangleMesh& mesh, const Vec3d& a, const Vec3d& b, const Vec3d& d,
                      std::uint32_t along, std::uint32_t up) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (std::uint32_t j = 0; j <= up; ++j)
        for (std::uint32_t i = 0; i <= along; ++i)
            mesh.vertices.push_back(
                Vec3f(a + (b - a) * (double(i) / along) + (d - a) * (double(j) / up)));
    const auto id = [&](std::uint32_t i, std::uint32_t j) { return base + j * (along + 1) + i; };
    for (std::uint32_t j = 0; j < up; ++j)
        for (std::uint32_t i = 0; i < along; ++i) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
}

/// An axis-aligned box from y = lo[1] to hi[1] without its bottom: four walls of `bays` cells
/// along each metre-ish of width and one cell a floor of `floor` height, and a flat roof.
void append_tower(TriangleMesh& mesh, const Vec3d& lo, const Vec3d& hi, double bay, double floor) {
    const auto cells = [](double length, double cell) {
        return std::max<std::uint32_t>(1, std::uint32_t(std::lround(length / cell)));
    };
    const std::uint32_t floors = cells(hi[1] - lo[1], floor);
    const std::uint32_t bays_x = cells(hi[0] - lo[0], bay), bays_z = cells(hi[2] - lo[2], bay);
    const double y0 = lo[1], y1 = hi[1];
    const Vec3d up{0, y1 - y0, 0};
    // Walls, counter-clockwise seen from outside (y up, x right, z towards the viewer).
    const Vec3d p00{lo[0], y0, lo[2]}, p10{hi[0], y0, lo[2]}, p11{hi[0], y0, hi[2]},
        p01{lo[0], y0, hi[2]};
    append_grid_quad(mesh, p01, p11, p01 + up, bays_x, floors);  // +z
    append_grid_quad(mesh, p11, p10, p11 + up, bays_z, floors);  // +x
    append_grid_quad(mesh, p10, p00, p10 + up, bays_x, floors);  // -z
    append_grid_quad(mesh, p00, p01, p00 + up, bays_z, floors);  // -x
    append_grid_quad(mesh, p01 + up, p11 + up, p00 + up, 1, 1);  // roof, facing +y
}

}  // namespace

TriangleMesh make_city(std::uint32_t blocks, std::uint64_t seed) {
    if (blocks < 1) throw Error("a city needs at least 1 block a side");
    constexpr double block = 60.0, street = 15.0, pitch = block + street;
    TriangleMesh mesh;
    SplitMix64 rng(seed);
    const double extent = blocks * pitch + street;
    // The ground: two triangles under everything, far wider than a facade's cell.
    const Vec3d g0{-street, 0, -street}, g1{extent, 0, -street}, g2{extent, 0, extent},
        g3{-street, 0, extent};
    append_grid_quad(mesh, g3, g2, g0, 1, 1);
    for (std::uint32_t bi = 0; bi < blocks; ++bi)
        for (std::uint32_t bj = 0; bj < blocks; ++bj) {
            const Vec3d corner{bi * pitch, 0, bj * pitch};
            // The plinth: a low slab over the whole block.
            const double plinth = rng.uniform(0.2, 1.0);
            append_tower(mesh, corner, corner + Vec3d{block, plinth, block}, block, plinth);
            // Towers on a grid of lots, some lots left empty.
            const auto lots = std::uint32_t(2 + rng.below(3));  // 2..4 a side
            const double lot = block / lots;
            for (std::uint32_t li = 0; li < lots; ++li)
                for (std::uint32_t lj = 0; lj < lots; ++lj) {
                    if (rng.below(5) == 0) continue;
                    const double w = lot * rng.uniform(0.45, 0.9), d = lot * rng.uniform(0.45, 0.9);
                    const Vec3d c = corner + Vec3d{(li + 0.5) * lot, plinth, (lj + 0.5) * lot};
                    // Heights: log-normal around 20 m with a long tail, clipped at 400 m.
                    const double normal = std::sqrt(-2 * std::log(1 - rng.uniform())) *
                                          std::cos(2 * 3.141592653589793 * rng.uniform());
                    double height = std::clamp(20.0 * std::exp(0.8 * normal), 4.0, 400.0);
                    // Facades of coarse or fine detail, as models from different sources have.
                    const double bay = rng.below(3) == 0 ? 1.5 : 6.0, floor = 3.5;
                    Vec3d half{w / 2, 0, d / 2};
                    double base = c[1];
                    // Tall towers step back once or twice.
                    const int steps = height > 60 ? 1 + int(rng.below(2)) : 0;
                    for (int s = 0; s <= steps; ++s) {
                        const double part = s == steps ? height : height * rng.uniform(0.3, 0.6);
                        append_tower(mesh, Vec3d{c[0] - half[0], base, c[2] - half[2]},
                                     Vec3d{c[0] + half[0], base + part, c[2] + half[2]}, bay,
                                     floor);
                        base += part;
                        height -= part;
                        half = half * rng.uniform(0.6, 0.85);
                    }
                }
        }
    return mesh;
}

}  // namespace bvhkit
