// Checks HMQ's blocks (hmq_format.hpp) as loaded from a world file, before any ray decodes
// them: tree_check.hpp says why. Every slot, forward offset and leaf record a traversal can
// reach from the top leaves is followed once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/section_archive.hpp"

namespace wavetrace::hmq {

// Fails `in` (naming "hmq.blocks") unless: each block's header and tables lie inside the
// array with node_slots >= 1 and node_slots + forward_slots <= 64; an inner node's children
// are later slots of its block, or the first two slots of a later block; the treelets are
// shallower than the traversal's stack; a leaf names one of its block's records, whose
// strip table entry exists, whose streams end inside the array, whose vertex slots name
// decoded vertices, whose triangle ids are below `triangles` and whose corner codes name two
// different corners.
void check_blocks(std::span<const BvhNode> top, std::span<const std::byte> blocks, std::size_t triangles,
                  const SectionLoader& in);

// The leaf record at byte `offset` of `records` (the 8-wide layout's leaf array), checked as
// check_blocks checks the records of blocks; fails naming `section`.
void check_leaf_record(std::span<const std::byte> records, std::uint64_t offset, std::size_t triangles,
                       const SectionLoader& in, std::string_view section);

}  // namespace wavetrace::hmq
