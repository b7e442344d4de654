#include "bvhkit/mesh/procedural.hpp"

#include "bvhkit/math/random.hpp"

#include <cmath>
#include <numbers>
#include <vector>

namespace bvhkit {

namespace {

using Rng = SplitMix64;  // deterministic on every machine (math/random.hpp)

Vec3f to_float(const Vec3d& v) {
    return Vec3f(v);
}

void check_size(std::uint64_t triangles, const char* what) {
    if (triangles > max_procedural_triangles)
        throw Error(std::string(what) + " would have " + std::to_string(triangles) +
                    " triangles, more than the limit of " +
                    std::to_string(max_procedural_triangles));
}

// --- Geodesic sphere -------------------------------------------------------------------------

struct Icosahedron {
    Vec3d corners[12];
    std::array<int, 3> faces[20];
    int edge_id[12][12];  // -1 where two corners share no edge
    std::array<int, 2> edges[30];
};

Icosahedron make_icosahedron() {
    Icosahedron ico;
    const double phi = std::numbers::phi;
    int n = 0;
    // The 12 cyclic permutations of (0, +-1, +-phi).
    for (int s1 : {-1, 1})
        for (int s2 : {-1, 1}) {
            ico.corners[n++] = {0.0, s1 * 1.0, s2 * phi};
            ico.corners[n++] = {s1 * 1.0, s2 * phi, 0.0};
            ico.corners[n++] = {s2 * phi, 0.0, s1 * 1.0};
        }
    // Edges join corners at distance 2; faces are triples of mutually adjacent corners, wound so
    // that their normal points away from the centre.
    auto adjacent = [&](int a, int b) {
        return std::abs(length_squared(ico.corners[a] - ico.corners[b]) - 4.0) < 1e-9;
    };
    int edge_count = 0;
    for (int a = 0; a < 12; ++a)
        for (int b = 0; b < 12; ++b) ico.edge_id[a][b] = -1;
    for (int a = 0; a < 12; ++a)
        for (int b = a + 1; b < 12; ++b)
            if (adjacent(a, b)) {
                ico.edges[edge_count] = {a, b};
                ico.edge_id[a][b] = ico.edge_id[b][a] = edge_count++;
            }
    int face_count = 0;
    for (int a = 0; a < 12; ++a)
        for (int b = a + 1; b < 12; ++b)
            for (int c = b + 1; c < 12; ++c)
                if (adjacent(a, b) && adjacent(b, c) && adjacent(a, c)) {
                    const Vec3d& pa = ico.corners[a];
                    const Vec3d normal = cross(ico.corners[b] - pa, ico.corners[c] - pa);
                    ico.faces[face_count++] =
                        dot(normal, pa) > 0 ? std::array{a, b, c} : std::array{a, c, b};
                }
    return ico;
}

// Smooth radial bumps: a normalised sum of plane waves with random directions, frequencies and
// phases, in [-1, 1].
class Bumps {
  public:
    Bumps(std::uint64_t seed) {
        Rng rng(seed);
        double total = 0;
        for (Wave& w : waves_) {
            w.direction = rng.unit_vector();
            w.frequency = rng.uniform(1.5, 9.0);
            w.phase = rng.uniform(0.0, 2.0 * std::numbers::pi);
            w.amplitude = 1.0 / w.frequency;
            total += w.amplitude;
        }
        for (Wave& w : waves_) w.amplitude /= total;
    }
    double operator()(const Vec3d& p) const {
        double sum = 0;
        for (const Wave& w : waves_)
            sum += w.amplitude * std::sin(w.frequency * dot(w.direction, p) + w.phase);
        return sum;
    }

