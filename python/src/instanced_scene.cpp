// InstancedScene<T>: bvhkit::Scene<T> (include/bvhkit/scene/, docs/scenes.md) for Python, where the
// package wraps it as bvhkit.Scene (python/bvhkit/_instances.py). Not to be confused with
// scene.cpp, which binds one mesh (bvhkit.TriangleMesh).
//
// Ids are int64: InstanceId::bits() (generation << 32 | slot), so an id kept past remove() never
// names the instance that reuses its slot; every call given it is a ValueError. A batch of changes
// checks every id, pose and option before it changes anything.
//
// Thread safety: the C++ queries are const and safe on many threads at once while nothing changes
// the scene (their lazy tree builds are under std::call_once). Here queries hold a shared lock and
// changes an exclusive one, so Python threads may call anything at any time; a batch query is
// spread over the extension's pool (run_batch) without the GIL.
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <shared_mutex>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/scene/closest_point.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/distance.hpp"
#include "bvhkit/scene/rays.hpp"
#include "bvhkit/scene/scene.hpp"
#include "bvhkit/scene/scene_file.hpp"
#include "common.hpp"

namespace bvhkit::python {
namespace {

/// (k, 3, 3) rotations, read only.
template <class T>
using Mats = nb::ndarray<const T, nb::shape<-1, 3, 3>, nb::c_contig, Cpu>;
template <class T>
using OutMats = nb::ndarray<T, nb::shape<-1, 3, 3>, nb::c_contig, Cpu>;
using Ids = Column<std::int64_t>;
using IdPairs = nb::ndarray<const std::int64_t, nb::shape<-1, 2>, nb::c_contig, Cpu>;

template <class T>
class InstancedScene {
  public:
    using Pose = Transform<T>;

    static Vec<T, 3> at(const T* p, std::size_t i) {
        return {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
    }
    static Pose pose_at(const Mats<T>& r, const Rows<T, 3>& t, std::size_t i) {
        Pose pose;
        const T* m = r.data() + 9 * i;
        for (std::size_t a = 0; a < 3; ++a)
            for (std::size_t b = 0; b < 3; ++b) pose.rotation[a][b] = m[3 * a + b];
        pose.translation = at(t.data(), i);
        return pose;
    }
    static InstanceId id_of(std::int64_t bits) {
        return InstanceId::from_bits(std::uint64_t(bits));
    }
    static std::int64_t bits_of(InstanceId id) { return std::int64_t(id.bits()); }

    // ---------------------------------------------------------------- changes

    std::uint32_t add_mesh(const Rows<T, 3>& vertices, const Faces& faces) {
        const BasicTriangleMesh<T> mesh = make_mesh<T>(vertices, faces);
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        return scene_.add_mesh(mesh).index();
    }

    /// One instance per row; every argument has k rows (the package broadcasts). All are checked
    /// before the first is added, so an Error adds none.
    void add_instances(const Column<std::int64_t>& geometry, const Mats<T>& rotations,
                       const Rows<T, 3>& translations, const Column<std::uint64_t>& user_data,
                       const Column<std::uint32_t>& group, const Column<std::uint32_t>& mask,
                       const Column<T>& margin, OutColumn<std::int64_t> ids) {
        const std::size_t k = geometry.shape(0);
        expect_rows(rotations, k, "rotations");
        expect_rows(translations, k, "translations");
        expect_rows(user_data, k, "user_data");
        expect_rows(group, k, "group");
        expect_rows(mask, k, "mask");
        expect_rows(margin, k, "margin");
        expect_rows(ids, k, "ids");
        std::vector<Pose> poses(k);
        std::vector<InstanceOptions<T>> options(k);
        for (std::size_t i = 0; i < k; ++i) {
            poses[i] = pose_at(rotations, translations, i);
            check_rigid_pose(poses[i], "add_instances", ("pose " + std::to_string(i)).c_str());
            options[i] = {user_data.data()[i], group.data()[i], mask.data()[i], margin.data()[i]};
            if (!(std::isfinite(options[i].margin) && options[i].margin >= T(0)))
                throw Error("margin: row " + std::to_string(i) + " must be finite and >= 0");
        }
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        for (std::size_t i = 0; i < k; ++i) {
            const std::int64_t g = geometry.data()[i];
            if (g < 0 || std::size_t(g) >= scene_.geometry_count())
                throw Error("geometry: " + std::to_string(g) + " is not one of the scene's " +
                            std::to_string(scene_.geometry_count()) + " meshes");
        }
        for (std::size_t i = 0; i < k; ++i)
            ids.data()[i] = bits_of(scene_.add_instance(
                GeometryId(std::uint32_t(geometry.data()[i])), poses[i], options[i]));
    }

    void set_poses(const Ids& ids, const Mats<T>& rotations, const Rows<T, 3>& translations) {
        const std::size_t k = ids.shape(0);
        expect_rows(rotations, k, "rotations");
        expect_rows(translations, k, "translations");
        std::vector<InstanceId> which(k);
        std::vector<Pose> poses(k);
        for (std::size_t i = 0; i < k; ++i) {
            which[i] = id_of(ids.data()[i]);
            poses[i] = pose_at(rotations, translations, i);
        }
        check_pose_rows(poses);
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "ids");
        scene_.set_poses(which, poses);  // checks every pose again before it moves any
    }
    /// Every pose finite and rigid (check_rigid_pose's rule), the error naming the argument and
    /// row as the package's own checks do: the per-call check a planner's loop pays is this one
    /// pass, not numpy's.
    static void check_pose_rows(const std::vector<Pose>& poses) {
        for (std::size_t i = 0; i < poses.size(); ++i) {
            const Pose& p = poses[i];
            bool finite = true;
            for (std::size_t a = 0; a < 3; ++a) {
                if (!std::isfinite(p.translation[a])) throw_bad_translation(i);
                for (std::size_t b = 0; b < 3; ++b)
                    finite = finite && std::isfinite(p.rotation[a][b]);
            }
            if (!finite) throw_bad_rotation_entry(i);
            if (!(rigid_deviation(p.rotation) <= rigid_tolerance<T>())) throw_not_a_rotation(i);
        }
    }

