#pragma once
// signed_distance_between(A, B, pose_of_b_in_a): for two closed solids (query/solid_model.hpp),
// the distance when their interiors are disjoint, minus the translational penetration depth when
// they overlap, with witness points and the direction, all in A's frame.
//
// Overlap: some faces meet (the exact test of collides(), touching included) or one interior holds
// the other (a vertex of one inside the other by the winding number, asked only when no faces
// meet). Penetration depth: the length of the shortest translation of B that leaves the interiors
// disjoint.
//
// How: every candidate translation is a direction d and the least t along d that separates, found
// by bisection on the exact overlap decision, so whatever is returned separates by construction
// and is checked: B moved by (1 + 1e-6) of it leaves no face meeting and no containment, by
// (1 - 1e-3) of it still overlaps. The directions:
// - both solids convex: the normal of EPA (convex/penetration.hpp) on the two hulls, which are
//   the solids; the answer is exact up to EPA's tolerance (quality Exact).
// - otherwise: a local optimisation over directions in the spirit of PolyDepth (Je, Tang, Lee,
//   Kim 2012, "PolyDepth: Real-time penetration depth computation using iterative contact-space
//   projection"): seeds (the hulls' EPA normal, the 26 directions of a cube's faces, edges and
//   corners, 64 more spread on the sphere), then from the best, projection steps along the
//   contact-space
//   normal at the touching configuration (the closest pair's direction just past contact: the
//   optimum translation is parallel to it), then a pattern search over directions with a
//   halving angle. The result is a proven upper bound on the depth (it separates) and a local
//   optimum (quality LocalOptimum); a translation through a pocket of A that B fits is a valid
//   separating translation and may be what is found.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "bvhkit/convex/penetration.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "bvhkit/query/solid_model.hpp"

namespace bvhkit {

enum class DepthQuality : std::uint8_t {
    Exact,         // apart (the distance), or both solids convex (EPA's tolerance)
    LocalOptimum,  // overlapping non-convex solids: a separating translation, locally shortest
};

template <class T>
struct MeshSignedDistance {
    /// The distance when the interiors are disjoint (> 0; 0 only for no overlap at all, as the
    /// exact test counts touching as overlap), minus the penetration depth when they overlap.
    T signed_distance = 0;
    /// Apart: the closest points. Overlapping: point_a on A's surface where B touches it once
    /// moved by depth * normal, point_b the point of B (at the pose given) that comes there.
    /// Always point_b - point_a = signed_distance * normal, up to rounding. A's frame.
    Vec<T, 3> point_a{}, point_b{};
    /// Unit direction: apart, from point_a to point_b; overlapping, the direction B moves (by the
    /// depth) to separate.
    Vec<T, 3> normal{};
    DepthQuality quality = DepthQuality::Exact;
    /// Overlapping with no faces meeting: one interior holds the other.
    bool contained = false;
    /// Whether the separation checks held (B moved by (1 + 1e-6) and (1 - 1e-3) of the
    /// translation); false only when the search ran out of steps (then the translation still
    /// separates, but a shorter one along it may too).
    bool verified = true;
    int overlap_tests = 0;  // exact overlap decisions made
};

struct MeshPenetrationOptions {
    int max_overlap_tests = 4000;        // the whole query's budget of exact overlap decisions
    double smallest_angle = 1e-4;        // radians: the pattern search's last step
    double search_precision = 1e-6;      // relative bracket of the bisections while searching
    double final_precision = 1.0 / 8e6;  // relative bracket of the answer's bisection
    /// A direction to try first besides the seeds (A's frame; zero: none), such as the last
    /// query's normal in a loop over moving solids, so that the answer follows its optimum.
    std::array<double, 3> hint{0, 0, 0};
};

namespace penetration_detail {

/// Error naming the first option out of its range: a budget below one test, a step or a bracket
/// that is not finite and positive (a zero step would search until the budget runs out).
inline void check_options(const MeshPenetrationOptions& o) {
    const auto fail = [](const char* name, double value, const char* range) {
        throw Error(std::string("signed_distance_between: options.") + name + " = " +
                    std::to_string(value) + " must be " + range);
    };
    if (o.max_overlap_tests < 1) fail("max_overlap_tests", o.max_overlap_tests, ">= 1");
    if (!(o.smallest_angle > 0 && o.smallest_angle <= 3.2))
        fail("smallest_angle", o.smallest_angle, "in (0, pi] radians");
    if (!(o.search_precision > 0 && o.search_precision < 1))
        fail("search_precision", o.search_precision, "in (0, 1)");
    if (!(o.final_precision > 0 && o.final_precision < 1))
        fail("final_precision", o.final_precision, "in (0, 1)");
}

template <BoundingVolume V>
class DepthSearch {
  public:
    using T = typename V::Scalar;
    using Vec3 = Vec<T, 3>;

