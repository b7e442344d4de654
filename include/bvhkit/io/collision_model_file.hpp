#pragma once
// Saving and loading a CollisionModel<V> (format: docs/serialization.md, kind 6). The file holds
// exactly what the model holds: the nodes with their volumes (the header's volume byte names the
// type), the slot -> triangle indices, the triangles in slot order, their vertex ids, the
// triangles left out of the tree, the triangle count and the model's scale. Nothing is rebuilt or
// refitted on load, so a loaded model answers collide and distance bit for bit as the saved one,
// and saving it again gives the same bytes.
//
// Loading trusts nothing: the envelope (size, checksum), every count against the bytes there are
// before anything is allocated, the tree's shape and every index (check_tree_structure), the
// skipped list, the scale's sign and the triangles' coordinates (finite, what the exact triangle
// tests need), always; then, unless LoadOptions::validate is false, what the builder guarantees:
// each triangle once (in the tree or skipped), volumes that are well formed (no NaN, finite
// centres, sizes >= 0, orthonormal axes) and contain every vertex of the triangles under their
// node (to a tolerance of a few units in the last place of the model's scale: the fits pad for
// their own rounding, so a fitted volume passes on any machine), and the scale the triangles give.
// A volume that a corruption shrank fails; one it grew only costs time. Whatever a build makes
// loads, at any finite scale: a size past T's largest finite value is stored as inf by the build
// and accepted here. Any failure is a bvhkit::Error.
//
// Thread safety: saving reads the model only; loading touches only its input and the model it
// returns.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_sections.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/math/wide_length.hpp"
#include "bvhkit/query/collision_model.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/obb_rss.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"

