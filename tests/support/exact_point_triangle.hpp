#pragma once
// The exact squared distance from a point to a triangle, for judging the library's closest point:
// big integers, no rounding anywhere. Every float or double coordinate is an integer times a
// power of two; scaled to a common exponent, the corners and the point are integer vectors and the
// squared distance is a rational number, the least of
//   - a corner's squared distance,
//   - an edge's, where the point's foot falls strictly inside it: (|w|^2 |e|^2 - (w.e)^2) / |e|^2
//     (w from the edge's start, e the edge; Lagrange's identity),
//   - the plane's, when the point's projection is on the inner side of all three edges (exact
//     signs of n . (edge x (p - start))): (n . (p - a))^2 / |n|^2.
// This shares nothing with the library's method (a rotated frame in wider floating point).
// to_long_double() rounds the result with a relative error below 2^-61 (the top 64 bits of the
// numerator and of the denominator), far below every tolerance it is compared with.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit::test::pt_exact {

/// A signed integer of any size: magnitude in 32-bit limbs, least significant first.
class BigInt {
  public:
    BigInt() = default;
    /// m * 2^shift (shift >= 0).
    static BigInt from(std::int64_t m, int shift) {
        BigInt r;
        r.neg_ = m < 0;
        std::uint64_t u = m < 0 ? std::uint64_t(0) - std::uint64_t(m) : std::uint64_t(m);
        r.mag_.assign(std::size_t(shift / 32), 0u);
        const int s = shift % 32;
        // Up to 64 + 31 bits, in three limbs.
        r.mag_.push_back(std::uint32_t(u << s));
        r.mag_.push_back(std::uint32_t((u << s) >> 32));
        r.mag_.push_back(s ? std::uint32_t(u >> (64 - s)) : 0u);
        r.trim();
        return r;
    }
    bool is_zero() const { return mag_.empty(); }
    int sign() const { return is_zero() ? 0 : (neg_ ? -1 : 1); }

    friend BigInt operator+(const BigInt& a, const BigInt& b) {
        if (a.neg_ == b.neg_) return make(add(a.mag_, b.mag_), a.neg_);
        if (compare(a.mag_, b.mag_) >= 0) return make(sub(a.mag_, b.mag_), a.neg_);
        return make(sub(b.mag_, a.mag_), b.neg_);
    }
    friend BigInt operator-(const BigInt& a, const BigInt& b) {
        BigInt nb = b;
        nb.neg_ = !b.neg_;
        nb.trim();
        return a + nb;
    }
    friend BigInt operator*(const BigInt& a, const BigInt& b) {
        std::vector<std::uint32_t> r(a.mag_.size() + b.mag_.size(), 0u);
        for (std::size_t i = 0; i < a.mag_.size(); ++i) {
            std::uint64_t carry = 0;
            for (std::size_t j = 0; j < b.mag_.size(); ++j) {
                const std::uint64_t t = std::uint64_t(a.mag_[i]) * b.mag_[j] + r[i + j] + carry;
                r[i + j] = std::uint32_t(t);
                carry = t >> 32;
            }
            r[i + b.mag_.size()] = std::uint32_t(carry);
        }
        return make(std::move(r), a.neg_ != b.neg_);
    }
    /// Sign of a - b.
    friend int compare(const BigInt& a, const BigInt& b) { return (a - b).sign(); }

    /// The value, rounded (relative error below 2^-62), as mantissa * 2^exponent.
    long double to_long_double() const {
        if (is_zero()) return 0.0L;
        const std::size_t n = mag_.size();
        // The top three limbs: at least 65 significant bits, truncated.
        long double m = 0;
        for (std::size_t k = 0; k < 3 && k < n; ++k)
            m = m * 4294967296.0L + (long double)mag_[n - 1 - k];
        const int dropped = n > 3 ? int(32 * (n - 3)) : 0;
        const long double v = std::ldexp(m, dropped);
        return neg_ ? -v : v;
    }
    /// log2 of the magnitude, roughly (for scaling before to_long_double overflows).
    int bit_length() const {
        if (is_zero()) return 0;
        return int(32 * (mag_.size() - 1)) + 32 - __builtin_clz(mag_.back());
    }
    /// The value divided by 2^k (truncated towards zero), k >= 0.
    BigInt shifted_down(int k) const {
        BigInt r;
        r.neg_ = neg_;
        const std::size_t limbs = std::size_t(k / 32);
        const int s = k % 32;
        for (std::size_t i = limbs; i < mag_.size(); ++i) {
            std::uint64_t v = mag_[i] >> s;
            if (s && i + 1 < mag_.size()) v |= std::uint64_t(mag_[i + 1]) << (32 - s);
            r.mag_.push_back(std::uint32_t(v));
        }
        r.trim();
        return r;
    }

