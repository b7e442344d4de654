// Tree<T, N>: the dynamic AABB tree for Python, changed and asked in batches. A batch of changes
// checks every box and id before it changes anything, so a bad row leaves the tree as it was.
// Queries hold a shared lock and run over threads without the GIL; changes hold an exclusive one.
// Ids are int64: ProxyId::bits() (generation << 32 | slot), so a kept id of a destroyed proxy never
// names the proxy that reuses its slot.
#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "bvhkit/dynamic/dynamic_tree.hpp"
#include "common.hpp"

namespace bvhkit::python {
namespace {

template <class T, std::size_t N>
class Tree {
  public:
    using VecT = Vec<T, N>;
    using Box = Aabb<T, N>;

    Tree(T margin, T margin_relative, T displacement_multiplier) {
        DynamicTreeOptions<T> o;
        o.margin_absolute = margin;
        o.margin_relative = margin_relative;
        o.displacement_multiplier = displacement_multiplier;
        tree_.set_options(o);
    }

    static VecT at(const T* p, std::size_t i) {
        VecT v;
        for (std::size_t a = 0; a < N; ++a) v[a] = p[N * i + a];
        return v;
    }
    /// Throws naming the first bad box of a batch (the library's rule: finite, min <= max).
    static void check_boxes(const Rows<T, N>& lo, const Rows<T, N>& hi, const char* where) {
        expect_rows(hi, lo.shape(0), "hi");
        for (std::size_t i = 0; i < lo.shape(0); ++i) {
            const std::string w = std::string(where) + ": row " + std::to_string(i);
            dynamic_detail::check_box(Box(at(lo.data(), i), at(hi.data(), i)), w.c_str());
        }
    }
    static ProxyId id_at(const Column<std::int64_t>& ids, std::size_t i) {
        return ProxyId::from_bits(std::uint64_t(ids.data()[i]));
    }
    void check_ids(const Column<std::int64_t>& ids, const char* where) const {
        for (std::size_t i = 0; i < ids.shape(0); ++i)
            if (!tree_.contains(id_at(ids, i)))
                throw Error(std::string(where) + ": ids[" + std::to_string(i) +
                            "] = " + std::to_string(ids.data()[i]) +
                            " is not a live proxy (destroyed, or never created by this tree)");
    }
    void create(const Rows<T, N>& lo, const Rows<T, N>& hi, OutColumn<std::int64_t> ids) {
        check_boxes(lo, hi, "create");
        expect_rows(ids, lo.shape(0), "ids");
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        for (std::size_t i = 0; i < lo.shape(0); ++i)
            ids.data()[i] =
                std::int64_t(tree_.create(Box(at(lo.data(), i), at(hi.data(), i))).bits());
    }
    void move(const Column<std::int64_t>& ids, const Rows<T, N>& lo, const Rows<T, N>& hi,
              const Rows<T, N>& displacement, OutColumn<bool> restructured) {
        check_boxes(lo, hi, "move");
        expect_rows(ids, lo.shape(0), "ids");
        expect_rows(displacement, lo.shape(0), "displacement");
        expect_rows(restructured, lo.shape(0), "out");
        for (std::size_t i = 0; i < lo.shape(0); ++i)
            dynamic_detail::check_vector(at(displacement.data(), i), "displacement", "move");
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "move");
        for (std::size_t i = 0; i < lo.shape(0); ++i)
            restructured.data()[i] = tree_.move(
                id_at(ids, i), Box(at(lo.data(), i), at(hi.data(), i)), at(displacement.data(), i));
    }
    void destroy(const Column<std::int64_t>& ids) {
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "destroy");
        check_unique(ids, "destroy");
        for (std::size_t i = 0; i < ids.shape(0); ++i) tree_.destroy(id_at(ids, i));
    }
    /// Throws naming the first id that repeats an earlier one: a sort of (id, position), so a
    /// batch of k ids costs O(k log k) under the exclusive lock, whatever the tree's size.
    static void check_unique(const Column<std::int64_t>& ids, const char* where) {
        std::vector<std::pair<std::int64_t, std::size_t>> order(ids.shape(0));
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = {ids.data()[i], i};
        std::sort(order.begin(), order.end());
        std::size_t first = order.size(), earlier = 0;
        for (std::size_t k = 1; k < order.size(); ++k)
            if (order[k].first == order[k - 1].first && order[k].second < first)
                first = order[k].second, earlier = order[k - 1].second;
        if (first < order.size())
            throw Error(std::string(where) + ": ids[" + std::to_string(first) + "] repeats ids[" +
                        std::to_string(earlier) + "] (" + std::to_string(ids.data()[first]) + ")");
    }

    nb::ndarray<nb::numpy, std::int64_t> find_pairs() {
        std::vector<std::int64_t> flat;
        {
            nb::gil_scoped_release release;
            const std::unique_lock<std::shared_mutex> lock(mutex_);
            tree_.find_pairs(pairs_);
            flat.reserve(2 * pairs_.size());
            for (const ProxyPair& p : pairs_)
                flat.insert(flat.end(), {std::int64_t(p.a.bits()), std::int64_t(p.b.bits())});
        }
        const std::size_t n = flat.size() / 2;
        return owned_array(std::move(flat), n, 2);
    }