namespace bvhkit {

namespace serial_detail {

/// One volume type's record in a file: its code, its size in scalars, its bytes, and the checks
/// validate() makes of it: well_formed(v) and contains(v, p, tol) (p in double; tol absolute).
template <class V>
struct VolumeCodec;

template <class T>
bool finite_all(std::initializer_list<T> values) {
    for (const T v : values)
        if (!std::isfinite(v)) return false;
    return true;
}
template <class T>
bool finite_vec(const Vec<T, 3>& v) {
    return finite_all({v[0], v[1], v[2]});
}
// What a build produces at the edges of T's range: a size (radius, extent, reach) or a slab's
// bound whose true value lies beyond T's largest finite value is stored as infinite, which still
// bounds everything (a float model at 3e38 has a box diagonal, and k-DOP projections, past
// FLT_MAX). Accepted as the builder makes it; NaN, negative sizes and inverted slabs are not.
template <class T>
bool size_ok(T size) {
    return size >= T(0);  // false for NaN
}
template <class T>
bool bound_ok(T lo, T hi) {
    return lo <= hi && lo < std::numeric_limits<T>::infinity() &&
           hi > -std::numeric_limits<T>::infinity();  // false for NaN
}
/// Rows of unit length, orthogonal to each other, within a few hundred units in the last place.
template <class T>
bool orthonormal(const Mat3<T>& axes) {
    constexpr double tol = double(std::numeric_limits<T>::epsilon()) * 64;
    for (std::size_t i = 0; i < 3; ++i) {
        if (!finite_vec(axes[i])) return false;
        for (std::size_t j = 0; j < 3; ++j) {
            const double d = dot(Vec3d(axes[i]), Vec3d(axes[j])) - (i == j ? 1.0 : 0.0);
            if (!(std::fabs(d) <= tol)) return false;
        }
    }
    return true;
}
template <class T>
void put_axes(ByteWriter& w, const Mat3<T>& m) {
    for (std::size_t i = 0; i < 3; ++i) put_vec(w, m[i]);
}
template <class T>
Mat3<T> get_axes(ByteReader& r) {
    Mat3<T> m;
    for (std::size_t i = 0; i < 3; ++i) m[i] = get_vec<T>(r);
    return m;
}

template <class T>
struct VolumeCodec<Aabb<T, 3>> {
    using V = Aabb<T, 3>;
    static constexpr VolumeCode code = VolumeCode::Aabb3;
    static constexpr std::size_t scalars = 6;
    static void put(ByteWriter& w, const V& v) { put_vec(w, v.min), put_vec(w, v.max); }
    static V get(ByteReader& r) {
        V v;
        v.min = get_vec<T>(r);
        v.max = get_vec<T>(r);
        return v;
    }
    static bool well_formed(const V& v) {
        return finite_vec(v.min) && finite_vec(v.max) && v.min[0] <= v.max[0] &&
               v.min[1] <= v.max[1] && v.min[2] <= v.max[2];
    }
    static bool contains(const V& v, const Vec3d& p, double tol) {
        for (std::size_t a = 0; a < 3; ++a)
            if (!(p[a] >= double(v.min[a]) - tol && p[a] <= double(v.max[a]) + tol)) return false;
        return true;
    }
};

template <class T>
struct VolumeCodec<Sphere<T>> {
    using V = Sphere<T>;
    static constexpr VolumeCode code = VolumeCode::Sphere;
    static constexpr std::size_t scalars = 4;
    static void put(ByteWriter& w, const V& v) { put_vec(w, v.center), w.scalar(v.radius); }
    static V get(ByteReader& r) {
        V v;
        v.center = get_vec<T>(r);
        v.radius = r.scalar<T>();
        return v;
    }
    static bool well_formed(const V& v) { return finite_vec(v.center) && size_ok(v.radius); }
    static bool contains(const V& v, const Vec3d& p, double tol) {
        return wide_length(p - Vec3d(v.center)) <= double(v.radius) + tol;
    }
};

template <class T>
struct VolumeCodec<Obb<T>> {
    using V = Obb<T>;
    static constexpr VolumeCode code = VolumeCode::Obb;
    static constexpr std::size_t scalars = 15;
    static void put(ByteWriter& w, const V& v) {
        put_vec(w, v.center), put_axes(w, v.axes), put_vec(w, v.extents);
    }
    static V get(ByteReader& r) {
        V v;
        v.center = get_vec<T>(r);
        v.axes = get_axes<T>(r);
        v.extents = get_vec<T>(r);
        return v;
    }
    static bool well_formed(const V& v) {
        return finite_vec(v.center) && orthonormal(v.axes) && size_ok(v.extents[0]) &&
               size_ok(v.extents[1]) && size_ok(v.extents[2]);
    }
    // In halves (exact outside denormals, which tol's floor covers): p - centre and its
    // projections pass DBL_MAX for a double model at the top of the range, where the halves' do
    // not.
    static bool contains(const V& v, const Vec3d& p, double tol) {
        const Vec3d q = Mat3<double>(v.axes) * (p * 0.5 - Vec3d(v.center) * 0.5);
        for (std::size_t a = 0; a < 3; ++a)
            if (!(std::fabs(q[a]) <= double(v.extents[a]) * 0.5 + tol * 0.5)) return false;
        return true;
    }
};

template <class T>
struct VolumeCodec<Rss<T>> {
    using V = Rss<T>;
    static constexpr VolumeCode code = VolumeCode::Rss;
    static constexpr std::size_t scalars = 15;
    static void put(ByteWriter& w, const V& v) {
        put_vec(w, v.center), put_axes(w, v.axes);
        w.scalar(v.half[0]), w.scalar(v.half[1]), w.scalar(v.radius);
    }
    static V get(ByteReader& r) {
        V v;
        v.center = get_vec<T>(r);
        v.axes = get_axes<T>(r);
        v.half[0] = r.scalar<T>();
        v.half[1] = r.scalar<T>();
        v.radius = r.scalar<T>();
        return v;
    }
    static bool well_formed(const V& v) {
        return finite_vec(v.center) && orthonormal(v.axes) && size_ok(v.half[0]) &&
               size_ok(v.half[1]) && size_ok(v.radius);
    }
    // In halves, as for the box.
    static bool contains(const V& v, const Vec3d& p, double tol) {
        const Vec3d q = Mat3<double>(v.axes) * (p * 0.5 - Vec3d(v.center) * 0.5);
        const double dx = std::max(std::fabs(q[0]) - double(v.half[0]) * 0.5, 0.0);
        const double dy = std::max(std::fabs(q[1]) - double(v.half[1]) * 0.5, 0.0);
        return wide_length(Vec3d(dx, dy, q[2])) <= double(v.radius) * 0.5 + tol * 0.5;
    }
};

/// The box and the swept sphere; the centre the traversals order by is the box's, derived.
template <class T>
struct VolumeCodec<ObbRss<T>> {
    using V = ObbRss<T>;
    using Box = VolumeCodec<Obb<T>>;
    using Swept = VolumeCodec<Rss<T>>;
    static constexpr VolumeCode code = VolumeCode::ObbRss;
    static constexpr std::size_t scalars = Box::scalars + Swept::scalars;
    static void put(ByteWriter& w, const V& v) { Box::put(w, v.obb), Swept::put(w, v.rss); }
    static V get(ByteReader& r) {
        V v;
        v.obb = Box::get(r);
        v.rss = Swept::get(r);
        v.center = v.obb.center;
        return v;
    }
    static bool well_formed(const V& v) {
        return Box::well_formed(v.obb) && Swept::well_formed(v.rss);
    }
    static bool contains(const V& v, const Vec3d& p, double tol) {
        return Box::contains(v.obb, p, tol) && Swept::contains(v.rss, p, tol);
    }
};

template <class T, std::size_t K>
requires(K == 14 || K == 18 || K == 26) struct VolumeCodec<Kdop<T, K>> {
    using V = Kdop<T, K>;
    static constexpr VolumeCode code =
        K == 14 ? VolumeCode::Kdop14 : (K == 18 ? VolumeCode::Kdop18 : VolumeCode::Kdop26);
    static constexpr std::size_t scalars = K;
    static void put(ByteWriter& w, const V& v) {
        for (std::size_t d = 0; d < V::slabs; ++d) w.scalar(v.lo[d]), w.scalar(v.hi[d]);
    }
    static V get(ByteReader& r) {
        V v;
        for (std::size_t d = 0; d < V::slabs; ++d) v.lo[d] = r.scalar<T>(), v.hi[d] = r.scalar<T>();
        return v;
    }
    static bool well_formed(const V& v) {
        for (std::size_t d = 0; d < V::slabs; ++d)
            if (!(bound_ok(v.lo[d], v.hi[d]))) return false;
        return true;
    }
    // The directions' lengths are at most sqrt(3): the tolerance along each is scaled by 2.
    static bool contains(const V& v, const Vec3d& p, double tol) {
        for (std::size_t d = 0; d < V::slabs; ++d) {
            double s = 0;
            for (std::size_t i = 0; i < 3; ++i) s += double(V::directions_int[d][i]) * p[i];
            if (!(s >= double(v.lo[d]) - 2 * tol && s <= double(v.hi[d]) + 2 * tol)) return false;
        }
        return true;
    }
};

/// ConvexHull<T, 16> (files hold the default cap only): the 16 point slots (unused ones zero), the
/// count as a scalar, the margin, the centre and the reach.
template <class T>
struct VolumeCodec<ConvexHull<T, 16>> {
    using V = ConvexHull<T, 16>;
    static constexpr VolumeCode code = VolumeCode::ConvexHull16;
    static constexpr std::size_t scalars = 3 * 16 + 1 + 1 + 3 + 1;
    static void put(ByteWriter& w, const V& v) {
        for (const auto& p : v.points) put_vec(w, p);
        w.scalar(T(v.count)), w.scalar(v.margin), put_vec(w, v.center), w.scalar(v.reach);
    }
    static V get(ByteReader& r) {
        V v;
        for (auto& p : v.points) p = get_vec<T>(r);
        const T count = r.scalar<T>();
        // A count that is not a whole number in [0, 16] is kept out of range for well_formed().
        v.count = count >= T(0) && count <= T(16) && count == std::floor(count)
                      ? std::uint32_t(count)
                      : std::uint32_t(17);
        v.margin = r.scalar<T>();
        v.center = get_vec<T>(r);
        v.reach = r.scalar<T>();
        return v;
    }
    /// Points, margin, centre and reach finite; the reach holds every point plus the margin (the
    /// bounding-sphere test relies on it), to the rounding of this check.
    static bool well_formed(const V& v) {
        if (v.count < 1 || v.count > 16) return false;
        if (!finite_vec(v.center) || !size_ok(v.margin) || !size_ok(v.reach)) return false;
        const double slack = 1 - 4 * double(std::numeric_limits<T>::epsilon());
        for (std::uint32_t i = 0; i < 16; ++i) {
            if (!finite_vec(v.points[i])) return false;
            if (i < v.count &&
                !(wide_length(Vec3d(v.points[i]) - Vec3d(v.center)) + double(v.margin) <=
                  double(v.reach) / slack))
                return false;
        }
        return true;
    }
    /// Around the centre and scaled by a power of two to about 1: the distance's squares would
    /// overflow double for a model at 1e155 (and sink at 1e-155).
    static bool contains(const V& v, const Vec3d& p, double tol) {
        const Vec3d c(v.center);
        double m = max_component(abs(p - c));
        for (const auto& q : v.vertices()) m = std::max(m, max_component(abs(Vec3d(q) - c)));
        const double unit = m > 0 && std::isfinite(m) ? std::ldexp(1.0, -std::ilogb(m)) : 1.0;
        std::vector<Vec3d> points;
        for (const auto& q : v.vertices()) points.push_back((Vec3d(q) - c) * unit);
        return hull_detail::distance_to_hull<double>((p - c) * unit, points) <=
               (double(v.margin) + tol) * unit;
    }
};

inline const char* volume_name(std::uint8_t code) {
    switch (VolumeCode(code)) {
        case VolumeCode::Aabb3:
            return "Aabb3";
        case VolumeCode::Aabb2:
            return "Aabb2";
        case VolumeCode::Sphere:
            return "Sphere";
        case VolumeCode::Obb:
            return "Obb";
        case VolumeCode::Rss:
            return "Rss";
        case VolumeCode::ObbRss:
            return "ObbRss";
        case VolumeCode::Kdop14:
            return "Kdop14";
        case VolumeCode::Kdop18:
            return "Kdop18";
        case VolumeCode::Kdop26:
            return "Kdop26";
        case VolumeCode::ConvexHull16:
            return "ConvexHull16";
    }
    return "unknown";
}

struct CollisionModelAccess {
    static constexpr const char* what = "CollisionModel file";

