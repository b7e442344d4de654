#pragma once
// The simplex step of GJK (Gilbert, Johnson and Keerthi 1988): the distance between two convex
// sets A and B known only through their support mappings is the distance of the origin to their
// Minkowski difference D = A - B. GJK keeps a simplex of up to four points of D; each step adds the
// support point w of D in the direction -v (v: the simplex's point nearest the origin) and shrinks
// the simplex to the smallest face that holds the new nearest point. |v| bounds the distance from
// above, v.w / |v| from below.
//
// GjkSimplex is that simplex: add() a point (with the point of A behind it, so that a caller can
// recover a witness point), nearest() replaces the simplex by the face nearest the origin and
// gives the nearest point. The nearest point on a triangle is found by the Voronoi regions of its
// vertices and edges (Ericson, Real-Time Collision Detection, 5.1.5); on a tetrahedron, by the
// faces the origin lies outside of. Rounding costs accuracy only: callers that need a guarantee
// (volumes/convex_hull.hpp) certify their answer from support values of their own.
#include <array>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <span>

#include "bvhkit/math/vec.hpp"

namespace bvhkit {

template <class T>
class GjkSimplex {
  public:
    std::size_t size() const { return size_; }
    void clear() { size_ = 0; }
    /// w = a - b: a point of D, `a` the point of A behind it.
    void add(const Vec<T, 3>& w, const Vec<T, 3>& a) {
        w_[size_] = w;
        a_[size_] = a;
        ++size_;
    }
    /// Shrinks the simplex to the face holding its point nearest the origin and returns that
    /// point; `contains_origin` is set (and the origin returned) when a full tetrahedron holds the
    /// origin.
    Vec<T, 3> nearest(bool& contains_origin) {
        contains_origin = false;
        switch (size_) {
            case 1:
                lambda_[0] = T(1);
                break;
            case 2:
                nearest_on_segment(0, 1);
                break;
            case 3:
                nearest_on_triangle(0, 1, 2);
                break;
            default:
                contains_origin = nearest_on_tetrahedron();
                if (contains_origin) return {};  // the weights are left as they were
                break;
        }
        Vec<T, 3> v{};
        for (std::size_t i = 0; i < size_; ++i) v += w_[i] * lambda_[i];
        return v;
    }
    /// The point of A with the simplex's weights (the witness of the nearest point).
    Vec<T, 3> witness_a() const {
        Vec<T, 3> a{};
        for (std::size_t i = 0; i < size_; ++i) a += a_[i] * lambda_[i];
        return a;
    }
    std::span<const T> weights() const { return {lambda_.data(), size_}; }
    /// True when `w` is one of the simplex's points already (GJK has converged).
    bool holds(const Vec<T, 3>& w) const {
        for (std::size_t i = 0; i < size_; ++i)
            if (w_[i] == w) return true;
        return false;
    }
    const Vec<T, 3>& point_a(std::size_t i) const { return a_[i]; }
    /// The simplex's i-th point of D (a - b).
    const Vec<T, 3>& point(std::size_t i) const { return w_[i]; }

  private:
    /// Keeps the listed vertices, with their weights, in that order.
    void keep(std::initializer_list<std::size_t> ids, std::initializer_list<T> weights) {
        std::array<Vec<T, 3>, 4> w, a;
        std::size_t n = 0;
        for (std::size_t id : ids) {
            w[n] = w_[id];
            a[n] = a_[id];
            ++n;
        }
        n = 0;
        for (T l : weights) lambda_[n++] = l;
        for (std::size_t i = 0; i < n; ++i) {
            w_[i] = w[i];
            a_[i] = a[i];
        }
        size_ = n;
    }

    void nearest_on_segment(std::size_t i, std::size_t j) {
        const Vec<T, 3> d = w_[j] - w_[i];
        const T along = -dot(w_[i], d), len2 = dot(d, d);
        if (along <= T(0) || !(len2 > T(0))) return keep({i}, {T(1)});
        if (along >= len2) return keep({j}, {T(1)});
        const T s = along / len2;
        keep({i, j}, {T(1) - s, s});
    }

