#pragma once
// Everything in one include.
#include "bvhkit/build/build.hpp"
#include "bvhkit/build/refit.hpp"
#include "bvhkit/bvh/iterate.hpp"
#include "bvhkit/bvh/statistics.hpp"
#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/segment.hpp"
#include "bvhkit/query/ray.hpp"
#include "bvhkit/triangle_bvh.hpp"
#include "bvhkit/version.hpp"