    template <class V>
    static std::vector<std::uint8_t> save(const CollisionModel<V>& model) {
        using T = typename V::Scalar;
        using Codec = VolumeCodec<V>;
        const auto& bvh = model.bvh_;
        const std::size_t slots = bvh.primitive_indices.size();
        ByteWriter w;
        w.reserve(bvh.nodes.size() * (Codec::scalars * sizeof(T) + 8) +
                  slots * (4 + 9 * sizeof(T) + 12) + model.report_.skipped.size() * 4 + 64);
        for (const auto& n : bvh.nodes) {
            Codec::put(w, n.bounds);
            w.u32(n.first);
            w.u32(n.count);
        }
        w.pad(8);
        put_u32s(w, bvh.primitive_indices);
        put_corners<T>(w, model.slot_triangles_);
        for (const auto& ids : model.slot_vertex_ids_)
            for (const std::uint32_t id : ids) w.u32(id);
        w.pad(8);
        put_u32s(w, model.report_.skipped);
        w.scalar(model.scale_);
        w.pad(8);
        TreeFileHeader h;
        h.kind = FileKind::CollisionModel;
        h.scalar = scalar_code<T>();
        h.volume = Codec::code;
        h.layout = 1;  // corners
        h.counts = {bvh.nodes.size(), slots, model.report_.skipped.size(), model.triangle_count_};
        return seal_tree_file(h, w.bytes());
    }

