#pragma once
// The SIMD layer: Float<W>, Int<W> and Mask<W>, four lanes (SSE2, every x86-64) and eight (AVX2),
// thin wrappers over the intrinsics, so that a kernel is written once for both widths; and the
// one-lane minss/maxss of simd/scalar.hpp. No header outside this folder names an intrinsic. The
// folder is in the lowest layer (it includes only standard headers), so every other may use it.
//
// The eight-lane functions carry the AVX2 target attribute themselves: the default build targets
// SSE2, and a kernel for eight lanes is compiled for AVX2 by simd/per_isa.hpp and chosen at run
// time (cpu_has_avx2). Every function is always inlined, so a kernel's instructions are the
// intrinsics' own.
//
// min and max keep the instructions' operand order: min(a, b) and max(a, b) return b when either
// is NaN. The ray walks rely on it (a 0 * inf plane distance in a, the accumulator in b).
#include "bvhkit/simd/avx2.hpp"
#include "bvhkit/simd/scalar.hpp"
#include "bvhkit/simd/sse2.hpp"
