#pragma once
// Exact references for the triangle-triangle tests, sharing no method or arithmetic with the
// library: coordinates become exact integers (support/exact_int.hpp) and
// - two closed triangles A and B meet exactly when the origin lies in the hull of the nine points
//   a_i - b_j (their Minkowski difference); by Caratheodory's theorem it then lies in a
//   non-degenerate tetrahedron, triangle or segment of those points, or is one of them, each
//   decided by signs of integer determinants (barycentric coordinates of the origin);
// - an orientation sign is the 3x3 determinant expanded as integers.
#include <vector>

#include "bvhkit/primitives/triangle.hpp"
#include "exact_int.hpp"

namespace bvhkit::test {

using IVec = std::array<ExactInt, 3>;

inline IVec isub(const IVec& a, const IVec& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline IVec icross(const IVec& a, const IVec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline ExactInt idot(const IVec& a, const IVec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline bool izero(const IVec& a) {
    return a[0].sign() == 0 && a[1].sign() == 0 && a[2].sign() == 0;
}

/// The points as integer vectors, all scaled by one power of two.
template <class T>
std::vector<IVec> to_integers(const std::vector<Vec<T, 3>>& pts) {
    int shift = -100000;
    for (const auto& p : pts)
        for (int k = 0; k < 3; ++k) shift = std::max(shift, ExactInt::shift_needed(double(p[k])));
    if (shift == -100000) shift = 0;
    std::vector<IVec> out;
    for (const auto& p : pts)
        out.push_back({ExactInt::scaled(double(p[0]), shift), ExactInt::scaled(double(p[1]), shift),
                       ExactInt::scaled(double(p[2]), shift)});
    return out;
}

/// Sign of ((b - a) x (c - a)) . (d - a), exactly.
template <class T>
int exact_orient3d(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const Vec<T, 3>& d) {
    const auto p = to_integers<T>({a, b, c, d});
    return idot(icross(isub(p[1], p[0]), isub(p[2], p[0])), isub(p[3], p[0])).sign();
}

/// Sign of (b - a) x (c - a) in the plane of coordinates x and y, exactly.
template <class T>
int exact_orient2d(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, std::size_t x,
                   std::size_t y) {
    const auto p = to_integers<T>({a, b, c});
    const IVec u = isub(p[1], p[0]), v = isub(p[2], p[0]);
    return (u[x] * v[y] - u[y] * v[x]).sign();
}

/// Whether closed triangles a and b (of any shape, zero area included) meet, exactly, given as
/// integer corners q[0..2] (a) and q[3..5] (b) at one scale.
inline bool exact_integer_triangles_meet(const std::vector<IVec>& q) {
    IVec p[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) p[3 * i + j] = isub(q[i], q[3 + j]);
    for (const auto& x : p)
        if (izero(x)) return true;
    // Determinants of every triple: det[p_i, p_j, p_k].
    ExactInt dets[84];
    int index[9][9][9];
    int count = 0;
    for (int i = 0; i < 9; ++i)
        for (int j = i + 1; j < 9; ++j) {
            const IVec c = icross(p[i], p[j]);
            for (int k = j + 1; k < 9; ++k) {
                index[i][j][k] = count;
                dets[count++] = idot(c, p[k]);
            }
        }
    const auto det3 = [&](int i, int j, int k) -> const ExactInt& { return dets[index[i][j][k]]; };
    // Tetrahedra: the origin's barycentric coordinates are N_m / D with N_m = (-1)^(m+1) times
    // the determinant of the other three points and D = sum of the N_m. The origin is in the
    // closed tetrahedron (and it is non-degenerate) exactly when the non-zero N_m, of which there
    // is at least one, share one sign.
    for (int i = 0; i < 9; ++i)
        for (int j = i + 1; j < 9; ++j)
            for (int k = j + 1; k < 9; ++k)
                for (int l = k + 1; l < 9; ++l) {
                    const int n[4] = {-det3(j, k, l).sign(), det3(i, k, l).sign(),
                                      -det3(i, j, l).sign(), det3(i, j, k).sign()};
                    bool pos = false, neg = false;
                    for (const int x : n) pos = pos || x > 0, neg = neg || x < 0;
                    if (pos != neg) return true;
                }
    // Triangles through the origin's plane: barycentric coordinates along their normal.
    for (int i = 0; i < 9; ++i)
        for (int j = i + 1; j < 9; ++j)
            for (int k = j + 1; k < 9; ++k) {
                if (det3(i, j, k).sign() != 0) continue;
                const IVec n = icross(isub(p[j], p[i]), isub(p[k], p[i]));
                if (izero(n)) continue;
                if (idot(icross(p[i], p[j]), n).sign() >= 0 &&
                    idot(icross(p[j], p[k]), n).sign() >= 0 &&
                    idot(icross(p[k], p[i]), n).sign() >= 0)
                    return true;
            }
    // Segments through the origin.
    for (int i = 0; i < 9; ++i)
        for (int j = i + 1; j < 9; ++j)
            if (izero(icross(p[i], p[j])) && idot(p[i], p[j]).sign() <= 0) return true;
    return false;
}

/// Whether closed triangles a and b (of any shape, zero area included) meet, exactly.
template <class T>
bool exact_triangles_meet(const Triangle<T>& a, const Triangle<T>& b) {
    return exact_integer_triangles_meet(to_integers<T>({a.p0, a.p1, a.p2, b.p0, b.p1, b.p2}));
}

}  // namespace bvhkit::test
