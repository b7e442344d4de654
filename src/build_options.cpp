#include <cmath>
#include <string>

#include "bvhkit/build/options.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/tuning.hpp"

namespace bvhkit {

const char* to_string(Builder b) {
    switch (b) {
        case Builder::BinnedSah:
            return "binned-sah";
        case Builder::SweepSah:
            return "sweep-sah";
        case Builder::TopDown:
            return "top-down";
        case Builder::BottomUp:
            return "bottom-up";
        case Builder::Insertion:
            return "insertion";
        case Builder::Lbvh:
            return "lbvh";
    }
    return "?";
}
const char* to_string(SplitAxis a) {
    return a == SplitAxis::LongestExtent ? "longest" : "variance";
}
const char* to_string(SplitPoint p) {
    switch (p) {
        case SplitPoint::ObjectMedian:
            return "median";
        case SplitPoint::ObjectMean:
            return "mean";
        case SplitPoint::SpatialMedian:
            return "spatial";
    }
    return "?";
}

std::vector<std::pair<std::string, BuildOptions>> all_builder_configurations() {
    std::vector<std::pair<std::string, BuildOptions>> out;
    BuildOptions o;
    out.emplace_back("binned-sah", o);
    o.builder = Builder::SweepSah;
    out.emplace_back("sweep-sah", o);
    for (SplitAxis a : {SplitAxis::LongestExtent, SplitAxis::LargestVariance})
        for (SplitPoint p :
             {SplitPoint::ObjectMedian, SplitPoint::ObjectMean, SplitPoint::SpatialMedian}) {
            BuildOptions t;
            t.builder = Builder::TopDown;
            t.axis_rule = a;
            t.point_rule = p;
            t.max_leaf_size = tuning::top_down_max_leaf_size;
            out.emplace_back(std::string(to_string(p)) + "-" + to_string(a), t);
        }
    for (Builder b : {Builder::BottomUp, Builder::Insertion, Builder::Lbvh}) {
        BuildOptions t;
        t.builder = b;
        out.emplace_back(to_string(b), t);
    }
    const std::size_t plain = out.size();
    for (std::size_t i = 0; i < plain; ++i) {
        BuildOptions t = out[i].second;
        t.optimize = true;
        out.emplace_back(out[i].first + "+opt", t);
    }
    return out;
}

namespace {

[[noreturn]] void bad_option(const std::string& field, const std::string& value,
                             const char* range) {
    throw Error("BuildOptions::" + field + " = " + value + " is invalid; valid: " + range);
}

}  // namespace

void validate_options(const BuildOptions& o) {
    const auto u = [](auto v) { return std::to_string(v); };
    if (static_cast<unsigned>(o.builder) > static_cast<unsigned>(Builder::Lbvh))
        bad_option("builder", u(static_cast<unsigned>(o.builder)), "a Builder enumerator");
    if (static_cast<unsigned>(o.axis_rule) > static_cast<unsigned>(SplitAxis::LargestVariance))
        bad_option("axis_rule", u(static_cast<unsigned>(o.axis_rule)), "a SplitAxis enumerator");
    if (static_cast<unsigned>(o.point_rule) > static_cast<unsigned>(SplitPoint::SpatialMedian))
        bad_option("point_rule", u(static_cast<unsigned>(o.point_rule)), "a SplitPoint enumerator");
    if (static_cast<unsigned>(o.non_finite) > static_cast<unsigned>(NonFinitePolicy::Reject))
        bad_option("non_finite", u(static_cast<unsigned>(o.non_finite)),
                   "a NonFinitePolicy enumerator");
    if (o.bin_count < 2 || o.bin_count > 256) bad_option("bin_count", u(o.bin_count), "2..256");
    if (o.max_leaf_size < 1) bad_option("max_leaf_size", u(o.max_leaf_size), ">= 1");
    if (o.max_depth > max_bvh_depth)
        bad_option("max_depth", u(o.max_depth), ("0.." + u(max_bvh_depth)).c_str());
    if (!std::isfinite(o.costs.traversal) || o.costs.traversal < 0)
        bad_option("costs.traversal", u(o.costs.traversal), "finite and >= 0");
    if (!std::isfinite(o.costs.intersection) || !(o.costs.intersection > 0))
        bad_option("costs.intersection", u(o.costs.intersection), "finite and > 0");
    if (o.costs.leaf_block > 64)
        bad_option("costs.leaf_block", u(o.costs.leaf_block), "0..64 (0: the tree's choice)");
    if (o.ploc_radius < 1 || o.ploc_radius > max_ploc_radius)
        bad_option("ploc_radius", u(o.ploc_radius), ("1.." + u(max_ploc_radius)).c_str());
}

BuildOptions parse_builder(std::string_view name) {
    for (auto& [n, o] : all_builder_configurations())
        if (n == name) return o;
    if (name == "top-down" || name == "top-down+opt") {
        BuildOptions o;
        o.builder = Builder::TopDown;
        o.max_leaf_size = tuning::top_down_max_leaf_size;
        o.optimize = name.ends_with("+opt");
        return o;
    }
    std::string valid;
    for (auto& [n, o] : all_builder_configurations()) valid += (valid.empty() ? "" : ", ") + n;
    throw Error("unknown builder '" + std::string(name) + "'; valid: " + valid +
                ", top-down[+opt]");
}

}  // namespace bvhkit