  private:
    using Mag = std::vector<std::uint32_t>;
    static BigInt make(Mag m, bool neg) {
        BigInt r;
        r.mag_ = std::move(m);
        r.neg_ = neg;
        r.trim();
        return r;
    }
    void trim() {
        while (!mag_.empty() && mag_.back() == 0) mag_.pop_back();
        if (mag_.empty()) neg_ = false;
    }
    static int compare(const Mag& a, const Mag& b) {
        if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
        for (std::size_t i = a.size(); i-- > 0;)
            if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
        return 0;
    }
    static Mag add(const Mag& a, const Mag& b) {
        Mag r(std::max(a.size(), b.size()) + 1, 0u);
        std::uint64_t carry = 0;
        for (std::size_t i = 0; i < r.size(); ++i) {
            const std::uint64_t t = carry + (i < a.size() ? a[i] : 0u) + (i < b.size() ? b[i] : 0u);
            r[i] = std::uint32_t(t);
            carry = t >> 32;
        }
        return r;
    }
    static Mag sub(const Mag& a, const Mag& b) {  // |a| >= |b|
        Mag r(a.size(), 0u);
        std::int64_t borrow = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            std::int64_t t = std::int64_t(a[i]) - (i < b.size() ? b[i] : 0u) - borrow;
            borrow = t < 0;
            if (t < 0) t += std::int64_t(1) << 32;
            r[i] = std::uint32_t(t);
        }
        return r;
    }

    bool neg_ = false;
    Mag mag_;
};

/// A rational with a positive denominator.
struct Rational {
    BigInt num, den;
    friend bool operator<(const Rational& a, const Rational& b) {
        return compare(a.num * b.den, b.num * a.den) < 0;
    }
    /// num / den * 2^exponent, rounded (relative error below 2^-61).
    long double to_long_double(int exponent = 0) const {
        if (num.is_zero()) return 0.0L;
        // Bring both to at most ~100 bits first so that long double neither overflows nor
        // underflows on the way.
        const int sn = std::max(0, num.bit_length() - 100),
                  sd = std::max(0, den.bit_length() - 100);
        const long double n = num.shifted_down(sn).to_long_double();
        const long double d = den.shifted_down(sd).to_long_double();
        return std::ldexp(n / d, exponent + sn - sd);
    }
};

using IVec = std::array<BigInt, 3>;

inline BigInt idot(const IVec& a, const IVec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline IVec isub(const IVec& a, const IVec& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline IVec icross(const IVec& a, const IVec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// The exact squared distance from p to the triangle: squared_distance.to_long_double(exponent).
struct ExactDistance {
    Rational squared_distance;
    int exponent = 0;  // of the squared distance (twice the coordinates' common exponent)
    long double value() const { return squared_distance.to_long_double(exponent); }
};

/// The exact squared distance from p to tri (finite coordinates).
template <class T>
ExactDistance exact_distance_squared(const Triangle<T>& tri, const Vec<T, 3>& p) {
    const Vec<T, 3>* pts[4] = {&tri.p0, &tri.p1, &tri.p2, &p};
    // Each coordinate as m * 2^e with an integer m of at most 53 bits; the least e is common.
    int least = 1 << 30;
    std::int64_t m[4][3];
    int e[4][3];
    for (int k = 0; k < 4; ++k)
        for (int a = 0; a < 3; ++a) {
            int ex = 0;
            const double f = std::frexp(double((*pts[k])[a]), &ex);
            m[k][a] = std::int64_t(std::ldexp(f, 53));
            e[k][a] = ex - 53;
            if (m[k][a] != 0) least = std::min(least, e[k][a]);
        }
    if (least == (1 << 30)) least = 0;
    IVec v[4];
    for (int k = 0; k < 4; ++k)
        for (int a = 0; a < 3; ++a)
            v[k][a] = m[k][a] == 0 ? BigInt() : BigInt::from(m[k][a], e[k][a] - least);
    const IVec &A = v[0], &B = v[1], &C = v[2], &P = v[3];
    const BigInt one = BigInt::from(1, 0);

    Rational best{idot(isub(P, A), isub(P, A)), one};
    const auto consider = [&](const Rational& r) {
        if (r < best) best = r;
    };
    consider({idot(isub(P, B), isub(P, B)), one});
    consider({idot(isub(P, C), isub(P, C)), one});
    const IVec* corners[3] = {&A, &B, &C};
    for (int k = 0; k < 3; ++k) {
        const IVec& s = *corners[k];
        const IVec e1 = isub(*corners[(k + 1) % 3], s), w = isub(P, s);
        const BigInt len2 = idot(e1, e1), along = idot(w, e1);
        if (along.sign() > 0 && compare(along, len2) < 0)
            consider({idot(w, w) * len2 - along * along, len2});
    }
    const IVec n = icross(isub(B, A), isub(C, A));
    const BigInt nn = idot(n, n);
    if (!nn.is_zero()) {
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
            const IVec& s = *corners[k];
            const IVec side = icross(isub(*corners[(k + 1) % 3], s), isub(P, s));
            inside = idot(n, side).sign() >= 0;
        }
        if (inside) {
            const BigInt h = idot(n, isub(P, A));
            consider({h * h, nn});
        }
    }
    return {best, 2 * least};
}

}  // namespace bvhkit::test::pt_exact