    template <class V>
    static CollisionModel<V> load(std::span<const std::uint8_t> file, const LoadOptions& options) {
        using T = typename V::Scalar;
        using Codec = VolumeCodec<V>;
        const auto fail = [&](const std::string& m) { throw Error(std::string(what) + ": " + m); };
        const OpenedTreeFile f = open_tree_file(file, FileKind::CollisionModel, what);
        const TreeFileHeader& h = f.header;
        if (h.scalar != scalar_code<T>())
            fail(std::string("the file holds a ") + scalar_name(std::uint8_t(h.scalar)) +
                 " model, loaded as " + scalar_name(std::uint8_t(scalar_code<T>())));
        if (h.volume != Codec::code)
            fail(std::string("the file holds a model with bounding volume ") +
                 volume_name(std::uint8_t(h.volume)) + " (code " + std::to_string(int(h.volume)) +
                 "), loaded as " + volume_name(std::uint8_t(Codec::code)));
        if (h.layout != 1) fail("unknown triangle layout " + std::to_string(int(h.layout)));
        const auto [node_count, slot_count, skipped_count, triangle_count] = h.counts;
        // Each count against the payload before it is multiplied or allocated.
        const std::uint64_t limit = h.payload_size;
        const std::uint64_t expected =
            section_bytes(node_count, Codec::scalars * sizeof(T) + 8, limit, what, "node") +
            section_bytes(slot_count, 4, limit, what, "slot") +
            section_bytes(slot_count, 9 * sizeof(T), limit, what, "triangle") +
            section_bytes(slot_count, 12, limit, what, "vertex id") +
            section_bytes(skipped_count, 4, limit, what, "skipped") + 8;
        if (expected != limit)
            fail("the counts need " + std::to_string(expected) + " payload bytes, the file has " +
                 std::to_string(limit));
        if (node_count > 0xffffffffu || slot_count > 0xffffffffu)
            fail("more than 2^32 - 1 nodes or slots");
        if (triangle_count != slot_count + skipped_count)
            fail("triangle count " + std::to_string(triangle_count) + " is not slots (" +
                 std::to_string(slot_count) + ") + skipped (" + std::to_string(skipped_count) +
                 ")");

        ByteReader r(f.payload, what);
        CollisionModel<V> model;
        auto& bvh = model.bvh_;
        bvh.nodes.resize(std::size_t(node_count));
        for (auto& n : bvh.nodes) {
            n.bounds = Codec::get(r);
            n.first = r.u32();
            n.count = r.u32();
        }
        r.skip_padding(8);
        get_u32s(r, bvh.primitive_indices, slot_count);
        get_corners(r, model.slot_triangles_, slot_count);
        model.slot_vertex_ids_.resize(std::size_t(slot_count));
        for (auto& ids : model.slot_vertex_ids_)
            for (std::uint32_t& id : ids) id = r.u32();
        r.skip_padding(8);
        auto& skipped = model.report_.skipped;
        get_u32s(r, skipped, skipped_count);
        model.scale_ = r.scalar<T>();
        r.skip_padding(8);
        model.triangle_count_ = std::size_t(triangle_count);

        check_tree_structure(bvh, triangle_count, what);
        check_skipped(skipped, triangle_count, what);
        // +inf is what scale_of() gives a model whose extent passes T's largest finite value.
        if (!(model.scale_ >= T(0))) fail("the scale is negative or NaN");
        // The exact triangle tests of collide() need finite coordinates (a NaN or an infinity
        // breaks the expansions' bounds): checked always, like an index. Any finite coordinate
        // is what a build keeps, and the predicates answer 0 where their products overflow
        // (math/predicates.hpp), so no tighter limit.
        for (std::size_t s = 0; s < model.slot_triangles_.size(); ++s)
            for (const Vec<T, 3>& p : {model.slot_triangles_[s].p0, model.slot_triangles_[s].p1,
                                       model.slot_triangles_[s].p2})
                if (!finite_vec(p))
                    fail("the triangle in slot " + std::to_string(s) + " is not finite");
        if (options.validate) validate_model(model, fail);
        return model;
    }

