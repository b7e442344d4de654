#pragma once
// DynamicTree::validate() and the input checks: every invariant of the proxy table and the move
// buffer (the tree's own are LinkedTree::validate's), checked from scratch, with a bvhkit::Error
// that names the first broken one.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "bvhkit/dynamic/tree_types.hpp"
#include "bvhkit/error.hpp"

namespace bvhkit::dynamic_detail {

inline std::string format_value(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

/// Throws unless every coordinate of `box` is finite and min <= max on every axis.
template <class T, std::size_t N>
void check_box(const Aabb<T, N>& box, const char* where) {
    static const char* const kAxis[] = {"x", "y", "z", "w"};
    for (std::size_t i = 0; i < N; ++i) {
        if (!std::isfinite(box.min[i]))
            throw Error(std::string(where) + ": box min." + kAxis[i] + " is " +
                        format_value(box.min[i]) + " (coordinates must be finite)");
        if (!std::isfinite(box.max[i]))
            throw Error(std::string(where) + ": box max." + kAxis[i] + " is " +
                        format_value(box.max[i]) + " (coordinates must be finite)");
    }
    for (std::size_t i = 0; i < N; ++i)
        if (box.min[i] > box.max[i])
            throw Error(std::string(where) + ": box min." + kAxis[i] + " = " +
                        format_value(box.min[i]) + " > max." + kAxis[i] + " = " +
                        format_value(box.max[i]));
}

template <class T, std::size_t N>
void check_vector(const Vec<T, N>& v, const char* what, const char* where) {
    for (std::size_t i = 0; i < N; ++i)
        if (!std::isfinite(v[i]))
            throw Error(std::string(where) + ": " + what + "[" + std::to_string(i) + "] is " +
                        format_value(v[i]) + " (must be finite)");
}

/// Throws when a query's vector holds a NaN (every comparison with it is false, so the walk would
/// report every proxy). Infinities stay allowed: a box from -inf to inf is a query for everything.
template <class T, std::size_t N>
void check_not_nan(const Vec<T, N>& v, const char* what, const char* where) {
    for (std::size_t i = 0; i < N; ++i)
        if (std::isnan(v[i]))
            throw Error(std::string(where) + ": " + what + "[" + std::to_string(i) +
                        "] is nan (a query must not hold NaN)");
}

/// DynamicTree::validate()'s check of one leaf of the tree: it names a proxy whose leaf it is and
/// whose tight box its fat box contains.
template <class T, std::size_t N, class U>
void check_leaf(const Node<T, N>& n, std::int32_t i, const std::vector<Proxy<T, N, U>>& proxies) {
    const auto broken = [](const std::string& what) {
        throw Error("DynamicTree::validate: " + what);
    };
    const std::int32_t p = n.value();
    const std::string leaf = "leaf node " + std::to_string(i);
    if (p < 0 || std::size_t(p) >= proxies.size())
        broken(leaf + " has proxy id " + std::to_string(p) + " out of range");
    if (proxies[std::size_t(p)].node != i)
        broken("proxy table: " + leaf + " names proxy " + std::to_string(p) + " whose node is " +
               std::to_string(proxies[std::size_t(p)].node));
    if (!n.box.contains(proxies[std::size_t(p)].box))
        broken("fat box of " + leaf + " does not contain proxy " + std::to_string(p) + "'s box");
}

/// Everything the proxy side of DynamicTree::validate() needs to see.
template <class T, std::size_t N, class U>
struct ProxyParts {
    const LinkedTree<T, N>& tree;
    const std::vector<Proxy<T, N, U>>& proxies;
    const std::vector<std::int32_t>& move_buffer;
    std::int32_t free_proxy;
    std::size_t proxy_count;
    std::size_t leaves;  // leaves in the tree (LinkedTree::validate)
};

/// The proxy table, its free list and the move buffer: live proxies point at leaves naming them
/// back, free slots form one list, every moved proxy is buffered once.
template <class T, std::size_t N, class U>
void validate_proxies(const ProxyParts<T, N, U>& t) {
    const auto broken = [](const std::string& what) {
        throw Error("DynamicTree::validate: " + what);
    };
    const auto cap = static_cast<std::int64_t>(t.tree.capacity());
    const auto pcap = static_cast<std::int64_t>(t.proxies.size());
    if (t.leaves != t.proxy_count)
        broken("leaf count: " + std::to_string(t.leaves) + " leaves, " +
               std::to_string(t.proxy_count) + " proxies");
    if (t.tree.node_count() != (t.leaves == 0 ? 0 : 2 * t.leaves - 1))
        broken("node count: " + std::to_string(t.tree.node_count()) + " nodes in use for " +
               std::to_string(t.leaves) + " leaves");
    std::size_t live = 0, retired = 0;
    for (std::int64_t p = 0; p < pcap; ++p) {
        const auto& px = t.proxies[std::size_t(p)];
        if (px.generation > ProxyId::max_generation)
            broken("proxy table: slot " + std::to_string(p) + " has generation " +
                   std::to_string(px.generation) + " past the largest");
        if (px.node == kNullNode) {
            if (px.moved)
                broken("proxy table: free proxy " + std::to_string(p) + " is marked moved");
            retired += px.generation == ProxyId::max_generation;
            continue;
        }
        ++live;
        if (px.node < 0 || px.node >= cap || t.tree.node(px.node).height != 0 ||
            !t.tree.node(px.node).is_leaf() || t.tree.node(px.node).value() != p)
            broken("proxy table: proxy " + std::to_string(p) + " names node " +
                   std::to_string(px.node) + " which is not its leaf");
    }
    if (live != t.proxy_count)
        broken("proxy table: " + std::to_string(live) + " live proxies, count says " +
               std::to_string(t.proxy_count));
    std::size_t free_proxies = 0;
    for (std::int32_t p = t.free_proxy; p != kNullNode; p = t.proxies[std::size_t(p)].next_free) {
        if (p < 0 || p >= pcap)
            broken("proxy free list: id " + std::to_string(p) + " out of range");
        if (t.proxies[std::size_t(p)].node != kNullNode)
            broken("proxy free list: proxy " + std::to_string(p) + " is live");
        if (t.proxies[std::size_t(p)].generation == ProxyId::max_generation)
            broken("proxy free list: slot " + std::to_string(p) +
                   " is retired (its generation "
                   "is the largest) but listed");
        if (++free_proxies > t.proxies.size()) broken("proxy free list has a cycle");
    }
    if (free_proxies + retired + t.proxy_count != t.proxies.size())
        broken("proxy free list: " + std::to_string(free_proxies) + " free + " +
               std::to_string(retired) + " retired + " + std::to_string(t.proxy_count) +
               " live != table size " + std::to_string(t.proxies.size()));
    // Move buffer: each id in range, flagged, and there once; every moved proxy is in it.
    std::size_t flagged = 0;
    for (const auto& px : t.proxies) {
        flagged += px.buffered;
        if (px.moved && !px.buffered) broken("move buffer: a moved proxy is not in it");
    }
    for (const std::int32_t id : t.move_buffer)
        if (id < 0 || id >= pcap || !t.proxies[std::size_t(id)].buffered)
            broken("move buffer: id " + std::to_string(id) + " is out of range or not flagged");
    if (flagged != t.move_buffer.size())
        broken("move buffer: " + std::to_string(t.move_buffer.size()) + " entries, " +
               std::to_string(flagged) + " proxies flagged (an id is listed twice)");
}

}  // namespace bvhkit::dynamic_detail
