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
#include "large_array.h"
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
  // The sorted distinct labels of the kept simplices; empty without labels.
  std::vector<int32_t> labelTable;
};

// For each of the tuples of `arity` distinct vertex ids below `vertexCount`
// (tuple i at tuples[i * arity]), the index of the first tuple with the same
// vertex set: i itself for the first. Linear in the tuples but for sorting
// those that share their least vertex.
LargeArray<uint32_t> firstWithSameVertices(const LargeArray<uint32_t>& tuples, int arity, uint32_t vertexCount);

// Fills `store` with the closure of the input's simplices, with vertex i of
// the input renamed ids[i]. Listed simplices are flagged kMeaningful (their
// orientation is data); faces added by the closure are not. With labels,
// listed simplices get the index of theirs in summary.labelTable, faces
// added by the closure kNoLabel. kdRank[id]: the rank of vertex `id` in the
// kd-tree's order, which lays the pools out cell by cell.
Status buildInputComplex(const Complex& complex, const std::vector<uint32_t>& ids,
                         const std::vector<uint32_t>& kdRank, SimplexStore& store, InputSummary& summary);

// Per split, in the decoder's order, one record byte per star entry of the
// split vertex (see split_record in vertex_split.h).
// With labels, also the label (table index, or kNoLabel: any) of every
// simplex the split creates, in the order the splitter decides them: for
// each star entry in canonical order, its copy's, then its added simplex's
// (the vertex entry's added simplex is the edge v1 v2).
struct SplitRecords {
  std::vector<uint8_t> bytes;
  std::vector<uint64_t> begin;  // first byte of each split's records
  std::vector<uint32_t> labels;
  std::vector<uint64_t> labelBegin;  // first label of each split's
};

// Merges the vertices of `splits` from the last split to the first.
void decimate(SimplexStore& store, const std::vector<VertexSplitIds>& splits,
              SplitRecords& records, const std::function<void(double)>& progress);

}  // namespace kdmesh
