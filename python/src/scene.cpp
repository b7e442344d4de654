// Scene<T>: one triangle mesh with every query on it. Rays go to a TriangleBvh built at once; the
// proximity structures (SignedDistanceMesh, which holds the ClosestPointMesh, and
// WindingNumberMesh) are built on first use, so a user of rays alone never pays for them.
//
// One set of faces for every structure: the faces the ray tree left out at the build (a NaN or
// infinite coordinate then) stay out of every query for the scene's life, as TriangleBvh::refit
// keeps them out of the ray tree. A refit that makes them finite does not bring them back into
// the proximity structures rebuilt after it (MeshWithoutTriangles, primitives/triangle_mesh.hpp),
// so rays, closest points, signed distances and winding numbers always see the same faces; a
// refit that gives a face of the set a non-finite coordinate is refused (TriangleBvh::refit).
//
// Thread safety: queries hold a shared lock, refit an exclusive one, so Python threads may call
// anything at any time (the GIL is released during the work).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>
#include <vector>

#include <nanobind/stl/optional.h>

#include "bvhkit/build/options.hpp"
#include "bvhkit/bvh/statistics.hpp"
#include "bvhkit/io/byte_codec.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/primitives/weld.hpp"
#include "bvhkit/query/crossings.hpp"
#include "bvhkit/query/point_order.hpp"
#include "bvhkit/query/signed_distance.hpp"
#include "bvhkit/query/winding_number.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "common.hpp"

