#pragma once
// BoxAccumulator: the box that builders grow over and over (bins, sweeps, node bounds). For 3D
// float boxes on x86 it keeps the box in two four-lane registers (simd::Float<4>), lo = (min x, min
// y, min z, -) and hi =
// (-, max x, max y, max z), which a 24-byte Aabb3f fills with two overlapping loads (floats 0-3 and
// 2-5, both inside the object), so growing by a box is two loads, a minps and a maxps. Elsewhere it
// is a plain Aabb. The builders only ever grow by finite boxes.
#include "bvhkit/math/aabb.hpp"
#include "bvhkit/simd/simd.hpp"

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

#if BVHKIT_SIMD
template <>
class BoxAccumulator<float, 3> {
    using F = simd::Float<4>;

  public:
    BoxAccumulator()
        : lo_(std::numeric_limits<float>::infinity()),
          hi_(-std::numeric_limits<float>::infinity()) {}

    void grow(const Aabb3f& b) {
        const float* p = &b.min[0];  // min xyz then max xyz, contiguous
        lo_ = min(lo_, F::load_unaligned(p));
        hi_ = max(hi_, F::load_unaligned(p + 2));
    }
    void grow(const BoxAccumulator& o) {
        lo_ = min(lo_, o.lo_);
        hi_ = max(hi_, o.hi_);
    }
    void grow_point(const Vec3f& p) {
        const F v = load(p);  // (x, y, z, 0)
        lo_ = min(lo_, v);
        hi_ = max(hi_, v.shuffle<0, 0, 1, 2>());
    }
    /// Branch-free choice of accumulator: `skip` is 0 in every lane to grow, +inf to leave the
    /// box as it is (a finite coordinate plus inf is inf, which min ignores; minus inf, max).
    void grow(const Aabb3f& b, F skip) {
        const float* p = &b.min[0];
        lo_ = min(lo_, F::load_unaligned(p) + skip);
        hi_ = max(hi_, F::load_unaligned(p + 2) - skip);
    }
    void grow_point(const Vec3f& p, F skip) {
        const F v = load(p);
        lo_ = min(lo_, v + skip);
        hi_ = max(hi_, v.shuffle<0, 0, 1, 2>() - skip);
    }
    /// (x, y, z, 0) without reading past the 12 bytes of the vector.
    static F load(const Vec3f& p) { return F::load3(&p[0]); }
    float area() const {
        // extent = hi - lo with lanes aligned: shift hi down one lane.
        const F e = max(hi_.shuffle<1, 2, 3, 3>() - lo_, F::zero());
        // (ex ey, ey ez, ez ex) in lanes 0-2, then their sum.
        const F p = e * e.shuffle<1, 2, 0, 3>();
        const float sum =
            add_first(add_first(p, p.shuffle<1, 1, 1, 1>()), p.shuffle<2, 2, 2, 2>()).first();
        return 2.0f * sum;
    }
    Aabb3f box() const {
        alignas(16) float l[4], h[4];
        lo_.store(l);
        hi_.store(h);
        return Aabb3f({l[0], l[1], l[2]}, {h[1], h[2], h[3]});
    }

  private:
    F lo_, hi_;
};
#endif

}  // namespace bvhkit
