#pragma once
// Shared pieces of every same-run comparison: timing by medians of repetitions, and the two ways a
// result table is printed (aligned text for people, a JSON array of objects for scripts).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <variant>
#include <vector>

namespace bvhkit::bench {

/// A mesh argument as the tables name it: a file's name without its folders, a generator's
/// spec (sphere:subdiv=5) as given.
std::string mesh_label(const std::string& arg);

/// Milliseconds taken by f(), median over `repetitions` runs (after one untimed warm-up when
/// asked).
double median_ms(int repetitions, const std::function<void()>& f, bool warm_up = true);

double median(std::vector<double> values);

/// Median milliseconds of f() and of g(), their repetitions interleaved (f, g, f, g, ...) so that a
/// change of load on a shared machine affects both alike and their ratio stays fair.
std::pair<double, double> median_ms_interleaved(int repetitions, const std::function<void()>& f,
                                                const std::function<void()>& g);
/// The same for any number of functions, run in turn each repetition.
std::vector<double> median_ms_interleaved(int repetitions,
                                          const std::vector<std::function<void()>>& fs);

/// One cell of a result row: text, an integer count or a real figure.
using Value = std::variant<std::string, long long, double>;

struct Row {
    std::vector<std::pair<std::string, Value>> fields;
    Row& set(const std::string& key, Value v);
    const Value* get(const std::string& key) const;
};

/// Prints rows as an aligned table (columns in first-seen order; missing cells are blank).
void print_table(std::FILE* out, const std::vector<Row>& rows);
/// Prints rows as a JSON array of objects, one object per row.
void print_json(std::FILE* out, const std::vector<Row>& rows);

}  // namespace bvhkit::bench
