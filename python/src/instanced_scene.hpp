#pragma once
// InstancedScene<T>: bvhkit::Scene<T> (include/bvhkit/scene/, docs/scenes.md) for Python, where the
// package wraps it as bvhkit.Scene (python/bvhkit/_instances.py); its collision and distance calls
// are in instanced_scene_pairs.hpp, the binding in instanced_scene.cpp. Not to be confused with
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
#include <optional>
#include <shared_mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bvhkit/scene/closest_point.hpp"
#include "bvhkit/scene/ray_batches.hpp"
#include "bvhkit/scene/rays.hpp"
#include "bvhkit/scene/scene.hpp"
#include "bvhkit/scene/scene_file.hpp"
#include "bvhkit/scene/signed_distance.hpp"
#include "common.hpp"

namespace bvhkit::python {

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
    /// The scene and its lock, for the collision and distance calls (instanced_scene_pairs.hpp).
    const bvhkit::Scene<T>& scene() const { return scene_; }
    std::shared_mutex& mutex() const { return mutex_; }

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

    /// per_ray(i, ray, top) for each ray, over the pool, without the GIL, under the shared lock.
    /// `top`: with flat_top, for a batch of at least ray_top_min_rays rays, the scene's top level
    /// flattened once for the call (SceneRayTop, scene/ray_batches.hpp, as the C++ batches do),
    /// else null.
    template <class Limits, class PerRay>
    void rays(const Rows<T, 3>& origins, const Rows<T, 3>& directions, const Limits& limits,
              unsigned threads, PerRay&& per_ray, bool flat_top = true) const {
        const std::size_t k = origins.shape(0);
        expect_rows(directions, k, "directions");
        const T *o = origins.data(), *d = directions.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        std::optional<SceneRayTop<T>> top;
        if (flat_top && k >= ray_top_min_rays(scene_)) top.emplace(scene_);
        const SceneRayTop<T>* flat = top ? &*top : nullptr;
        run_batch(k, 256, threads, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i)
                per_ray(i, Ray<T, 3>(at(o, i), at(d, i), limits.tmin(i), limits.tmax(i)), flat);
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
        rays(origins, directions, limits, threads,
             [&](std::size_t i, const Ray<T, 3>& ray, const SceneRayTop<T>* top) {
                 const SceneHit<T> h = top ? top->closest_hit(ray) : closest_hit(scene_, ray);
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
             [&](std::size_t i, const Ray<T, 3>& ray, const SceneRayTop<T>* top) {
                 op[i] = top ? top->any_hit(ray) : any_hit(scene_, ray);
             });
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
        rays(
            origins, directions, limits(tmin, tmax, origins.shape(0)), threads,
            [&](std::size_t i, const Ray<T, 3>& ray, const SceneRayTop<T>*) {
                thread_local std::vector<SceneHit<T>> hits;
                all_hits(scene_, ray, hits);
                auto& part = parts[i / grain];
                part.insert(part.end(), hits.begin(), hits.end());
                splits[i + 1] = std::int64_t(hits.size());
            },
            false);  // all hits walk the dynamic top level
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
        point_answers(points, distance, point, instance, geometry, face, barycentric, threads,
                      [&](const Vec<T, 3>& q) {
                          const ScenePoint<T> c = bvhkit::closest_point(scene_, q);
                          return std::pair(c.distance, c);
                      });
    }

    /// closest_point's answers with the distance signed (scene/signed_distance.hpp): negative
    /// inside any instance, by `sign` ("pseudonormal" or "winding_number").
    void signed_distance(const Rows<T, 3>& points, const std::string& sign, OutColumn<T> distance,
                         OutRows<T, 3> point, OutColumn<std::int64_t> instance,
                         OutColumn<std::int64_t> geometry, OutColumn<std::int64_t> face,
                         OutRows<T, 3> barycentric, unsigned threads) const {
        SceneSign rule;
        if (sign == "pseudonormal")
            rule = SceneSign::pseudonormal;
        else if (sign == "winding_number")
            rule = SceneSign::winding_number;
        else
            throw Error("sign: '" + sign + "' is not one of 'pseudonormal', 'winding_number'");
        point_answers(points, distance, point, instance, geometry, face, barycentric, threads,
                      [&](const Vec<T, 3>& q) {
                          const SceneSignedDistance<T> s = bvhkit::signed_distance(scene_, q, rule);
                          return std::pair(s.distance, s.closest);
                      });
    }

    /// query(point) -> (distance, ScenePoint) for each point, over the pool, without the GIL,
    /// under the shared lock, written to the arrays (NaN points and -1 ids where nothing is found).
    template <class Query>
    void point_answers(const Rows<T, 3>& points, OutColumn<T> distance, OutRows<T, 3> point,
                       OutColumn<std::int64_t> instance, OutColumn<std::int64_t> geometry,
                       OutColumn<std::int64_t> face, OutRows<T, 3> barycentric, unsigned threads,
                       Query&& query) const {
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
                const auto [d, c] = query(at(p, i));
                const T nan = std::numeric_limits<T>::quiet_NaN();
                dp[i] = d;
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

    /// Whether each point is inside any instance (scene/signed_distance.hpp's contains()).
    void contains_points(const Rows<T, 3>& points, OutColumn<bool> out, unsigned threads) const {
        const std::size_t k = points.shape(0);
        expect_rows(out, k, "out");
        const T* p = points.data();
        bool* op = out.data();
        nb::gil_scoped_release release;
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        run_batch(k, 64, threads, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) op[i] = bvhkit::contains(scene_, at(p, i));
        });
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

}  // namespace bvhkit::python