    DepthSearch(const SolidModel<V>& a, const SolidModel<V>& b, const Transform<T>& pose,
                const MeshPenetrationOptions& options)
        : a_(a), b_(b), pose_(pose), options_(options) {
        // A length below which a depth is rounding: the scale of the coordinates.
        tiny_ = T(64) * std::numeric_limits<T>::epsilon() *
                (a.collision().scale() + b.collision().scale() +
                 max_component(bvhkit::max(pose.translation, -pose.translation)));
    }

    int tests() const { return tests_; }

    /// Whether the interiors overlap with B moved by v.
    bool overlaps_at(const Vec3& v, bool* contained = nullptr) {
        ++tests_;
        const Transform<T> p{pose_.rotation, pose_.translation + v};
        if (collides(a_.collision(), b_.collision(), p)) return true;
        bool c = false;
        for (const Vec3& q : b_.probes()) c = c || a_.contains(p.apply(q));
        const Transform<T> back = p.inverse();
        for (const Vec3& q : a_.probes()) c = c || b_.contains(back.apply(q));
        if (contained) *contained = c;
        return c;
    }
    bool overlaps(const Vec3& d, T t) { return overlaps_at(d * t); }
    bool out_of_budget() const { return tests_ >= options_.max_overlap_tests; }

    /// A t at which B moved by t d is strictly beyond A's hull along d (so apart).
    T beyond(const Vec3& d) const {
        const Vec3 sa = a_.hull().support(d);
        const Vec3 db = pose_.rotation.transposed() * (-d);
        const Vec3 sb = pose_.apply(b_.hull().support(db));
        const T gap = dot(d, sa) - dot(d, sb);
        return std::max(gap, T(0)) * T(1.001) + T(4) * tiny_ + T(1e-6) * scale();
    }

    /// Bisection of [lo, hi] (overlap at lo, apart at hi) until hi - lo <= rel * hi or below
    /// the rounding length; returns hi (apart).
    T bisect(const Vec3& d, T lo, T hi, double rel) {
        while (hi - lo > T(rel) * hi && hi > tiny_ && !out_of_budget()) {
            const T mid = lo + (hi - lo) / 2;
            if (mid <= lo || mid >= hi) break;
            if (overlaps(d, mid))
                lo = mid;
            else
                hi = mid;
        }
        return hi;
    }

    /// The least separating t along d (apart at t, overlapping just below), starting from `hi`
    /// known apart; the lower end is guessed near hi first, so a small improvement costs few
    /// steps.
    T along(const Vec3& d, T hi, double rel) {
        T lo = 0;
        const T guess = hi * T(0.95);
        if (guess > tiny_) {
            if (overlaps(d, guess))
                lo = guess;
            else
                hi = guess;
        }
        return bisect(d, lo, hi, rel);
    }

    /// Whether direction d beats the best: apart at best * (1 - margin) along d, then its own
    /// least t.
    bool improve(Vec3 d, double margin) {
        const T len = length(d);
        if (!(len > T(0))) return false;
        d = d * (T(1) / len);
        const T probe = best_t_ * T(1 - margin);
        if (out_of_budget() || overlaps(d, probe)) return false;
        const T t = along(d, probe, options_.search_precision);
        best_t_ = t;
        best_d_ = d;
        return true;
    }

    void start(const Vec3& d) {
        best_d_ = d;
        const T top = beyond(d);
        best_t_ = along(d, top, options_.search_precision);
    }