    /// The origin's nearest point on triangle (i, j, k), by the Voronoi region it falls in.
    void nearest_on_triangle(std::size_t i, std::size_t j, std::size_t k) {
        const Vec<T, 3> a = w_[i], b = w_[j], c = w_[k];
        const Vec<T, 3> ab = b - a, ac = c - a;
        const T d1 = -dot(ab, a), d2 = -dot(ac, a);
        if (d1 <= T(0) && d2 <= T(0)) return keep({i}, {T(1)});
        const T d3 = -dot(ab, b), d4 = -dot(ac, b);
        if (d3 >= T(0) && d4 <= d3) return keep({j}, {T(1)});
        const T vc = d1 * d4 - d3 * d2;
        if (vc <= T(0) && d1 >= T(0) && d3 <= T(0)) {
            const T s = d1 / (d1 - d3);
            return keep({i, j}, {T(1) - s, s});
        }
        const T d5 = -dot(ab, c), d6 = -dot(ac, c);
        if (d6 >= T(0) && d5 <= d6) return keep({k}, {T(1)});
        const T vb = d5 * d2 - d1 * d6;
        if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) {
            const T s = d2 / (d2 - d6);
            return keep({i, k}, {T(1) - s, s});
        }
        const T va = d3 * d6 - d5 * d4;
        if (va <= T(0) && d4 - d3 >= T(0) && d5 - d6 >= T(0)) {
            const T s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            return keep({j, k}, {T(1) - s, s});
        }
        const T sum = va + vb + vc;
        if (!(sum > T(0))) {
            // A flat triangle: its nearest point is on one of its edges.
            return nearest_on_flat_triangle(i, j, k);
        }
        const T v = vb / sum, w = vc / sum;
        keep({i, j, k}, {T(1) - v - w, v, w});
    }

    void nearest_on_flat_triangle(std::size_t i, std::size_t j, std::size_t k) {
        const std::array<std::array<std::size_t, 2>, 3> edges{{{i, j}, {j, k}, {i, k}}};
        T best = std::numeric_limits<T>::infinity();
        std::array<std::size_t, 2> pick = edges[0];
        for (const auto& e : edges) {
            const Vec<T, 3> d = w_[e[1]] - w_[e[0]];
            const T len2 = dot(d, d);
            T s = len2 > T(0) ? -dot(w_[e[0]], d) / len2 : T(0);
            s = s < T(0) ? T(0) : (s > T(1) ? T(1) : s);
            const T dist = length_squared(w_[e[0]] + d * s);
            if (dist < best) {
                best = dist;
                pick = e;
            }
        }
        nearest_on_segment(pick[0], pick[1]);
    }

    /// True when the origin is inside (or on) the tetrahedron; otherwise shrinks to the nearest of
    /// the faces the origin is outside of.
    bool nearest_on_tetrahedron() {
        static constexpr std::size_t faces[4][4] = {
            {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // three corners, opposite
        T best = std::numeric_limits<T>::infinity();
        GjkSimplex nearest_face;
        for (int f = 0; f < 4; ++f) {
            const Vec<T, 3>& a = w_[faces[f][0]];
            const Vec<T, 3> n = cross(w_[faces[f][1]] - a, w_[faces[f][2]] - a);
            const T origin_side = -dot(n, a), opposite_side = dot(n, w_[faces[f][3]] - a);
            // Outside: the origin and the opposite corner on different sides (a flat tetrahedron
            // counts every face as a candidate).
            if (!(origin_side * opposite_side < T(0)) && opposite_side != T(0)) continue;
            GjkSimplex face;
            for (int c = 0; c < 3; ++c) face.add(w_[faces[f][c]], a_[faces[f][c]]);
            bool unused;
            const T dist = length_squared(face.nearest(unused));
            if (dist < best) {
                best = dist;
                nearest_face = face;
            }
        }
        if (nearest_face.size_ == 0) return true;
        *this = nearest_face;
        return false;
    }

    std::array<Vec<T, 3>, 4> w_{}, a_{};
    std::array<T, 4> lambda_{};
    std::size_t size_ = 0;
};

}  // namespace bvhkit