    /// New options for instances, every row checked before any changes: of user_data, group,
    /// mask and margin, those whose bit (1, 2, 4, 8) is set in `given`; the others stay (read
    /// and written under the same lock, so no other thread's change between is undone).
    void set_options(const Ids& ids, const Column<std::uint64_t>& user_data,
                     const Column<std::uint32_t>& group, const Column<std::uint32_t>& mask,
                     const Column<T>& margin, unsigned given) {
        const std::size_t k = ids.shape(0);
        expect_rows(user_data, k, "user_data");
        expect_rows(group, k, "group");
        expect_rows(mask, k, "mask");
        expect_rows(margin, k, "margin");
        if (given & 8u)
            for (std::size_t i = 0; i < k; ++i)
                if (!(std::isfinite(margin.data()[i]) && margin.data()[i] >= T(0)))
                    throw Error("margin: row " + std::to_string(i) + " must be finite and >= 0");
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "ids");
        for (std::size_t i = 0; i < k; ++i) {
            const InstanceId id = id_of(ids.data()[i]);
            InstanceOptions<T> o = scene_.options(id);
            if (given & 1u) o.user_data = user_data.data()[i];
            if (given & 2u) o.group = group.data()[i];
            if (given & 4u) o.mask = mask.data()[i];
            if (given & 8u) o.margin = margin.data()[i];
            scene_.set_options(id, o);
        }
    }

    void remove(const Ids& ids) {
        std::vector<std::int64_t> sorted(ids.data(), ids.data() + ids.shape(0));
        std::sort(sorted.begin(), sorted.end());
        if (const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
            twice != sorted.end())
            throw Error("ids: " + std::to_string(*twice) + " appears more than once");
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "ids");
        for (std::size_t i = 0; i < ids.shape(0); ++i) scene_.remove(id_of(ids.data()[i]));
    }

    // ---------------------------------------------------------------- accessors

