// The encoder's side of connectivity coding, fine to coarse: the input
// complex on the decoder's vertex ids, then vertex merges in exactly the
// reverse of the decoder's split order, each recording the codes the
// decoder will need to undo it.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "kdmesh/kdmesh.h"
#include "simplex_store.h"

namespace kdmesh {

// A vertex split of the decoder: `kept` (the first half) keeps the id of the
// split vertex, `added` is the new id of the second half.
struct VertexSplitIds {
  uint32_t kept, added;
};

// What the input held and what was repaired on the way in.
struct InputSummary {
  std::array<uint32_t, 4> maximal{};  // kept simplices per dimension; [0] isolated vertices
  int maxDimension = 0;
  InputRepairs repairs;
};

// Fills `store` with the closure of the input's simplices, with vertex i of
// the input renamed ids[i]. Listed simplices are flagged kMeaningful (their
// orientation is data); faces added by the closure are not.
Status buildInputComplex(const Complex& complex, const std::vector<uint32_t>& ids,
                         SimplexStore& store, InputSummary& summary);

// Per split, in the decoder's order, one record byte per star entry of the
// split vertex (see split_record in vertex_split.h).
struct SplitRecords {
  std::vector<uint8_t> bytes;
  std::vector<uint64_t> begin;  // first byte of each split's records
};

// Merges the vertices of `splits` from the last split to the first.
void decimate(SimplexStore& store, const std::vector<VertexSplitIds>& splits,
              SplitRecords& records, const std::function<void(double)>& progress);

}  // namespace kdmesh