    /// scale() computed in double: largest |coordinate| plus the box's diagonal.
    template <class T>
    static double wide_scale(std::span<const Triangle<T>> tris) {
        Aabb<T, 3> box;
        for (const Triangle<T>& t : tris) box.grow(t.p0).grow(t.p1).grow(t.p2);
        if (box.is_empty()) return 0;
        return double(max_component(bvhkit::max(box.max, -box.min))) +
               wide_length(Vec3d(box.max) - Vec3d(box.min));
    }

    /// What the builder guarantees of a model (the structure was checked already).
    template <class V, class Fail>
    static void validate_model(const CollisionModel<V>& model, Fail&& fail) {
        using T = typename V::Scalar;
        using Codec = VolumeCodec<V>;
        const auto& bvh = model.bvh_;
        const auto& tris = model.slot_triangles_;
        // Each triangle once: in one slot, or skipped (which the counts make the rest).
        std::vector<std::uint8_t> seen(model.triangle_count_, 0);
        for (const std::uint32_t p : bvh.primitive_indices)
            if (seen[p]++) fail("triangle " + std::to_string(p) + " is in two slots");
        for (const std::uint32_t p : model.report_.skipped)
            if (seen[p]) fail("triangle " + std::to_string(p) + " is skipped but in the tree");
        const T scale = CollisionModel<V>::scale_of(tris);
        if (std::memcmp(&scale, &model.scale_, sizeof(T)) != 0)
            fail("the scale is not the one the triangles give");
        // Each node's volume around every vertex under it: the run of slots below a node, from
        // the leaves up (children after parents, as check_tree_structure made sure).
        // The scale in double (finite for every float model) and an absolute floor for the
        // rounding of coordinates in denormals, where the fits' relative pads vanish.
        const double tol = double(std::numeric_limits<T>::epsilon()) * 16 * wide_scale<T>(tris) +
                           64 * double(std::numeric_limits<T>::denorm_min());
        const auto runs = node_slot_runs(bvh);
        std::vector<std::uint32_t> below(bvh.nodes.size(), 0);  // slots under each node
        for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
            const auto& node = bvh.nodes[n];
            below[n] = node.is_leaf() ? node.count : below[node.left()] + below[node.right()];
            if (runs[n].second - runs[n].first != below[n])
                fail("node " + std::to_string(n) + ": the slots under it are not contiguous");
        }
        for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
            const V& v = bvh.nodes[n].bounds;
            if (!Codec::well_formed(v))
                fail("node " + std::to_string(n) +
                     ": the volume is not finite, has a negative size or axes that are not "
                     "orthonormal");
            for (std::uint32_t s = runs[n].first; s < runs[n].second; ++s)
                for (const Vec<T, 3>& p : {tris[s].p0, tris[s].p1, tris[s].p2})
                    if (!Codec::contains(v, Vec3d(p), tol))
                        fail("node " + std::to_string(n) + " does not contain triangle " +
                             std::to_string(bvh.primitive_indices[s]));
        }
    }
};

}  // namespace serial_detail

/// The model as a file's bytes (to write elsewhere, or to pickle).
template <BoundingVolume V>
std::vector<std::uint8_t> to_bytes(const CollisionModel<V>& model) {
    return serial_detail::CollisionModelAccess::save(model);
}

template <BoundingVolume V>
void save(const CollisionModel<V>& model, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(model));
}

/// A model from bytes written by to_bytes / save; V (volume and scalar type) must match the file's.
template <BoundingVolume V>
CollisionModel<V> collision_model_from_bytes(std::span<const std::uint8_t> bytes,
                                             const LoadOptions& options = {}) {
    return serial_detail::CollisionModelAccess::load<V>(bytes, options);
}

template <BoundingVolume V>
CollisionModel<V> load_collision_model(const std::filesystem::path& path,
                                       const LoadOptions& options = {}) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return collision_model_from_bytes<V>(bytes, options);
    });
}

}  // namespace bvhkit