    /// Runs per_item(i, out) over a batch on threads; out gets (i, proxy) rows, gathered in item
    /// order, so the answer does not depend on the thread count.
    template <class PerItem>
    nb::ndarray<nb::numpy, std::int64_t> gather(std::size_t k, unsigned threads,
                                                PerItem&& per_item) const {
        std::vector<std::int64_t> flat;
        {
            nb::gil_scoped_release release;
            const std::shared_lock<std::shared_mutex> lock(mutex_);
            constexpr std::size_t grain = 256;
            std::vector<std::vector<std::int64_t>> chunks((k + grain - 1) / grain);
            run_batch(k, grain, threads, [&](std::size_t b, std::size_t e) {
                auto& out = chunks[b / grain];
                for (std::size_t i = b; i < e; ++i) per_item(i, out);
            });
            for (const auto& c : chunks) flat.insert(flat.end(), c.begin(), c.end());
        }
        const std::size_t n = flat.size() / 2;
        return owned_array(std::move(flat), n, 2);
    }
    nb::ndarray<nb::numpy, std::int64_t> query(const Rows<T, N>& lo, const Rows<T, N>& hi,
                                               unsigned threads) const {
        check_boxes(lo, hi, "query");
        return gather(lo.shape(0), threads, [&](std::size_t i, std::vector<std::int64_t>& out) {
            tree_.query(Box(at(lo.data(), i), at(hi.data(), i)), [&](ProxyId id) {
                out.insert(out.end(), {std::int64_t(i), std::int64_t(id.bits())});
                return true;
            });
        });
    }
    nb::ndarray<nb::numpy, std::int64_t> ray_cast(const Rows<T, N>& origins,
                                                  const Rows<T, N>& directions,
                                                  const Column<T>& max_fraction,
                                                  unsigned threads) const {
        const std::size_t k = origins.shape(0);
        expect_rows(directions, k, "directions");
        expect_rows(max_fraction, k, "max_fraction");
        return gather(k, threads, [&](std::size_t i, std::vector<std::int64_t>& out) {
            const T limit = max_fraction.data()[i];
            // A negative answer means "go on without clipping": every box on the segment.
            tree_.ray_cast(at(origins.data(), i), at(directions.data(), i), limit,
                           [&](ProxyId id, T) {
                               out.insert(out.end(), {std::int64_t(i), std::int64_t(id.bits())});
                               return T(-1);
                           });
        });
    }

    nb::tuple boxes(const Column<std::int64_t>& ids) const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        check_ids(ids, "boxes");
        const std::size_t k = ids.shape(0);
        std::vector<T> lo(N * k), hi(N * k);
        for (std::size_t i = 0; i < k; ++i) {
            const Box& b = tree_.box(id_at(ids, i));
            for (std::size_t a = 0; a < N; ++a) {
                lo[N * i + a] = b.min[a];
                hi[N * i + a] = b.max[a];
            }
        }
        return nb::make_tuple(owned_array(std::move(lo), k, N), owned_array(std::move(hi), k, N));
    }
    nb::dict stats() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        nb::dict d;
        d["proxies"] = tree_.size();
        d["height"] = tree_.height();
        d["sah_cost"] = tree_.sah_cost();
        d["area_ratio"] = tree_.area_ratio();
        d["memory_bytes"] = tree_.memory_bytes();
        return d;
    }
    void validate() const {
        const std::shared_lock<std::shared_mutex> lock(mutex_);
        tree_.validate();
    }
    std::size_t size() const { return tree_.size(); }
    void rebuild() {
        nb::gil_scoped_release release;
        const std::unique_lock<std::shared_mutex> lock(mutex_);
        tree_.rebuild(true);
    }

  private:
    DynamicTree<T, N> tree_;
    std::vector<ProxyPair> pairs_;
    mutable std::shared_mutex mutex_;
};

template <class T, std::size_t N>
void bind_tree(nb::module_& m, const char* name) {
    using Tr = Tree<T, N>;
    nb::class_<Tr>(m, name, "A dynamic AABB tree (see bvhkit.DynamicTree2D / DynamicTree3D).")
        .def(nb::init<T, T, T>(), nb::arg("margin"), nb::arg("margin_relative"),
             nb::arg("displacement_multiplier"), "An empty tree.")
        .def("create", &Tr::create, nb::arg("lo"), nb::arg("hi"), nb::arg("ids"),
             "Adds one proxy per box; writes their ids.")
        .def("move", &Tr::move, nb::arg("ids"), nb::arg("lo"), nb::arg("hi"),
             nb::arg("displacement"), nb::arg("out"), "New boxes for existing proxies.")
        .def("destroy", &Tr::destroy, nb::arg("ids"), "Removes proxies.")
        .def("find_pairs", &Tr::find_pairs,
             "Overlapping pairs involving a proxy created or moved since the last call, (p, 2).")
        .def("query", &Tr::query, nb::arg("lo"), nb::arg("hi"), nb::arg("threads"),
             "(query index, proxy id) rows for every proxy box overlapping each query box.")
        .def("ray_cast", &Tr::ray_cast, nb::arg("origins"), nb::arg("directions"),
             nb::arg("max_fraction"), nb::arg("threads"),
             "(ray index, proxy id) rows for every proxy box each segment crosses.")
        .def("boxes", &Tr::boxes, nb::arg("ids"), "(lo, hi) of the proxies' tight boxes.")
        .def("stats", &Tr::stats, "Size, height and quality measures.")
        .def("validate", &Tr::validate, "Checks every invariant; ValueError if one is broken.")
        .def("rebuild", &Tr::rebuild, "Rebuilds the whole tree top-down (binned SAH).")
        .def("__len__", &Tr::size, "Number of live proxies.");
}

}  // namespace

void bind_dynamic(nb::module_& m) {
    bind_tree<float, 2>(m, "Tree2_f32");
    bind_tree<float, 3>(m, "Tree3_f32");
    bind_tree<double, 2>(m, "Tree2_f64");
    bind_tree<double, 3>(m, "Tree3_f64");
}

}  // namespace bvhkit::python
