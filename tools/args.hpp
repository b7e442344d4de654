#pragma once
// The one command-line parser of bvhkit and bvhkit-bench: `--name value`, `--flag`, positionals.
// Unknown options and missing values are errors that name the option. Every command spells an
// option the same way (--out FILE, --threads N, --volume NAME, --boxes N, --json, ...); the
// spellings an earlier release used are still read, with a note naming the new one.
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "bvhkit/error.hpp"

namespace bvhkit::tools {

/// An earlier spelling and the option it now is. An old spelling is read only by a command that
/// has the new option, so `--n` means `--boxes` where boxes are counted and nothing elsewhere.
struct OldSpelling {
    std::string_view old_name, new_name;
};
inline constexpr OldSpelling kOldSpellings[] = {
    {"-o", "--out"},
    {"--bv", "--volume"},
    {"--n", "--boxes"},
    {"--size", "--extent"},  // bench scene's mesh size; --size is an image's size elsewhere
};

class Args {
  public:
    /// `valued`: options that take a value; `flags`: options that do not.
    Args(int argc, char** argv, std::set<std::string> valued, std::set<std::string> flags) {
        for (int i = 1; i < argc; ++i) {
            std::string a = argv[i];
            if (a == "--help" || a == "-h") {
                help_ = true;
                continue;
            }
            if (!(a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])) &&
                  a[1] != '.')) {
                positional_.push_back(a);
                continue;
            }
            for (const OldSpelling& s : kOldSpellings)
                if (a == s.old_name && (valued.count(std::string(s.new_name)) ||
                                        flags.count(std::string(s.new_name)))) {
                    std::fprintf(stderr, "note: %s is now %s\n", a.c_str(),
                                 std::string(s.new_name).c_str());
                    a = s.new_name;
                    break;
                }
            if (flags.count(a)) {
                flags_.insert(a);
            } else if (valued.count(a)) {
                if (i + 1 >= argc) throw Error("option " + a + " needs a value");
                values_[a] = argv[++i];
            } else {
                throw Error("unknown option " + a + " (see --help)");
            }
        }
    }
    bool help() const { return help_; }
    bool flag(const std::string& name) const { return flags_.count(name) != 0; }
    bool has(const std::string& name) const { return values_.count(name) != 0; }
    std::string value(const std::string& name, const std::string& fallback = "") const {
        auto it = values_.find(name);
        return it == values_.end() ? fallback : it->second;
    }
    long long integer(const std::string& name, long long fallback, long long lo,
                      long long hi) const {
        if (!has(name)) return fallback;
        const std::string v = value(name);
        char* end = nullptr;
        const long long x = std::strtoll(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || x < lo || x > hi)
            throw Error("option " + name + ": '" + v + "' is not an integer in [" +
                        std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return x;
    }
    /// --threads N: 0 (the default) is every core when bvhkit has oneTBB, 1 is the calling thread.
    unsigned threads() const { return unsigned(integer("--threads", 0, 0, 4096)); }
    const std::vector<std::string>& positional() const { return positional_; }

  private:
    bool help_ = false;
    std::set<std::string> flags_;
    std::map<std::string, std::string> values_;
    std::vector<std::string> positional_;
};

/// A command line that cannot run: one error line naming what is wrong, then the usage; exit 2.
inline int usage_error(const char* command, const std::string& what, const char* help) {
    std::fprintf(stderr, "bvhkit %s: error: %s\n\n%s", command, what.c_str(), help);
    return 2;
}

}  // namespace bvhkit::tools
