#include "labels.h"

#include <algorithm>
#include <limits>
#include <string>

#include "crc32.h"

namespace kdmesh {
namespace {

const char* const kListName[4] = {"", "edge", "triangle", "tetrahedron"};

}  // namespace

Status checkLabels(const Complex& complex) {
  for (int d = 1; d <= 3; ++d) {
    const size_t labels = complex.labels.of(d).size(), simplices = complex.simplexCount(d);
    if (labels != 0 && labels != simplices)
      return Status::error(ErrorCode::InvalidInput, std::to_string(labels) + " " + kListName[d] + " labels for " +
                                                        std::to_string(simplices) + " " + kListName[d] +
                                                        (simplices == 1 ? "" : "s") + " (give one per " +
                                                        kListName[d] + " or none)");
  }
  return Status::success();
}

std::vector<int32_t> labelTable(const Complex& complex) {
  std::vector<int32_t> table;
  if (complex.labels.empty()) return table;
  for (int d = 1; d <= 3; ++d) {
    const std::vector<int32_t>& labels = complex.labels.of(d);
    if (labels.empty() && complex.simplexCount(d) > 0) table.push_back(0);
    table.insert(table.end(), labels.begin(), labels.end());
  }
  std::sort(table.begin(), table.end());
  table.erase(std::unique(table.begin(), table.end()), table.end());
  return table;
}

void writeLabelTable(const std::vector<int32_t>& table, std::vector<uint8_t>& out) {
  const size_t start = out.size();
  uint8_t bytes[10];
  auto put = [&](uint64_t value) { out.insert(out.end(), bytes, bytes + putVarint(bytes, value)); };
  put(table.size());
  for (size_t i = 0; i < table.size(); ++i) {
    if (i == 0) {
      const int64_t first = table[0];
      put(uint64_t(first) << 1 ^ uint64_t(first >> 63));  // zigzag
    } else {
      put(uint64_t(int64_t(table[i]) - table[i - 1] - 1));
    }
  }
  const uint32_t crc = crc32(out.data() + start, out.size() - start);
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(crc >> (8 * i)));
}

Parsed readLabelTable(const uint8_t* in, size_t available, uint64_t maxCount, std::vector<int32_t>& out,
                      size_t& size, Status& error) {
  auto malformed = [&error](const std::string& what) {
    error = Status::error(ErrorCode::CorruptHeader, "corrupt label table: " + what);
    return Parsed::Malformed;
  };
  const uint8_t* at = in;
  const uint8_t* const end = in + available;
  uint64_t count = 0;
  Parsed read = readVarint(at, end, 5, 0xffffffffu, count);
  if (read != Parsed::Complete) return read == Parsed::Incomplete ? read : malformed("bad label count");
  if (count == 0 || count > maxCount)
    return malformed(std::to_string(count) + " labels for " + std::to_string(maxCount) + " simplices");
  std::vector<int32_t> table;
  constexpr int64_t kLow = std::numeric_limits<int32_t>::min(), kHigh = std::numeric_limits<int32_t>::max();
  for (uint64_t i = 0; i < count; ++i) {
    uint64_t value = 0;
    read = readVarint(at, end, 5, 0xffffffffu, value);
    if (read != Parsed::Complete) return read == Parsed::Incomplete ? read : malformed("bad label");
    // Each label is at least one byte read: memory follows the bytes given.
    const int64_t label = i == 0 ? int64_t(value >> 1 ^ (0 - (value & 1))) : int64_t(table.back()) + 1 + int64_t(value);
    if (label < kLow || label > kHigh) return malformed("label out of the 32-bit range");
    table.push_back(int32_t(label));
  }
  const size_t checked = size_t(at - in);
  if (available - checked < 4) return Parsed::Incomplete;
  const uint32_t stored = uint32_t(at[0]) | uint32_t(at[1]) << 8 | uint32_t(at[2]) << 16 | uint32_t(at[3]) << 24;
  if (crc32(in, checked) != stored) return malformed("checksum mismatch");
  size = checked + 4;
  out = std::move(table);
  return Parsed::Complete;
}

LabelCoder::LabelCoder(uint32_t tableSize) : tableSize_(tableSize) {
  while (tableSize > 1 && (uint64_t(1) << indexBits_) < tableSize) ++indexBits_;
  treeBits_ = std::min(indexBits_, kTreeBits);
  tree_.resize(size_t(1) << treeBits_);
}

}  // namespace kdmesh
