#include "report.hpp"

#include <cmath>
#include <filesystem>
#include <string_view>

namespace bvhkit::bench {

std::string mesh_label(const std::string& arg) {
    return std::filesystem::exists(arg) ? std::filesystem::path(arg).filename().string() : arg;
}

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double median_ms(int repetitions, const std::function<void()>& f, bool warm_up) {
    if (warm_up) f();
    std::vector<double> times;
    for (int r = 0; r < std::max(1, repetitions); ++r) {
        const auto start = std::chrono::steady_clock::now();
        f();
        const auto stop = std::chrono::steady_clock::now();
        times.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    }
    return median(times);
}

std::vector<double> median_ms_interleaved(int repetitions,
                                          const std::vector<std::function<void()>>& fs) {
    for (const auto& f : fs) f();  // warm-up
    std::vector<std::vector<double>> times(fs.size());
    for (int r = 0; r < std::max(1, repetitions); ++r)
        for (std::size_t i = 0; i < fs.size(); ++i) times[i].push_back(median_ms(1, fs[i], false));
    std::vector<double> out;
    for (auto& t : times) out.push_back(median(t));
    return out;
}

std::pair<double, double> median_ms_interleaved(int repetitions, const std::function<void()>& f,
                                                const std::function<void()>& g) {
    const std::vector<double> t = median_ms_interleaved(repetitions, {f, g});
    return {t[0], t[1]};
}

Row& Row::set(const std::string& key, Value v) {
    for (auto& [k, old] : fields)
        if (k == key) {
            old = std::move(v);
            return *this;
        }
    fields.emplace_back(key, std::move(v));
    return *this;
}

const Value* Row::get(const std::string& key) const {
    for (const auto& [k, v] : fields)
        if (k == key) return &v;
    return nullptr;
}

static std::string to_text(const Value& v) {
    if (auto s = std::get_if<std::string>(&v)) return *s;
    if (auto i = std::get_if<long long>(&v)) return std::to_string(*i);
    const double d = std::get<double>(v);
    char buf[64];
    const double a = std::fabs(d);
    std::snprintf(buf, sizeof buf, a != 0 && (a < 0.01 || a >= 1e7) ? "%.3e" : "%.3f", d);
    return buf;
}

static std::string json_escape(std::string_view s) {
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(c));
            out += buf;
        } else {
            out += c;
        }
    }
    return out;
}

void print_table(std::FILE* out, const std::vector<Row>& rows) {
    std::vector<std::string> columns;
    for (const auto& r : rows)
        for (const auto& [k, v] : r.fields)
            if (std::find(columns.begin(), columns.end(), k) == columns.end()) columns.push_back(k);
    std::vector<std::size_t> width(columns.size());
    for (std::size_t c = 0; c < columns.size(); ++c) {
        width[c] = columns[c].size();
        for (const auto& r : rows)
            if (auto v = r.get(columns[c])) width[c] = std::max(width[c], to_text(*v).size());
    }
    for (std::size_t c = 0; c < columns.size(); ++c)
        std::fprintf(out, "%-*s  ", static_cast<int>(width[c]), columns[c].c_str());
    std::fprintf(out, "\n");
    for (std::size_t c = 0; c < columns.size(); ++c)
        std::fprintf(out, "%s  ", std::string(width[c], '-').c_str());
    std::fprintf(out, "\n");
    for (const auto& r : rows) {
        for (std::size_t c = 0; c < columns.size(); ++c) {
            const Value* v = r.get(columns[c]);
            const std::string text = v ? to_text(*v) : "";
            const bool numeric = v && !std::holds_alternative<std::string>(*v);
            std::fprintf(out, numeric ? "%*s  " : "%-*s  ", static_cast<int>(width[c]),
                         text.c_str());
        }
        std::fprintf(out, "\n");
    }
}

void print_json(std::FILE* out, const std::vector<Row>& rows) {
    std::fprintf(out, "[\n");
    for (std::size_t i = 0; i < rows.size(); ++i) {
        std::fprintf(out, "  {");
        const auto& f = rows[i].fields;
        for (std::size_t j = 0; j < f.size(); ++j) {
            std::fprintf(out, "%s\"%s\": ", j ? ", " : "", json_escape(f[j].first).c_str());
            const Value& v = f[j].second;
            if (auto s = std::get_if<std::string>(&v)) {
                std::fprintf(out, "\"%s\"", json_escape(*s).c_str());
            } else if (auto n = std::get_if<long long>(&v)) {
                std::fprintf(out, "%lld", *n);
            } else {
                const double d = std::get<double>(v);
                if (std::isfinite(d))
                    std::fprintf(out, "%.6g", d);
                else
                    std::fprintf(out, "null");
            }
        }
        std::fprintf(out, "}%s\n", i + 1 < rows.size() ? "," : "");
    }
    std::fprintf(out, "]\n");
}

}  // namespace bvhkit::bench
