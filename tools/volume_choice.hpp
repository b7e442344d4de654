#pragma once
// `--volume NAME` of the collide and distance commands: the bounding volume types a CollisionModel
// can be built with, by name, written once for every command that offers the choice.
#include <string>

#include "bvhkit/error.hpp"
#include "bvhkit/volumes/aabb_volume.hpp"
#include "bvhkit/volumes/convex_hull.hpp"
#include "bvhkit/volumes/kdop.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/obb_rss.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "bvhkit/volumes/sphere.hpp"

namespace bvhkit::tools {

inline constexpr const char* kVolumeNames = "aabb, obb, rss, obbrss, sphere, kdop18, hull";

template <class V>
struct VolumeTag {
    using type = V;
};

/// Calls run(VolumeTag<V>{}) with the volume type named `name`; an unknown name is an Error.
template <class Run>
void with_volume(const std::string& name, Run&& run) {
    if (name == "aabb")
        run(VolumeTag<Aabb3f>{});
    else if (name == "obb")
        run(VolumeTag<Obb<float>>{});
    else if (name == "rss")
        run(VolumeTag<Rss<float>>{});
    else if (name == "obbrss")
        run(VolumeTag<ObbRss<float>>{});
    else if (name == "sphere")
        run(VolumeTag<Sphere<float>>{});
    else if (name == "kdop18")
        run(VolumeTag<Kdop<float, 18>>{});
    else if (name == "hull")
        run(VolumeTag<ConvexHull<float>>{});
    else
        throw Error("--volume: unknown bounding volume '" + name + "' (" + kVolumeNames + ")");
}

}  // namespace bvhkit::tools
