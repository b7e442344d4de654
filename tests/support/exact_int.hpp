#pragma once
// An exact signed integer for test references, with +, -, * and comparison, nothing else.
// Floating-point inputs are dyadic rationals m * 2^e, so a set of them scaled by one common power
// of two (scaled) becomes integers, and any polynomial of them (determinants, dot products) is
// computed exactly.
//
// With GMP (BVHKIT_TEST_HAVE_GMP, found by tests/CMakeLists.txt) the arithmetic and the reading of
// a double are GMP's (mpz_class, mpq_class), apart from the library's own exact integers
// (math/exact_integer.hpp). Without it, a sign-and-magnitude integer of 32-bit limbs written here
// stands in; the library's DyadicInt has the same shape, so such a build's references are weaker.
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#if defined(BVHKIT_TEST_HAVE_GMP)
#include <gmpxx.h>
#endif

namespace bvhkit::test {

#if defined(BVHKIT_TEST_HAVE_GMP)

class ExactInt {
  public:
    ExactInt() = default;
    explicit ExactInt(std::int64_t v) : z_(static_cast<long>(v)) {
        static_assert(sizeof(long) == sizeof(std::int64_t), "mpz_class takes a 64-bit long here");
    }

    /// x * 2^shift, which must be an integer (throws otherwise).
    static ExactInt scaled(double x, int shift) {
        mpq_class q(x);  // exact: every finite double is a rational with a power-of-two denominator
        if (shift >= 0)
            mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<unsigned long>(shift));
        else
            mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<unsigned long>(-shift));
        if (q.get_den() != 1) throw std::logic_error("ExactInt::scaled: not an integer");
        ExactInt r;
        r.z_ = q.get_num();
        return r;
    }

    /// The shift that makes x * 2^shift an integer (for scaled()): the smallest one.
    static int shift_needed(double x) {
        if (x == 0) return -100000;
        const mpq_class q(x);
        if (q.get_den() != 1) return static_cast<int>(mpz_sizeinbase(q.get_den_mpz_t(), 2)) - 1;
        return -static_cast<int>(mpz_scan1(q.get_num_mpz_t(), 0));  // trailing zero bits
    }

    int sign() const { return sgn(z_); }

    friend ExactInt operator-(ExactInt a) {
        a.z_ = -a.z_;
        return a;
    }
    friend ExactInt operator+(const ExactInt& a, const ExactInt& b) {
        return ExactInt(a.z_ + b.z_);
    }
    friend ExactInt operator-(const ExactInt& a, const ExactInt& b) {
        return ExactInt(a.z_ - b.z_);
    }
    friend ExactInt operator*(const ExactInt& a, const ExactInt& b) {
        return ExactInt(a.z_ * b.z_);
    }
    friend bool operator==(const ExactInt& a, const ExactInt& b) { return a.z_ == b.z_; }

  private:
    explicit ExactInt(mpz_class z) : z_(std::move(z)) {}
    mpz_class z_;
};

#else

class ExactInt {
  public:
    static constexpr int limbs = 48;  // 1,536 bits: degree-4 polynomials of float coordinates

    ExactInt() = default;
    // Only the used limbs are copied (the rest is never read).
    ExactInt(const ExactInt& o) : n_(o.n_), sign_(o.sign_) {
        for (int i = 0; i < n_; ++i) mag_[i] = o.mag_[i];
    }
    ExactInt& operator=(const ExactInt& o) {
        n_ = o.n_;
        sign_ = o.sign_;
        for (int i = 0; i < n_; ++i) mag_[i] = o.mag_[i];
        return *this;
    }
    explicit ExactInt(std::int64_t v) {
        sign_ = v > 0 ? 1 : v < 0 ? -1 : 0;
        std::uint64_t m = v < 0 ? std::uint64_t(0) - std::uint64_t(v) : std::uint64_t(v);
        while (m != 0) {
            mag_[n_++] = std::uint32_t(m);
            m >>= 32;
        }
    }

    /// x * 2^shift, which must be an integer (throws otherwise).
    static ExactInt scaled(double x, int shift) {
        ExactInt r;
        if (x == 0) return r;
        int e = 0;
        const double f = std::frexp(std::fabs(x), &e);  // |x| = f 2^e, f in [0.5, 1)
        auto m = std::uint64_t(std::ldexp(f, 53));
        int k = e - 53 + shift;
        while (k < 0 && (m & 1) == 0) m >>= 1, ++k;
        if (k < 0) throw std::logic_error("ExactInt::scaled: not an integer");
        r.sign_ = x > 0 ? 1 : -1;
        while (m != 0) {
            r.mag_[r.n_++] = std::uint32_t(m);
            m >>= 32;
        }
        r.shift_left(k);
        return r;
    }

