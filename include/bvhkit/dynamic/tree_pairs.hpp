#pragma once
// The dynamic tree's pair finding: the overlapping pairs that involve a proxy of the move buffer
// (DynamicTree::find_pairs), and the step from one persistent pair set to the next with the pairs
// that began and ended in between (DynamicTree::update_pairs).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "bvhkit/dynamic/tree_queries.hpp"
#include "bvhkit/dynamic/tree_types.hpp"

namespace bvhkit::dynamic_detail {

/// Every overlapping pair (tight boxes, touching counts) that involves a moved proxy of `buffer`
/// (slot indices, sorted in place), each once as (a, b) with a < b, into `out`, sorted.
template <class T, std::size_t N, class U>
void collect_moved_pairs(const TreeView<T, N, U>& v, std::vector<std::int32_t>& buffer,
                         std::vector<ProxyPair>& out) {
    out.clear();
    std::sort(buffer.begin(), buffer.end());
    for (const std::int32_t q : buffer) {
        if (!v.proxies[q].moved) continue;  // destroyed since it was buffered
        const ProxyId qid = proxy_id(v, q);
        query_box(
            v, v.proxies[q].box,
            [&](ProxyId oid) {
                // Skip itself; when both moved, only the query from the smaller slot reports.
                const std::int32_t o = oid.index();
                if (o != q && !(v.proxies[o].moved && o < q))
                    out.push_back(oid < qid ? ProxyPair{oid, qid} : ProxyPair{qid, oid});
                return true;
            },
            nullptr);
    }
    std::sort(out.begin(), out.end());
}

/// One pair step. `prev`: the pairs overlapping after the last step (sorted). `found`: every pair
/// overlapping now that involves a moved proxy (sorted). touched(id): the proxy's slot moved, was
/// created or was destroyed since the last step; ended(id): the slot was destroyed since. A pair of
/// prev with no touched proxy still overlaps; one with a touched proxy persists only if found again
/// (the same ids: a slot reused since has a new generation, so its pairs end and begin) and, for
/// trees loaded from files without generations, neither slot ended. Writes the new set to
/// `next` and appends the ended and begun pairs (both sorted) to `ends` and `begins`.
template <class Touched, class Ended>
void step_pair_set(const std::vector<ProxyPair>& prev, const std::vector<ProxyPair>& found,
                   Touched&& touched, Ended&& ended, std::vector<ProxyPair>& next,
                   std::vector<ProxyPair>& ends, std::vector<ProxyPair>& begins) {
    next.clear();
    std::size_t i = 0, j = 0;
    while (i < prev.size() || j < found.size()) {
        if (j == found.size() || (i < prev.size() && prev[i] < found[j])) {
            const ProxyPair p = prev[i++];
            if (touched(p.a) || touched(p.b))
                ends.push_back(p);
            else
                next.push_back(p);
        } else if (i == prev.size() || found[j] < prev[i]) {
            begins.push_back(found[j]);
            next.push_back(found[j++]);
        } else {  // in both: the same ids (without generations, maybe not the same proxies)
            const ProxyPair p = found[j++];
            ++i;
            if (ended(p.a) || ended(p.b)) ends.push_back(p), begins.push_back(p);
            next.push_back(p);
        }
    }
}

}  // namespace bvhkit::dynamic_detail
