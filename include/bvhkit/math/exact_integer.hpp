#pragma once
// DyadicInt: a signed integer of bounded size (sign and magnitude in 32-bit limbs, only the used
// limbs touched) for the rare exact evaluations that floating-point expansions cannot size in
// advance: the corners of a triangle carried by a pose, R x + t, taken exactly (a sum of products
// of doubles), and orientation determinants of such corners (query/posed_triangles.hpp).
//
// Every finite double is m * 2^e with integer m and e >= -1074, so a set of doubles scaled by one
// common power of two are integers (from_double), and sums and products of them stay exact.
// Capacity: `limbs` bounds the magnitude; the largest use is a determinant of three differences of
// such corners, each a product of two doubles plus a double: below 2^(3 * (2 * 1074 + 1027) + 8),
// which 300 limbs (9,600 bits) hold.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace bvhkit::exact {

class DyadicInt {
  public:
    static constexpr int limbs = 300;

    DyadicInt() = default;
    DyadicInt(const DyadicInt& o) : n_(o.n_), sign_(o.sign_) {
        std::copy(o.mag_.begin(), o.mag_.begin() + n_, mag_.begin());
    }
    DyadicInt& operator=(const DyadicInt& o) {
        n_ = o.n_;
        sign_ = o.sign_;
        std::copy(o.mag_.begin(), o.mag_.begin() + n_, mag_.begin());
        return *this;
    }

    /// The exponent s for which x * 2^s is the smallest integer multiple of x's last bit: for
    /// from_double, every x of a set needs shift >= lowest_shift(x). 0 gives a very small value.
    static int lowest_shift(double x) {
        if (x == 0) return -4000;
        int e = 0;
        auto m = std::uint64_t(std::ldexp(std::frexp(std::fabs(x), &e), 53));  // |x| = m 2^(e-53)
        int k = e - 53;
        while ((m & 1) == 0) m >>= 1, ++k;
        return -k;
    }

    /// x * 2^shift for finite x with shift >= lowest_shift(x) (an integer).
    static DyadicInt from_double(double x, int shift) {
        DyadicInt r;
        if (x == 0) return r;
        int e = 0;
        auto m = std::uint64_t(std::ldexp(std::frexp(std::fabs(x), &e), 53));
        int k = e - 53 + shift;
        while (k < 0) m >>= 1, ++k;  // only zero bits leave (shift >= lowest_shift(x))
        r.sign_ = x > 0 ? 1 : -1;
        while (m != 0) {
            r.mag_[r.n_++] = std::uint32_t(m);
            m >>= 32;
        }
        r.shift_left(k);
        return r;
    }

    int sign() const { return sign_; }

    friend DyadicInt operator-(DyadicInt a) {
        a.sign_ = -a.sign_;
        return a;
    }
    friend DyadicInt operator+(const DyadicInt& a, const DyadicInt& b) {
        if (a.sign_ == 0) return b;
        if (b.sign_ == 0) return a;
        DyadicInt r;
        if (a.sign_ == b.sign_) {
            add_mag(a, b, r);
            r.sign_ = a.sign_;
            return r;
        }
        const int c = compare_mag(a, b);
        if (c == 0) return r;
        if (c > 0) {
            sub_mag(a, b, r);
            r.sign_ = a.sign_;
        } else {
            sub_mag(b, a, r);
            r.sign_ = b.sign_;
        }
        return r;
    }
    friend DyadicInt operator-(const DyadicInt& a, const DyadicInt& b) { return a + (-b); }
    friend DyadicInt operator*(const DyadicInt& a, const DyadicInt& b) {
        DyadicInt r;
        if (a.sign_ == 0 || b.sign_ == 0) return r;
        r.n_ = std::min(a.n_ + b.n_, limbs);  // the header's capacity: never reached
        std::fill(r.mag_.begin(), r.mag_.begin() + r.n_, 0u);
        for (int i = 0; i < a.n_; ++i) {
            std::uint64_t carry = 0;
            for (int j = 0; j < b.n_ && i + j < limbs; ++j) {
                const std::uint64_t t =
                    std::uint64_t(a.mag_[i]) * b.mag_[j] + r.mag_[i + j] + carry;
                r.mag_[i + j] = std::uint32_t(t);
                carry = t >> 32;
            }
            if (i + b.n_ < limbs) r.mag_[i + b.n_] = std::uint32_t(carry);
        }
        r.trim();
        r.sign_ = r.n_ == 0 ? 0 : a.sign_ * b.sign_;
        return r;
    }
    friend bool operator<(const DyadicInt& a, const DyadicInt& b) { return (a - b).sign_ < 0; }
    friend bool operator>(const DyadicInt& a, const DyadicInt& b) { return b < a; }

  private:
    static int compare_mag(const DyadicInt& a, const DyadicInt& b) {
        if (a.n_ != b.n_) return a.n_ < b.n_ ? -1 : 1;
        for (int i = a.n_; i-- > 0;)
            if (a.mag_[i] != b.mag_[i]) return a.mag_[i] < b.mag_[i] ? -1 : 1;
        return 0;
    }
    static void add_mag(const DyadicInt& a, const DyadicInt& b, DyadicInt& r) {
        const int n = std::max(a.n_, b.n_);
        std::uint64_t carry = 0;
        for (int i = 0; i < n; ++i) {
            const std::uint64_t t =
                std::uint64_t(i < a.n_ ? a.mag_[i] : 0) + (i < b.n_ ? b.mag_[i] : 0) + carry;
            r.mag_[i] = std::uint32_t(t);
            carry = t >> 32;
        }
        r.n_ = n;
        if (carry != 0 && n < limbs) r.mag_[r.n_++] = std::uint32_t(carry);
    }
    static void sub_mag(const DyadicInt& a, const DyadicInt& b, DyadicInt& r) {  // |a| > |b|
        std::int64_t borrow = 0;
        for (int i = 0; i < a.n_; ++i) {
            std::int64_t t = std::int64_t(a.mag_[i]) - (i < b.n_ ? b.mag_[i] : 0) - borrow;
            borrow = t < 0 ? 1 : 0;
            if (t < 0) t += std::int64_t(1) << 32;
            r.mag_[i] = std::uint32_t(t);
        }
        r.n_ = a.n_;
        r.trim();
    }
    void shift_left(int k) {
        if (n_ == 0 || k == 0) return;
        const int words = k / 32, bits = k % 32;
        const int top = std::min(n_ + words + 1, limbs);
        for (int i = top - 1; i >= 0; --i) {
            std::uint64_t v = 0;
            const int src = i - words;
            if (src >= 0 && src < n_) v = std::uint64_t(mag_[src]) << bits;
            if (bits != 0 && src - 1 >= 0 && src - 1 < n_) v |= mag_[src - 1] >> (32 - bits);
            mag_[i] = std::uint32_t(v);
        }
        n_ = top;
        trim();
    }
    void trim() {
        while (n_ > 0 && mag_[n_ - 1] == 0) --n_;
        if (n_ == 0) sign_ = 0;
    }

    int n_ = 0;
    int sign_ = 0;
    std::array<std::uint32_t, limbs> mag_;  // limbs at n_ and above are never read
};

}  // namespace bvhkit::exact