    std::size_t size() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        return scene_.instance_count();
    }
    std::size_t geometry_count() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        return scene_.geometry_count();
    }
    bool contains(std::int64_t id) const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        return scene_.contains(id_of(id));
    }
    nb::ndarray<nb::numpy, std::int64_t> ids() const {
        std::vector<std::int64_t> out;
        {
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            out.reserve(scene_.instance_count());
            scene_.for_each_instance([&](InstanceId id) { out.push_back(bits_of(id)); });
        }
        const std::size_t n = out.size();
        return owned_array(std::move(out), n, 0);
    }
    /// Each instance's geometry, user data, group, mask, margin and pose.
    void describe(const Ids& ids, OutColumn<std::int64_t> geometry,
                  OutColumn<std::uint64_t> user_data, OutColumn<std::uint32_t> group,
                  OutColumn<std::uint32_t> mask, OutColumn<T> margin, OutMats<T> rotations,
                  OutRows<T, 3> translations) const {
        const std::size_t k = ids.shape(0);
        expect_rows(geometry, k, "geometry");
        expect_rows(user_data, k, "user_data");
        expect_rows(group, k, "group");
        expect_rows(mask, k, "mask");
        expect_rows(margin, k, "margin");
        expect_rows(rotations, k, "rotations");
        expect_rows(translations, k, "translations");
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "ids");
        for (std::size_t i = 0; i < k; ++i) {
            const SceneInstance<T>& r = scene_.instance(id_of(ids.data()[i]));
            geometry.data()[i] = std::int64_t(r.geometry.index());
            user_data.data()[i] = r.options.user_data;
            group.data()[i] = r.options.group;
            mask.data()[i] = r.options.mask;
            margin.data()[i] = r.options.margin;
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t b = 0; b < 3; ++b)
                    rotations.data()[9 * i + 3 * a + b] = r.pose.rotation[a][b];
                translations.data()[3 * i + a] = r.pose.translation[a];
            }
        }
    }
    /// (lo, hi) of the union of the instances' world boxes (lo = inf, hi = -inf when empty).
    nb::tuple bounds() const {
        Aabb<T, 3> b;
        {
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            b = scene_.bounds();
        }
        std::vector<T> lo(3), hi(3);
        for (std::size_t a = 0; a < 3; ++a) {
            lo[a] = b.is_empty() ? std::numeric_limits<T>::infinity() : b.min[a];
            hi[a] = b.is_empty() ? -std::numeric_limits<T>::infinity() : b.max[a];
        }
        return nb::make_tuple(owned_array(std::move(lo), 3, 0), owned_array(std::move(hi), 3, 0));
    }
    void validate() const {
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        scene_.validate();
    }
    void prepare() const {
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        scene_.prepare();
    }

    // ---------------------------------------------------------------- rays

    using PerRayLimits = bvhkit::python::PerRayLimits<T>;
    using SharedLimits = bvhkit::python::SharedLimits<T>;
    static PerRayLimits limits(const Column<T>& tmin, const Column<T>& tmax, std::size_t k) {
        expect_rows(tmin, k, "tmin");
        expect_rows(tmax, k, "tmax");
        for (std::size_t i = 0; i < k; ++i)
            if (tmin.data()[i] < T(0))
                throw Error("tmin: row " + std::to_string(i) +
                            " is negative; scene rays start at tmin >= 0");
        return {tmin.data(), tmax.data()};
    }
    static SharedLimits limits(T tmin, T tmax) {
        if (tmin < T(0)) throw Error("tmin: negative; scene rays start at tmin >= 0");
        return {tmin, tmax};
    }

    /// per_ray(i, ray) for each ray, over the pool, without the GIL, under the shared lock.
    template <class Limits, class PerRay>
    void rays(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Limits& limits,
              unsigned threads, PerRay&& per_ray) const {
        const std::size_t k = origins.shape(0);
        expect_rows(directions, k, "directions");
        const T *o = origins.data(), *d = directions.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        run_batch(k, 256, threads, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i)
                per_ray(i, Ray<T, 3>(at(o, i), at(d, i), limits.tmin(i), limits.tmax(i)));
        });
    }

    void intersect(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Column<T>& tmin,
                   const Column<T>& tmax, OutColumn<T> t, OutColumn<std::int64_t> instance,
                   OutColumn<std::int64_t> geometry, OutColumn<std::int64_t> face,
                   OutRows<T, 3> barycentric, OutRows<T, 3> normal, unsigned threads) const {
        intersect_within(origins, directions, limits(tmin, tmax, origins.shape(0)), t, instance,
                         geometry, face, barycentric, normal, threads);
    }
    /// intersect with one [tmin, tmax] for every ray.
    void intersect_shared(const Rows<T, 3>& origins, const Rows<T, 3>& directions, T tmin, T tmax,
                          OutColumn<T> t, OutColumn<std::int64_t> instance,
                          OutColumn<std::int64_t> geometry, OutColumn<std::int64_t> face,
                          OutRows<T, 3> barycentric, OutRows<T, 3> normal, unsigned threads) const {
        intersect_within(origins, directions, limits(tmin, tmax), t, instance, geometry, face,
                         barycentric, normal, threads);
    }
    template <class Limits>
    void intersect_within(const Rows<T, 3>& origins, const Rows<T, 3>& directions,
                          const Limits& limits, OutColumn<T> t, OutColumn<std::int64_t> instance,
                          OutColumn<std::int64_t> geometry, OutColumn<std::int64_t> face,
                          OutRows<T, 3> barycentric, OutRows<T, 3> normal, unsigned threads) const {
        const std::size_t k = origins.shape(0);
        for (const auto* c : {&instance, &geometry, &face}) expect_rows(*c, k, "out");
        expect_rows(t, k, "t");
        expect_rows(barycentric, k, "barycentric");
        expect_rows(normal, k, "normal");
        T *tp = t.data(), *bp = barycentric.data(), *np_ = normal.data();
        std::int64_t *ip = instance.data(), *gp = geometry.data(), *fp = face.data();
        rays(origins, directions, limits, threads, [&](std::size_t i, const Ray<T, 3>& ray) {
            const SceneHit<T> h = closest_hit(scene_, ray);
            tp[i] = h.t;
            ip[i] = h ? bits_of(h.instance) : -1;
            gp[i] = h ? std::int64_t(h.geometry.index()) : -1;
            fp[i] = h ? std::int64_t(h.face) : -1;
            bp[3 * i] = h ? T(1) - h.u - h.v : T(0);
            bp[3 * i + 1] = h.u;
            bp[3 * i + 2] = h.v;
            const Vec<T, 3> n = unit(h.normal);
            for (std::size_t a = 0; a < 3; ++a) np_[3 * i + a] = n[a];
        });
    }

    void occluded(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Column<T>& tmin,
                  const Column<T>& tmax, OutColumn<bool> out, unsigned threads) const {
        expect_rows(out, origins.shape(0), "out");
        bool* op = out.data();
        rays(origins, directions, limits(tmin, tmax, origins.shape(0)), threads,
             [&](std::size_t i, const Ray<T, 3>& ray) { op[i] = any_hit(scene_, ray); });
    }

    /// Every hit of every ray, sorted by ray then t: (ray_index, t, instance, geometry, face,
    /// barycentric, ray_splits), ray_splits (k + 1,) the offsets of each ray's hits.
    nb::tuple list_intersections(const Rows<T, 3>& origins, const Rows<T, 3>& directions,
                                 const Column<T>& tmin, const Column<T>& tmax,
                                 unsigned threads) const {
        const std::size_t k = origins.shape(0);
        constexpr std::size_t grain = 256;
        // One part per chunk of the batch: run_batch hands each chunk to exactly one call, so the
        // parts need no lock, and joined in order they are sorted by ray.
        std::vector<std::vector<SceneHit<T>>> parts((k + grain - 1) / grain);
        std::vector<std::int64_t> splits(k + 1, 0);
        rays(origins, directions, limits(tmin, tmax, origins.shape(0)), threads,
             [&](std::size_t i, const Ray<T, 3>& ray) {
                 thread_local std::vector<SceneHit<T>> hits;
                 all_hits(scene_, ray, hits);
                 auto& part = parts[i / grain];
                 part.insert(part.end(), hits.begin(), hits.end());
                 splits[i + 1] = std::int64_t(hits.size());
             });
        for (std::size_t i = 0; i < k; ++i) splits[i + 1] += splits[i];
        const std::size_t n = std::size_t(splits[k]);
        std::vector<std::int64_t> ray(n), instance(n), geometry(n), face(n);
        std::vector<T> t(n), bary(3 * n);
        std::size_t j = 0;
        for (std::size_t i = 0; i < k; ++i)
            for (std::int64_t m = splits[i]; m < splits[i + 1]; ++m)
                ray[std::size_t(m)] = std::int64_t(i);
        for (const auto& part : parts)
            for (const SceneHit<T>& h : part) {
                t[j] = h.t;
                instance[j] = bits_of(h.instance);
                geometry[j] = std::int64_t(h.geometry.index());
                face[j] = std::int64_t(h.face);
                bary[3 * j] = T(1) - h.u - h.v;
                bary[3 * j + 1] = h.u;
                bary[3 * j + 2] = h.v;
                ++j;
            }
        return nb::make_tuple(
            owned_array(std::move(ray), n, 0), owned_array(std::move(t), n, 0),
            owned_array(std::move(instance), n, 0), owned_array(std::move(geometry), n, 0),
            owned_array(std::move(face), n, 0), owned_array(std::move(bary), n, 3),
            owned_array(std::move(splits), k + 1, 0));
    }

    // ---------------------------------------------------------------- proximity

    void closest_point(const Rows<T, 3>& points, OutColumn<T> distance, OutRows<T, 3> point,
                       OutColumn<std::int64_t> instance, OutColumn<std::int64_t> geometry,
                       OutColumn<std::int64_t> face, OutRows<T, 3> barycentric,
                       unsigned threads) const {
        const std::size_t k = points.shape(0);
        expect_rows(distance, k, "distance");
        expect_rows(point, k, "point");
        for (const auto* c : {&instance, &geometry, &face}) expect_rows(*c, k, "out");
        expect_rows(barycentric, k, "barycentric");
        const T* p = points.data();
        T *dp = distance.data(), *cp = point.data(), *bp = barycentric.data();
        std::int64_t *ip = instance.data(), *gp = geometry.data(), *fp = face.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        run_batch(k, 64, threads, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                const ScenePoint<T> c = bvhkit::closest_point(scene_, at(p, i));
                const T nan = std::numeric_limits<T>::quiet_NaN();
                dp[i] = c.distance;
                for (std::size_t a = 0; a < 3; ++a) cp[3 * i + a] = c ? c.point[a] : nan;
                ip[i] = c ? bits_of(c.instance) : -1;
                gp[i] = c ? std::int64_t(c.geometry.index()) : -1;
                fp[i] = c ? std::int64_t(c.face) : -1;
                bp[3 * i] = c ? T(1) - c.u - c.v : T(0);
                bp[3 * i + 1] = c.u;
                bp[3 * i + 2] = c.v;
            }
        });
    }

    // ---------------------------------------------------------------- collision

    nb::ndarray<nb::numpy, std::int64_t> colliding_pairs(const IdPairs& ignore) const {
        std::vector<std::int64_t> flat;
        {
            const std::vector<InstancePair> skip = pairs_of(ignore);
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            check_pairs(ignore);
            std::vector<InstancePair> out;
            bvhkit::colliding_pairs(scene_, out, skip);
            flat.reserve(2 * out.size());
            for (const InstancePair& p : out) flat.insert(flat.end(), {bits_of(p.a), bits_of(p.b)});
        }
        const std::size_t n = flat.size() / 2;
        return owned_array(std::move(flat), n, 2);
    }
    bool any_collision(const IdPairs& ignore) const {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        check_pairs(ignore);
        return bvhkit::any_collision(scene_, skip);
    }
    /// The instances that geometry `geometry` at the one pose given collides with (its group,
    /// mask and margin as an instance's), in slot order; at most one with stop_at_first.
    nb::ndarray<nb::numpy, std::int64_t> colliding_instances(
        std::int64_t geometry, const Mats<T>& rotation, const Rows<T, 3>& translation,
        std::uint32_t group, std::uint32_t mask, T margin, bool stop_at_first) const {
        expect_rows(rotation, 1, "rotation");
        expect_rows(translation, 1, "translation");
        const Pose pose = pose_at(rotation, translation, 0);
        InstanceOptions<T> options;
        options.group = group;
        options.mask = mask;
        options.margin = margin;
        std::vector<std::int64_t> flat;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            if (geometry < 0 || std::size_t(geometry) >= scene_.geometry_count())
                throw Error("geometry: " + std::to_string(geometry) +
                            " is not one of the scene's " +
                            std::to_string(scene_.geometry_count()) + " meshes");
            std::vector<InstanceId> found;
            bvhkit::colliding_instances(scene_, GeometryId(std::uint32_t(geometry)), pose, options,
                                        found, stop_at_first);
            for (const InstanceId id : found) flat.push_back(bits_of(id));
        }
        const std::size_t n = flat.size();
        return owned_array(std::move(flat), n, 0);
    }

    /// The pairs of this scene (a) and `other` (b) that collide, (p, 2) ids sorted by a's slot
    /// then b's. `ignore` rows are (id of this scene, id of other).
    nb::ndarray<nb::numpy, std::int64_t> colliding_pairs_with(const InstancedScene& other,
                                                              const IdPairs& ignore) const {
        std::vector<std::int64_t> flat;
        {
            const std::vector<InstancePair> skip = pairs_of(ignore);
            nb::gil_scoped_release release;
            const Both lock(*this, other);
            check_cross_pairs(other, ignore);
            std::vector<InstancePair> out;
            bvhkit::colliding_pairs(scene_, other.scene_, out, skip);
            flat.reserve(2 * out.size());
            for (const InstancePair& p : out) flat.insert(flat.end(), {bits_of(p.a), bits_of(p.b)});
        }
        const std::size_t n = flat.size() / 2;
        return owned_array(std::move(flat), n, 2);
    }
    bool any_collision_with(const InstancedScene& other, const IdPairs& ignore) const {
        const std::vector<InstancePair> skip = pairs_of(ignore);
        nb::gil_scoped_release release;
        const Both lock(*this, other);
        check_cross_pairs(other, ignore);
        return bvhkit::any_collision(scene_, other.scene_, skip);
    }

    // ---------------------------------------------------------------- distance

    /// The closest pair: pack() of none or one.
    nb::tuple closest_pair(const IdPairs& ignore) const {
        std::vector<SceneDistance<T>> found;
        {
            const std::vector<InstancePair> skip = pairs_of(ignore);
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            check_pairs(ignore);
            if (const SceneDistance<T> d = bvhkit::closest_pair(scene_, skip)) found.push_back(d);
        }
        return pack(found);
    }
    nb::tuple pairs_within(T threshold, const IdPairs& ignore) const {
        std::vector<SceneDistance<T>> found;
        {
            const std::vector<InstancePair> skip = pairs_of(ignore);
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            check_pairs(ignore);
            bvhkit::pairs_within(scene_, threshold, found, skip);
        }
        return pack(found);
    }
    /// The instance nearest geometry `geometry` at the one pose given: pack() of none or one,
    /// its a -1.
    nb::tuple closest_instance(std::int64_t geometry, const Mats<T>& rotation,
                               const Rows<T, 3>& translation, std::uint32_t group,
                               std::uint32_t mask, T margin) const {
        expect_rows(rotation, 1, "rotation");
        expect_rows(translation, 1, "translation");
        const Pose pose = pose_at(rotation, translation, 0);
        InstanceOptions<T> options;
        options.group = group;
        options.mask = mask;
        options.margin = margin;
        std::vector<SceneDistance<T>> found;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            if (geometry < 0 || std::size_t(geometry) >= scene_.geometry_count())
                throw Error("geometry: " + std::to_string(geometry) +
                            " is not one of the scene's " +
                            std::to_string(scene_.geometry_count()) + " meshes");
            if (const SceneDistance<T> d = bvhkit::closest_instance(
                    scene_, GeometryId(std::uint32_t(geometry)), pose, options))
                found.push_back(d);
        }
        return pack(found);
    }

    // ---------------------------------------------------------------- saving and loading

    /// The scene in the library's file format (scene/scene_file.hpp, kind 7).
    nb::bytes to_bytes() const {
        std::vector<std::uint8_t> out;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            out = bvhkit::to_bytes(scene_);
        }
        return nb::bytes(reinterpret_cast<const char*>(out.data()), out.size());
    }
    /// Replaces the scene with the one `data` holds (everything checked first: an Error leaves
    /// the scene as it was).
    void load_bytes(nb::bytes data) {
        const auto* p = reinterpret_cast<const std::uint8_t*>(data.c_str());
        const std::size_t n = data.size();
        nb::gil_scoped_release release;  // bytes are immutable: no one changes them meanwhile
        bvhkit::Scene<T> loaded = scene_from_bytes<T>(std::span<const std::uint8_t>(p, n));
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        scene_ = std::move(loaded);
    }

  private:
    /// Throws naming the first id of `ids` that names no live instance (the caller holds a lock).
    void check_ids(const Ids& ids, const char* name) const {
        for (std::size_t i = 0; i < ids.shape(0); ++i)
            if (!scene_.contains(id_of(ids.data()[i])))
                throw Error(std::string(name) + "[" + std::to_string(i) +
                            "] = " + std::to_string(ids.data()[i]) +
                            " names no live instance of this scene (removed, stale or never "
                            "added)");
    }
    static std::vector<InstancePair> pairs_of(const IdPairs& pairs) {
        std::vector<InstancePair> out(pairs.shape(0));
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = {id_of(pairs.data()[2 * i]), id_of(pairs.data()[2 * i + 1])};
        return out;
    }
    void check_pairs(const IdPairs& pairs) const {
        for (std::size_t i = 0; i < 2 * pairs.shape(0); ++i)
            if (!scene_.contains(id_of(pairs.data()[i])))
                throw Error("ignore[" + std::to_string(i / 2) + ", " + std::to_string(i % 2) +
                            "] = " + std::to_string(pairs.data()[i]) +
                            " names no live instance of this scene (removed, stale or never "
                            "added)");
    }
    /// Both scenes' shared locks (one when they are the same object: a shared_mutex is not to be
    /// locked twice by one thread), taken in address order so that two calls with the scenes in
    /// either order cannot wait for each other behind a writer.
    struct Both {
        std::shared_lock<std::shared_mutex> first, second;
        Both(const InstancedScene& x, const InstancedScene& y) {
            const InstancedScene* lo = &x < &y ? &x : &y;
            const InstancedScene* hi = &x < &y ? &y : &x;
            first = std::shared_lock<std::shared_mutex>(lo->mutex_);
            if (hi != lo) second = std::shared_lock<std::shared_mutex>(hi->mutex_);
        }
    };
    void check_cross_pairs(const InstancedScene& other, const IdPairs& pairs) const {
        for (std::size_t i = 0; i < 2 * pairs.shape(0); ++i) {
            const bool mine = i % 2 == 0;
            if (!(mine ? scene_ : other.scene_).contains(id_of(pairs.data()[i])))
                throw Error(
                    "ignore[" + std::to_string(i / 2) + ", " + std::to_string(i % 2) +
                    "] = " + std::to_string(pairs.data()[i]) + " names no live instance of " +
                    (mine ? "this scene" : "the other scene") + " (removed, stale or never added)");
        }
    }
    /// (distance (p,), ids (p, 2), point_a (p, 3), point_b (p, 3), faces (p, 2)); a null id -1.
    static nb::tuple pack(const std::vector<SceneDistance<T>>& v) {
        const std::size_t n = v.size();
        std::vector<T> d(n), pa(3 * n), pb(3 * n);
        std::vector<std::int64_t> ids(2 * n), faces(2 * n);
        for (std::size_t i = 0; i < n; ++i) {
            d[i] = v[i].distance;
            ids[2 * i] = v[i].a.is_null() ? -1 : bits_of(v[i].a);
            ids[2 * i + 1] = bits_of(v[i].b);
            faces[2 * i] = std::int64_t(v[i].face_a);
            faces[2 * i + 1] = std::int64_t(v[i].face_b);
            for (std::size_t a = 0; a < 3; ++a)
                pa[3 * i + a] = v[i].point_a[a], pb[3 * i + a] = v[i].point_b[a];
        }
        return nb::make_tuple(owned_array(std::move(d), n, 0), owned_array(std::move(ids), n, 2),
                              owned_array(std::move(pa), n, 3), owned_array(std::move(pb), n, 3),
                              owned_array(std::move(faces), n, 2));
    }
    /// The hit's world normal at unit length, computed in double (zeros for a miss, and where the
    /// triangle's normal underflowed).
    static Vec<T, 3> unit(const Vec<T, 3>& n) {
        const double x = n[0], y = n[1], z = n[2];
        const double len = std::sqrt(x * x + y * y + z * z);
        if (!(len > 0) || !std::isfinite(len)) return {T(0), T(0), T(0)};
        return {T(x / len), T(y / len), T(z / len)};
    }

    bvhkit::Scene<T> scene_;
    mutable std::shared_mutex mutex_;
};

