#pragma once
// contact_manifold(A, B, pose_of_b_in_a, ...): the contacts of two overlapping closed meshes as a
// solver wants them, each a point, a unit normal, a depth and a face of each mesh, grouped into
// connected overlap regions and reduced to a few well-spread points per region. docs/collision.md
// defines every quantity; in short, in A's frame:
//   curve contacts   the ends of each intersection segment of an intersecting face pair (fa, fb):
//                    depth 0, as they lie on both surfaces; the normal is that of the face the
//                    other triangle reaches less far behind (fb's outward normal when fa's corners
//                    lie less deep behind fb's plane than fb's behind fa's, else minus fa's).
//   vertex contacts  each vertex of A strictly inside B (and of B inside A): depth is its distance
//                    to the other surface, the normal points from the vertex to its closest point
//                    there (for A's vertices; the opposite for B's).
//   edge contacts    the middle of each piece of an intersecting face's edge that runs inside the
//                    other mesh from a crossing of its surface to another crossing or to a vertex
//                    inside, with depth and normal as a vertex's: where no vertex is inside (two
//                    crossed bars) these carry the depth.
// Every normal points from B into A: moving A along it (or B against it) by the depth separates
// that contact. Vertices inside are found from the intersection curve: the corners of the
// intersecting faces are tested (pseudonormal sign, query/signed_distance.hpp), and from each one
// inside the walk goes over the mesh's edges to every vertex it reaches without touching a face
// that meets the other mesh: such an edge cannot cross the other surface, so those vertices are
// inside too. A closed component of one mesh wholly inside the other meets no face and gives no
// contact.
// Regions: the union of the intersecting face pairs' corners (of both meshes) and of the walks'
// edges; each connected part is one region. Reduction per region (the four-point rule of game
// engines' contact caches): the deepest point, the point farthest from it, the point making the
// largest triangle with those, then the one adding the most area across an edge of that
// triangle, measured in the plane normal to the deepest point's normal; beyond four, the point
// farthest from those chosen.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/query/contact_mesh.hpp"
#include "bvhkit/query/pairs_model.hpp"

namespace bvhkit {

enum class ContactKind : std::uint8_t {
    Curve,      // on the intersection curve of triangle_a and triangle_b
    VertexOfA,  // a vertex of A (of triangle_a) inside B; triangle_b holds its closest point
    VertexOfB,  // a vertex of B (of triangle_b) inside A; triangle_a holds its closest point
    EdgeOfA,    // the middle of a piece of an edge of A (of triangle_a) inside B
    EdgeOfB,    // the middle of a piece of an edge of B (of triangle_b) inside A
};

template <class T>
struct ContactPoint {
    Vec<T, 3> point{};                             // in A's frame
    Vec<T, 3> normal{};                            // unit, in A's frame, from B into A
    T depth = 0;                                   // >= 0
    std::uint32_t triangle_a = 0, triangle_b = 0;  // mesh indices
    std::uint32_t region = 0;                      // index of its overlap region
    ContactKind kind = ContactKind::Curve;
};

struct ContactOptions {
    std::uint32_t max_points_per_region = 4;  // 0: every contact of every region
    bool inside_vertices = true;  // false: curve contacts only (for meshes that are not closed)
    /// false: of the vertices inside, only the corners of intersecting faces (no walk to the
    /// vertices beyond): the work stays proportional to the intersecting pairs, and a deep
    /// overlap's depth is then only what the curve's neighbourhood shows.
    bool walk_inside = true;
    DescentRule rule = DescentRule::Larger;
};

namespace detail {

/// An edge of an intersecting face crossing a face of the other mesh: the edge's end nodes (the
/// smaller in the high half), the crossing's parameter from the smaller end, the edge's face.
struct EdgeCrossing {
    std::uint64_t key;
    double t;
    std::uint32_t face;
    friend bool operator<(const EdgeCrossing& x, const EdgeCrossing& y) {
        return x.key != y.key ? x.key < y.key : x.t < y.t;
    }
};

/// Reused storage of contact_manifold: every array grows to the largest meshes seen and is never
/// cleared between queries; an entry is valid when its stamp equals the query's epoch.
template <class T>
struct ContactWorkspace {
    std::vector<ContactPoint<T>> all;   // every contact, before the reduction
    std::vector<std::uint32_t> node;    // union-find node of each contact in `all`
    std::vector<std::uint32_t> parent;  // union-find over A's welded vertices, then B's
    std::vector<std::uint32_t> stamp;   // epoch at which parent[] was set
    std::vector<std::uint32_t> curve;   // epoch at which a vertex was found on an intersecting face
    std::vector<std::uint32_t> seen;    // epoch at which a vertex was reached by a walk
    std::vector<std::uint32_t> region;  // region index of a root (valid with the root's stamp)
    std::vector<std::uint32_t> numbered;  // epoch at which a root got its region index
    std::vector<std::uint32_t> inside;    // epoch at which a vertex was found inside the other
    std::vector<EdgeCrossing> crossings;  // where the intersecting faces' edges cross
    std::vector<std::uint32_t> corners_a, corners_b;  // corners of the intersecting faces
    std::vector<std::uint32_t> queue, order, counts, region_index;
    std::vector<std::uint8_t> chosen;
    std::vector<double> gap;  // reduction: distance to the nearest point chosen
    NearestScratch<T> scratch;
    std::uint32_t epoch = 0;