  private:
    struct Wave {
        Vec3d direction;
        double frequency, phase, amplitude;
    };
    Wave waves_[8];
};

}  // namespace

namespace {

// Vertex numbering of the geodesic sphere without a lookup table: the 12 corners, then f-1 points
// per edge (counted from the edge's lower-numbered corner), then (f-1)(f-2)/2 points inside each
// face. Lattice point (i, j) of a face (A, B, C) is A + i/f (B - A) + j/f (C - A).
struct GeodesicNumbering {
    const Icosahedron& ico;
    std::uint64_t f;
    std::uint64_t edge_base = 12;
    std::uint64_t face_base = edge_base + 30 * (f - 1);
    std::uint64_t per_face = (f - 1) * (f - 2) / 2;
    std::uint64_t vertex_count = face_base + 20 * per_face;

    std::uint64_t on_edge_id(std::uint64_t e, std::uint64_t t) const {
        return edge_base + e * (f - 1) + (t - 1);
    }
    std::uint64_t interior(std::uint64_t face, std::uint64_t i, std::uint64_t j) const {
        const std::uint64_t row_start = (i - 1) * (f - 1) - (i - 1) * i / 2;
        return face_base + face * per_face + row_start + (j - 1);
    }
    std::uint64_t on_edge(int from, int to, std::uint64_t steps_from_first) const {
        const int e = ico.edge_id[from][to];
        const std::uint64_t t = from < to ? steps_from_first : f - steps_from_first;
        return on_edge_id(static_cast<std::uint64_t>(e), t);
    }
    std::uint32_t lattice(int face, std::uint64_t i, std::uint64_t j) const {
        const auto [a, b, c] = ico.faces[face];
        std::uint64_t id;
        if (i == 0 && j == 0) {
            id = static_cast<std::uint64_t>(a);
        } else if (i == f) {
            id = static_cast<std::uint64_t>(b);
        } else if (j == f) {
            id = static_cast<std::uint64_t>(c);
        } else if (j == 0) {
            id = on_edge(a, b, i);
        } else if (i == 0) {
            id = on_edge(a, c, j);
        } else if (i + j == f) {
            id = on_edge(b, c, j);
        } else {
            id = interior(static_cast<std::uint64_t>(face), i, j);
        }
        return static_cast<std::uint32_t>(id);
    }
};

/// Every vertex, projected to the unit sphere and pushed out by the bumps. Radial displacement
/// keeps the surface star-shaped about the centre (radius stays positive), so it stays closed, free
/// of self-intersections and outward-facing.
void place_geodesic_vertices(TriangleMesh& mesh, const GeodesicNumbering& n, float displacement,
                             std::uint64_t seed) {
    const Icosahedron& ico = n.ico;
    const std::uint64_t f = n.f;
    mesh.vertices.resize(n.vertex_count);
    const Bumps bumps(seed);
    auto place = [&](std::uint64_t id, const Vec3d& on_plane) {
        const Vec3d unit = normalize(on_plane);
        const double radius = displacement > 0.0f ? 1.0 + displacement * bumps(unit) : 1.0;
        mesh.vertices[id] = to_float(unit * radius);
    };
    for (int c = 0; c < 12; ++c) place(static_cast<std::uint64_t>(c), ico.corners[c]);
    for (int e = 0; e < 30; ++e) {
        const Vec3d& a = ico.corners[ico.edges[e][0]];
        const Vec3d& b = ico.corners[ico.edges[e][1]];
        for (std::uint64_t t = 1; t < f; ++t)
            place(n.on_edge_id(static_cast<std::uint64_t>(e), t),
                  a + (b - a) * (static_cast<double>(t) / static_cast<double>(f)));
    }
    for (int face = 0; face < 20; ++face) {
        const auto [ia, ib, ic] = ico.faces[face];
        const Vec3d &a = ico.corners[ia], &b = ico.corners[ib], &c = ico.corners[ic];
        for (std::uint64_t i = 1; i + 1 < f; ++i)
            for (std::uint64_t j = 1; i + j < f; ++j) {
                const double u = static_cast<double>(i) / static_cast<double>(f);
                const double w = static_cast<double>(j) / static_cast<double>(f);
                place(n.interior(static_cast<std::uint64_t>(face), i, j),
                      a + (b - a) * u + (c - a) * w);
            }
    }
}

/// The f^2 small triangles of each face; both small triangles of a lattice cell keep the face's
/// winding (counter-clockwise from outside).
void add_geodesic_triangles(TriangleMesh& mesh, const GeodesicNumbering& n) {
    const std::uint64_t f = n.f;
    mesh.triangles.reserve(20 * f * f);
    for (int face = 0; face < 20; ++face)
        for (std::uint64_t i = 0; i < f; ++i)
            for (std::uint64_t j = 0; i + j < f; ++j) {
                mesh.triangles.push_back(
                    {n.lattice(face, i, j), n.lattice(face, i + 1, j), n.lattice(face, i, j + 1)});
                if (i + j + 2 <= f)
                    mesh.triangles.push_back({n.lattice(face, i + 1, j),
                                              n.lattice(face, i + 1, j + 1),
                                              n.lattice(face, i, j + 1)});
            }
}

}  // namespace

TriangleMesh make_geodesic_sphere(std::uint32_t frequency, float displacement, std::uint64_t seed) {
    if (frequency < 1) throw Error("sphere frequency must be at least 1");
    if (!(displacement >= 0.0f && displacement < 1.0f))
        throw Error("sphere displacement must be in [0, 1), got " + std::to_string(displacement));
    const std::uint64_t f = frequency;
    check_size(20 * f * f, "the sphere");
    const Icosahedron ico = make_icosahedron();
    const GeodesicNumbering numbering{ico, f};
    TriangleMesh mesh;
    place_geodesic_vertices(mesh, numbering, displacement, seed);
    add_geodesic_triangles(mesh, numbering);
    return mesh;
}

TriangleMesh make_sphere(std::uint32_t subdivisions, float displacement, std::uint64_t seed) {
    if (subdivisions > 10)
        throw Error("sphere subdivisions must be at most 10 (20 * 4^10 = 21M triangles), got " +
                    std::to_string(subdivisions));
    return make_geodesic_sphere(std::uint32_t(1) << subdivisions, displacement, seed);
}

TriangleMesh make_torus(std::uint32_t u, std::uint32_t v, float major_radius, float minor_radius) {
    if (u < 3 || v < 3) throw Error("torus needs at least 3 segments each way");
    if (!(minor_radius > 0.0f && minor_radius < major_radius))
        throw Error("torus radii must satisfy 0 < minor < major");
    check_size(2ull * u * v, "the torus");
    TriangleMesh mesh;
    mesh.vertices.reserve(std::size_t(u) * v);
    for (std::uint32_t i = 0; i < u; ++i) {
        const double theta = 2.0 * std::numbers::pi * i / u;
        for (std::uint32_t j = 0; j < v; ++j) {
            const double phi = 2.0 * std::numbers::pi * j / v;
            const double ring = major_radius + minor_radius * std::cos(phi);
            mesh.vertices.push_back(to_float(
                {ring * std::cos(theta), ring * std::sin(theta), minor_radius * std::sin(phi)}));
        }
    }
    auto id = [&](std::uint32_t i, std::uint32_t j) { return (i % u) * v + (j % v); };
    mesh.triangles.reserve(2 * std::size_t(u) * v);
    for (std::uint32_t i = 0; i < u; ++i)
        for (std::uint32_t j = 0; j < v; ++j) {
            // d(theta) x d(phi) points out of the tube, so (i,j) -> (i+1,j) -> (i+1,j+1) is
            // counter-clockwise seen from outside.
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return mesh;
}

namespace {

// Value noise: random values at integer lattice points (hashed from the seed), smoothly blended.
double lattice_value(std::int64_t x, std::int64_t y, std::uint64_t salt) {
    Rng rng(salt ^ (static_cast<std::uint64_t>(x) * 0x9e3779b97f4a7c15ull) ^
            (static_cast<std::uint64_t>(y) * 0xc2b2ae3d27d4eb4full));
    rng.next();
    return rng.uniform();
}

double value_noise(double x, double y, std::uint64_t salt) {
    const double fx = std::floor(x), fy = std::floor(y);
    const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
    auto smooth = [](double t) { return t * t * (3.0 - 2.0 * t); };
    const double tx = smooth(x - fx), ty = smooth(y - fy);
    const double a = lattice_value(ix, iy, salt), b = lattice_value(ix + 1, iy, salt);
    const double c = lattice_value(ix, iy + 1, salt), d = lattice_value(ix + 1, iy + 1, salt);
    return (a + (b - a) * tx) * (1.0 - ty) + (c + (d - c) * tx) * ty;
}

}  // namespace

TriangleMesh make_terrain(std::uint32_t grid_n, std::uint64_t seed) {
    if (grid_n < 1) throw Error("terrain grid must be at least 1");
    check_size(2ull * grid_n * grid_n, "the terrain");
    const std::uint32_t side = grid_n + 1;
    TriangleMesh mesh;
    mesh.vertices.reserve(std::size_t(side) * side);
    Rng salts(seed);
    std::uint64_t octave_salt[6];
    for (auto& s : octave_salt) s = salts.next();
    for (std::uint32_t i = 0; i < side; ++i)
        for (std::uint32_t j = 0; j < side; ++j) {
            const double x = static_cast<double>(i) / grid_n, z = static_cast<double>(j) / grid_n;
            // Six octaves of noise, each twice the frequency and half the amplitude (fBm).
            double height = 0, amplitude = 0.125, frequency = 4.0;
            for (const std::uint64_t salt : octave_salt) {
                height += amplitude * value_noise(x * frequency, z * frequency, salt);
                amplitude *= 0.5;
                frequency *= 2.0;
            }
            mesh.vertices.push_back(to_float({x, height, z}));
        }
    mesh.triangles.reserve(2 * std::size_t(grid_n) * grid_n);
    auto id = [&](std::uint32_t i, std::uint32_t j) { return i * side + j; };
    for (std::uint32_t i = 0; i < grid_n; ++i)
        for (std::uint32_t j = 0; j < grid_n; ++j) {
            // Counter-clockwise seen from +y.
            mesh.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
        }
    return mesh;
}

namespace {

// Appends a closed box, its faces split into cells x cells quads; `inward` flips the winding.
void append_box(TriangleMesh& mesh, const Vec3d& lo, const Vec3d& hi, double yaw,
                std::uint32_t cells, bool inward) {
    const Vec3d centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    const double c = std::cos(yaw), s = std::sin(yaw);
    for (int n = 0; n < 3; ++n) {
        for (const double sign : {1.0, -1.0}) {
            // In-plane axes ordered so that u x v points along sign * n (x y z cyclic).
            const int u = sign > 0 ? (n + 1) % 3 : (n + 2) % 3;
            const int v = sign > 0 ? (n + 2) % 3 : (n + 1) % 3;
            const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
            for (std::uint32_t i = 0; i <= cells; ++i)
                for (std::uint32_t j = 0; j <= cells; ++j) {
                    Vec3d p;
                    p[static_cast<std::size_t>(n)] = sign;
                    p[static_cast<std::size_t>(u)] = -1.0 + 2.0 * i / cells;
                    p[static_cast<std::size_t>(v)] = -1.0 + 2.0 * j / cells;
                    Vec3d q{p[0] * half[0], p[1] * half[1], p[2] * half[2]};
                    // Rotate about the vertical (y) axis through the centre.
                    q = Vec3d{c * q[0] + s * q[2], q[1], -s * q[0] + c * q[2]};
                    mesh.vertices.push_back(to_float(centre + q));
                }
            auto id = [&](std::uint32_t i, std::uint32_t j) { return base + i * (cells + 1) + j; };
            for (std::uint32_t i = 0; i < cells; ++i)
                for (std::uint32_t j = 0; j < cells; ++j) {
                    std::array<std::uint32_t, 3> t1{id(i, j), id(i + 1, j), id(i + 1, j + 1)};
                    std::array<std::uint32_t, 3> t2{id(i, j), id(i + 1, j + 1), id(i, j + 1)};
                    if (inward) {
                        std::swap(t1[1], t1[2]);
                        std::swap(t2[1], t2[2]);
                    }
                    mesh.triangles.push_back(t1);
                    mesh.triangles.push_back(t2);
                }
        }
    }
}

}  // namespace

TriangleMesh make_room(std::uint32_t object_count, std::uint64_t seed) {
    constexpr std::uint32_t sphere_frequency = 4;  // 320 triangles per sphere
    check_size(768ull + 320ull * object_count, "the room");
    TriangleMesh mesh;
    const Vec3d room_lo{0.0, 0.0, 0.0}, room_hi{10.0, 4.0, 10.0};
    append_box(mesh, room_lo, room_hi, 0.0, 8, /*inward=*/true);
    const TriangleMesh unit_sphere = make_geodesic_sphere(sphere_frequency);
    Rng rng(seed);
    for (std::uint32_t k = 0; k < object_count; ++k) {
        if (rng.below(2) == 0) {
            const Vec3d size{rng.uniform(0.2, 1.5), rng.uniform(0.2, 1.5), rng.uniform(0.2, 1.5)};
            // Keep the rotated box inside the room: its footprint is within a circle of radius
            // |size.xz| / 2 around the centre.
            const double reach = 0.5 * std::sqrt(size[0] * size[0] + size[2] * size[2]) + 0.05;
            const Vec3d centre{rng.uniform(reach, 10.0 - reach), rng.uniform(0.0, 4.0 - size[1]),
                               rng.uniform(reach, 10.0 - reach)};
            const Vec3d lo{centre[0] - size[0] / 2, centre[1], centre[2] - size[2] / 2};
            append_box(mesh, lo, lo + size, rng.uniform(0.0, std::numbers::pi), 1, false);
        } else {
            const double r = rng.uniform(0.1, 0.8);
            const Vec3d centre{rng.uniform(r + 0.05, 10.0 - r - 0.05),
                               rng.uniform(r + 0.05, 4.0 - r - 0.05),
                               rng.uniform(r + 0.05, 10.0 - r - 0.05)};
            const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
            for (const Vec3f& p : unit_sphere.vertices)
                mesh.vertices.push_back(to_float(centre + Vec3d(p) * r));
            for (const auto& t : unit_sphere.triangles)
                mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
        }
    }
    return mesh;
}

TriangleMesh make_soup(std::uint64_t triangle_count, std::uint64_t seed) {
    if (triangle_count < 1) throw Error("soup needs at least 1 triangle");
    check_size(triangle_count, "the soup");
    TriangleMesh mesh;
    mesh.vertices.reserve(3 * triangle_count);
    mesh.triangles.reserve(triangle_count);
    Rng rng(seed);
    for (std::uint64_t t = 0; t < triangle_count; ++t) {
        const Vec3d centre{rng.uniform(), rng.uniform(), rng.uniform()};
        const double size = std::pow(10.0, rng.uniform(-3.0, -1.0));  // log-uniform 0.001..0.1
        const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
        for (int c = 0; c < 3; ++c) {
            Vec3d p = centre + Vec3d{rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0),
                                     rng.uniform(-1.0, 1.0)} *
                                   size;
            for (std::size_t axis = 0; axis < 3; ++axis) p[axis] = std::clamp(p[axis], 0.0, 1.0);
            mesh.vertices.push_back(to_float(p));
        }
        mesh.triangles.push_back({first, first + 1, first + 2});
    }
    return mesh;
}

}  // namespace bvhkit
