#pragma once
// The BSP module in one include: BspTree and its queries.
#include "bvhkit/bsp/bsp_tree.hpp"
#include "bvhkit/bsp/order.hpp"
#include "bvhkit/bsp/ray.hpp"
#include "bvhkit/bsp/solid.hpp"
