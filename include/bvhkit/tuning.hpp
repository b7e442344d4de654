#pragma once
// The speed settings of bvhkit, in one place. Each value here is chosen for time or memory, not
// for correctness: another value in its stated range still gives a valid tree and queries that
// decide the same. The builders' settings and the leaf limits do shape the tree, so where two
// answers tie, which one a query names may change with them (not for rays: at an equal t every
// walk names the triangle of lower index). Each line says
// why the value is what it is and which bench shows it; the figures, with their dates and
// machines, are in docs/benchmarks.md. The headers that use a value name it from here, under their
// own names where they had one.
//
// Correctness limits are not here: file format versions, max_bvh_depth and the stack capacities
// it bounds, the exact-arithmetic widths, the 32-bit masks that bound a stream's size.
//
// Benches (docs/benchmarks.md): `bvhkit-bench rays MESH` (build, R1-R3, batch rows R2-mt/R3-mt),
// `bvhkit info MESH --all-builders` (SAH cost, boxes and triangles a ray), `bvhkit-bench nearest
// MESH [--scaling]`, `bvhkit-bench dynamic`, `bvhkit bsp MESH`, and the micro benchmarks of
// bench/micro (`bvhkit_micro`).
#include <cstddef>
#include <cstdint>

namespace bvhkit::tuning {

// ---- Builders (BuildOptions and the top-down rules) ----

/// BuildOptions::bin_count: 32 bins traced the same rays within noise and built as fast or
/// slower. `bvhkit-bench rays MESH`, `bvhkit info MESH`.
inline constexpr std::uint32_t sah_bins = 16;
/// BuildOptions::max_leaf_size: the cap over the SAH's own leaves, no lower than the widest leaf
/// block (wide8_leaf_block), below which nodes would be split at the object median.
/// `bvhkit info MESH --all-builders`.
inline constexpr std::uint32_t max_leaf_size = 8;
/// BuildOptions::max_leaf_size of the classic top-down rules' configurations (parse_builder,
/// all_builder_configurations): with no SAH to stop them, smaller leaves than the SAH builders'.
/// `bvhkit info MESH --all-builders`.
inline constexpr std::uint32_t top_down_max_leaf_size = 4;
/// collision_build_options(): small leaves, since a leaf pair costs count_a * count_b triangle
/// tests. `bvhkit-bench collide MESH`.
inline constexpr std::uint32_t collision_max_leaf_size = 2;
/// SahCosts: a box test and a triangle test priced alike; 0.5 to 2 for the box changed no ray row
/// beyond noise. `bvhkit-bench rays MESH`.
inline constexpr double sah_traversal_cost = 1.0;
inline constexpr double sah_intersection_cost = 1.0;
/// BuildOptions::ploc_radius: neighbours the bottom-up builder searches each side, tree quality
/// against build time (a round costs 2 * radius area evaluations a cluster).
/// `bvhkit info MESH --builder bottom-up`.
inline constexpr std::uint32_t ploc_radius = 16;

/// Binned SAH: a node of n primitives bins into min_bins + n / primitives_per_bin bins (at most
/// bin_count), as in Embree: the sweep over bins is a per-node cost that would dominate the many
/// small nodes. `bvhkit-bench rays MESH` (build row).
inline constexpr std::uint32_t binned_sah_min_bins = 4;
inline constexpr std::uint32_t binned_sah_primitives_per_bin = 20;
/// Binned SAH: nodes of at least this many primitives bin in chunks on several threads; below,
/// a task costs more than it saves. `bvhkit_micro --benchmark_filter=build` (builds on every
/// core; bench/micro).
inline constexpr std::size_t parallel_binning_from = std::size_t(1) << 15;
/// Binned SAH: primitives per chunk of the parallel binning.
inline constexpr std::size_t binning_chunk = 8192;
/// Sweep SAH: nodes of at least this many primitives sweep their three axes in parallel.
inline constexpr std::size_t parallel_axes_from = std::size_t(1) << 15;
/// Top-down builders: primitives per chunk of the parallel passes over a range (fixed, so a
/// chunk's result never depends on the thread count).
inline constexpr std::size_t partition_chunk = 8192;
/// Top-down builders: ranges at least this long are partitioned stably through a scratch buffer
/// (in parallel chunks), shorter ones in place, which is faster when there is nothing to share.
inline constexpr std::size_t stable_partition_from = 4 * partition_chunk;
/// Top-down builders: nodes larger than this are split one task each; a smaller node builds its
/// subtree serially as one task (small against large meshes, to balance; not tiny, to pay for a
/// task's allocations). `bvhkit_micro --benchmark_filter=build`.
inline constexpr std::uint32_t parallel_subtree_cutoff = 4096;
/// Insertion builder and reinsertion optimizer: nodes the sibling search expands per insertion
/// before it takes the best found; bounds the build on heavily overlapping boxes, which would
/// otherwise be quadratic. `bvhkit info MESH --builder insertion`.
inline constexpr std::size_t insertion_max_expansions = 64;

/// SpatialSplitOptions::alpha: spatial splits only where the object split's children overlap by
/// more than this share of the root's area; the paper's 1e-5 built up to three times slower for the
/// same rays. `bvhkit-bench rays MESH --high-quality`.
inline constexpr double spatial_split_alpha = 1e-3;
/// SpatialSplitOptions::bins: 16 built faster than 32 to the same SAH cost within 1%.
/// `bvhkit-bench rays MESH --high-quality`.
inline constexpr std::uint32_t spatial_split_bins = 16;
/// TriangleBvhOptions::auto_spatial_splits: the child overlap (build/spatial_split_choice.hpp)
/// from which the spatial-split build is made: scans, height fields and a city measure below, and
/// gained nothing from spatial splits; rooms and triangle soups above, where they pay.
/// `bvhkit-bench rays MESH` (rows bvhkit-auto).
inline constexpr double spatial_splits_from_overlap = 0.2;
/// Spatial splits: nodes of at most this many references try object splits only (spatial binning
/// is most of the build, and few of its splits win in small nodes).
inline constexpr std::uint32_t spatial_split_min_count = 8;

// ---- Ray layouts and ray paths (TriangleBvh<float>) ----

/// SahCosts::leaf_block that TriangleBvh builds with for each wide layout: leaves priced in
/// blocks as wide as the walk's triangle groups, so a node of one block is a leaf without a
/// search (a faster build, the same rays). `bvhkit-bench rays MESH`.
inline constexpr std::uint32_t wide8_leaf_block = 8;
inline constexpr std::uint32_t wide4_leaf_block = 4;
/// Costs of the wide collapses (make_wide_ray_bvh, collapse_to_wide_sah): a wide node's test in
/// units of one triangle group's test, high because a node is a dependent load that misses the
/// caches once the tree outgrows them, where a leaf's groups lie side by side; lower costs made
/// the large scans slower, higher ones the soups and rooms. `bvhkit-bench rays MESH`.
inline constexpr double wide8_node_cost = 32;
inline constexpr double wide4_node_cost = 16;
/// The most triangles a leaf child of the wide collapses holds whatever the costs say: bounds a
/// leaf's tests where boxes of zero area (flat, axis-aligned groups) make any leaf look free.
/// `bvhkit-bench rays MESH`.
inline constexpr std::uint32_t wide8_leaf_limit = 64;
inline constexpr std::uint32_t wide4_leaf_limit = 32;
/// Rays a stream keeps in flight (query/ray_stream.hpp): four to sixteen measured alike; eight.
/// `bvhkit-bench rays MESH` (rows R2-mt, R3-mt).
inline constexpr int stream_width = 8;
/// Trace batches walk as streams from this eight-wide layout size on: a layout that stays in a
/// core's L2 has little latency to hide, and interleaving costs it branch prediction.
/// `bvhkit-bench rays MESH` (R2-mt against R2).
inline constexpr std::size_t stream_from_layout_bytes = std::size_t(2) << 20;
/// Rays an octant stream holds (query/ray_octant_stream.hpp; at most 32, one bit each in a
/// 32-bit mask): 32 beat 16 on the bunny and igea. `bvhkit-bench rays MESH` (R3-mt).
inline constexpr int octant_stream_size = 32;
/// Occlusion batches take octant streams below this eight-wide layout size, the interleaved
/// walks above: there a node's rays are few and the walk waits for memory, which interleaving
/// hides better. `bvhkit-bench rays MESH` (R3-mt).
inline constexpr std::size_t octant_streams_below_layout_bytes = std::size_t(8) << 20;
/// A run of octant_stream_size consecutive rays of a trace batch walks as one packet
/// (query/ray_coherence.hpp) when its rays share a direction octant, their directions lie within
/// an angle of sine packet_direction_spread of the first one's, and their origins within this
/// fraction of the tree's extent of the first one's on every axis: camera rays of a row or tile,
/// and shadow rays from near points towards one light, do. Measured by R1 (camera rays) batched
/// against one by one, docs/benchmarks.md ("Packets of coherent rays").
inline constexpr float packet_direction_spread = 0.125f;
inline constexpr float packet_origin_spread = 0.125f;
/// Rays per task of the batch calls: large enough to pay for a task, small enough to balance
/// incoherent rays over the cores. `bvhkit-bench rays MESH` (R2-mt, R3-mt).
inline constexpr std::size_t ray_batch_grain = 256;

// ---- Point batches and box queries ----

/// spatial_order: the most points sorted as one run; keeps the sort's buffers at 64 MB whatever
/// the batch, and 4M points to a run are dense enough that neighbours share the tree.
/// `bvhkit-bench nearest MESH`.
inline constexpr std::size_t spatial_order_run = std::size_t(1) << 22;
/// Batches from this many points on are answered in spatial order; below, the sort costs about
/// what it saves. `bvhkit-bench nearest MESH --points N`.
inline constexpr std::size_t spatial_order_from = 4096;
/// spatial_order: points per task of its parallel passes.
inline constexpr std::size_t spatial_order_grain = 16384;
/// spatial_order: runs shorter than this are one radix sort; longer ones are split into 129
/// buckets on their top bits, sorted in parallel and mostly in cache. `bvhkit-bench nearest
/// MESH --scaling`.
inline constexpr std::size_t spatial_order_one_sort_below = std::size_t(1) << 16;
/// Queries per task of the batched overlap queries (as ray_batch_grain).
inline constexpr std::size_t overlap_batch_grain = 256;

// ---- Stacks kept on the caller's frame ----

/// Entries the BSP traversal stack holds without a heap block (a ray needs depth + 2, a visit
/// 2 depth + 4). `bvhkit bsp MESH`.
inline constexpr std::size_t bsp_stack_inline = 128;
/// Vertices a BSP polygon split classifies without a heap block.
inline constexpr std::size_t bsp_split_inline = 64;
/// Entries the dynamic tree's query stack holds before it spills to the heap: more than any
/// balanced tree needs. `bvhkit-bench dynamic`.
inline constexpr std::size_t dynamic_stack_inline = 256;

}  // namespace bvhkit::tuning
