#include "scene_bench.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>

#include "bvhkit/exec/executor.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/scene/collision.hpp"
#include "bvhkit/scene/distance.hpp"
#include "bvhkit/scene/scene.hpp"
#include "robot_arm.hpp"

#if BVHKIT_HAVE_FCL
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#endif

namespace bvhkit::bench {

std::vector<std::string> scene_bench_default_meshes() {
    // 69,451 + 22,866 + 6,320 + 968 = 99,605 triangles.
    return {"stanford-bunny.obj", "dragon-lowres.ply", "teapot.obj", "suzanne.obj"};
}

namespace {
// Named inside the anonymous namespace: the workloads are compiled as unity batches, and the
// other files have helpers of the same names.
namespace s1 {

using Poses = std::array<Transform<double>, ArmShape::bodies>;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// One configuration's answer: whether anything collides, and if not the smallest distance over
/// the same pairs (arm against environment, non-neighbouring bodies of the arm).
struct Answer {
    bool colliding = false;
    double distance = kInf;
};

/// Bodies i and j of the arm are checked against each other unless they are neighbours in the
/// chain (a joint always holds them in contact).
constexpr bool self_pair(std::size_t i, std::size_t j) {
    return (i > j ? i - j : j - i) > 1;
}

/// The environment's meshes in double, each centred and scaled to `size` across, with the world
/// position of its centre.
struct Environment {
    std::vector<BasicTriangleMesh<double>> meshes;
    std::vector<Vec<double, 3>> places;
    std::size_t triangles = 0;
};

Environment make_environment(const SceneBenchOptions& o) {
    Environment env;
    const std::size_t n = o.meshes.size();
    for (std::size_t i = 0; i < n; ++i) {
        const TriangleMesh f = load_mesh(o.meshes[i]);
        const Aabb<float, 3> b = f.bounds();
        double extent = 0;
        for (std::size_t a = 0; a < 3; ++a) extent = std::max(extent, double(b.max[a] - b.min[a]));
        if (!(extent > 0 && std::isfinite(extent)))
            throw Error("bench scene: mesh " + o.meshes[i] + " has no finite extent to scale");
        BasicTriangleMesh<double> m;
        m.triangles = f.triangles;
        for (const auto& v : f.vertices) {
            Vec<double, 3> p;
            for (std::size_t a = 0; a < 3; ++a)
                p[a] = (double(v[a]) - 0.5 * (double(b.min[a]) + double(b.max[a]))) *
                       (o.object_size / extent);
            m.vertices.push_back(p);
        }
        env.triangles += m.triangles.size();
        env.meshes.push_back(std::move(m));
        // Around the base at the arm's middle reach, alternating heights.
        const double angle = 2 * std::numbers::pi * double(i) / double(std::max<std::size_t>(n, 1));
        const double radius = 0.55, height = i % 2 ? 0.3 : 0.6;
        env.places.push_back({radius * std::cos(angle), radius * std::sin(angle), height});
    }
    return env;
}

Transform<double> translation(const Vec<double, 3>& t) {
    Transform<double> p;
    p.translation = t;
    return p;
}

/// A way of answering every configuration: fills answers[i] for each.
using Job = std::function<void(std::vector<Answer>&)>;

constexpr std::uint32_t kWorld = 1, kArm = 2;

/// bvhkit, the manager style: one Scene holding the environment and the arm, the arm's instances
/// moved by set_poses, then any_collision and (when free) closest_pair over the whole scene. The
/// group/mask filter keeps environment pairs out; the ignore list the neighbouring links.
struct OneScene {
    Scene<double> scene;
    std::vector<InstanceId> arm;
    std::vector<InstancePair> ignore;

