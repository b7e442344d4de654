#pragma once
// The fat boxes of the dynamic tree: a proxy's box grown by a margin and stretched along its
// predicted displacement, so that a small motion stays inside it and move() only updates the tight
// box (Box2D's fat AABBs). Also the options' checks.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/dynamic/tree_validate.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit::dynamic_detail {

template <class T>
void check_options(const DynamicTreeOptions<T>& o) {
    const auto bad = [](const char* name, T v) {
        return Error(std::string("DynamicTree options: ") + name + " = " + format_value(double(v)) +
                     " (must be finite and >= 0)");
    };
    if (!(std::isfinite(o.margin_absolute) && o.margin_absolute >= 0))
        throw bad("margin_absolute", o.margin_absolute);
    if (!(std::isfinite(o.margin_relative) && o.margin_relative >= 0))
        throw bad("margin_relative", o.margin_relative);
    if (!(std::isfinite(o.displacement_multiplier) && o.displacement_multiplier >= 0))
        throw bad("displacement_multiplier", o.displacement_multiplier);
}

/// The fat margin of a box: may be inf (the extent of a box spanning +-FLT_MAX overflows) but
/// never NaN, since a zero relative margin is not multiplied by that extent.
template <class T, std::size_t N>
T margin(const DynamicTreeOptions<T>& o, const Aabb<T, N>& box) {
    T m = o.margin_absolute;
    if (o.margin_relative > T(0)) {
        T e = T(0);
        for (std::size_t i = 0; i < N; ++i) e = std::max(e, box.max[i] - box.min[i]);
        m += o.margin_relative * e;
    }
    return m;
}

/// The box grown by the margin on every side, then stretched along the predicted displacement,
/// then clamped to the finite range: any finite box gets a finite fat box that contains it.
template <class T, std::size_t N>
Aabb<T, N> fat_box(const DynamicTreeOptions<T>& o, const Aabb<T, N>& box,
                   const Vec<T, N>& displacement) {
    constexpr T big = std::numeric_limits<T>::max();
    const T m = margin(o, box);
    Aabb<T, N> fat;
    for (std::size_t i = 0; i < N; ++i) {
        T lo = box.min[i] - m, hi = box.max[i] + m;
        const T s = o.displacement_multiplier * displacement[i];  // +-inf, never NaN
        if (s < 0)
            lo += s;
        else
            hi += s;
        fat.min[i] = std::max(lo, -big);
        fat.max[i] = std::min(hi, big);
    }
    return fat;
}

/// Whether a fat box that still contains the new tight box is kept by move(): unless it is much too
/// large (say after a fast move that stopped), the limit being the fresh fat box grown by three
/// more margins and predictions.
template <class T, std::size_t N>
bool keeps_fat_box(const DynamicTreeOptions<T>& o, const Aabb<T, N>& current, const Aabb<T, N>& box,
                   const Aabb<T, N>& fresh, const Vec<T, N>& displacement) {
    if (!current.contains(box)) return false;
    const Vec<T, N> slack =
        Vec<T, N>(T(3) * margin(o, box)) + abs(displacement) * (T(3) * o.displacement_multiplier);
    return Aabb<T, N>(fresh.min - slack, fresh.max + slack).contains(current);
}

}  // namespace bvhkit::dynamic_detail
