// Simplex labels in the stream: the label table that follows the attribute
// table, and the coding of each new simplex's label at the vertex split
// that creates it.
//
// Labels are coded as indices into the table (the sorted distinct labels).
// A split creates simplices by codes 3 and 4 (the copy of a star simplex,
// and the simplex one dimension up on it); each new simplex gets one
// adaptive bit "same label as its parent" (the star simplex it comes from;
// for the vertex's new edge, the star's first edge), with models by its
// dimension, by copy or added, and by whether the split vertex's star held
// simplices of that dimension with different labels; if not, one bit
// "the star's other label" when the star has one; and otherwise its index
// in the table by a bit tree of adaptive models over the index's leading
// bits, the rest at probability 1/2. A table of one label codes nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "container.h"
#include "kdmesh/kdmesh.h"
#include "range_coder.h"
#include "simplex_store.h"

namespace kdmesh {

// Whether the complex's labels can be encoded: each label vector empty or
// of its list's simplex count, and none on a complex without simplices.
Status checkLabels(const Complex& complex);
// The sorted distinct labels of the complex, with 0 when a list with
// simplices has no labels but another list has; empty without labels.
std::vector<int32_t> labelTable(const Complex& complex);
// The label of simplex i of dimension d, by the rule of labelTable().
inline int32_t labelOf(const Complex& complex, int d, size_t i) {
  const std::vector<int32_t>& labels = complex.labels.of(d);
  return labels.empty() ? 0 : labels[i];
}

// The table: its count, the first label as a zigzag varint, each next one
// as its difference to the previous minus one (a varint), then a CRC-32 of
// those bytes.
void writeLabelTable(const std::vector<int32_t>& table, std::vector<uint8_t>& out);
// Reads a table of at most `maxCount` labels from in[0..available):
// Incomplete (and `out` untouched) until the whole table is there;
// Malformed (with a CorruptHeader `error`) on a bad one. Takes memory in
// proportion to the bytes read, whatever the count says.
Parsed readLabelTable(const uint8_t* in, size_t available, uint64_t maxCount, std::vector<int32_t>& out,
                      size_t& size, Status& error);

class LabelCoder {
 public:
  // Most significant bits of an index that get adaptive models.
  static constexpr int kTreeBits = 12;

  explicit LabelCoder(uint32_t tableSize);

  // Decides the label of a new simplex of `dimension` from its parent's
  // (kNoLabel: no parent); `mixed`: the split vertex's star held simplices
  // of that dimension with different labels; `other`: a label of the star
  // other than the parent's (kNoLabel: none), the likely one when the
  // parent's is not. On the encoder `recorded` is the label it must
  // get, or kNoLabel when any will do; the decoder ignores it. Returns the
  // label, or kNoLabel for an index outside the table (corrupt data).
  template <class Coder>
  uint32_t code(Coder& coder, int dimension, bool isCopy, bool mixed, uint32_t parent, uint32_t other,
                uint32_t recorded) {
    if (tableSize_ <= 1) return 0;
    const bool hasParent = parent != kNoLabel;
    const bool same = hasParent && (recorded == kNoLabel || recorded == parent);
    if (hasParent && coder.bit(sameModels_[dimension - 1][isCopy][mixed], same)) return parent;
    if (recorded == kNoLabel) recorded = other != kNoLabel ? other : 0;  // no parent, and any label will do
    if (other != kNoLabel && coder.bit(otherModels_[dimension - 1][isCopy], recorded == other)) return other;
    // Index bits, most significant first: a tree over the top ones.
    uint32_t index = 0, node = 1;
    for (int b = indexBits_ - 1; b >= indexBits_ - treeBits_; --b) {
      const bool bit = coder.bit(tree_[node], (recorded >> b) & 1);
      node = node << 1 | bit;
      index = index << 1 | bit;
    }
    const int low = indexBits_ - treeBits_;
    if (low > 0) index = index << low | coder.uniform(recorded & ((1u << low) - 1), 1u << low);
    return index < tableSize_ ? index : kNoLabel;
  }

 private:
  uint32_t tableSize_;
  int indexBits_ = 0;  // bit length of tableSize_ - 1
  int treeBits_ = 0;
  // [dimension - 1][copy or added][mixed star]
  BitModel sameModels_[3][2][2];
  // [dimension - 1][copy or added]
  BitModel otherModels_[3][2];
  std::vector<BitModel> tree_;  // node 1 is the root, node n's children 2n, 2n + 1
};

}  // namespace kdmesh
