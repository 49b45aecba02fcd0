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
//
// Quantized float attributes (AttributeQuantization) are coded the same
// way on their quantized values, the images: the decoder keeps the float32
// values they stand for, and the mapping back from those floats to the
// images is exact (docs/FORMAT.md), so encoder and decoder predict from
// the same images.
//
// Geometric octahedral attributes (a surface's normals) wait until the
// kd-tree is complete: then each vertex's values are coded, vertex by
// vertex, against the normal of its triangles in the final complex,
// corrected by that normal's error at its neighbours already decoded.
// Normals made from the surface are predicted far better so than by
// coarse neighbours at the vertex's creation; a prefix shows the normals
// of its own triangles meanwhile.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "container.h"
#include "kdmesh/kdmesh.h"
#include "range_coder.h"
#include "simplex_store.h"

namespace kdmesh {

inline bool isOctahedral(AttributeQuantization::Kind kind) {
  return kind == AttributeQuantization::Octahedral || kind == AttributeQuantization::GeometricOctahedral;
}

// Whether the complex's attributes can be encoded: at most kMaxAttributes,
// names of 1..kMaxAttributeNameBytes printable ASCII characters without
// repeats, 1..4 components of a known type, one value per vertex.
Status checkAttributes(const Complex& complex);

// How the encoder codes each attribute under `options` (attributeBits,
// normalBits): in `out`, one per attribute. InvalidArgument for bits out
// of range, InvalidInput for non-finite values to quantize.
Status chooseQuantization(const Complex& complex, const EncodeOptions& options,
                          std::vector<AttributeQuantization>& out);

// The attribute table: per attribute its type, components, name, coding
// (`quantization`, one per attribute) and the root vertex's values (of
// input vertex `root`, as the decoder will hold them), then a CRC-32 of
// the table.
void writeAttributeTable(const std::vector<VertexAttribute>& attributes,
                         const std::vector<AttributeQuantization>& quantization, uint32_t root,
                         std::vector<uint8_t>& out);
// Reads a table of `count` attributes from in[0..available) into `out`:
// their descriptors, each with one vertex's values (the root's). Incomplete
// (and `out` untouched) until the whole table is there; Malformed (with
// `error`) on a bad table.
Parsed readAttributeTable(const uint8_t* in, size_t available, uint8_t count, std::vector<VertexAttribute>& out,
                          size_t& size, Status& error);

// The values of quantized attributes as a decoder holds them, the values
// their images stand for, one vector per attribute (empty for exact ones,
// whose values are held as they are). The encoder predicts from these, as
// the decoder does.
std::vector<std::vector<uint8_t>> heldValues(const std::vector<VertexAttribute>& attributes,
                                             const std::vector<AttributeQuantization>& quantization);

// For each vertex, over `positions` (3 floats per vertex), the unit normal
// of its triangles in `store` (the sum S of their oriented area vectors
// over its length; zero without triangles) and how far they agree on it
// (|S| over the sum of the vectors' lengths; 0 without triangles): 4
// doubles per vertex in `out`, what geometric octahedral predictions start
// from. Each vertex walks its own incidence list (docs/FORMAT.md), so
// encoder and decoder, which hold the same store, add in the same order and
// agree to the bit.
void triangleNormals(const SimplexStore& store, const std::vector<float>& positions, std::vector<double>& out);

// The other ends of `vertex`'s edges in `store` with lower ids (whose
// values after the kd-tree come first), in edge list order, in `out`.
void earlierNeighbours(const SimplexStore& store, uint32_t vertex, std::vector<uint32_t>& out);

class AttributeCoder {
 public:
  // Codes the attributes as `quantization` says (one per attribute), or
  // without it as each attribute's own field says (the decoder's table).
  explicit AttributeCoder(const std::vector<VertexAttribute>& attributes,
                          const std::vector<AttributeQuantization>* quantization = nullptr);