    /// The contact-space normal at the best touching configuration: the closest pair's direction
    /// with B just past contact.
    bool contact_normal(Vec3& n) {
        const T t = best_t_ * T(1 + 1e-4) + T(4) * tiny_;
        const Transform<T> p{pose_.rotation, pose_.translation + best_d_ * t};
        const DistanceResult<T> r = distance(a_.collision(), b_.collision(), p);
        const Vec3 g = r.point_b - r.point_a;
        const T len = length(g);
        if (!(r.distance > T(0)) || !(len > T(0))) return false;
        n = g * (T(1) / len);
        return true;
    }

    void search(const Vec3& seed_hint) {
        // Seeds.
        start(seed_hint);
        const Vec3 hint{T(options_.hint[0]), T(options_.hint[1]), T(options_.hint[2])};
        if (length_squared(hint) > T(0)) improve(hint, 1e-6);
        for (int x = -1; x <= 1; ++x)
            for (int y = -1; y <= 1; ++y)
                for (int z = -1; z <= 1; ++z)
                    if (x || y || z) improve(Vec3{T(x), T(y), T(z)}, 1e-6);
        // A Fibonacci lattice on the sphere fills the lattice's gaps: each costs one test unless
        // it is better.
        for (int k = 0; k < fibonacci_seeds; ++k) {
            const double z = 1 - (2 * k + 1) / double(fibonacci_seeds);
            const double rho = std::sqrt(1 - z * z), phi = k * 2.399963229728653;
            improve(Vec3{T(rho * std::cos(phi)), T(rho * std::sin(phi)), T(z)}, 1e-6);
        }
        // Projection steps: toward the contact-space normal.
        for (int k = 0; k < 16 && !out_of_budget(); ++k) {
            Vec3 n;
            if (!contact_normal(n) || dot(n, best_d_) > T(1 - 1e-12)) break;
            bool moved = false;
            for (const T w : {T(1), T(0.5), T(0.25)})
                if (improve(best_d_ + (n - best_d_) * w, 1e-6)) {
                    moved = true;
                    break;
                }
            if (!moved) break;
        }
        // Pattern search over directions: 8 neighbours in the tangent plane, the angle halving
        // when none is better.
        double angle = 0.25;
        while (angle >= options_.smallest_angle && !out_of_budget()) {
            const Vec3 u = normalize(any_perpendicular(best_d_));
            const Vec3 v = cross(best_d_, u);
            const T s = T(std::tan(angle));
            bool moved = false;
            for (int k = 0; k < 8 && !moved; ++k) {
                const double phi = k * 0.7853981633974483;
                const Vec3 step = (u * T(std::cos(phi)) + v * T(std::sin(phi))) * s;
                moved = improve(best_d_ + step, 1e-7);
            }
            if (!moved) angle *= 0.5;
        }
    }

    /// The answer: the best direction's least t to the final precision, then the checks of the
    /// translation as returned (t rounded to T, times the unit normal in T).
    T finish(bool& verified) {
        const Vec3 d = best_d_;
        T hi = best_t_;
        T lo = std::max(T(0), hi * T(1 - 4 * options_.search_precision));
        if (lo > 0 && !overlaps(d, lo)) lo = 0;
        hi = bisect(d, lo, hi, options_.final_precision);
        verified = false;
        const T top = beyond(d);
        for (int round = 0; round < 8; ++round) {
            if (hi <= tiny_) {
                verified = !overlaps(d, hi * T(1 + 1e-6));
                if (verified) break;
            }
            const T over = hi * T(1 + 1e-6);
            if (overlaps(d, over)) {
                // Apart at hi, overlapping just past it: a gap B only just fits; look farther.
                hi = bisect(d, over, top, options_.final_precision);
                continue;
            }
            const T under = hi * T(1 - 1e-3);
            if (!overlaps(d, under)) {
                hi = bisect(d, T(0), under, options_.final_precision);
                continue;
            }
            verified = true;
            break;
        }
        best_t_ = hi;
        return hi;
    }

    const Vec3& direction() const { return best_d_; }
    T depth() const { return best_t_; }
    T scale() const { return a_.collision().scale() + b_.collision().scale(); }

  private:
    static constexpr int fibonacci_seeds = 64;

    static Vec3 any_perpendicular(const Vec3& d) {
        const T ax = std::abs(d[0]), ay = std::abs(d[1]), az = std::abs(d[2]);
        if (ax <= ay && ax <= az) return cross(d, Vec3{T(1), T(0), T(0)});
        if (ay <= az) return cross(d, Vec3{T(0), T(1), T(0)});
        return cross(d, Vec3{T(0), T(0), T(1)});
    }

