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
// Every normal points from B into A: moving A along it (or B against it) by the depth separates
// that contact. Vertices inside are found from the intersection curve: the corners of the
// intersecting faces are tested (pseudonormal sign, query/signed_distance.hpp), and from each one
// inside the walk goes over the mesh's edges to every vertex it reaches without touching a face
// that meets the other mesh: such an edge cannot cross the other surface, so those vertices are
// inside too. A closed component of one mesh wholly inside the other meets no face and gives no
// contact, and a region where no vertex lies inside the other mesh (edges passing through faces
// only, as two crossed bars) has depth 0.
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
    DescentRule rule = DescentRule::Larger;
};

namespace detail {

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
    std::vector<std::uint32_t> corner_list, queue, order, counts, region_index;
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
            region.resize(nodes);
        }
        if (++epoch == 0) {  // wrapped: old stamps could match again
            std::fill(stamp.begin(), stamp.end(), 0);
            std::fill(curve.begin(), curve.end(), 0);
            std::fill(seen.begin(), seen.end(), 0);
            std::fill(numbered.begin(), numbered.end(), 0);
            epoch = 1;
        }
        all.clear();
        node.clear();
        corner_list.clear();
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

/// Contacts of one mesh's vertices inside the other: `self` is the mesh whose vertices are
/// tested, `other` the one they may be inside; `to_other` carries self's frame into other's,
/// `to_a` other's directions into A's frame. `of_a`: self is A. Node ids of self's vertices are
/// offset by `base`.
template <class T>
void inside_vertex_contacts(const ContactMesh<T>& self, const ContactMesh<T>& other,
                            const Transform<double>& to_other, const Transform<double>& self_to_a,
                            const Mat3<double>& other_to_a, bool of_a, std::uint32_t base,
                            double tiny, std::size_t first_corner, std::size_t end_corner,
                            ContactWorkspace<T>& w) {
    MeshPoint<T> near;  // each search starts from the previous closest point
    const auto add = [&](std::uint32_t v, bool known_inside) {
        const Vec<T, 3>& own_point = self.vertex(v);
        if (!(std::isfinite(own_point[0]) && std::isfinite(own_point[1]) &&
              std::isfinite(own_point[2])))
            return false;  // a vertex of faces the models left out
        const Vec<T, 3> q(to_other.apply(Vec3d(own_point)));
        const SignedDistance<T> sd = other.surface().signed_distance(q, near, w.scratch);
        if (!sd.closest) return false;
        near = sd.closest;
        if (!known_inside && !(sd.distance < T(0))) return false;
        const double d = double(sd.closest.distance);
        // From the vertex to its closest point: the way out of the other mesh. Where the distance
        // is within rounding of zero its direction is noise, and the face normal stands in.
        const Vec3d face = other.normal(sd.closest.triangle);
        Vec3d out = d > tiny ? unit_or(Vec3d(sd.closest.point) - Vec3d(q), face) : face;
        out = other_to_a * out;
        ContactPoint<T> c;
        c.point = Vec<T, 3>(self_to_a.apply(Vec3d(self.vertex(v))));
        c.depth = sd.closest.distance;
        const std::uint32_t own = self.faces_at(v).empty() ? 0 : self.faces_at(v)[0];
        if (of_a) {
            c.normal = Vec<T, 3>(out);
            c.kind = ContactKind::VertexOfA;
            c.triangle_a = own;
            c.triangle_b = sd.closest.triangle;
        } else {
            c.normal = Vec<T, 3>(-out);
            c.kind = ContactKind::VertexOfB;
            c.triangle_a = sd.closest.triangle;
            c.triangle_b = own;
        }
        w.all.push_back(c);
        w.node.push_back(base + v);
        return true;
    };
    for (std::size_t i = first_corner; i < end_corner; ++i) {
        const std::uint32_t start = w.corner_list[i];
        if (!add(start, false)) continue;
        w.queue.clear();
        w.queue.push_back(start);
        for (std::size_t head = 0; head < w.queue.size(); ++head) {
            const std::uint32_t x = w.queue[head];
            for (const std::uint32_t f : self.faces_at(x))
                for (const std::uint32_t u : self.corners(f)) {
                    // A corner of a face meeting the other mesh is tested on its own.
                    if (w.curve[base + u] == w.epoch || w.seen[base + u] == w.epoch) continue;
                    w.seen[base + u] = w.epoch;
                    w.unite(base + x, base + u);
                    if (add(u, true)) w.queue.push_back(u);
                }
        }
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

    // Curve contacts, and the corners of the intersecting faces.
    const auto mark = [&](std::uint32_t n) {
        if (w.curve[n] != w.epoch) {
            w.curve[n] = w.epoch;
            w.corner_list.push_back(n);
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
            mark(fa[k]);
            mark(na + fb[k]);
            w.unite(fa[0], fa[k]);
            w.unite(fa[0], na + fb[k]);
        }
    }
    if (options.inside_vertices) {
        // The corner list holds A's corners and B's (offset by na) interleaved: split it.
        std::stable_partition(w.corner_list.begin(), w.corner_list.end(),
                              [&](std::uint32_t n) { return n < na; });
        const std::size_t split =
            std::size_t(std::find_if(w.corner_list.begin(), w.corner_list.end(),
                                     [&](std::uint32_t n) { return n >= na; }) -
                        w.corner_list.begin());
        for (std::size_t i = split; i < w.corner_list.size(); ++i) w.corner_list[i] -= na;
        const double eps = double(std::numeric_limits<T>::epsilon());
        detail::inside_vertex_contacts(ca, cb, inverse, identity, pose.rotation, true, 0,
                                       64 * eps * double(b.scale()), 0, split, w);
        // B's vertices: its curve and seen stamps live at offset na.
        detail::inside_vertex_contacts(cb, ca, pose, pose, identity.rotation, false, na,
                                       64 * eps * double(a.scale()), split, w.corner_list.size(),
                                       w);
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
