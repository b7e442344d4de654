// The mesh specs ("sphere:subdiv=4", "room:objects=200", ...): parsing, checking and dispatch
// to the generators of procedural.cpp and procedural_city.cpp.
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "bvhkit/mesh/procedural.hpp"

namespace bvhkit {

// --- Spec parsing ----------------------------------------------------------------------------

namespace {

struct KindInfo {
    std::string_view name;
    std::string_view keys;  // for messages
};

constexpr KindInfo kinds[] = {
    {"sphere", "subdiv=5 (0..10) or freq=F, displacement=0 (0..1), seed=1"},
    {"torus", "u=96, v=48, major=1, minor=0.3"},
    {"terrain", "n=256, seed=1"},
    {"room", "objects=50, seed=1"},
    {"soup", "n=100000, seed=1"},
    {"city", "blocks=8 (1..40), seed=1"},
};

std::string kind_names() {
    std::string s;
    for (const KindInfo& k : kinds) {
        if (!s.empty()) s.append(", ");
        s.append(k.name);
    }
    return s;
}

// Joins message pieces (GCC 12 reports a false -Wrestrict on "literal" + std::string chains).
std::string concat(std::initializer_list<std::string_view> parts) {
    std::string s;
    for (const std::string_view p : parts) s.append(p);
    return s;
}

class SpecArgs {
  public:
    SpecArgs(std::string_view spec, const KindInfo& kind) : spec_(spec), kind_(kind) {
        const std::size_t colon = spec.find(':');
        if (colon == std::string_view::npos) return;
        // Every comma-separated item must be key=value: "sphere:" and "a=1," are errors.
        std::string_view rest = spec.substr(colon + 1);
        for (bool more = true; more;) {
            const std::size_t comma = rest.find(',');
            const std::string_view item = rest.substr(0, comma);
            more = comma != std::string_view::npos;
            if (more) rest = rest.substr(comma + 1);
            const std::size_t eq = item.find('=');
            if (eq == std::string_view::npos || eq == 0)
                fail(concat({"expected key=value, got '", item, "'"}));
            for (const auto& [k, v] : pairs_)
                if (k == item.substr(0, eq)) fail(concat({"key '", k, "' given twice"}));
            pairs_.push_back({item.substr(0, eq), item.substr(eq + 1)});
            used_.push_back(false);
        }
    }

    std::uint64_t integer(std::string_view key, std::uint64_t fallback, std::uint64_t lo,
                          std::uint64_t hi) {
        const std::string_view* text = find(key);
        if (!text) return fallback;
        std::uint64_t v = 0;
        const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
        if (ec != std::errc() || ptr != text->data() + text->size() || text->empty())
            fail(concat({"'", key, "' needs a non-negative integer, got '", *text, "'"}));
        if (v < lo || v > hi)
            fail(concat({"'", key, "' must be in ", std::to_string(lo), "..", std::to_string(hi),
                         ", got ", std::to_string(v)}));
        return v;
    }
    float real(std::string_view key, float fallback) {
        const std::string_view* text = find(key);
        if (!text) return fallback;
        float v = 0;
        const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
        if (ec != std::errc() || ptr != text->data() + text->size() || text->empty() ||
            !std::isfinite(v))
            fail(concat({"'", key, "' needs a number, got '", *text, "'"}));
        return v;
    }
    bool has(std::string_view key) const {
        for (const auto& [k, v] : pairs_)
            if (k == key) return true;
        return false;
    }
    /// After reading: any key nobody asked for is an Error listing the valid ones.
    void reject_unused() const {
        for (std::size_t i = 0; i < pairs_.size(); ++i)
            if (!used_[i]) fail(concat({"unknown key '", pairs_[i].first, "'"}));
    }
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(concat(
            {"bad mesh spec '", spec_, "': ", what, " (", kind_.name, " takes ", kind_.keys, ")"}));
    }