    /// The shift that makes x * 2^shift an integer (for scaled()).
    static int shift_needed(double x) {
        if (x == 0) return -100000;
        int e = 0;
        const double f = std::frexp(std::fabs(x), &e);
        auto m = std::uint64_t(std::ldexp(f, 53));
        int k = e - 53;
        while ((m & 1) == 0) m >>= 1, ++k;
        return -k;
    }

    int sign() const { return sign_; }

    friend ExactInt operator-(ExactInt a) {
        a.sign_ = -a.sign_;
        return a;
    }
    friend ExactInt operator+(const ExactInt& a, const ExactInt& b) {
        if (a.sign_ == 0) return b;
        if (b.sign_ == 0) return a;
        ExactInt r;
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
    friend ExactInt operator-(const ExactInt& a, const ExactInt& b) { return a + (-b); }
    friend ExactInt operator*(const ExactInt& a, const ExactInt& b) {
        ExactInt r;
        if (a.sign_ == 0 || b.sign_ == 0) return r;
        if (a.n_ + b.n_ > limbs) throw std::overflow_error("ExactInt: too many bits");
        for (int i = 0; i < a.n_ + b.n_; ++i) r.mag_[i] = 0;
        for (int i = 0; i < a.n_; ++i) {
            std::uint64_t carry = 0;
            for (int j = 0; j < b.n_; ++j) {
                const std::uint64_t t =
                    std::uint64_t(a.mag_[i]) * b.mag_[j] + r.mag_[i + j] + carry;
                r.mag_[i + j] = std::uint32_t(t);
                carry = t >> 32;
            }
            r.mag_[i + b.n_] = std::uint32_t(carry);
        }
        r.n_ = a.n_ + b.n_;
        r.trim();
        r.sign_ = a.sign_ * b.sign_;
        return r;
    }
    friend bool operator==(const ExactInt& a, const ExactInt& b) { return (a - b).sign_ == 0; }

  private:
    void trim() {
        while (n_ > 0 && mag_[n_ - 1] == 0) --n_;
        if (n_ == 0) sign_ = 0;
    }
    void shift_left(int k) {
        const int words = k / 32, bits = k % 32;
        if (n_ + words + 1 > limbs) throw std::overflow_error("ExactInt: too many bits");
        for (int i = n_; i < n_ + words + 1; ++i) mag_[i] = 0;
        for (int i = n_ - 1; i >= 0; --i) mag_[i + words] = mag_[i];
        for (int i = 0; i < words; ++i) mag_[i] = 0;
        n_ += words;
        if (bits != 0) {
            std::uint32_t carry = 0;
            for (int i = words; i < n_; ++i) {
                const std::uint32_t v = mag_[i];
                mag_[i] = (v << bits) | carry;
                carry = v >> (32 - bits);
            }
            if (carry != 0) mag_[n_++] = carry;
        }
        trim();
    }
    static int compare_mag(const ExactInt& a, const ExactInt& b) {
        if (a.n_ != b.n_) return a.n_ < b.n_ ? -1 : 1;
        for (int i = a.n_ - 1; i >= 0; --i)
            if (a.mag_[i] != b.mag_[i]) return a.mag_[i] < b.mag_[i] ? -1 : 1;
        return 0;
    }
    static void add_mag(const ExactInt& a, const ExactInt& b, ExactInt& r) {
        const int n = a.n_ > b.n_ ? a.n_ : b.n_;
        if (n + 1 > limbs) throw std::overflow_error("ExactInt: too many bits");
        std::uint64_t carry = 0;
        for (int i = 0; i < n; ++i) {
            const std::uint64_t t =
                std::uint64_t(i < a.n_ ? a.mag_[i] : 0) + (i < b.n_ ? b.mag_[i] : 0) + carry;
            r.mag_[i] = std::uint32_t(t);
            carry = t >> 32;
        }
        r.mag_[n] = std::uint32_t(carry);
        r.n_ = n + 1;
        r.trim();
    }
    static void sub_mag(const ExactInt& a, const ExactInt& b, ExactInt& r) {  // |a| > |b|
        std::int64_t borrow = 0;
        for (int i = 0; i < a.n_; ++i) {
            std::int64_t t = std::int64_t(a.mag_[i]) - (i < b.n_ ? b.mag_[i] : 0) - borrow;
            borrow = t < 0 ? 1 : 0;
            if (t < 0) t += std::int64_t(1) << 32;
            r.mag_[i] = std::uint32_t(t);
        }
        r.n_ = a.n_;
        r.sign_ = 1;
        r.trim();
    }

    std::array<std::uint32_t, limbs> mag_;  // limbs at n_ and above are never read
    int n_ = 0;
    int sign_ = 0;
};

#endif

}  // namespace bvhkit::test