  // A new vertex's values of one attribute predicted, as images: `images`,
  // the rounded mean of its neighbours' (octahedral normals: the image of
  // the sum of their normals), or its parent's without neighbours;
  // `spread`, per coded component, the bit length of the range of the
  // neighbours' images (0 without neighbours), which says how far to trust
  // the mean.
  struct Prediction {
    uint32_t images[4];
    uint8_t spread[4];
  };
  // valuesOf(id) gives a vertex's values as the decoder holds them
  // (heldValues()), and so does `parent`.
  template <class ValuesOf>
  void predict(size_t a, const std::vector<uint32_t>& neighbours, const uint8_t* parent, ValuesOf&& valuesOf,
               Prediction& out) const {
    const Layout& layout = layouts_[a];
    if (neighbours.empty()) {
      images(layout, parent, out.images);
      std::fill(out.spread, out.spread + 4, uint8_t(0));
      return;
    }
    const bool octahedral = isOctahedral(layout.kind);
    uint64_t sum[4] = {0, 0, 0, 0};
    uint32_t low[4] = {0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}, high[4] = {0, 0, 0, 0};
    // Octahedral: the range of the images in the mirror image too (code()
    // takes the images there when the prediction lies in the lower
    // hemisphere).
    uint32_t mirroredLow[2] = {0xffffffffu, 0xffffffffu}, mirroredHigh[2] = {0, 0};
    double direction[3] = {0, 0, 0};
    for (const uint32_t v : neighbours) {
      const uint8_t* values = valuesOf(v);
      uint32_t image[4];
      images(layout, values, image);
      for (int c = 0; c < layout.components; ++c) {
        sum[c] += image[c];
        low[c] = std::min(low[c], image[c]);
        high[c] = std::max(high[c], image[c]);
      }
      if (octahedral) {
        addNormal(values, direction);  // held values: the normal the image stands for
        mirrorOctahedral(layout, image);
        for (int c = 0; c < 2; ++c) {
          mirroredLow[c] = std::min(mirroredLow[c], image[c]);
          mirroredHigh[c] = std::max(mirroredHigh[c], image[c]);
        }
      }
    }
    for (int c = 0; c < layout.components; ++c) {
      out.images[c] = uint32_t((sum[c] + neighbours.size() / 2) / neighbours.size());
      out.spread[c] = uint8_t(bitLength(high[c] - low[c]));
    }
    if (octahedral) {
      octahedralImages(layout, direction, out.images);
      if (lowerHemisphere(layout, out.images))
        for (int c = 0; c < 2; ++c) out.spread[c] = uint8_t(bitLength(mirroredHigh[c] - mirroredLow[c]));
    }
  }

  // A geometric octahedral attribute's prediction for `vertex` from
  // triangleNormals() (4 per vertex): the unit normal of its triangles
  // (none give +z), moved by kNeighbourErrorShare of the mean error of that
  // normal at its neighbours whose values are known (`decoded`: their held
  // values by valuesOf(id)), since the quantization of the positions tilts
  // nearby normals alike; trusted as far as its triangles agree.
  template <class ValuesOf>
  void predictFromTriangles(size_t a, const std::vector<double>& normals, uint32_t vertex,
                            const std::vector<uint32_t>& decoded, ValuesOf&& valuesOf, Prediction& out) const {
    const double* own = &normals[size_t(vertex) * 4];
    double direction[3] = {own[0], own[1], own[2]};
    if (!decoded.empty()) {
      double error[3] = {0, 0, 0};
      for (const uint32_t n : decoded) {
        const double* predicted = &normals[size_t(n) * 4];
        const uint8_t* values = valuesOf(n);
        for (int c = 0; c < 3; ++c) {
          float held;
          std::memcpy(&held, values + 4 * c, 4);
          error[c] += double(held) - predicted[c];
        }
      }
      const double share = kNeighbourErrorShare / double(decoded.size());
      for (int c = 0; c < 3; ++c) direction[c] += share * error[c];
    }
    octahedralImages(layouts_[a], direction, out.images);
    std::fill(out.spread, out.spread + 4, agreementSpread(own[3]));
  }
  // Writes to `values` the normal of attribute `a` that `direction` stands
  // for, as a decoder holds it (the quantized unit vector).
  void holdDirection(size_t a, const double* direction, uint8_t* values) const;
  // Whether attribute `a` is coded after the kd-tree (GeometricOctahedral).
  bool codedAfterGeometry(size_t a) const { return layouts_[a].kind == AttributeQuantization::GeometricOctahedral; }