    void begin(std::size_t nodes) {
        if (parent.size() < nodes) {
            parent.resize(nodes);
            stamp.assign(nodes, 0);
            curve.assign(nodes, 0);
            seen.assign(nodes, 0);
            numbered.assign(nodes, 0);
            inside.assign(nodes, 0);
            region.resize(nodes);
        }
        if (++epoch == 0) {  // wrapped: old stamps could match again
            std::fill(stamp.begin(), stamp.end(), 0);
            std::fill(curve.begin(), curve.end(), 0);
            std::fill(seen.begin(), seen.end(), 0);
            std::fill(numbered.begin(), numbered.end(), 0);
            std::fill(inside.begin(), inside.end(), 0);
            epoch = 1;
        }
        all.clear();
        node.clear();
        corners_a.clear();
        corners_b.clear();
        crossings.clear();
    }
    std::uint32_t find(std::uint32_t x) {
        if (stamp[x] != epoch) {
            stamp[x] = epoch;
            parent[x] = x;
            return x;
        }
        while (parent[x] != x) {
            parent[x] = parent[parent[x]];  // path halving
            x = parent[x];
        }
        return x;
    }
    void unite(std::uint32_t x, std::uint32_t y) {
        x = find(x);
        y = find(y);
        if (x != y) parent[std::max(x, y)] = std::min(x, y);  // deterministic root: the smaller
    }
};

}  // namespace detail

template <class T>
struct ContactManifold {
    bool colliding = false;
    /// The reduced contacts, region by region, each region's deepest first.
    std::vector<ContactPoint<T>> points;
    /// Region r's points are points[region_offsets[r]] .. points[region_offsets[r + 1] - 1].
    std::vector<std::uint32_t> region_offsets;
    /// Per region: the normal and depth of its deepest contact (points[region_offsets[r]]).
    std::vector<Vec<T, 3>> region_normals;
    std::vector<T> region_depths;
    std::size_t candidate_count = 0;  // contacts before the reduction
    CollideResult<T> pairs;           // the intersecting face pairs and their segments
    detail::ContactWorkspace<T> work;