namespace bvhkit::python {
namespace {

template <class T>
Vec<T, 3> row(const T* p, std::size_t i) {
    return {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
}

template <class T>
class Scene {
  public:
    /// `spatial_splits` "on": the ray tree is the high-quality build (TriangleBvhOptions::
    /// spatial_splits), which needs the binned SAH builder without the optimizer; "auto": that
    /// build where the default tree's boxes overlap enough to pay (TriangleBvhOptions::
    /// auto_spatial_splits; with another builder the default build); "off": the default build.
    Scene(const Rows<T, 3>& vertices, const Faces& faces, const std::string& builder,
          const std::string& ray_test, unsigned threads, const std::string& spatial_splits)
        : mesh_(make_mesh<T>(vertices, faces)), options_(parse_builder(builder)) {
        if (ray_test != "fast" && ray_test != "watertight")
            throw Error("ray_test: '" + ray_test + "' is not one of 'fast', 'watertight'");
        if (spatial_splits != "off" && spatial_splits != "on" && spatial_splits != "auto")
            throw Error("spatial_splits: '" + spatial_splits +
                        "' is not one of 'off', 'on', 'auto'");
        options_.threads = threads;
        nb::gil_scoped_release release;
        build_rays(ray_test == "fast", spatial_splits == "on", {}, spatial_splits == "auto");
    }

    /// A scene from the parts state() gave (bvhkit/_scene_file.py holds them in one container):
    /// the trees are loaded from their files, checked as every load is, and must cover exactly
    /// the mesh's faces. Nothing is rebuilt, except a ray tree with spatial splits, which has no
    /// file format: `tree` then lists the faces left out of it (u32, ascending) and the tree is
    /// built again without them, with `fast` for its ray test (the build is serial and
    /// deterministic: the same tree unless the mesh was refitted). Any failure is a
    /// bvhkit::Error (ValueError).
    Scene(const Rows<T, 3>& vertices, const Faces& faces, const std::string& builder,
          unsigned threads, const nb::bytes& tree, const std::optional<nb::bytes>& sdf,
          const std::optional<nb::bytes>& winding, bool spatial_splits, bool fast)
        : mesh_(make_mesh<T>(vertices, faces)), options_(parse_builder(builder)) {
        options_.threads = threads;
        const auto span = [](const nb::bytes& b) {
            return std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(b.c_str()),
                                                 b.size());
        };
        const std::size_t nt = mesh_.triangles.size();
        const auto check = [&](std::size_t count, const char* what) {
            if (count != nt)
                throw Error(std::string(what) + ": covers " + std::to_string(count) +
                            " faces, the mesh has " + std::to_string(nt));
        };
        // The bytes objects stay referenced by the caller and are immutable: safe without the GIL.
        const auto tree_bytes = span(tree);
        const std::optional<std::span<const std::uint8_t>> sdf_bytes =
            sdf ? std::optional(span(*sdf)) : std::nullopt;
        const std::optional<std::span<const std::uint8_t>> winding_bytes =
            winding ? std::optional(span(*winding)) : std::nullopt;
        nb::gil_scoped_release release;
        if (spatial_splits) {
            const std::vector<std::uint32_t> left_out = read_left_out(tree_bytes, nt);
            build_rays(fast, true, left_out);
            if (!std::ranges::equal(rays_.skipped(), left_out))
                throw Error("ray tree: the faces left out are not the ones the data lists (" +
                            std::to_string(rays_.skipped().size()) + " against " +
                            std::to_string(left_out.size()) + ")");
        } else {
            rays_ = triangle_bvh_from_bytes<T>(tree_bytes);
        }
        check(rays_.triangle_count(), "ray tree");
        if (sdf_bytes) {
            sdf_ = std::make_unique<SignedDistanceMesh<T>>(
                signed_distance_mesh_from_bytes<T>(*sdf_bytes));
            check(sdf_->closest_point_mesh().triangle_count(), "signed distance tree");
        }
        if (winding_bytes)
            winding_ = std::make_unique<WindingNumberMesh<T>>(
                winding_number_mesh_from_bytes<T>(*winding_bytes));
    }

    using Ray3 = Ray<T, 3>;
    /// Calls per_chunk(first, rays) for runs of up to ray_chunk rays, rays[j] the batch's ray
    /// first + j: the tree's stream calls walk several at once (query/ray_stream.hpp).
    static constexpr std::size_t ray_chunk = 256;
    using PerRayLimits = bvhkit::python::PerRayLimits<T>;
    using SharedLimits = bvhkit::python::SharedLimits<T>;
    template <class PerChunk>
    void ray_chunks(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Column<T>& tmin,
                    const Column<T>& tmax, unsigned threads, PerChunk&& per_chunk) const {
        expect_rows(tmin, origins.shape(0), "tmin");
        expect_rows(tmax, origins.shape(0), "tmax");
        ray_chunks(origins, directions, PerRayLimits{tmin.data(), tmax.data()}, threads, per_chunk);
    }
    template <class Limits, class PerChunk>
    void ray_chunks(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Limits& limits,
                    unsigned threads, PerChunk&& per_chunk) const {
        const std::size_t k = origins.shape(0);
        expect_rows(directions, k, "directions");
        const T *o = origins.data(), *d = directions.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        run_batch(k, 1024, threads, [&](std::size_t b, std::size_t e) {
            Ray3 chunk[ray_chunk];
            for (std::size_t first = b; first < e; first += ray_chunk) {
                const std::size_t n = std::min(ray_chunk, e - first);
                for (std::size_t j = 0; j < n; ++j) {
                    const std::size_t i = first + j;
                    chunk[j] = Ray3(row(o, i), row(d, i), limits.tmin(i), limits.tmax(i));
                }
                per_chunk(first, std::span<const Ray3>(chunk, n));
            }
        });
    }

    void intersect(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Column<T>& tmin,
                   const Column<T>& tmax, OutColumn<T> t, OutColumn<std::int64_t> face,
                   OutRows<T, 3> barycentric, unsigned threads) const {
        expect_rows(tmin, origins.shape(0), "tmin");
        expect_rows(tmax, origins.shape(0), "tmax");
        intersect_within(origins, directions, PerRayLimits{tmin.data(), tmax.data()}, t, face,
                         barycentric, threads);
    }
    /// intersect for rays their caller knows to be coherent: every 32 consecutive rays walk as
    /// one packet (TriangleBvh::trace_packets); the same answers.
    void intersect_packets(const Rows<T, 3>& origins, const Rows<T, 3>& directions,
                           const Column<T>& tmin, const Column<T>& tmax, OutColumn<T> t,
                           OutColumn<std::int64_t> face, OutRows<T, 3> barycentric,
                           unsigned threads) const {
        expect_rows(tmin, origins.shape(0), "tmin");
        expect_rows(tmax, origins.shape(0), "tmax");
        intersect_within(origins, directions, PerRayLimits{tmin.data(), tmax.data()}, t, face,
                         barycentric, threads, true);
    }
    /// intersect with one [tmin, tmax] for every ray.
    void intersect_shared(const Rows<T, 3>& origins, const Rows<T, 3>& directions, T tmin, T tmax,
                          OutColumn<T> t, OutColumn<std::int64_t> face, OutRows<T, 3> barycentric,
                          unsigned threads) const {
        intersect_within(origins, directions, SharedLimits{tmin, tmax}, t, face, barycentric,
                         threads);
    }
    template <class Limits>
    void intersect_within(const Rows<T, 3>& origins, const Rows<T, 3>& directions,
                          const Limits& limits, OutColumn<T> t, OutColumn<std::int64_t> face,
                          OutRows<T, 3> barycentric, unsigned threads, bool packets = false) const {
        expect_rows(t, origins.shape(0), "t");
        expect_rows(face, origins.shape(0), "face");
        expect_rows(barycentric, origins.shape(0), "barycentric");
        T *tp = t.data(), *bp = barycentric.data();
        std::int64_t* fp = face.data();
        ray_chunks(origins, directions, limits, threads,
                   [&](std::size_t first, std::span<const Ray3> chunk) {
                       Hit<T> hits[ray_chunk];
                       const std::span<Hit<T>> out(hits, chunk.size());
                       if (packets)
                           rays_.trace_packets(chunk, out, 1u);
                       else
                           rays_.trace_on_calling_thread(chunk, out);
                       for (std::size_t j = 0; j < chunk.size(); ++j) {
                           const Hit<T>& h = hits[j];
                           const std::size_t i = first + j;
                           tp[i] = h ? h.t : std::numeric_limits<T>::infinity();
                           fp[i] = h ? std::int64_t(h.primitive) : -1;
                           bp[3 * i] = h ? T(1) - h.u - h.v : T(0);
                           bp[3 * i + 1] = h.u;
                           bp[3 * i + 2] = h.v;
                       }
                   });
    }
    void occluded(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Column<T>& tmin,
                  const Column<T>& tmax, OutColumn<bool> out, unsigned threads) const {
        expect_rows(out, origins.shape(0), "out");
        bool* op = out.data();
        ray_chunks(origins, directions, tmin, tmax, threads,
                   [&](std::size_t first, std::span<const Ray3> chunk) {
                       std::uint8_t flags[ray_chunk];
                       rays_.occluded_stream(chunk, std::span<std::uint8_t>(flags, chunk.size()));
                       for (std::size_t j = 0; j < chunk.size(); ++j) op[first + j] = flags[j] != 0;
                   });
    }
    void count_intersections(const Rows<T, 3>& origins, const Rows<T, 3>& directions,
                             const Column<T>& tmin, const Column<T>& tmax,
                             OutColumn<std::int64_t> out, unsigned threads) const {
        expect_rows(out, origins.shape(0), "out");
        std::int64_t* op = out.data();
        ray_chunks(origins, directions, tmin, tmax, threads,
                   [&](std::size_t first, std::span<const Ray3> chunk) {
                       for (std::size_t j = 0; j < chunk.size(); ++j) {
                           std::int64_t n = 0;
                           rays_.all_hits(chunk[j], [&](const Hit<T>&) { return ++n, true; });
                           op[first + j] = n;
                       }
                   });
    }

    /// A thread's storage for point queries: the walk's, and the previous point's closest point,
    /// which the next walk starts from (the points come in spatial order).
    struct PointScratch {
        NearestScratch<T> nearest;
        MeshPoint<T> previous;
    };
    /// Calls per_point(i, p, scratch) for each point, on `threads` threads, without the GIL.
    /// Batches of up to this many points run on the calling thread (see points()).
    static constexpr std::size_t small_batch = 8;
    /// Which point queries need the winding number tree: inside() on a closed surface asks the
    /// ray tree instead.
    enum class WindingTree { not_needed, needed, unless_closed };
    template <class PerPoint>
    void points(const Rows<T, 3>& pts, unsigned threads, bool need_sdf, WindingTree need_winding,
                PerPoint&& per_point) const {
        const T* p = pts.data();
        const std::size_t k = pts.shape(0);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        prepare(need_sdf, need_winding);
        if (k <= small_batch) {
            // A few points (a planner's one-point calls): no order to find, no batch to spread,
            // and the calling thread's scratch, whose heap has grown already. The previous
            // closest point is another call's (maybe another mesh's): never a start.
            thread_local PointScratch scratch;
            scratch.previous = {};
            for (std::size_t i = 0; i < k; ++i) per_point(i, row(p, i), scratch);
            return;
        }
        // A large batch is answered in spatial order (bvhkit/query/point_order.hpp): neighbours
        // find the tree's nodes in cache. Each point's answer is its own, whatever the order.
        const std::vector<std::uint32_t> order = batch_order(
            k, [&](std::size_t i) { return row(p, i); }, BatchExecutor{threads});
        run_batch(k, 256, threads, [&](std::size_t b, std::size_t e) {
            PointScratch scratch;
            for (std::size_t j = b; j < e; ++j) per_point(order[j], row(p, order[j]), scratch);
        });
    }

    void closest_point(const Rows<T, 3>& pts, double max_distance, OutColumn<T> distance,
                       OutRows<T, 3> closest, OutColumn<std::int64_t> face,
                       OutRows<T, 3> barycentric, unsigned threads) const {
        const std::size_t k = pts.shape(0);
        expect_rows(distance, k, "distance");
        expect_rows(closest, k, "closest");
        expect_rows(face, k, "face");
        expect_rows(barycentric, k, "barycentric");
        T *dp = distance.data(), *cp = closest.data(), *bp = barycentric.data();
        std::int64_t* fp = face.data();
        points(pts, threads, true, WindingTree::not_needed,
               [&](std::size_t i, const Vec<T, 3>& p, auto& scratch) {
                   // The limit itself, in double, not its square in T (inf past 1.8e19 in float32).
                   const MeshPoint<T> c = scratch.previous =
                       sdf_->closest_point_mesh().closest_point_within(
                           p, max_distance, scratch.previous, scratch.nearest);
                   const T nan = std::numeric_limits<T>::quiet_NaN();
                   dp[i] = c ? c.distance : std::numeric_limits<T>::infinity();
                   for (int a = 0; a < 3; ++a) cp[3 * i + a] = c ? c.point[a] : nan;
                   fp[i] = c ? std::int64_t(c.triangle) : -1;
                   bp[3 * i] = c ? T(1) - c.u - c.v : T(0);
                   bp[3 * i + 1] = c.u;
                   bp[3 * i + 2] = c.v;
               });
    }
    void signed_distance(const Rows<T, 3>& pts, const std::string& sign, OutColumn<T> out,
                         unsigned threads) const {
        expect_rows(out, pts.shape(0), "out");
        T* op = out.data();
        if (sign == "pseudonormal") {
            points(pts, threads, true, WindingTree::not_needed,
                   [&](std::size_t i, const Vec<T, 3>& p, auto& scratch) {
                       const SignedDistance<T> r =
                           sdf_->signed_distance(p, scratch.previous, scratch.nearest);
                       scratch.previous = r.closest;
                       op[i] = r.distance;
                   });
        } else if (sign == "winding_number") {
            // On a closed surface the sign is contains()'s: one ray's crossings.
            points(pts, threads, true, WindingTree::unless_closed,
                   [&](std::size_t i, const Vec<T, 3>& p, auto& scratch) {
                       const MeshPoint<T> c = scratch.previous =
                           sdf_->closest_point_mesh().closest_point(p, scratch.previous,
                                                                    scratch.nearest);
                       const T d = c ? c.distance : std::numeric_limits<T>::infinity();
                       op[i] = inside(p) ? -d : d;
                   });
        } else {
            throw Error("sign: '" + sign + "' is not one of 'pseudonormal', 'winding_number'");
        }
    }
    void winding_number(const Rows<T, 3>& pts, bool exact, T beta, OutColumn<T> out,
                        unsigned threads) const {
        expect_rows(out, pts.shape(0), "out");
        T* op = out.data();
        points(pts, threads, false, WindingTree::needed,
               [&](std::size_t i, const Vec<T, 3>& p, auto&) {
                   op[i] = exact ? winding_->exact(p) : winding_->fast(p, beta);
               });
    }

    /// Whether each point is inside (winding number above 1/2). On a closed oriented surface
    /// traced by the watertight test (is_closed()), one ray's signed crossings give the winding
    /// number (query/crossings.hpp); where they cannot decide, and on other meshes, the fast
    /// winding number does.
    void contains(const Rows<T, 3>& pts, OutColumn<bool> out, unsigned threads) const {
        expect_rows(out, pts.shape(0), "out");
        bool* op = out.data();
        points(pts, threads, false, WindingTree::unless_closed,
               [&](std::size_t i, const Vec<T, 3>& p, auto&) { op[i] = inside(p); });
    }
    /// Whether contains() decides by ray crossings: the faces of the ray tree form a closed
    /// oriented surface and its ray test is watertight.
    bool is_closed() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        const std::lock_guard<std::mutex> build_lock(build_mutex_);
        return closed_surface();
    }

