// No include guard: included once for each file of kernels, after defining BVHKIT_SIMD_KERNELS.
//
// Compiles the kernels of the header named by BVHKIT_SIMD_KERNELS once per instruction set, from
// the one source (the pattern of Embree's per-ISA builds, here within one translation unit):
// in namespace bvhkit::detail::sse2 for the default target, and again in bvhkit::detail::avx2
// with every function compiled for AVX2, so that a kernel's eight-lane operations inline into it.
// The walks choose avx2's at run time (cpu_has_avx2). The kernels header opens
// `namespace bvhkit::detail::BVHKIT_SIMD_ISA`, and includes nothing: a header first included
// inside the AVX2 region would have its inline functions compiled for AVX2 and used by all.
#include "bvhkit/simd/simd.hpp"

#if !defined(BVHKIT_SIMD_KERNELS)
#error "define BVHKIT_SIMD_KERNELS, the header of the kernels, before including simd/per_isa.hpp"
#endif

#if BVHKIT_SIMD
#define BVHKIT_SIMD_ISA sse2
#include BVHKIT_SIMD_KERNELS
#undef BVHKIT_SIMD_ISA
#endif

#if BVHKIT_SIMD_AVX2
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
#define BVHKIT_SIMD_ISA avx2
#include BVHKIT_SIMD_KERNELS
#undef BVHKIT_SIMD_ISA
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

#undef BVHKIT_SIMD_KERNELS