    OneScene(const Environment& env, const BasicTriangleMesh<double>& link,
             const BasicTriangleMesh<double>& gripper, const Poses& start) {
        for (std::size_t i = 0; i < env.meshes.size(); ++i)
            scene.add_instance(scene.add_mesh(env.meshes[i]), translation(env.places[i]),
                               {.group = kWorld, .mask = kArm});
        const GeometryId lg = scene.add_mesh(link), gg = scene.add_mesh(gripper);
        for (std::size_t k = 0; k < ArmShape::bodies; ++k)
            arm.push_back(scene.add_instance(k < ArmShape::links ? lg : gg, start[k],
                                             {.group = kArm, .mask = kWorld | kArm}));
        for (std::size_t k = 0; k + 1 < ArmShape::bodies; ++k)
            ignore.push_back({arm[k], arm[k + 1]});
        scene.prepare();
    }
    Answer answer(const Poses& poses) {
        scene.set_poses(arm, poses);
        Answer a;
        a.colliding = any_collision(scene, std::span<const InstancePair>(ignore));
        if (!a.colliding)
            a.distance = closest_pair(scene, std::span<const InstancePair>(ignore)).distance;
        return a;
    }
};

/// bvhkit with two scenes: the environment's (never changed, so any number of threads may query
/// it) and the arm's, moved by set_poses; per configuration any_collision and closest_pair
/// between the two and within the arm (neighbours ignored). Batched, each chunk of
/// configurations has its own arm scene and all share the environment's.
struct ArmScene {
    Scene<double> scene;
    std::vector<InstanceId> arm;
    std::vector<InstancePair> ignore;

    ArmScene(const BasicTriangleMesh<double>& link, const BasicTriangleMesh<double>& gripper,
             const Poses& start) {
        const GeometryId lg = scene.add_mesh(link), gg = scene.add_mesh(gripper);
        for (std::size_t k = 0; k < ArmShape::bodies; ++k)
            arm.push_back(scene.add_instance(k < ArmShape::links ? lg : gg, start[k]));
        for (std::size_t k = 0; k + 1 < ArmShape::bodies; ++k)
            ignore.push_back({arm[k], arm[k + 1]});
        scene.prepare();
    }
    Answer answer(const Scene<double>& env, const Poses& poses) {
        scene.set_poses(arm, poses);
        const std::span<const InstancePair> neighbours(ignore);
        Answer a;
        a.colliding = any_collision(scene, env) || any_collision(scene, neighbours);
        if (!a.colliding)
            a.distance = std::min(closest_pair(scene, env).distance,
                                  closest_pair(scene, neighbours).distance);
        return a;
    }
};

Scene<double> environment_scene(const Environment& e) {
    Scene<double> env;
    for (std::size_t i = 0; i < e.meshes.size(); ++i)
        env.add_instance(env.add_mesh(e.meshes[i]), translation(e.places[i]));
    env.prepare();
    return env;
}

/// bvhkit, const queries: the environment alone is a Scene (never changed, so many threads may
/// query it); each body of the arm is a posed geometry asked with collides_with and
/// closest_instance, and the non-neighbouring bodies are tested pairwise on the geometries'
/// collision models after a world-box check.
struct ConstQueries {
    Scene<double> env;
    std::array<GeometryId, ArmShape::bodies> geometry;