template <class T>
void bind_instanced_type(nb::module_& m, const char* name) {
    using S = InstancedScene<T>;
    nb::class_<S>(m, name, "Posed instances of shared meshes (see bvhkit.Scene).")
        .def(nb::init<>())
        .def("add_mesh", &S::add_mesh, nb::arg("vertices"), nb::arg("faces"))
        .def("add_instances", &S::add_instances, nb::arg("geometry"), nb::arg("rotations"),
             nb::arg("translations"), nb::arg("user_data"), nb::arg("group"), nb::arg("mask"),
             nb::arg("margin"), nb::arg("ids"))
        .def("set_poses", &S::set_poses, nb::arg("ids"), nb::arg("rotations"),
             nb::arg("translations"))
        .def("set_options", &S::set_options, nb::arg("ids"), nb::arg("user_data"), nb::arg("group"),
             nb::arg("mask"), nb::arg("margin"), nb::arg("given"))
        .def("remove", &S::remove, nb::arg("ids"))
        .def("__len__", &S::size)
        .def("geometry_count", &S::geometry_count)
        .def("contains", &S::contains, nb::arg("id"))
        .def("ids", &S::ids)
        .def("describe", &S::describe, nb::arg("ids"), nb::arg("geometry"), nb::arg("user_data"),
             nb::arg("group"), nb::arg("mask"), nb::arg("margin"), nb::arg("rotations"),
             nb::arg("translations"))
        .def("bounds", &S::bounds)
        .def("validate", &S::validate)
        .def("prepare", &S::prepare)
        .def("intersect", &S::intersect, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("t"), nb::arg("instance"), nb::arg("geometry"),
             nb::arg("face"), nb::arg("barycentric"), nb::arg("normal"), nb::arg("threads"))
        .def("intersect_shared", &S::intersect_shared, nb::arg("origins"), nb::arg("directions"),
             nb::arg("tmin"), nb::arg("tmax"), nb::arg("t"), nb::arg("instance"),
             nb::arg("geometry"), nb::arg("face"), nb::arg("barycentric"), nb::arg("normal"),
             nb::arg("threads"))
        .def("occluded", &S::occluded, nb::arg("origins"), nb::arg("directions"), nb::arg("tmin"),
             nb::arg("tmax"), nb::arg("out"), nb::arg("threads"))
        .def("list_intersections", &S::list_intersections, nb::arg("origins"),
             nb::arg("directions"), nb::arg("tmin"), nb::arg("tmax"), nb::arg("threads"))
        .def("closest_point", &S::closest_point, nb::arg("points"), nb::arg("distance"),
             nb::arg("point"), nb::arg("instance"), nb::arg("geometry"), nb::arg("face"),
             nb::arg("barycentric"), nb::arg("threads"))
        .def("colliding_pairs", &S::colliding_pairs, nb::arg("ignore"))
        .def("any_collision", &S::any_collision, nb::arg("ignore"))
        .def("colliding_instances", &S::colliding_instances, nb::arg("geometry"),
             nb::arg("rotation"), nb::arg("translation"), nb::arg("group"), nb::arg("mask"),
             nb::arg("margin"), nb::arg("stop_at_first"))
        .def("colliding_pairs_with", &S::colliding_pairs_with, nb::arg("other"), nb::arg("ignore"))
        .def("any_collision_with", &S::any_collision_with, nb::arg("other"), nb::arg("ignore"))
        .def("to_bytes", &S::to_bytes)
        .def("load_bytes", &S::load_bytes, nb::arg("data"))
        .def("closest_pair", &S::closest_pair, nb::arg("ignore"))
        .def("pairs_within", &S::pairs_within, nb::arg("threshold"), nb::arg("ignore"))
        .def("closest_instance", &S::closest_instance, nb::arg("geometry"), nb::arg("rotation"),
             nb::arg("translation"), nb::arg("group"), nb::arg("mask"), nb::arg("margin"));
}

}  // namespace

void bind_instanced_scene(nb::module_& m) {
    bind_instanced_type<float>(m, "InstancedScene32");
    bind_instanced_type<double>(m, "InstancedScene64");
}

}  // namespace bvhkit::python