    void refit(const Rows<T, 3>& vertices) {
        if (vertices.shape(0) != mesh_.vertices.size())
            throw Error("vertices: " + std::to_string(vertices.shape(0)) + " rows, the scene has " +
                        std::to_string(mesh_.vertices.size()));
        const T* v = vertices.data();
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        refit_vertices(mesh_.vertices, v, [&] { rays_.refit(mesh_); });
        // The proximity structures are rebuilt when next asked for, over the same faces as the
        // ray tree (prepare()).
        sdf_.reset();
        winding_.reset();
        closed_.reset();  // welding is by position, which the refit changed
    }

    nb::dict stats() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        const BvhStatistics s = statistics(rays_.bvh());
        nb::dict d;
        d["triangles"] = rays_.triangle_count();
        d["skipped"] = rays_.skipped().size();
        d["nodes"] = s.node_count;
        d["leaves"] = s.leaf_count;
        d["depth"] = s.depth;
        d["average_leaf_size"] = s.average_leaf_size();
        d["sah_cost"] = s.sah_cost;
        d["builder"] = to_string(options_.builder);
        d["spatial_splits"] = spatial_splits_;
        d["references"] = s.primitive_count;  // above the triangles where splits cut some
        return d;
    }
    nb::ndarray<nb::numpy, std::int64_t> skipped() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        std::vector<std::int64_t> s(rays_.skipped().begin(), rays_.skipped().end());
        const std::size_t n = s.size();
        return owned_array(std::move(s), n, 0);
    }
    std::size_t triangle_count() const { return mesh_.triangles.size(); }

    /// What the loading constructor takes: (vertices, faces int64, ray_test, ray tree file bytes
    /// (with spatial splits, the faces left out of the tree as u32), signed distance file bytes or
    /// None, winding number file bytes or None, spatial_splits), the proximity files only where
    /// those structures have been built. One consistent snapshot.
    nb::tuple state() const {
        std::vector<T> v;
        std::vector<std::int64_t> f;
        std::vector<std::uint8_t> tree, sdf, winding;
        bool has_sdf = false, has_winding = false, fast = false;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            const std::lock_guard<std::mutex> build_lock(build_mutex_);  // sdf_, winding_ stable
            v.reserve(3 * mesh_.vertices.size());
            for (const auto& p : mesh_.vertices) v.insert(v.end(), {p[0], p[1], p[2]});
            f.reserve(3 * mesh_.triangles.size());
            for (const auto& t : mesh_.triangles) f.insert(f.end(), {t[0], t[1], t[2]});
            fast = rays_.triangle_test() == TriangleTest::Fast;
            if (spatial_splits_) {
                serial_detail::ByteWriter out;  // little-endian, whatever this machine's order
                for (const std::uint32_t face : rays_.skipped()) out.u32(face);
                tree = std::move(out.bytes());
            } else {
                tree = to_bytes(rays_);
            }
            if ((has_sdf = bool(sdf_))) sdf = to_bytes(*sdf_);
            if ((has_winding = bool(winding_))) winding = to_bytes(*winding_);
        }
        const auto bytes = [](const std::vector<std::uint8_t>& b) {
            return nb::bytes(reinterpret_cast<const char*>(b.data()), b.size());
        };
        const std::size_t nv = mesh_.vertices.size(), nf = mesh_.triangles.size();
        return nb::make_tuple(owned_array(std::move(v), nv, 3), owned_array(std::move(f), nf, 3),
                              fast ? "fast" : "watertight", bytes(tree),
                              has_sdf ? nb::object(bytes(sdf)) : nb::none(),
                              has_winding ? nb::object(bytes(winding)) : nb::none(),
                              spatial_splits_);
    }

  private:
    /// The ray tree over the mesh, by the scene's builder, without the faces of `left_out` (the
    /// caller has released the GIL).
    void build_rays(bool fast, bool spatial_splits, std::span<const std::uint32_t> left_out = {},
                    bool auto_splits = false) {
        TriangleBvhOptions ray_options(options_);
        ray_options.triangle_test = fast ? TriangleTest::Fast : TriangleTest::Watertight;
        ray_options.spatial_splits = spatial_splits;
        ray_options.auto_spatial_splits = auto_splits;
        if (left_out.empty()) {
            rays_ = TriangleBvh<T>(mesh_, ray_options);
        } else {
            // A NaN corner leaves a face out, as it left it out of the tree that was saved.
            std::vector<Triangle<T>> triangles(mesh_.triangles.size());
            for (std::size_t i = 0; i < triangles.size(); ++i)
                triangles[i] = triangle_at<T>(mesh_, i);
            for (const std::uint32_t face : left_out)
                triangles[face].p0[0] = std::numeric_limits<T>::quiet_NaN();
            rays_ = TriangleBvh<T>(triangles, ray_options);
        }
        // An automatic choice that kept the split tree is saved and loaded as a forced one: the
        // same options, and the build is deterministic.
        spatial_splits_ = spatial_splits || rays_.has_split_references();
    }

    /// The faces a spatial-split scene's data says were left out of its ray tree: u32
    /// little-endian, ascending, each below `faces`.
    static std::vector<std::uint32_t> read_left_out(std::span<const std::uint8_t> bytes,
                                                    std::size_t faces) {
        if (bytes.size() % 4 != 0)
            throw Error("ray tree: the list of faces left out has " + std::to_string(bytes.size()) +
                        " bytes, not a multiple of 4");
        serial_detail::ByteReader in(bytes, "ray tree");
        std::vector<std::uint32_t> left_out(bytes.size() / 4);
        for (std::size_t k = 0; k < left_out.size(); ++k) {
            const std::uint32_t face = in.u32();
            if (face >= faces || (k > 0 && face <= left_out[k - 1]))
                throw Error("ray tree: the faces left out are not ascending face indices below " +
                            std::to_string(faces));
            left_out[k] = face;
        }
        return left_out;
    }

    /// Builds what a query needs, once (the caller holds the shared lock; builders take this one),
    /// over the ray tree's faces: those it left out stay out even if a refit made them finite.
    void prepare(bool need_sdf, WindingTree winding) const {
        const std::lock_guard<std::mutex> lock(build_mutex_);
        const bool need_winding = winding == WindingTree::needed ||
                                  (winding == WindingTree::unless_closed && !closed_surface());
        if ((!need_sdf || sdf_) && (!need_winding || winding_)) return;
        const auto build = [&](const auto& mesh) {
            if (need_sdf && !sdf_) sdf_ = std::make_unique<SignedDistanceMesh<T>>(mesh, options_);
            if (need_winding && !winding_)
                winding_ = std::make_unique<WindingNumberMesh<T>>(mesh, options_);
        };
        if (rays_.skipped().empty())
            build(mesh_);
        else
            build(MeshWithoutTriangles<T>(mesh_, rays_.skipped()));
    }

    /// is_closed(), found once (the caller holds the shared lock and build_mutex_).
    bool closed_surface() const {
        if (!closed_)
            closed_ = rays_.triangle_test() == TriangleTest::Watertight &&
                      is_closed_surface(mesh_, weld_vertices(mesh_),
                                        std::vector<std::uint32_t>(rays_.skipped().begin(),
                                                                   rays_.skipped().end()));
        return *closed_;
    }
    /// Whether p is inside (winding number above 1/2): by ray crossings on a closed surface, by
    /// the fast winding number where they cannot decide (rare, so its tree is built on the first
    /// such point) and on other meshes (the caller has prepared the winding number tree then).
    /// The caller holds the shared lock.
    bool inside(const Vec<T, 3>& p) const {
        if (*closed_) {  // set by prepare(), which points() called under this shared lock
            if (const std::optional<int> w = crossing_winding_number(rays_, p)) return *w >= 1;
            prepare(false, WindingTree::needed);
        }
        return winding_->inside(p);
    }

    BasicTriangleMesh<T> mesh_;
    BuildOptions options_;
    TriangleBvh<T> rays_;
    bool spatial_splits_ = false;  // rays_ is the high-quality build (rebuilt on loading)
    mutable std::unique_ptr<SignedDistanceMesh<T>> sdf_;
    mutable std::unique_ptr<WindingNumberMesh<T>> winding_;
    mutable std::optional<bool> closed_;
    mutable std::shared_mutex mutex_;
    mutable std::mutex build_mutex_;
};