    ConstQueries(const Environment& e, const BasicTriangleMesh<double>& link,
                 const BasicTriangleMesh<double>& gripper) {
        for (std::size_t i = 0; i < e.meshes.size(); ++i)
            env.add_instance(env.add_mesh(e.meshes[i]), translation(e.places[i]));
        const GeometryId lg = env.add_mesh(link), gg = env.add_mesh(gripper);
        for (std::size_t k = 0; k < ArmShape::bodies; ++k)
            geometry[k] = k < ArmShape::links ? lg : gg;
        env.prepare();
    }
    Answer answer(const Poses& poses) const {
        using W = AccurateScalar<double>;
        std::array<Aabb<double, 3>, ArmShape::bodies> box;
        for (std::size_t k = 0; k < ArmShape::bodies; ++k) {
            const SceneGeometry<double>& g = env.geometry_at(geometry[k]);
            box[k] = g.world_box(poses[k], g.pose_pad(poses[k]));
        }
        const auto model = [&](std::size_t k) -> const auto& {
            return env.geometry_at(geometry[k]).collision_model();
        };
        Answer a;
        for (std::size_t i = 0; i < ArmShape::bodies && !a.colliding; ++i)
            for (std::size_t j = i + 2; j < ArmShape::bodies && !a.colliding; ++j)
                a.colliding = scene_detail::boxes_within(box[i], box[j], 0.0) &&
                              collides(model(i), model(j),
                                       scene_detail::relative_pose<W>(poses[i], poses[j]));
        for (std::size_t k = 0; k < ArmShape::bodies && !a.colliding; ++k)
            a.colliding = collides_with(env, geometry[k], poses[k]);
        if (a.colliding) return a;
        for (std::size_t k = 0; k < ArmShape::bodies; ++k)
            a.distance =
                std::min(a.distance, closest_instance(env, geometry[k], poses[k]).distance);
        for (std::size_t i = 0; i < ArmShape::bodies; ++i)
            for (std::size_t j = i + 2; j < ArmShape::bodies; ++j)
                if (double(scene_detail::box_gap(box[i], box[j])) < a.distance) {
                    DistanceOptions<double> cut;
                    cut.upper_bound = a.distance;  // the running minimum prunes the pair's walk
                    a.distance =
                        std::min(a.distance,
                                 distance(model(i), model(j),
                                          scene_detail::relative_pose<W>(poses[i], poses[j]), cut)
                                     .distance);
                }
        return a;
    }
};

#if BVHKIT_HAVE_FCL
fcl::Transform3d to_fcl(const Transform<double>& p) {
    fcl::Transform3d t = fcl::Transform3d::Identity();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) t.linear()(i, j) = p.rotation[i][j];
        t.translation()(i) = p.translation[i];
    }
    return t;
}

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl_model(const BasicTriangleMesh<double>& mesh) {
    auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
    std::vector<fcl::Vector3d> points;
    std::vector<fcl::Triangle> triangles;
    for (const auto& v : mesh.vertices) points.emplace_back(v[0], v[1], v[2]);
    for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    model->beginModel();
    model->addSubModel(points, triangles);
    model->endModel();
    return model;
}

/// Every object carries its body index as user data (the environment's: kEnvironment; FCL leaves
/// user data uninitialised), so the callbacks can skip neighbouring bodies of the arm.
constexpr std::size_t kEnvironment = ~std::size_t(0);
bool fcl_pair_wanted(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2) {
    const std::size_t a = *static_cast<const std::size_t*>(o1->getUserData());
    const std::size_t b = *static_cast<const std::size_t*>(o2->getUserData());
    return a == kEnvironment || b == kEnvironment || self_pair(a, b);
}

// The broadphase callbacks, with the logic of FCL's DefaultCollisionFunction and
// DefaultDistanceFunction (stop at the first contact; keep the running minimum in one result,
// which FCL's mesh distance also uses to prune) plus the neighbour filter.
struct FclCollisionData {
    fcl::CollisionRequestd request;
    fcl::CollisionResultd result;
    bool done = false;
};
bool fcl_collide_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* d = static_cast<FclCollisionData*>(data);
    if (d->done) return true;
    if (!fcl_pair_wanted(o1, o2)) return false;
    fcl::collide(o1, o2, d->request, d->result);
    d->done = d->result.isCollision();
    return d->done;
}
struct FclDistanceData {
    fcl::DistanceRequestd request;
    fcl::DistanceResultd result;
    bool done = false;
};
bool fcl_distance_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data,
                           double& dist) {
    auto* d = static_cast<FclDistanceData*>(data);
    if (d->done) {
        dist = d->result.min_distance;
        return true;
    }
    if (!fcl_pair_wanted(o1, o2)) {
        dist = d->result.min_distance;
        return false;
    }
    fcl::distance(o1, o2, d->request, d->result);
    dist = d->result.min_distance;
    d->done = dist <= 0;
    return d->done;
}

/// FCL as its users call it: the environment in one DynamicAABBTreeCollisionManager (set up
/// once), the arm in another; per configuration each body's setTransform and the arm manager's
/// update, then arm-against-environment and arm-against-itself collide, and when free the same
/// two distance calls.
struct FclManagers {
    std::vector<std::shared_ptr<fcl::CollisionObjectd>> env_objects, arm_objects;
    std::array<std::size_t, ArmShape::bodies> index{};
    std::size_t environment_marker = kEnvironment;
    fcl::DynamicAABBTreeCollisionManagerd env, arm;