    std::size_t region_count() const {
        return region_offsets.empty() ? 0 : region_offsets.size() - 1;
    }
};

namespace detail {

using Vec3d = Vec<double, 3>;

inline Vec3d unit_or(const Vec3d& v, const Vec3d& fallback) {
    const double l = std::hypot(v[0], v[1], v[2]);
    return l > 0 && std::isfinite(l) ? v / l : fallback;
}

/// One mesh probed against the other: `self` is the mesh whose points are tested, `other` the
/// one they may be inside; `to_other` carries self's frame into other's, `self_to_a` self's into
/// A's, `other_to_a` other's directions into A's. Node ids of self's vertices are offset by
/// `base`; `tiny` is the distance below which a direction to the closest point is noise.
template <class T>
struct Side {
    const ContactMesh<T>& self;
    const ContactMesh<T>& other;
    Transform<double> to_other, self_to_a;
    Mat3<double> other_to_a;
    bool of_a;
    std::uint32_t base;
    double tiny;
};

/// Tests point x of self (in self's frame) against the other mesh and, when it is inside (or
/// `known_inside`), adds its contact; `own` is self's face it belongs to, `node` its region node.
template <class T>
bool probe(const Side<T>& s, const Vec3d& x, bool known_inside, std::uint32_t own,
           std::uint32_t node, bool vertex, MeshPoint<T>& near, ContactWorkspace<T>& w) {
    if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
        return false;  // a vertex of faces the models left out
    const Vec<T, 3> q(s.to_other.apply(x));
    const SignedDistance<T> sd = s.other.surface().signed_distance(q, near, w.scratch);
    if (!sd.closest) return false;
    near = sd.closest;
    if (!known_inside && !(sd.distance < T(0))) return false;
    // From the point to its closest point: the way out of the other mesh. Where the distance is
    // within rounding of zero its direction is noise, and the face normal stands in.
    const Vec3d face = s.other.normal(sd.closest.triangle);
    const double d = double(sd.closest.distance);
    const Vec3d out =
        s.other_to_a * (d > s.tiny ? unit_or(Vec3d(sd.closest.point) - Vec3d(q), face) : face);
    ContactPoint<T> c;
    c.point = Vec<T, 3>(s.self_to_a.apply(x));
    c.depth = sd.closest.distance;
    if (s.of_a) {
        c.normal = Vec<T, 3>(out);
        c.kind = vertex ? ContactKind::VertexOfA : ContactKind::EdgeOfA;
        c.triangle_a = own;
        c.triangle_b = sd.closest.triangle;
    } else {
        c.normal = Vec<T, 3>(-out);
        c.kind = vertex ? ContactKind::VertexOfB : ContactKind::EdgeOfB;
        c.triangle_a = sd.closest.triangle;
        c.triangle_b = own;
    }
    w.all.push_back(c);
    w.node.push_back(node);
    return true;
}

/// Contacts of self's vertices inside the other mesh, from the corners of its intersecting faces
/// (`corners`, in self's own ids): each is tested, and from each one inside a walk reaches the
/// vertices joined to it by faces that meet nothing of the other mesh.
template <class T>
void inside_vertex_contacts(const Side<T>& s, const std::vector<std::uint32_t>& corners, bool walk,
                            ContactWorkspace<T>& w) {
    MeshPoint<T> near;  // each search starts from the previous closest point
    const auto add = [&](std::uint32_t v, bool known_inside) {
        const std::span<const std::uint32_t> at = s.self.faces_at(v);
        if (!probe(s, Vec3d(s.self.vertex(v)), known_inside, at.empty() ? 0 : at[0], s.base + v,
                   true, near, w))
            return false;
        w.inside[s.base + v] = w.epoch;
        return true;
    };
    for (const std::uint32_t start : corners) {
        if (!add(start, false) || !walk) continue;
        w.queue.clear();
        w.queue.push_back(start);
        for (std::size_t head = 0; head < w.queue.size(); ++head) {
            const std::uint32_t x = w.queue[head];
            for (const std::uint32_t f : s.self.faces_at(x))
                for (const std::uint32_t u : s.self.corners(f)) {
                    // A corner of a face meeting the other mesh is tested on its own.
                    const std::uint32_t n = s.base + u;
                    if (w.curve[n] == w.epoch || w.seen[n] == w.epoch) continue;
                    w.seen[n] = w.epoch;
                    w.unite(s.base + x, n);
                    if (add(u, true)) w.queue.push_back(u);
                }
        }
    }
}

/// Records where the edges of triangle p (welded ids `ids`, region nodes offset by `base`, face
/// `face`) cross triangle q of unit normal nq (right-handed on q's corners), all in A's frame.
/// Each edge is taken from its smaller id, so the two faces sharing it give the same parameter.
template <class T>
void record_crossings(const Vec3d* p, const std::array<std::uint32_t, 3>& ids, std::uint32_t base,
                      std::uint32_t face, const Vec3d* q, const Vec3d& nq, ContactWorkspace<T>& w) {
    for (int k = 0; k < 3; ++k) {
        const int i = ids[k] < ids[(k + 1) % 3] ? k : (k + 1) % 3;
        const int j = i == k ? (k + 1) % 3 : k;
        if (ids[i] == ids[j]) continue;
        const double si = dot(nq, p[i] - q[0]), sj = dot(nq, p[j] - q[0]);
        if (!((si < 0 && sj > 0) || (si > 0 && sj < 0))) continue;
        const double t = si / (si - sj);
        const Vec3d x = p[i] + (p[j] - p[i]) * t;
        bool in = true;
        for (int m = 0; m < 3 && in; ++m) in = dot(cross(q[(m + 1) % 3] - q[m], x - q[m]), nq) >= 0;
        if (in)
            w.crossings.push_back({std::uint64_t(base + ids[i]) << 32 | (base + ids[j]), t, face});
    }
}

/// Contacts in the middle of each piece of an intersecting face's edge that runs inside the other
/// mesh from a crossing to another crossing or to a vertex inside (the crossings sorted along
/// each edge): where no vertex is inside (two crossed bars), these carry the depth.
template <class T>
void edge_contacts(const Side<T>& sa, const Side<T>& sb, ContactWorkspace<T>& w) {
    std::sort(w.crossings.begin(), w.crossings.end());
    MeshPoint<T> near_a, near_b;
    for (std::size_t g = 0; g < w.crossings.size();) {
        std::size_t e = g;
        while (e < w.crossings.size() && w.crossings[e].key == w.crossings[g].key) ++e;
        const std::uint32_t lo = std::uint32_t(w.crossings[g].key >> 32);
        const std::uint32_t hi = std::uint32_t(w.crossings[g].key);
        const Side<T>& s = lo < sb.base ? sa : sb;
        MeshPoint<T>& near = lo < sb.base ? near_a : near_b;
        const Vec3d p0(s.self.vertex(lo - s.base)), p1(s.self.vertex(hi - s.base));
        const auto piece = [&](double t0, double t1, std::uint32_t face) {
            if (!(t1 - t0 > 1e-9)) return;  // one crossing found twice (at an edge of the other)
            probe(s, p0 + (p1 - p0) * ((t0 + t1) / 2), false, face, lo, false, near, w);
        };
        if (w.inside[lo] == w.epoch) piece(0, w.crossings[g].t, w.crossings[g].face);
        for (std::size_t i = g; i + 1 < e; ++i)
            piece(w.crossings[i].t, w.crossings[i + 1].t, w.crossings[i].face);
        if (w.inside[hi] == w.epoch) piece(w.crossings[e - 1].t, 1, w.crossings[e - 1].face);
        g = e;
    }
}

/// The deepest-first, well-spread choice of at most k of the region's contacts all[order[b..e)],
/// appended to `out`.
template <class T>
void reduce_region(ContactWorkspace<T>& w, std::size_t b, std::size_t e, std::uint32_t k,
                   std::vector<ContactPoint<T>>& out) {
    const auto& all = w.all;
    // Deeper first; at equal depth a vertex (where the material is) before a curve point.
    const auto deeper = [&](std::uint32_t x, std::uint32_t y) {
        if (all[x].depth != all[y].depth) return all[x].depth > all[y].depth;
        const bool vx = all[x].kind != ContactKind::Curve, vy = all[y].kind != ContactKind::Curve;
        return vx != vy ? vx : x < y;
    };
    if (k == 0 || e - b <= k) {
        std::sort(w.order.begin() + std::ptrdiff_t(b), w.order.begin() + std::ptrdiff_t(e), deeper);
        for (std::size_t i = b; i < e; ++i) out.push_back(all[w.order[i]]);
        return;
    }
    std::uint32_t pick[4] = {w.order[b], 0, 0, 0};
    for (std::size_t i = b + 1; i < e; ++i)
        if (deeper(w.order[i], pick[0])) pick[0] = w.order[i];
    const Vec3d n(all[pick[0]].normal);
    // Positions in the plane normal to n, relative to the deepest point.
    const auto flat = [&](std::uint32_t x) {
        const Vec3d d = Vec3d(all[x].point) - Vec3d(all[pick[0]].point);
        return d - n * dot(n, d);
    };
    for (std::size_t i = b; i < e; ++i) {
        w.chosen[i - b] = w.order[i] == pick[0];
        w.gap[i - b] = length(flat(w.order[i]));
    }
    out.push_back(all[pick[0]]);
    std::size_t count = 1;
    while (count < k) {
        double best = 0;
        std::size_t at = e;
        for (int pass = 0; pass < 2 && at == e; ++pass)
            for (std::size_t i = b; i < e; ++i) {
                if (w.chosen[i - b]) continue;
                const Vec3d p = flat(w.order[i]);
                double score;
                if (pass == 1 || count == 1 || count >= 4) {
                    score = w.gap[i - b];
                } else if (count == 2) {  // twice the triangle's area
                    score = std::fabs(dot(cross(flat(pick[1]), p), n));
                } else {  // twice the area added across the triangle's edge that p lies beyond
                    const Vec3d t[3] = {Vec3d{}, flat(pick[1]), flat(pick[2])};
                    const double s = dot(cross(t[1], t[2]), n) >= 0 ? 1.0 : -1.0;
                    score = 0;
                    for (int j = 0; j < 3; ++j)
                        score =
                            std::max(score, -s * dot(cross(t[(j + 1) % 3] - t[j], p - t[j]), n));
                }
                // Equal spread, to rounding: the deeper point (a corner inside rather than the
                // curve point above it, which the projection sets apart by rounding only).
                const double slack = 1e-9 * best;
                if (score > best + slack ||
                    (at != e && score >= best - slack && deeper(w.order[i], w.order[at])))
                    best = std::max(best, score), at = i;
            }
        if (at == e) break;  // every point left coincides with one chosen
        w.chosen[at - b] = 1;
        const std::uint32_t x = w.order[at];
        if (count < 4) pick[count] = x;
        ++count;
        out.push_back(all[x]);
        const Vec3d px = flat(x);
        for (std::size_t i = b; i < e; ++i)
            w.gap[i - b] = std::min(w.gap[i - b], length(flat(w.order[i]) - px));
    }
}

}  // namespace detail

/// The contact manifold of A and B (B placed in A's frame by pose_of_b_in_a), defined in the
/// header comment above and docs/collision.md. `ca` and `cb` are the ContactMeshes of the meshes
/// the models were built from. Returns whether the models intersect; `result` is cleared, then
/// filled (reuse one result across queries: its storage is kept). The pose must be finite and
/// rigid (Error otherwise, as for collide).
template <BoundingVolume V>
bool contact_manifold(const CollisionModel<V>& a, const ContactMesh<typename V::Scalar>& ca,
                      const CollisionModel<V>& b, const ContactMesh<typename V::Scalar>& cb,
                      const Transform<typename V::Scalar>& pose_of_b_in_a,
                      const ContactOptions& options, ContactManifold<typename V::Scalar>& result) {
    using T = typename V::Scalar;
    using detail::Vec3d;
    if (ca.triangle_count() != a.triangle_count() || cb.triangle_count() != b.triangle_count())
        throw Error("contact_manifold: a ContactMesh has " +
                    std::to_string(ca.triangle_count() != a.triangle_count()
                                       ? ca.triangle_count()
                                       : cb.triangle_count()) +
                    " triangles, its CollisionModel " +
                    std::to_string(ca.triangle_count() != a.triangle_count() ? a.triangle_count()
                                                                             : b.triangle_count()));
    result.points.clear();
    result.region_offsets.clear();
    result.region_normals.clear();
    result.region_depths.clear();
    result.candidate_count = 0;
    collide(a, b, pose_of_b_in_a, CollideOptions{CollideMode::AllPairs, options.rule, true},
            result.pairs);
    result.colliding = result.pairs.colliding;
    if (!result.colliding) return false;

    auto& w = result.work;
    const std::uint32_t na = std::uint32_t(ca.vertex_count());
    w.begin(std::size_t(na) + cb.vertex_count());
    const Transform<double> pose(pose_of_b_in_a), inverse = pose.inverse(), identity{};

    // Curve contacts, the corners of the intersecting faces, and where their edges cross.
    const auto mark = [&](std::uint32_t n, std::vector<std::uint32_t>& list, std::uint32_t v) {
        if (w.curve[n] != w.epoch) {
            w.curve[n] = w.epoch;
            list.push_back(v);
        }
    };
    for (const Contact<T>& pair : result.pairs.contacts) {
        const auto& fa = ca.corners(pair.triangle_a);
        const auto& fb = cb.corners(pair.triangle_b);
        const Vec3d pa[3] = {Vec3d(ca.vertex(fa[0])), Vec3d(ca.vertex(fa[1])),
                             Vec3d(ca.vertex(fa[2]))};
        const Vec3d pb[3] = {pose.apply(Vec3d(cb.vertex(fb[0]))),
                             pose.apply(Vec3d(cb.vertex(fb[1]))),
                             pose.apply(Vec3d(cb.vertex(fb[2])))};
        const Vec3d na_ = ca.normal(pair.triangle_a);
        const Vec3d nb_ = pose.rotation * cb.normal(pair.triangle_b);
        double behind_a = 0, behind_b = 0;  // fb's corners behind fa's plane, fa's behind fb's
        for (int k = 0; k < 3; ++k) {
            behind_a = std::max(behind_a, -dot(na_, pb[k] - pa[0]));
            behind_b = std::max(behind_b, -dot(nb_, pa[k] - pb[0]));
        }
        ContactPoint<T> c;  // depth 0: the point lies on both surfaces
        c.triangle_a = pair.triangle_a;
        c.triangle_b = pair.triangle_b;
        c.normal = Vec<T, 3>(behind_b <= behind_a ? nb_ : -na_);
        c.point = pair.p;
        w.all.push_back(c);
        w.node.push_back(fa[0]);
        if (!(pair.q == pair.p)) {
            c.point = pair.q;
            w.all.push_back(c);
            w.node.push_back(fa[0]);
        }
        for (int k = 0; k < 3; ++k) {
            mark(fa[k], w.corners_a, fa[k]);
            mark(na + fb[k], w.corners_b, fb[k]);
            w.unite(fa[0], fa[k]);
            w.unite(fa[0], na + fb[k]);
        }
        if (options.inside_vertices) {
            detail::record_crossings(pa, fa, 0, pair.triangle_a, pb, nb_, w);
            detail::record_crossings(pb, fb, na, pair.triangle_b, pa, na_, w);
        }
    }
    if (options.inside_vertices) {
        const double eps = double(std::numeric_limits<T>::epsilon());
        const detail::Side<T> side_a{
            ca, cb, inverse, identity, pose.rotation, true, 0, 64 * eps * double(b.scale())};
        const detail::Side<T> side_b{
            cb, ca, pose, pose, identity.rotation, false, na, 64 * eps * double(a.scale())};
        detail::inside_vertex_contacts(side_a, w.corners_a, options.walk_inside, w);
        detail::inside_vertex_contacts(side_b, w.corners_b, options.walk_inside, w);
        detail::edge_contacts(side_a, side_b, w);
    }

    // Regions, numbered in the order of their first contact.
    result.candidate_count = w.all.size();
    std::uint32_t regions = 0;
    w.counts.clear();
    w.region_index.resize(w.all.size());
    for (std::size_t i = 0; i < w.all.size(); ++i) {
        const std::uint32_t root = w.find(w.node[i]);
        if (w.numbered[root] != w.epoch) {
            w.numbered[root] = w.epoch;
            w.region[root] = regions++;
            w.counts.push_back(0);
        }
        w.region_index[i] = w.region[root];
        w.all[i].region = w.region[root];
        ++w.counts[w.region[root]];
    }
    // Counting sort of the contacts by region, stable.
    result.region_offsets.assign(1, 0);
    for (std::uint32_t r = 0; r < regions; ++r) {
        const std::uint32_t c = w.counts[r];
        w.counts[r] = result.region_offsets.back();
        result.region_offsets.push_back(result.region_offsets.back() + c);
    }
    w.order.resize(w.all.size());
    for (std::size_t i = 0; i < w.all.size(); ++i)
        w.order[w.counts[w.region_index[i]]++] = std::uint32_t(i);
    w.chosen.resize(w.all.size());
    w.gap.resize(w.all.size());
    std::uint32_t start = 0;
    for (std::uint32_t r = 0; r < regions; ++r) {
        const std::uint32_t end = result.region_offsets[r + 1];
        result.region_offsets[r] = std::uint32_t(result.points.size());
        detail::reduce_region(w, start, end, options.max_points_per_region, result.points);
        result.region_normals.push_back(result.points[result.region_offsets[r]].normal);
        result.region_depths.push_back(result.points[result.region_offsets[r]].depth);
        start = end;
    }
    result.region_offsets[regions] = std::uint32_t(result.points.size());
    return true;
}

}  // namespace bvhkit
