#pragma once
// BoxAccumulator: the box that builders grow over and over (bins, sweeps, node bounds). For 3D
// float boxes on x86 it keeps the box in two SSE registers, lo = (min x, min y, min z, -) and hi =
// (-, max x, max y, max z), which a 24-byte Aabb3f fills with two overlapping loads (floats 0-3 and
// 2-5, both inside the object), so growing by a box is two loads, a minps and a maxps. Elsewhere it
// is a plain Aabb. The builders only ever grow by finite boxes.
#include "bvhkit/math/aabb.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bvhkit {

template <class T, std::size_t N>
class BoxAccumulator {
  public:
    void grow(const Aabb<T, N>& b) { box_.grow(b); }
    void grow(const BoxAccumulator& o) { box_.grow(o.box_); }
    void grow_point(const Vec<T, N>& p) { box_.grow(p); }
    T area() const { return box_.area(); }
    Aabb<T, N> box() const { return box_; }

  private:
    Aabb<T, N> box_;
};

#if defined(__SSE2__)
template <>
class BoxAccumulator<float, 3> {
  public:
    BoxAccumulator()
        : lo_(_mm_set1_ps(std::numeric_limits<float>::infinity())),
          hi_(_mm_set1_ps(-std::numeric_limits<float>::infinity())) {}

    void grow(const Aabb3f& b) {
        const float* p = &b.min[0];  // min xyz then max xyz, contiguous
        lo_ = _mm_min_ps(lo_, _mm_loadu_ps(p));
        hi_ = _mm_max_ps(hi_, _mm_loadu_ps(p + 2));
    }
    void grow(const BoxAccumulator& o) {
        lo_ = _mm_min_ps(lo_, o.lo_);
        hi_ = _mm_max_ps(hi_, o.hi_);
    }
    void grow_point(const Vec3f& p) {
        const __m128 v = load(p);  // (x, y, z, 0)
        lo_ = _mm_min_ps(lo_, v);
        hi_ = _mm_max_ps(hi_, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 1, 0, 0)));
    }
    /// Branch-free choice of accumulator: `skip` is 0 in every lane to grow, +inf to leave the
    /// box as it is (a finite coordinate plus inf is inf, which min ignores; minus inf, max).
    void grow(const Aabb3f& b, __m128 skip) {
        const float* p = &b.min[0];
        lo_ = _mm_min_ps(lo_, _mm_add_ps(_mm_loadu_ps(p), skip));
        hi_ = _mm_max_ps(hi_, _mm_sub_ps(_mm_loadu_ps(p + 2), skip));
    }
    void grow_point(const Vec3f& p, __m128 skip) {
        const __m128 v = load(p);
        lo_ = _mm_min_ps(lo_, _mm_add_ps(v, skip));
        hi_ = _mm_max_ps(hi_, _mm_sub_ps(_mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 1, 0, 0)), skip));
    }
    /// (x, y, z, 0) without reading past the 12 bytes of the vector.
    static __m128 load(const Vec3f& p) {
        // 8 bytes for x, y (__m64 may alias anything) and 4 for z; no store-forwarding stall.
        const __m128 xy = _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(&p[0]));
        return _mm_movelh_ps(xy, _mm_load_ss(&p[2]));
    }
    float area() const {
        // extent = hi - lo with lanes aligned: shift hi down one lane.
        const __m128 e = _mm_max_ps(
            _mm_sub_ps(_mm_shuffle_ps(hi_, hi_, _MM_SHUFFLE(3, 3, 2, 1)), lo_), _mm_setzero_ps());
        // (ex ey, ey ez, ez ex) in lanes 0-2, then their sum.
        const __m128 p = _mm_mul_ps(e, _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1)));
        const float sum =
            _mm_cvtss_f32(_mm_add_ss(_mm_add_ss(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 1, 1, 1))),
                                     _mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 2, 2, 2))));
        return 2.0f * sum;
    }
    Aabb3f box() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo_);
        _mm_store_ps(h, hi_);
        return Aabb3f({l[0], l[1], l[2]}, {h[1], h[2], h[3]});
    }

  private:
    __m128 lo_, hi_;
};
#endif

}  // namespace bvhkit