  private:
    const std::string_view* find(std::string_view key) {
        for (std::size_t i = 0; i < pairs_.size(); ++i)
            if (pairs_[i].first == key) {
                used_[i] = true;
                return &pairs_[i].second;
            }
        return nullptr;
    }
    std::string_view spec_;
    const KindInfo& kind_;
    std::vector<std::pair<std::string_view, std::string_view>> pairs_;
    std::vector<bool> used_;
};

const KindInfo* find_kind(std::string_view spec) {
    const std::string_view kind = spec.substr(0, spec.find(':'));
    for (const KindInfo& k : kinds)
        if (k.name == kind) return &k;
    return nullptr;
}

}  // namespace

bool is_procedural_kind(std::string_view spec) {
    return find_kind(spec) != nullptr;
}

std::string procedural_spec_help() {
    std::string s;
    for (const KindInfo& k : kinds) {
        s.append("  ").append(k.name).append(": ").append(k.keys).append("\n");
    }
    return s;
}

TriangleMesh make_procedural(std::string_view spec) {
    const KindInfo* kind = find_kind(spec);
    if (!kind)
        throw Error(concat({"bad mesh spec '", spec, "': unknown kind '",
                            spec.substr(0, spec.find(':')), "' (kinds: ", kind_names(), ")"}));
    SpecArgs args(spec, *kind);
    TriangleMesh mesh;
    // Sizes are checked here too so that a spec error names the spec rather than the generator.
    auto limit = [&](std::uint64_t triangles) {
        if (triangles > max_procedural_triangles)
            args.fail(std::to_string(triangles) + " triangles exceed the limit of " +
                      std::to_string(max_procedural_triangles));
    };
    if (kind->name == "sphere") {
        if (args.has("subdiv") && args.has("freq")) args.fail("give subdiv or freq, not both");
        const auto freq = args.has("freq") ? args.integer("freq", 1, 1, 1295)
                                           : std::uint64_t(1) << args.integer("subdiv", 5, 0, 10);
        const float displacement = args.real("displacement", 0.0f);
        if (!(displacement >= 0.0f && displacement < 1.0f))
            args.fail("'displacement' must be in [0, 1)");
        const std::uint64_t seed = args.integer("seed", 1, 0, ~0ull);
        args.reject_unused();
        limit(20 * freq * freq);
        mesh = make_geodesic_sphere(static_cast<std::uint32_t>(freq), displacement, seed);
    } else if (kind->name == "torus") {
        const auto u = args.integer("u", 96, 3, 1u << 20);
        const auto v = args.integer("v", 48, 3, 1u << 20);
        const float major = args.real("major", 1.0f);
        const float minor = args.real("minor", 0.3f);
        if (!(minor > 0.0f && minor < major)) args.fail("radii must satisfy 0 < minor < major");
        args.reject_unused();
        limit(2 * u * v);
        mesh =
            make_torus(static_cast<std::uint32_t>(u), static_cast<std::uint32_t>(v), major, minor);
    } else if (kind->name == "terrain") {
        const auto n = args.integer("n", 256, 1, 4096);
        const std::uint64_t seed = args.integer("seed", 1, 0, ~0ull);
        args.reject_unused();
        limit(2 * n * n);
        mesh = make_terrain(static_cast<std::uint32_t>(n), seed);
    } else if (kind->name == "room") {
        const auto objects = args.integer("objects", 50, 0, 100000);
        const std::uint64_t seed = args.integer("seed", 1, 0, ~0ull);
        args.reject_unused();
        mesh = make_room(static_cast<std::uint32_t>(objects), seed);
    } else if (kind->name == "city") {
        const auto blocks = args.integer("blocks", 8, 1, 40);
        const std::uint64_t seed = args.integer("seed", 1, 0, ~0ull);
        args.reject_unused();
        mesh = make_city(static_cast<std::uint32_t>(blocks), seed);
    } else {
        const auto n = args.integer("n", 100000, 1, max_procedural_triangles);
        const std::uint64_t seed = args.integer("seed", 1, 0, ~0ull);
        args.reject_unused();
        mesh = make_soup(n, seed);
    }
    return mesh;
}

}  // namespace bvhkit
