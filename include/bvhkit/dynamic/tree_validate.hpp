#pragma once
// DynamicTree::validate() and the input checks: every invariant of the node pool and the proxy
// table, checked from scratch, with a bvhkit::Error that names the first broken one.
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

/// Everything validate() needs to see of a tree.
template <class T, std::size_t N, class U>
struct TreeParts {
    const std::vector<Node<T, N>>& nodes;
    const std::vector<Proxy<T, N, U>>& proxies;
    const std::vector<ProxyId>& move_buffer;
    std::int32_t root;
    std::int32_t free_node;
    std::int32_t free_proxy;
    std::size_t node_count;
    std::size_t proxy_count;
};

[[noreturn]] inline void broken(const std::string& what) {
    throw Error("DynamicTree::validate: " + what);
}

template <class T, std::size_t N, class U>
void validate_tree(const TreeParts<T, N, U>& t) {
    const auto cap = static_cast<std::int64_t>(t.nodes.size());
    const auto pcap = static_cast<std::int64_t>(t.proxies.size());
    const auto node_name = [](std::int64_t i) { return "node " + std::to_string(i); };

    // Structure: walk down from the root; every reached node is in range, in use, reached once.
    std::vector<std::uint8_t> seen(t.nodes.size(), 0);
    std::size_t reached = 0, leaves = 0;
    if (t.root != kNullNode) {
        if (t.root < 0 || t.root >= cap)
            broken("root index " + std::to_string(t.root) + " out of range");
        if (t.nodes[t.root].parent != kNullNode)
            broken("root " + node_name(t.root) + " has a parent");
        std::vector<std::int32_t> stack{t.root};
        while (!stack.empty()) {
            const std::int32_t i = stack.back();
            stack.pop_back();
            if (i < 0 || i >= cap) broken("child index " + std::to_string(i) + " out of range");
            if (seen[i]) broken(node_name(i) + " is reached twice (the structure is not a tree)");
            seen[i] = 1;
            ++reached;
            const Node<T, N>& n = t.nodes[i];
            if (n.height < 0) broken(node_name(i) + " is in the tree but marked free");
            if (n.is_leaf()) {
                ++leaves;
                const ProxyId p = n.proxy();
                if (p < 0 || p >= pcap)
                    broken("leaf " + node_name(i) + " has proxy id " + std::to_string(p) +
                           " out of range");
                if (t.proxies[p].node != i)
                    broken("proxy table: leaf " + node_name(i) + " names proxy " +
                           std::to_string(p) + " whose node is " +
                           std::to_string(t.proxies[p].node));
                if (n.height != 0)
                    broken("leaf " + node_name(i) + " has height " + std::to_string(n.height));
                if (!n.box.contains(t.proxies[p].box))
                    broken("fat box of leaf " + node_name(i) + " does not contain proxy " +
                           std::to_string(p) + "'s box");
                continue;
            }
            for (const std::int32_t c : {n.child1, n.child2}) {
                if (c < 0 || c >= cap)
                    broken(node_name(i) + " has child index " + std::to_string(c) +
                           " out of range");
                const Node<T, N>& cn = t.nodes[c];
                if (cn.parent != i)
                    broken("parent link: " + node_name(c) + " is a child of " + std::to_string(i) +
                           " but its parent is " + std::to_string(cn.parent));
                if (!n.box.contains(cn.box))
                    broken("box of internal " + node_name(i) + " does not enclose its child " +
                           std::to_string(c));
                if (cn.enlarged && !n.enlarged)
                    broken(node_name(c) + " is marked enlarged but its parent " +
                           std::to_string(i) + " is not");
                stack.push_back(c);
            }
            if (n.child1 == n.child2) broken(node_name(i) + " has the same child twice");
            const int h = 1 + std::max<int>(t.nodes[n.child1].height, t.nodes[n.child2].height);
            if (n.height != h)
                broken(node_name(i) + " has height " + std::to_string(n.height) + ", expected " +
                       std::to_string(h));
        }
    }
    if (reached != t.node_count)
        broken("node count: " + std::to_string(reached) + " nodes reachable from the root, " +
               std::to_string(t.node_count) + " in use");
    if (leaves != t.proxy_count)
        broken("leaf count: " + std::to_string(leaves) + " leaves, " +
               std::to_string(t.proxy_count) + " proxies");

    // Free list: every node not in the tree is on it exactly once, marked free.
    std::size_t free_nodes = 0;
    for (std::int32_t i = t.free_node; i != kNullNode; i = t.nodes[i].parent) {
        if (i < 0 || i >= cap) broken("free list: index " + std::to_string(i) + " out of range");
        if (seen[i]) broken("free list: " + node_name(i) + " is also in the tree or listed twice");
        seen[i] = 1;
        if (t.nodes[i].height != -1) broken("free list: " + node_name(i) + " is not marked free");
        ++free_nodes;
    }
    if (free_nodes + t.node_count != t.nodes.size())
        broken("free list: " + std::to_string(free_nodes) + " free + " +
               std::to_string(t.node_count) + " used != pool size " +
               std::to_string(t.nodes.size()));

    // Proxy table: live proxies point at leaves naming them back; free slots form one list.
    std::size_t live = 0;
    for (std::int64_t p = 0; p < pcap; ++p) {
        const auto& px = t.proxies[p];
        if (px.node == kNullNode) {
            if (px.moved)
                broken("proxy table: free proxy " + std::to_string(p) + " is marked moved");
            continue;
        }
        ++live;
        if (px.node < 0 || px.node >= cap || t.nodes[px.node].height != 0 ||
            !t.nodes[px.node].is_leaf() || t.nodes[px.node].proxy() != p)
            broken("proxy table: proxy " + std::to_string(p) + " names node " +
                   std::to_string(px.node) + " which is not its leaf");
    }
    if (live != t.proxy_count)
        broken("proxy table: " + std::to_string(live) + " live proxies, count says " +
               std::to_string(t.proxy_count));
    std::size_t free_proxies = 0;
    for (std::int32_t p = t.free_proxy; p != kNullNode; p = t.proxies[p].next_free) {
        if (p < 0 || p >= pcap)
            broken("proxy free list: id " + std::to_string(p) + " out of range");
        if (t.proxies[p].node != kNullNode)
            broken("proxy free list: proxy " + std::to_string(p) + " is live");
        if (++free_proxies > t.proxies.size()) broken("proxy free list has a cycle");
    }
    // Move buffer: each id in range, flagged, and there once; every moved proxy is in it.
    std::size_t flagged = 0;
    for (const auto& px : t.proxies) {
        flagged += px.buffered;
        if (px.moved && !px.buffered) broken("move buffer: a moved proxy is not in it");
    }
    for (const ProxyId id : t.move_buffer)
        if (id < 0 || id >= pcap || !t.proxies[id].buffered)
            broken("move buffer: id " + std::to_string(id) + " is out of range or not flagged");
    if (flagged != t.move_buffer.size())
        broken("move buffer: " + std::to_string(t.move_buffer.size()) + " entries, " +
               std::to_string(flagged) + " proxies flagged (an id is listed twice)");
    if (free_proxies + t.proxy_count != t.proxies.size())
        broken("proxy free list: " + std::to_string(free_proxies) + " free + " +
               std::to_string(t.proxy_count) + " live != table size " +
               std::to_string(t.proxies.size()));
}

}  // namespace bvhkit::dynamic_detail