    const SolidModel<V>& a_;
    const SolidModel<V>& b_;
    Transform<T> pose_;
    MeshPenetrationOptions options_;
    T tiny_ = 0;
    int tests_ = 0;
    Vec3 best_d_{};
    T best_t_ = 0;
};

/// The first seed direction: the hulls' EPA normal (+z when EPA gives none).
template <BoundingVolume V>
Vec<typename V::Scalar, 3> seed_direction(const SolidModel<V>& a, const SolidModel<V>& b,
                                          const Transform<typename V::Scalar>& pose,
                                          bool* epa_converged) {
    using T = typename V::Scalar;
    const Transform<T> identity{Mat3<T>::identity(), Vec<T, 3>(T(0))};
    // GJK and EPA work on the pair brought to unit size (convex/distance.hpp), so the hulls'
    // answer holds at every scale.
    const ConvexSignedDistance<T> h = convex_signed_distance(a.hull(), identity, b.hull(), pose);
    if (epa_converged) *epa_converged = h.converged;
    if (length_squared(h.normal) > T(0.5)) return h.normal;
    return Vec<T, 3>{T(0), T(0), T(1)};
}

/// v at unit length, computed after scaling by its largest component so that neither a huge nor
/// a tiny v over- or underflows; zero for a zero or non-finite v.
template <class T>
Vec<T, 3> unit_direction(const Vec<T, 3>& v) {
    const T m = max_component(bvhkit::max(v, -v));
    if (!(m > T(0)) || !std::isfinite(m)) return Vec<T, 3>(T(0));
    const Vec<T, 3> w = v / m;
    return w / std::sqrt(dot(w, w));
}

}  // namespace penetration_detail

/// The signed distance between solids A and B, B placed in A's frame by pose_of_b_in_a (finite and
/// rigid, else Error): see the header comment.
template <BoundingVolume V>
MeshSignedDistance<typename V::Scalar> signed_distance_between(
    const SolidModel<V>& a, const SolidModel<V>& b,
    const Transform<typename V::Scalar>& pose_of_b_in_a,
    const MeshPenetrationOptions& options = {}) {
    using T = typename V::Scalar;
    check_rigid_pose(pose_of_b_in_a, "signed_distance_between", "pose_of_b_in_a");
    penetration_detail::check_options(options);
    MeshSignedDistance<T> r;
    penetration_detail::DepthSearch<V> s(a, b, pose_of_b_in_a, options);
    // Apart, by the exact decision (no face meets, no piece inside the other solid): the
    // surfaces' distance, which rounding may make 0 but never negative.
    bool contained = false;
    if (!s.overlaps_at(Vec<T, 3>(T(0)), &contained)) {
        const DistanceResult<T> apart = distance(a.collision(), b.collision(), pose_of_b_in_a);
        r.signed_distance = apart.distance;
        r.point_a = apart.point_a;
        r.point_b = apart.point_b;
        r.normal = penetration_detail::unit_direction(apart.point_b - apart.point_a);
        r.quality = DepthQuality::Exact;
        r.overlap_tests = s.tests();
        return r;
    }
    r.contained = contained;
    bool epa_converged = false;
    const Vec<T, 3> seed = penetration_detail::seed_direction(a, b, pose_of_b_in_a, &epa_converged);
    if (a.convex() && b.convex() && epa_converged) {
        s.start(seed);
        r.quality = DepthQuality::Exact;
    } else {
        s.search(seed);
        r.quality = DepthQuality::LocalOptimum;
    }
    bool verified = false;
    const T depth = s.finish(verified);
    const Vec<T, 3> d = s.direction();
    r.verified = verified;
    r.signed_distance = -depth;
    r.normal = d;
    // The witnesses: the closest pair just past the separating translation, B's point carried
    // back to the pose given.
    const T past = depth * T(1 + 1e-6);
    const Transform<T> moved{pose_of_b_in_a.rotation, pose_of_b_in_a.translation + d * past};
    const DistanceResult<T> w = distance(a.collision(), b.collision(), moved);
    r.point_a = w.point_a;
    r.point_b = w.point_a - d * depth;
    r.overlap_tests = s.tests();
    return r;
}

}  // namespace bvhkit