    FclManagers(const Environment& e, const BasicTriangleMesh<double>& link,
                const BasicTriangleMesh<double>& gripper, const Poses& start) {
        for (std::size_t i = 0; i < e.meshes.size(); ++i) {
            env_objects.push_back(std::make_shared<fcl::CollisionObjectd>(
                fcl_model(e.meshes[i]), to_fcl(translation(e.places[i]))));
            env_objects.back()->setUserData(&environment_marker);
            env.registerObject(env_objects.back().get());
        }
        env.setup();
        const auto lm = fcl_model(link), gm = fcl_model(gripper);
        for (std::size_t k = 0; k < ArmShape::bodies; ++k) {
            index[k] = k;
            arm_objects.push_back(std::make_shared<fcl::CollisionObjectd>(
                k < ArmShape::links ? lm : gm, to_fcl(start[k])));
            arm_objects.back()->setUserData(&index[k]);
            arm.registerObject(arm_objects.back().get());
        }
        arm.setup();
    }
    Answer answer(const Poses& poses) {
        for (std::size_t k = 0; k < ArmShape::bodies; ++k) {
            arm_objects[k]->setTransform(to_fcl(poses[k]));
            arm_objects[k]->computeAABB();
        }
        arm.update();
        Answer a;
        FclCollisionData c;
        arm.collide(&env, &c, fcl_collide_callback);
        if (!c.done) arm.collide(&c, fcl_collide_callback);
        a.colliding = c.done;
        if (a.colliding) return a;
        FclDistanceData d;
        arm.distance(&env, &d, fcl_distance_callback);
        arm.distance(&d, fcl_distance_callback);
        a.distance = d.result.min_distance;
        return a;
    }
};
#endif

double now_ms() {
    return std::chrono::duration<double, std::milli>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

}  // namespace s1
}  // namespace

