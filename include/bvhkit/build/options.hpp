#pragma once
// BuildOptions: one struct chooses the builder and its parameters. The default, binned SAH with 16
// bins, is the right choice for ray tracing; the others (the classic top-down rules, bottom-up
// clustering, insertion, the Morton-code hierarchy) are there to compare and to teach.
#include <cstdint>
#include <string_view>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/bvh/statistics.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

enum class Builder {
    BinnedSah,  // Wald 2007: SAH evaluated at bin boundaries; fast, near full-sweep quality
    SweepSah,  // SAH evaluated between every pair of sorted centroids; slowest, best greedy quality
    TopDown,   // the classic rules below: an axis rule and a split-point rule
    BottomUp,  // PLOC (Meister and Bittner 2018): agglomerative clustering in Morton order
    Insertion,  // one primitive at a time, branch-and-bound SAH with rotations (Bittner, Hapala,
                // Havran 2013)
    Lbvh,       // Karras 2012: the Morton-code hierarchy; the fastest build, lower quality
};

/// Axis rules of the classic top-down builder, evaluated on the node's primitive centroids (the
/// box's own longest axis can have all centroids equal, which gives no split).
enum class SplitAxis { LongestExtent, LargestVariance };

/// Split-point rules of the classic top-down builder.
enum class SplitPoint {
    ObjectMedian,   // half the primitives on each side
    ObjectMean,     // at the mean centroid coordinate
    SpatialMedian,  // at the middle of the node's box
};

/// What to do with a primitive whose box has a NaN or infinite coordinate.
enum class NonFinitePolicy {
    Skip,    // leave it out of the tree (it can never be hit) and list it in BuildReport::skipped
    Reject,  // throw bvhkit::Error naming the first such primitive
};

/// Every field is checked when a build starts (validate_options); a value outside the range given
/// beside it throws bvhkit::Error naming the field and its range.
struct BuildOptions {
    Builder builder = Builder::BinnedSah;
    std::uint32_t bin_count = tuning::sah_bins;           // binned SAH: 2..256
    std::uint32_t max_leaf_size = tuning::max_leaf_size;  // >= 1; a larger node is always split
    std::uint32_t max_depth =
        max_bvh_depth;  // 0..max_bvh_depth; a node at this depth becomes a leaf, whatever its size
    /// SAH builders and the bottom-up builders' collapse: leaf cost vs split cost. traversal
    /// finite and >= 0, intersection finite and > 0.
    SahCosts costs{};
    SplitAxis axis_rule = SplitAxis::LongestExtent;
    SplitPoint point_rule = SplitPoint::ObjectMedian;
    NonFinitePolicy non_finite = NonFinitePolicy::Skip;
    /// Run the reinsertion optimizer (Bittner et al. 2013, build/reinsertion.hpp) after the build;
    /// it keeps the built tree when it finds no cheaper one.
    bool optimize = false;
    /// Threads for the builders when bvhkit was built with oneTBB: the top-down ones (binned and
    /// sweep SAH, the classic rules) split large nodes and whole subtrees in parallel, bottom-up
    /// and LBVH run their passes in parallel; insertion and the optimizer are serial. 0 = all,
    /// 1 = serial, k = at most k; any k above the hardware's concurrency is clamped to it. The tree
    /// is the same, bit for bit, for every value.
    unsigned threads = 0;
    /// Bottom-up: neighbours searched on each side, 1..max_ploc_radius (each round costs
    /// 2 * radius area evaluations per cluster).
    std::uint32_t ploc_radius = tuning::ploc_radius;
};

inline constexpr std::uint32_t max_ploc_radius = 64;

/// Throws bvhkit::Error naming the first field of `options` outside its valid range (see
/// BuildOptions). build_bvh() calls it before anything else.
void validate_options(const BuildOptions& options);

struct BuildReport {
    std::vector<std::uint32_t> skipped;  // primitives left out for non-finite boxes, ascending
};

const char* to_string(Builder b);
const char* to_string(SplitAxis a);
const char* to_string(SplitPoint p);
/// Parses "binned-sah", "sweep-sah", "top-down", "median|mean|spatial-longest|variance",
/// "bottom-up", "insertion", "lbvh", each optionally followed by "+opt" (the reinsertion
/// optimizer), into options; throws bvhkit::Error listing the valid names.
BuildOptions parse_builder(std::string_view name);
/// Every builder configuration: binned SAH, sweep SAH, each top-down axis x point rule, bottom-up,
/// insertion and LBVH; then each of those again with "+opt" (the reinsertion optimizer).
std::vector<std::pair<std::string, BuildOptions>> all_builder_configurations();

}  // namespace bvhkit
