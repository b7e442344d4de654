#include <string>

#include "bvhkit/build/options.hpp"
#include "bvhkit/error.hpp"

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
            t.max_leaf_size = 4;
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

BuildOptions parse_builder(std::string_view name) {
    for (auto& [n, o] : all_builder_configurations())
        if (n == name) return o;
    if (name == "top-down" || name == "top-down+opt") {
        BuildOptions o;
        o.builder = Builder::TopDown;
        o.max_leaf_size = 4;
        o.optimize = name.ends_with("+opt");
        return o;
    }
    std::string valid;
    for (auto& [n, o] : all_builder_configurations()) valid += (valid.empty() ? "" : ", ") + n;
    throw Error("unknown builder '" + std::string(name) + "'; valid: " + valid +
                ", top-down[+opt]");
}

}  // namespace bvhkit