  // Codes the values of one vertex of attribute `a` (encoder: `child`; the
  // decoder writes them there) against `prediction`.
  template <class Coder>
  void code(Coder& coder, size_t a, const Prediction& prediction, uint8_t* child) {
    const Layout& layout = layouts_[a];
    uint32_t to[4], coded[4], predicted[4];
    images(layout, child, to);  // the encoder's values; ignored by the decoder
    std::copy(prediction.images, prediction.images + 4, predicted);
    // A normal predicted in the lower hemisphere is coded in the mirror
    // image (z negated), where the prediction lies in the diamond and its
    // neighbourhood away from the square's edges, across which the
    // octahedral map jumps.
    const bool mirrored = isOctahedral(layout.kind) && lowerHemisphere(layout, predicted);
    if (mirrored) {
      mirrorOctahedral(layout, predicted);
      mirrorOctahedral(layout, to);
    }
    int previousLength = 0;
    for (int c = 0; c < layout.components; ++c) {
      const uint32_t from = predicted[c];
      const size_t context = (size_t(c) * kLengthClasses + size_t(lengthClass(previousLength))) * kLengthClasses +
                             size_t(lengthClass(prediction.spread[c]));
      const uint32_t difference = codeDifference(coder, models_[layout.firstModels + context], layout.bits,
                                                 (to[c] - from) & layout.mask, previousLength);
      coded[c] = (from + difference) & layout.mask;
    }
    if (mirrored) mirrorOctahedral(layout, coded);
    store(layout, child, coded);
  }

  // How an attribute is coded: its coded components (2 for octahedral
  // normals), their width and the quantization's parameters.
  struct Layout {
    AttributeType type;
    int components, bytes, bits;
    uint32_t mask;
    size_t firstModels;
    AttributeQuantization::Kind kind;
    uint32_t top;  // the largest quantized value
    double minimum[4], step[4];
  };
  static Layout layoutOf(const VertexAttribute& attribute, const AttributeQuantization& quantization,
                         size_t firstModels);
  // A vertex's values as unsigned integers (images), one per coded
  // component: exact values' bits, floats in value order; quantized values
  // their quantization (clamped to its range).
  static void images(const Layout& layout, const uint8_t* values, uint32_t* out);
  // The values that images stand for (clamped to the quantization's range).
  static void store(const Layout& layout, uint8_t* values, const uint32_t* images);
  // Whether octahedral images lie outside the diamond (z < 0).
  static bool lowerHemisphere(const Layout& layout, const uint32_t* images);
  // Octahedral images of the mirror image (z negated): an involution on
  // canonical images, which it keeps canonical.
  static void mirrorOctahedral(const Layout& layout, uint32_t* images);

 private:
  struct Models {
    BitModel nonZero, sign;
    std::array<BitModel, 32> length;   // unary: longer than i + 1 bits?
    std::array<BitModel, 64> leading;  // the two bits after the leading one, by length
  };
  static constexpr int kLengthClasses = 4;
  static int lengthClass(int length) { return length == 0 ? 0 : length <= 2 ? 1 : length <= 5 ? 2 : 3; }
  static void addNormal(const uint8_t* values, double* sum);
  static constexpr double kNeighbourErrorShare = 0.375;
  // A spread (as lengthClass() reads it) for how far a vertex's triangles
  // agree on its normal (triangleNormals()).
  static uint8_t agreementSpread(double agreement) {
    return agreement >= 0.9 ? 0 : agreement >= 0.7 ? 1 : agreement >= 0.5 ? 3 : 6;
  }
  static void octahedralImages(const Layout& layout, const double* direction, uint32_t* out);

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