std::vector<Row> run_scene_bench(const SceneBenchOptions& o, std::FILE* progress) {
    using namespace s1;
    const ArmShape shape;
    const Environment env = make_environment(o);
    const BasicTriangleMesh<double> link =
        make_capsule(shape.radius, shape.link_length, shape.around, shape.rings);
    const BasicTriangleMesh<double> gripper = make_gripper();
    const auto q = random_configurations(shape, o.configurations, o.seed);
    std::vector<Poses> poses(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) poses[i] = arm_poses(shape, q[i]);
    const Poses start = arm_poses(shape, {});
    if (progress)
        std::fprintf(progress,
                     "S1: %zu environment meshes, %zu triangles; arm of %zu links (%zu triangles "
                     "each) and a gripper (%zu); %zu configurations\n",
                     env.meshes.size(), env.triangles, ArmShape::links, link.triangles.size(),
                     gripper.triangles.size(), q.size());

    OneScene one(env, link, gripper, start);
    const Scene<double> env_scene = environment_scene(env);
    // Batched: chunks of configurations, each with its own arm scene (built up front: a few
    // thousand triangles each), so no two threads ever move the same scene.
    constexpr std::size_t grain = 64;
    std::vector<std::unique_ptr<ArmScene>> arms;
    for (std::size_t c = 0; c < std::max<std::size_t>(1, (poses.size() + grain - 1) / grain); ++c)
        arms.push_back(std::make_unique<ArmScene>(link, gripper, start));
    const ConstQueries shared(env, link, gripper);
    const Executor batch(o.threads);
    const unsigned batch_threads =
        o.threads == 0 ? hardware_threads() : std::min(o.threads, hardware_threads());

    struct Runner {
        std::string library, mode;
        unsigned threads;
        Job job;
    };
    std::vector<Runner> runners;
    runners.push_back({"bvhkit", "scene_set_poses", 1, [&](std::vector<Answer>& out) {
                           for (std::size_t i = 0; i < poses.size(); ++i)
                               out[i] = one.answer(poses[i]);
                       }});
    runners.push_back({"bvhkit", "two_scenes", 1, [&](std::vector<Answer>& out) {
                           for (std::size_t i = 0; i < poses.size(); ++i)
                               out[i] = arms[0]->answer(env_scene, poses[i]);
                       }});
    runners.push_back(
        {"bvhkit", "two_scenes_batched", batch_threads, [&](std::vector<Answer>& out) {
             batch.parallel_for(poses.size(), grain, [&](std::size_t b, std::size_t e) {
                 ArmScene& arm = *arms[b / grain];
                 for (std::size_t i = b; i < e; ++i) out[i] = arm.answer(env_scene, poses[i]);
             });
         }});
    runners.push_back({"bvhkit", "const_queries", 1, [&](std::vector<Answer>& out) {
                           for (std::size_t i = 0; i < poses.size(); ++i)
                               out[i] = shared.answer(poses[i]);
                       }});
    runners.push_back(
        {"bvhkit", "const_queries_batched", batch_threads, [&](std::vector<Answer>& out) {
             batch.parallel_for(poses.size(), 64, [&](std::size_t b, std::size_t e) {
                 for (std::size_t i = b; i < e; ++i) out[i] = shared.answer(poses[i]);
             });
         }});
#if BVHKIT_HAVE_FCL
    FclManagers fcl_side(env, link, gripper, start);
    runners.push_back({"fcl", "manager", 1, [&](std::vector<Answer>& out) {
                           for (std::size_t i = 0; i < poses.size(); ++i)
                               out[i] = fcl_side.answer(poses[i]);
                       }});
#endif

    // Interleaved repetitions: every repetition runs each runner once in turn, after one untimed
    // round that also records the answers compared below.
    const std::size_t n = runners.size();
    std::vector<std::vector<Answer>> answers(n, std::vector<Answer>(poses.size()));
    // The process's CPU time beside the wall time: on a shared machine the batched rows' ratio
    // of the two says how many cores they really got.
    std::vector<std::vector<double>> times(n), cpu(n);
    for (std::size_t k = 0; k < n; ++k) runners[k].job(answers[k]);
    std::vector<Answer> scratch(poses.size());
    for (int r = 0; r < std::max(1, o.repetitions); ++r)
        for (std::size_t k = 0; k < n; ++k) {
            const std::clock_t c0 = std::clock();
            const double t0 = now_ms();
            runners[k].job(scratch);
            times[k].push_back(now_ms() - t0);
            cpu[k].push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
            if (progress)
                std::fprintf(progress, "  rep %d %s %s: %.1f ms (cpu %.1f ms)\n", r,
                             runners[k].library.c_str(), runners[k].mode.c_str(), times[k].back(),
                             cpu[k].back());
        }

    // Agreement with the last runner (FCL when present, else bvhkit's scene).
    const std::size_t ref = n - 1;
    std::vector<Row> rows;
    double fcl_ms = 0;
#if BVHKIT_HAVE_FCL
    fcl_ms = median(times[ref]);
#endif
    for (std::size_t k = 0; k < n; ++k) {
        std::size_t colliding = 0, flag_diff = 0, free_count = 0;
        double worst_abs = 0, worst_rel = 0, min_free = kInf;
        for (std::size_t i = 0; i < poses.size(); ++i) {
            const Answer& a = answers[k][i];
            const Answer& b = answers[ref][i];
            colliding += a.colliding;
            flag_diff += a.colliding != b.colliding;
            if (!a.colliding && !b.colliding) {
                ++free_count;
                const double diff = std::fabs(a.distance - b.distance);
                worst_abs = std::max(worst_abs, diff);
                worst_rel = std::max(worst_rel, diff / std::max(1e-300, std::fabs(b.distance)));
                min_free = std::min(min_free, b.distance);
            }
        }
        const double ms = median(times[k]);
        Row row;
        row.set("workload", "S1").set("library", runners[k].library).set("mode", runners[k].mode);
        row.set("threads", (long long)runners[k].threads);
        row.set("configurations", (long long)poses.size()).set("colliding", (long long)colliding);
        row.set("ms", ms).set("us_per_config", ms * 1000.0 / double(poses.size()));
        row.set("cpu_ms", median(cpu[k]));
        if (fcl_ms > 0 && k != ref) row.set("vs_fcl", fcl_ms / ms);
        if (k != ref) {
            row.set("flags_differ", (long long)flag_diff);
            row.set("distance_max_abs_diff", worst_abs).set("distance_max_rel_diff", worst_rel);
        }
        rows.push_back(row);
        if (progress && k != ref)
            std::fprintf(progress,
                         "  agreement %s %s vs %s %s: colliding flags differ at %zu/%zu, distance "
                         "max abs diff %.3e (rel %.3e) over %zu free configurations (smallest "
                         "distance %.3e)\n",
                         runners[k].library.c_str(), runners[k].mode.c_str(),
                         runners[ref].library.c_str(), runners[ref].mode.c_str(), flag_diff,
                         poses.size(), worst_abs, worst_rel, free_count, min_free);
    }
    return rows;
}

}  // namespace bvhkit::bench
