// Vertex attributes in the stream: the table that starts the body, and the
// coding of each new vertex's values.
//
// Every vertex of a prefix stands for one input vertex, the one that keeps
// its id down to the last level: the input vertex first in kd-tree order
// among those of its cell. When a cell splits into two non-empty halves,
// the first half keeps the vertex (and its values) and the second half's
// new vertex gets the values of its own first input vertex. A prefix
// therefore shows every vertex with exact values, and the last level has
// every input vertex's. The new values are predicted by the mean of the new
// vertex's neighbours in the complex (after its split), or by its parent's
// without neighbours (point clouds), and coded component by component as
// differences modulo 2^(8 · bytes) on the values' bits (float32 bits first
// mapped to integers in the order of their values, so that close values
// have close images): zero or not, sign, bit length in unary, the two bits
// after the leading one with adaptive models, the rest uniformly. A
// component's models are chosen by the bit length of the previous
// component's difference (colour channels, the axes of a normal, move
// together) and by how far the neighbours' values spread.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "container.h"
#include "kdmesh/kdmesh.h"
#include "range_coder.h"

namespace kdmesh {

// Whether the complex's attributes can be encoded: at most kMaxAttributes,
// names of 1..kMaxAttributeNameBytes printable ASCII characters without
// repeats, 1..4 components of a known type, one value per vertex.
Status checkAttributes(const Complex& complex);

// The attribute table: per attribute its type, components, name and the
// root vertex's values (of input vertex `root`), then a CRC-32 of the table.
void writeAttributeTable(const std::vector<VertexAttribute>& attributes, uint32_t root, std::vector<uint8_t>& out);
// Reads a table of `count` attributes from in[0..available) into `out`:
// their descriptors, each with one vertex's values (the root's). Incomplete
// (and `out` untouched) until the whole table is there; Malformed (with
// `error`) on a bad table.
Parsed readAttributeTable(const uint8_t* in, size_t available, uint8_t count, std::vector<VertexAttribute>& out,
                          size_t& size, Status& error);

class AttributeCoder {
 public:
  explicit AttributeCoder(const std::vector<VertexAttribute>& attributes);

  // A new vertex's values of one attribute predicted: `values`, the
  // rounded mean of its neighbours' (their images), or its parent's without
  // neighbours; `spread`, per component, the bit length of the range of the
  // neighbours' images (0 without neighbours), which says how far to trust
  // the mean.
  struct Prediction {
    uint8_t values[16];
    uint8_t spread[4];
  };
  // valuesOf(id) gives a vertex's values.
  template <class ValuesOf>
  void predict(size_t a, const std::vector<uint32_t>& neighbours, const uint8_t* parent, ValuesOf&& valuesOf,
               Prediction& out) const {
    const Layout& layout = layouts_[a];
    if (neighbours.empty()) {
      std::copy(parent, parent + layout.components * layout.bytes, out.values);
      std::fill(out.spread, out.spread + 4, uint8_t(0));
      return;
    }
    for (int c = 0; c < layout.components; ++c) {
      uint64_t sum = 0;
      uint32_t low = 0xffffffffu, high = 0;
      for (const uint32_t v : neighbours) {
        const uint32_t value = image(layout, valuesOf(v), c);
        sum += value;
        low = std::min(low, value);
        high = std::max(high, value);
      }
      store(layout, out.values, c, uint32_t((sum + neighbours.size() / 2) / neighbours.size()));
      out.spread[c] = uint8_t(bitLength(high - low));
    }
  }

  // Codes the values of one vertex of attribute `a` (encoder: `child`; the
  // decoder writes them there) against `prediction`.
  template <class Coder>
  void code(Coder& coder, size_t a, const Prediction& prediction, uint8_t* child) {
    const Layout& layout = layouts_[a];
    int previousLength = 0;
    for (int c = 0; c < layout.components; ++c) {
      const uint32_t from = image(layout, prediction.values, c);
      const uint32_t to = image(layout, child, c);  // the encoder's value; ignored by the decoder
      const size_t context = (size_t(c) * kLengthClasses + size_t(lengthClass(previousLength))) * kLengthClasses +
                             size_t(lengthClass(prediction.spread[c]));
      const uint32_t difference = codeDifference(coder, models_[layout.firstModels + context], layout.bits,
                                                 (to - from) & layout.mask, previousLength);
      store(layout, child, c, (from + difference) & layout.mask);
    }
  }

 private:
  struct Models {
    BitModel nonZero, sign;
    std::array<BitModel, 32> length;   // unary: longer than i + 1 bits?
    std::array<BitModel, 64> leading;  // the two bits after the leading one, by length
  };
  struct Layout {
    AttributeType type;
    int components, bytes, bits;
    uint32_t mask;
    size_t firstModels;
  };
  static constexpr int kLengthClasses = 4;
  static int lengthClass(int length) { return length == 0 ? 0 : length <= 2 ? 1 : length <= 5 ? 2 : 3; }
  // A value's bits as an unsigned integer, floats in value order.
  static uint32_t image(const Layout& layout, const uint8_t* values, int component);
  static void store(const Layout& layout, uint8_t* values, int component, uint32_t image);

  // Codes a `bits`-bit difference (two's complement); returns it and the
  // bit length of its magnitude in `length`.
  template <class Coder>
  static uint32_t codeDifference(Coder& coder, Models& m, int bits, uint32_t difference, int& length) {
    const uint32_t signBit = uint32_t(1) << (bits - 1);
    const bool negative = (difference & signBit) != 0;
    // The magnitude, 1..2^(bits-1): a negative difference's is its two's
    // complement.
    const uint64_t magnitude = negative ? (uint64_t(1) << bits) - difference : difference;
    if (!coder.bit(m.nonZero, magnitude != 0)) {
      length = 0;
      return 0;
    }
    const bool down = coder.bit(m.sign, negative);
    int n = 1;
    while (n < bits && coder.bit(m.length[size_t(n - 1)], n < bitLength(magnitude))) ++n;
    length = n;
    // The bits below the leading one: two modelled, the rest uniform.
    uint64_t value = 1;
    for (int i = n - 2; i >= 0; --i) {
      const bool bit = (magnitude >> i) & 1;
      if (i >= n - 3) {
        value = value << 1 | coder.bit(m.leading[size_t(2 * (n - 1) + (n - 2 - i))], bit);
      } else {
        const int take = std::min(i + 1, 16);
        const uint32_t chunk = uint32_t((magnitude >> (i + 1 - take)) & ((uint64_t(1) << take) - 1));
        value = value << take | coder.uniform(chunk, uint32_t(1) << take);
        i -= take - 1;
      }
    }
    if (value > signBit) value = signBit;  // a corrupt stream: keep the value in range
    return down ? uint32_t((uint64_t(1) << bits) - value) : uint32_t(value);
  }
  static int bitLength(uint64_t v) {
    int n = 0;
    for (; v != 0; v >>= 1) ++n;
    return n;
  }

  std::vector<Layout> layouts_;
  std::vector<Models> models_;
};

}  // namespace kdmesh