template <class T>
void bind_scene_type(nb::module_& m, const char* name) {
    using S = Scene<T>;
    nb::class_<S>(m, name,
                  "A triangle mesh ready for ray and proximity queries (see bvhkit.TriangleMesh).")
        .def(nb::init<const Rows<T, 3>&, const Faces&, const std::string&, const std::string&,
                      unsigned, const std::string&>(),
             nb::arg("vertices"), nb::arg("faces"), nb::arg("builder"), nb::arg("ray_test"),
             nb::arg("threads"), nb::arg("spatial_splits"), "Builds the ray tree over the mesh.")
        .def(nb::init<const Rows<T, 3>&, const Faces&, const std::string&, unsigned,
                      const nb::bytes&, const std::optional<nb::bytes>&,
                      const std::optional<nb::bytes>&, bool, bool>(),
             nb::arg("vertices"), nb::arg("faces"), nb::arg("builder"), nb::arg("threads"),
             nb::arg("tree"), nb::arg("sdf").none(), nb::arg("winding").none(),
             nb::arg("spatial_splits"), nb::arg("fast"),
             "Loads the scene from the parts state() gave (only a spatial-split ray tree is "
             "rebuilt).")
        .def("state", &S::state, "The mesh and the built trees' files, for saving.")
        .def("intersect", &S::intersect, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("t"), nb::arg("face"), nb::arg("barycentric"),
             nb::arg("threads"), "Closest hit of each ray into the output arrays.")
        .def("intersect_shared", &S::intersect_shared, nb::arg("origins"), nb::arg("directions"),
             nb::arg("tmin"), nb::arg("tmax"), nb::arg("t"), nb::arg("face"),
             nb::arg("barycentric"), nb::arg("threads"),
             "intersect with one [tmin, tmax] for every ray.")
        .def("intersect_packets", &S::intersect_packets, nb::arg("origins"), nb::arg("directions"),
             nb::arg("tmin"), nb::arg("tmax"), nb::arg("t"), nb::arg("face"),
             nb::arg("barycentric"), nb::arg("threads"),
             "intersect for coherent rays, 32 consecutive rays a packet.")
        .def("occluded", &S::occluded, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("out"), nb::arg("threads"),
             "Whether each ray hits anything within [tmin, tmax].")
        .def("count_intersections", &S::count_intersections, nb::arg("origins"),
             nb::arg("directions"), nb::arg("tmin"), nb::arg("tmax"), nb::arg("out"),
             nb::arg("threads"), "The number of triangles each ray hits within [tmin, tmax].")
        .def("closest_point", &S::closest_point, nb::arg("points"), nb::arg("max_distance"),
             nb::arg("distance"), nb::arg("closest"), nb::arg("face"), nb::arg("barycentric"),
             nb::arg("threads"), "Closest point of the mesh to each point.")
        .def("signed_distance", &S::signed_distance, nb::arg("points"), nb::arg("sign"),
             nb::arg("out"), nb::arg("threads"), "Signed distance of each point (negative inside).")
        .def("winding_number", &S::winding_number, nb::arg("points"), nb::arg("exact"),
             nb::arg("beta"), nb::arg("out"), nb::arg("threads"),
             "Generalized winding number of each point.")
        .def("contains", &S::contains, nb::arg("points"), nb::arg("out"), nb::arg("threads"),
             "Whether each point is inside (winding number above 1/2).")
        .def("is_closed", &S::is_closed,
             "Whether contains() decides by ray crossings (a closed oriented surface).")
        .def("refit", &S::refit, nb::arg("vertices"), "New vertex positions, same faces.")
        .def("stats", &S::stats, "Tree statistics of the ray tree.")
        .def("skipped", &S::skipped, "Faces left out for non-finite coordinates.")
        .def_prop_ro("triangle_count", &S::triangle_count, "Number of faces.");
}

}  // namespace

void bind_scene(nb::module_& m) {
    bind_scene_type<float>(m, "Scene32");
    bind_scene_type<double>(m, "Scene64");
}

}  // namespace bvhkit::python
