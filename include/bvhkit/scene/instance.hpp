#pragma once
// The small types of a Scene (scene.hpp): the ids of geometry and instances, the options an
// instance is added with, and a pair of instances.
//
// An InstanceId is the instance's slot and the slot's generation (as the dynamic tree's ProxyId,
// whose bits it carries): a slot is reused after remove() with the next generation, so an id kept
// past its instance's removal never names the new instance, and the scene's calls given it throw
// bvhkit::Error. Geometry is never removed, so a GeometryId is its index.
#include <compare>
#include <cstdint>
#include <string>

#include "bvhkit/dynamic/tree_types.hpp"

namespace bvhkit {

class GeometryId {
  public:
    constexpr GeometryId() = default;
    constexpr explicit GeometryId(std::uint32_t index) : index_(index) {}
    constexpr std::uint32_t index() const { return index_; }
    constexpr bool is_null() const { return index_ == kNull; }
    friend constexpr bool operator==(GeometryId, GeometryId) = default;
    friend constexpr auto operator<=>(GeometryId, GeometryId) = default;

  private:
    static constexpr std::uint32_t kNull = 0xFFFFFFFFu;
    std::uint32_t index_ = kNull;
};

class InstanceId {
  public:
    /// The null id: names no instance.
    constexpr InstanceId() = default;
    constexpr explicit InstanceId(ProxyId proxy) : proxy_(proxy) {}
    /// The id whose bits() are `bits` (one that no scene handed out is simply not live).
    static constexpr InstanceId from_bits(std::uint64_t bits) {
        return InstanceId(ProxyId::from_bits(bits));
    }
    constexpr std::int32_t index() const { return proxy_.index(); }
    constexpr std::uint32_t generation() const { return proxy_.generation(); }
    constexpr std::uint64_t bits() const { return proxy_.bits(); }
    constexpr bool is_null() const { return proxy_.is_null(); }
    /// The id of the instance's box in the scene's top-level tree.
    constexpr ProxyId proxy() const { return proxy_; }
    std::string text() const { return proxy_.text(); }
    friend constexpr bool operator==(InstanceId, InstanceId) = default;
    /// By slot, then generation (not by bits(), whose high half is the generation): the order of
    /// for_each_instance and of the collision queries' output, whatever slots were reused. The
    /// null id (slot -1) comes first.
    friend constexpr std::strong_ordering operator<=>(InstanceId x, InstanceId y) {
        if (const auto by_slot = x.index() <=> y.index(); by_slot != 0) return by_slot;
        return x.generation() <=> y.generation();
    }
    template <class Os>
    friend auto operator<<(Os& os, InstanceId id) -> decltype(os << std::string()) {
        return os << id.text();
    }

  private:
    ProxyId proxy_;
};

/// What an instance carries besides its geometry and pose.
template <class T>
struct InstanceOptions {
    std::uint64_t user_data = 0;  // the caller's own (an index, a handle, a pointer as an integer)
    /// Collision filter: two instances may collide iff (group_a & mask_b) && (group_b & mask_a).
    std::uint32_t group = 1;
    std::uint32_t mask = 0xFFFFFFFFu;
    /// A distance added around the instance for collision: two instances collide when their
    /// meshes are within margin_a + margin_b of each other. Finite and >= 0.
    T margin = 0;
};

/// Two instances, a.index() < b.index(); ordered by a, then b (InstanceId's order: by slot). For
/// the pairs between two scenes (collision.hpp), a is of the first scene and b of the second, and
/// their slots may be in either order.
struct InstancePair {
    InstanceId a, b;
    friend constexpr bool operator==(const InstancePair&, const InstancePair&) = default;
    friend constexpr auto operator<=>(const InstancePair&, const InstancePair&) = default;
};

/// Whether the group/mask filter lets two instances collide.
template <class T>
constexpr bool may_collide(const InstanceOptions<T>& a, const InstanceOptions<T>& b) {
    return (a.group & b.mask) != 0 && (b.group & a.mask) != 0;
}

}  // namespace bvhkit
