#pragma once
// Saving and loading a Scene (format: docs/serialization.md, kind 7). The file holds each
// geometry's mesh once (vertices and triangles as added), each live instance's record (its id
// with the slot's generation, geometry, pose as stored, options) and the top-level DynamicTree as
// built (a whole kind 5 file inside this one: fat boxes, node pool and proxy table, so ids, free
// slots and generations carry over, and every walk visits the instances in the same order). The
// scene options are the tree's, which that file holds.
//
// Not stored, made again on load: each geometry's convex hull (for the world boxes) and the
// bottom-level trees, built lazily as in any scene. Both are functions of the mesh alone, so the
// loaded scene gives bit-identical answers to every query. The instances' world boxes are
// recomputed from their poses and must be the ones the saved tree holds (grown by the margins):
// a file whose poses and tree disagree is an Error.
//
// Loading trusts nothing: the envelope (tree_file.hpp: magic, version, size, checksum), then every
// count against the bytes before allocating, the meshes' indices, the instance ids against the
// tree's live proxies (each exactly once), the poses (finite, rigid, stored as the scene stores
// them), the margins, and at the end Scene::validate(). Any failure is a bvhkit::Error.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit {

namespace serial_detail {

inline constexpr std::uint8_t scene_layout = 1;
inline constexpr std::uint64_t scene_geometry_bytes = 16;  // vertex count, triangle count
template <class T>
inline constexpr std::uint64_t scene_instance_bytes = 8 + 4 * 4 + 8 + 13 * sizeof(T);

struct SceneAccess {
    static constexpr const char* what = "Scene file";

    template <class T>
    static std::vector<std::uint8_t> save(const Scene<T>& s) {
        ByteWriter w;
        const std::vector<std::uint8_t> tree = to_bytes(s.tree_);
        std::uint64_t vertices = 0, triangles = 0;
        for (const auto& g : s.geometry_)
            vertices += g->mesh().vertices.size(), triangles += g->mesh().triangles.size();
        w.u64(tree.size());
        for (const auto& g : s.geometry_)
            w.u64(g->mesh().vertices.size()), w.u64(g->mesh().triangles.size());
        for (const auto& g : s.geometry_)
            for (const Vec<T, 3>& v : g->mesh().vertices)
                w.scalar(v[0]), w.scalar(v[1]), w.scalar(v[2]);
        w.pad(8);
        for (const auto& g : s.geometry_)
            for (const auto& t : g->mesh().triangles) w.u32(t[0]), w.u32(t[1]), w.u32(t[2]);
        w.pad(8);
        std::uint64_t instances = 0;
        s.for_each_instance([&](InstanceId id) {
            const SceneInstance<T>& r = s.instances_[std::size_t(id.index())];
            w.u64(id.bits());
            w.u32(r.geometry.index()), w.u32(r.options.group), w.u32(r.options.mask), w.u32(0);
            w.u64(r.options.user_data);
            for (std::size_t i = 0; i < 3; ++i)
                for (std::size_t j = 0; j < 3; ++j) w.scalar(r.pose.rotation[i][j]);
            for (std::size_t i = 0; i < 3; ++i) w.scalar(r.pose.translation[i]);
            w.scalar(r.options.margin);
            ++instances;
        });
        w.pad(8);
        std::vector<std::uint8_t>& out = w.bytes();
        out.insert(out.end(), tree.begin(), tree.end());
        w.pad(8);
        TreeFileHeader h;
        h.kind = FileKind::Scene;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = scene_layout;
        h.counts = {s.geometry_.size(), vertices, triangles, instances};
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static Scene<T> load(std::span<const std::uint8_t> file) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::Scene, what);
        const TreeFileHeader& h = f.header;
        if (h.scalar != scalar_code<T>())
            throw Error(std::string(what) + ": the file holds " +
                        scalar_name(std::uint8_t(h.scalar)) + " coordinates, " +
                        scalar_name(std::uint8_t(scalar_code<T>())) + " were asked for");
        if (h.volume != VolumeCode::Aabb3 || h.layout != scene_layout)
            throw Error(std::string(what) + ": unknown volume or layout " +
                        std::to_string(int(h.layout)));
        const auto [geometry_count, vertex_count, triangle_count, instance_count] = h.counts;
        const std::uint64_t limit = f.payload.size();
        // Every section's size against the payload before anything is allocated (each by
        // division, so no count can overflow the sum).
        std::uint64_t need = 8;
        need += section_bytes(geometry_count, scene_geometry_bytes, limit, what, "geometry");
        need += section_bytes(vertex_count, 3 * sizeof(T), limit, what, "vertex");
        need += section_bytes(triangle_count, 12, limit, what, "triangle");
        need += section_bytes(instance_count, scene_instance_bytes<T>, limit, what, "instance");
        ByteReader r(f.payload, what);
        if (need > limit)
            r.fail("the counts claim more than the file's " + std::to_string(limit) + " bytes");
        if (geometry_count >= 0xFFFFFFFEu) r.fail("too many meshes");
        const std::uint64_t tree_bytes = r.u64();
        if (tree_bytes > limit - need) r.fail("the top-level tree claims more bytes than remain");
        std::vector<std::uint64_t> counts(2 * geometry_count);
        std::uint64_t vertex_sum = 0, triangle_sum = 0;
        for (std::size_t g = 0; g < geometry_count; ++g) {
            counts[2 * g] = r.u64(), counts[2 * g + 1] = r.u64();
            if (counts[2 * g] > vertex_count - vertex_sum ||
                counts[2 * g + 1] > triangle_count - triangle_sum)
                r.fail("the meshes hold more vertices or triangles than the header counts");
            vertex_sum += counts[2 * g], triangle_sum += counts[2 * g + 1];
        }
        if (vertex_sum != vertex_count || triangle_sum != triangle_count)
            r.fail("the meshes hold fewer vertices or triangles than the header counts");
        std::vector<BasicTriangleMesh<T>> meshes(geometry_count);
        for (std::size_t g = 0; g < geometry_count; ++g) {
            meshes[g].vertices.resize(counts[2 * g]);
            for (Vec<T, 3>& v : meshes[g].vertices)
                for (std::size_t a = 0; a < 3; ++a) v[a] = r.scalar<T>();
        }
        r.skip_padding(8);
        for (std::size_t g = 0; g < geometry_count; ++g) {
            meshes[g].triangles.resize(counts[2 * g + 1]);
            for (auto& t : meshes[g].triangles) t = {r.u32(), r.u32(), r.u32()};
        }
        r.skip_padding(8);
        struct Record {
            InstanceId id;
            SceneInstance<T> instance;
        };
        std::vector<Record> records(instance_count);
        for (Record& rec : records) {
            rec.id = InstanceId::from_bits(r.u64());
            SceneInstance<T>& x = rec.instance;
            x.geometry = GeometryId(r.u32());
            x.options.group = r.u32(), x.options.mask = r.u32();
            if (r.u32() != 0) r.fail("reserved instance field is not zero");
            x.options.user_data = r.u64();
            for (std::size_t i = 0; i < 3; ++i)
                for (std::size_t j = 0; j < 3; ++j) x.pose.rotation[i][j] = r.scalar<T>();
            for (std::size_t i = 0; i < 3; ++i) x.pose.translation[i] = r.scalar<T>();
            x.options.margin = r.scalar<T>();
        }
        r.skip_padding(8);
        const std::span<const std::uint8_t> tree_file = r.take(tree_bytes);
        r.skip_padding(8);
        if (r.remaining() != 0) r.fail("bytes left after the last section");

