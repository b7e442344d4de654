#pragma once
// ObbRss<T>: an oriented box and a rectangle swept sphere over the same triangles, so that one
// CollisionModel answers both collision and distance at the speed of the better volume for each
// (the pairing of Larsen, Gottschalk, Lin and Manocha 1999's RSS with Gottschalk, Lin and Manocha
// 1996's OBB). Overlap tests and the descent rule use the box, which is tighter for overlap;
// distance lower bounds use the swept sphere, whose bound is the exact distance between the
// volumes. It costs the memory of both (two fits a node at build time).
#include "bvhkit/volumes/obb.hpp"
#include "bvhkit/volumes/rss.hpp"

namespace bvhkit {

template <class T>
struct ObbRss {
    using Scalar = T;
    Obb<T> obb;
    Rss<T> rss;
    Vec<T, 3> center{};  // the box's centre, by which the traversals order children
};

template <class T>
struct VolumeTraits<ObbRss<T>> {
    using V = ObbRss<T>;
    using Box = VolumeTraits<Obb<T>>;
    using Swept = VolumeTraits<Rss<T>>;
    using Prepared = PreparedPose<T>;
    static constexpr bool merge_is_tight = false;

    static V fit(std::span<const Triangle<T>> tris) {
        return make(Box::fit(tris), Swept::fit(tris));
    }
    static V merge(const V& a, const V& b) {
        return make(Box::merge(a.obb, b.obb), Swept::merge(a.rss, b.rss));
    }
    static bool overlaps(const V& a, const V& b) { return Box::overlaps(a.obb, b.obb); }
    static Prepared prepare(const Transform<T>& pose, T slack) { return {pose, slack}; }
    static bool overlaps(const V& a, const V& b, const Prepared& p) {
        return Box::overlaps(a.obb, b.obb, p);
    }
    static T size(const V& v) { return Box::size(v.obb); }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p) {
        return Swept::distance_lower_bound(a.rss, b.rss, p);
    }
    static T distance_lower_bound(const V& a, const V& b, const Prepared& p, T cutoff) {
        return Swept::distance_lower_bound(a.rss, b.rss, p, cutoff);
    }

    /// b carried into A's frame once for the several tests of a traversal step (see obb.hpp).
    static V place(const V& b, const Prepared& p) {
        return make(Box::place(b.obb, p), Swept::place(b.rss, p));
    }
    static bool overlaps_placed(const V& a, const V& w, T slack) {
        return Box::overlaps_placed(a.obb, w.obb, slack);
    }
    static T distance_lower_bound_placed(const V& a, const V& w, T slack, T cutoff) {
        return Swept::distance_lower_bound_placed(a.rss, w.rss, slack, cutoff);
    }

  private:
    static V make(const Obb<T>& box, const Rss<T>& swept) { return {box, swept, box.center}; }
};

}  // namespace bvhkit
