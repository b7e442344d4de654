#pragma once
// DynamicTree's upkeep (dynamic/dynamic_tree.hpp declares them): rebuild and optimize, which
// change the tree's shape to raise its quality, and clear, shrink_to_fit and shift_origin, which
// reset, repack or move the whole state at once. Included at the end of dynamic_tree.hpp; either
// header may be included first.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "bvhkit/dynamic/dynamic_tree.hpp"

namespace bvhkit {

template <class T, std::size_t N, class UserData>
void DynamicTree<T, N, UserData>::rebuild(bool full) {
    check_not_walking("DynamicTree::rebuild");
    tree_.rebuild(full);
}

template <class T, std::size_t N, class UserData>
int DynamicTree<T, N, UserData>::optimize(int max_reinsertions) {
    check_not_walking("DynamicTree::optimize");
    if (max_reinsertions <= 0 || proxy_count_ < 3) return 0;
    auto& cand = optimize_scratch_;
    cand.clear();
    for (std::int32_t id = 0; id < static_cast<std::int32_t>(proxies_.size()); ++id) {
        const std::int32_t leaf = proxies_[id].node;
        if (leaf == dynamic_detail::kNullNode || leaf == tree_.root()) continue;
        const double own =
            std::max(linked::box_area(tree_.node(leaf).box), double(std::numeric_limits<T>::min()));
        const double ratio = linked::box_area(tree_.node(tree_.node(leaf).parent).box) / own;
        cand.push_back({ratio == ratio ? ratio : 0.0, leaf});  // inf / inf: not a candidate
    }
    const std::size_t k =
        std::min<std::size_t>(cand.size(), static_cast<std::size_t>(max_reinsertions));
    const auto worse = [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    };
    std::nth_element(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(k) - 1, cand.end(),
                     worse);
    std::sort(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(k), worse);
    for (std::size_t i = 0; i < k; ++i) {
        tree_.detach(cand[i].second, options_.rotate);
        tree_.insert(cand[i].second, insertion());
    }
    return static_cast<int>(k);
}

template <class T, std::size_t N, class UserData>
void DynamicTree<T, N, UserData>::clear() {
    check_not_walking("DynamicTree::clear");
    std::uint64_t floor = generation_floor_;
    for (const Proxy& p : proxies_) floor = std::max(floor, next_generation(p));
    tree_.clear();
    if (floor > ProxyId::max_generation) {
        for (Proxy& p : proxies_) p = Proxy{}, p.generation = ProxyId::max_generation;
    } else {
        release(proxies_);
        generation_floor_ = std::uint32_t(floor);
    }
    release(move_buffer_);
    release(pairs_);
    release(pending_ends_);
    pairs_valid_ = true;
    release_scratch();
    free_proxy_ = dynamic_detail::kNullNode;
    proxy_count_ = 0;
}

template <class T, std::size_t N, class UserData>
void DynamicTree<T, N, UserData>::shrink_to_fit() {
    check_not_walking("DynamicTree::shrink_to_fit");
    std::size_t keep = proxies_.size();
    // A retired slot stays: a new one in its place could only start at its last generation.
    while (keep > 0 && proxies_[keep - 1].node == dynamic_detail::kNullNode &&
           proxies_[keep - 1].generation < ProxyId::max_generation) {
        // A slot made again later starts past every generation a dropped one handed out.
        generation_floor_ = std::max(generation_floor_, proxies_[keep - 1].generation);
        --keep;
    }
    if (keep < proxies_.size()) {
        // Pairs naming a dropped slot end at the next update_pairs().
        std::size_t kept = 0;
        for (const ProxyPair& p : pairs_)
            if (std::size_t(p.a.index()) >= keep || std::size_t(p.b.index()) >= keep)
                pending_ends_.push_back(p);
            else
                pairs_[kept++] = p;
        pairs_.resize(kept);
        // Destroyed slots past the end leave the move buffer (find_pairs skips them anyway).
        move_buffer_.erase(
            std::remove_if(move_buffer_.begin(), move_buffer_.end(),
                           [keep](std::int32_t slot) { return std::size_t(slot) >= keep; }),
            move_buffer_.end());
        proxies_.resize(keep);
        free_proxy_ = dynamic_detail::kNullNode;  // relist the free slots, smallest first
        for (std::size_t slot = keep; slot-- > 0;)
            if (proxies_[slot].node == dynamic_detail::kNullNode &&
                proxies_[slot].generation < ProxyId::max_generation)
                proxies_[slot].next_free = free_proxy_, free_proxy_ = std::int32_t(slot);
    }
    proxies_.shrink_to_fit();
    tree_.shrink_to_fit(
        [this](std::int32_t slot, std::int32_t leaf) { proxies_[std::size_t(slot)].node = leaf; });
    move_buffer_.shrink_to_fit();
    pairs_.shrink_to_fit();
    release_scratch();
}

template <class T, std::size_t N, class UserData>
void DynamicTree<T, N, UserData>::shift_origin(
    const typename DynamicTree<T, N, UserData>::VecT& new_origin) {
    check_not_walking("DynamicTree::shift_origin");
    dynamic_detail::check_vector(new_origin, "new_origin", "DynamicTree::shift_origin");
    for (std::size_t slot = 0; slot < proxies_.size(); ++slot) {
        const Proxy& p = proxies_[slot];
        if (p.node == dynamic_detail::kNullNode) continue;
        const Box b(p.box.min - new_origin, p.box.max - new_origin);
        for (std::size_t i = 0; i < N; ++i)
            if (!std::isfinite(b.min[i]) || !std::isfinite(b.max[i]))
                throw Error("DynamicTree::shift_origin: new_origin[" + std::to_string(i) +
                            "] = " + dynamic_detail::format_value(double(new_origin[i])) +
                            " would move proxy " +
                            to_string(ProxyId(std::int32_t(slot), p.generation)) +
                            "'s box outside the finite range");
    }
    constexpr T big = std::numeric_limits<T>::max();
    tree_.update_boxes([&](Box& b) {
        b = Box(bvhkit::max(b.min - new_origin, VecT(-big)),
                bvhkit::min(b.max - new_origin, VecT(big)));
    });
    for (Proxy& p : proxies_)
        if (p.node != dynamic_detail::kNullNode)
            p.box = Box(p.box.min - new_origin, p.box.max - new_origin);
}

}  // namespace bvhkit