        Scene<T> s;
        try {
            s.tree_ = dynamic_tree_from_bytes<T, 3, std::uint64_t>(tree_file);
        } catch (const Error& e) {
            throw Error(std::string(what) + ": its top-level tree: " + e.what());
        }
        if (s.tree_.size() != instance_count)
            r.fail("the tree holds " + std::to_string(s.tree_.size()) + " instances, the file " +
                   std::to_string(instance_count) + " records");
        for (BasicTriangleMesh<T>& m : meshes) {
            try {
                (void)s.add_mesh(m);
            } catch (const Error& e) {
                throw Error(std::string(what) + ": mesh " + std::to_string(s.geometry_count()) +
                            ": " + e.what());
            }
            m = {};  // the scene holds its own copy
        }
        s.instances_.resize(std::size_t(s.tree_.id_bound()));
        std::int32_t previous = -1;
        for (const Record& rec : records) {
            // Live in the tree (the slot and its generation), in increasing slot order: so each
            // live proxy has exactly one record.
            if (!s.tree_.contains(rec.id.proxy()) || rec.id.index() <= previous)
                r.fail("instance id " + rec.id.text() +
                       " is not a live proxy of the top-level tree in slot order");
            previous = rec.id.index();
            const SceneInstance<T>& x = rec.instance;
            if (x.geometry.index() >= s.geometry_count())
                r.fail("instance " + rec.id.text() + " names mesh " +
                       std::to_string(x.geometry.index()) + " of " +
                       std::to_string(s.geometry_count()));
            try {
                check_rigid_pose(x.pose, what, "pose");
                Scene<T>::check_options(x.options, what);
            } catch (const Error& e) {
                r.fail("instance " + rec.id.text() + ": " + e.what());
            }
            SceneInstance<T>& slot = s.instances_[std::size_t(rec.id.index())];
            slot = x;
            const SceneGeometry<T>& g = *s.geometry_[x.geometry.index()];
            slot.box = g.world_box(x.pose, g.pose_pad(x.pose));
        }
        try {
            s.validate();
        } catch (const Error& e) {
            throw Error(std::string(what) + ": " + e.what());
        }
        return s;
    }
};

}  // namespace serial_detail

/// The scene as bytes (format: docs/serialization.md, kind 7): meshes, instances, top-level tree.
template <class T>
std::vector<std::uint8_t> to_bytes(const Scene<T>& scene) {
    return serial_detail::SceneAccess::save(scene);
}

/// Writes the scene to `path` (beside and renamed, as every file: tree_file.hpp); an Error when
/// any step of the write fails, leaving no partial file.
template <class T>
void save(const Scene<T>& scene, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(scene));
}

/// A Scene<T> from bytes written by to_bytes / save (T the saved scalar type). Its bottom-level
/// trees are built at the first query that needs them, as in a new scene (prepare() builds them).
template <class T>
Scene<T> scene_from_bytes(std::span<const std::uint8_t> bytes) {
    return serial_detail::SceneAccess::load<T>(bytes);
}

template <class T>
Scene<T> load_scene(const std::filesystem::path& path) {
    return serial_detail::load_file(
        path, [&](std::span<const std::uint8_t> bytes) { return scene_from_bytes<T>(bytes); });
}

}  // namespace bvhkit
