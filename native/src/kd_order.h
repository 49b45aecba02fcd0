// The kd-tree order of the vertices: every cell of every level is one
// contiguous range of it.
#pragma once

#include <cstdint>
#include <vector>

#include "split_schedule.h"

namespace kdmesh {

__extension__ typedef unsigned __int128 KdKey;

// A vertex's key lists, from the most significant of its `schedule.levels`
// low bits, the side it takes at every split; sorting by key therefore sorts
// by kd-tree cell at every level at once.
struct KdOrder {
  std::vector<KdKey> keys;         // ascending
  std::vector<uint32_t> vertices;  // vertices[i] has keys[i]
};

// `coords` holds 3 integer coordinates per vertex. Equal keys (coincident
// vertices) keep their input order, so the result is deterministic.
KdOrder kdOrder(const std::vector<uint32_t>& coords, const SplitSchedule& schedule);

}  // namespace kdmesh
