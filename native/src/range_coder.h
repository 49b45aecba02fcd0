// Binary adaptive range coder.
//
// A carry-propagating range coder in the style of LZMA's: 32-bit range,
// 15-bit probabilities, byte-wise renormalisation. Both sides share one
// interface so that a modelling routine written once as a template serves the
// encoder and the decoder: `bit(model, value)` encodes `value` and returns it
// on the encoder, and ignores `value` and returns the decoded bit on the
// decoder; `uniform(value, count)` does the same for a value in [0, count).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace kdmesh {

constexpr int kProbabilityBits = 15;
constexpr uint32_t kProbabilityOne = 1u << kProbabilityBits;

// Adaptive estimate of P(bit == 0). Two estimators are averaged: a fast one
// that follows local changes and a slow one whose rate starts high and
// settles as observations accumulate, so that a context seen a few times
// learns quickly and a context seen often becomes precise.
struct BitModel {
  uint16_t fast = kProbabilityOne / 2;
  uint16_t slow = kProbabilityOne / 2;
  uint16_t seen = 0;

  uint32_t probabilityOfZero() const { return (uint32_t(fast) + slow) >> 1; }

  // Inlined always: GCC left it out of line in the encoder's kd-tree walk,
  // where it runs for nearly every coded bit.
  [[gnu::always_inline]] void update(bool bit) {
    // The slow rate by observations seen: 1/2 for the first eight, ...,
    // 1/128 from the 64th on.
    static constexpr uint8_t kSlowShift[9] = {1, 2, 3, 4, 5, 5, 6, 6, 7};
    const int slowShift = kSlowShift[std::min<int>(seen, 64) >> 3];
    seen = uint16_t(seen + (seen < 0xffff));
    // Keep the slow estimate away from 0 and 1 so every symbol stays
    // codable; a step towards one bound cannot cross the other. Both steps
    // are computed and one kept: the bit is a coin toss for a branch.
    const uint16_t fastIfOne = uint16_t(fast - (fast >> 4));
    const uint16_t fastIfZero = uint16_t(fast + ((kProbabilityOne - fast) >> 4));
    const uint16_t slowIfOne = uint16_t(std::max<int>(slow - (slow >> slowShift), 31));
    const uint16_t slowIfZero =
        uint16_t(std::min<int>(slow + ((kProbabilityOne - slow) >> slowShift), kProbabilityOne - 31));
    fast = bit ? fastIfOne : fastIfZero;
    slow = bit ? slowIfOne : slowIfZero;
  }
};

// -log2(p) for a probability in units of 1/kProbabilityOne, tabulated with
// 12-bit resolution; used to account the information content of the stream.
class CostTable {
 public:
  static double bits(uint32_t probability) {
    static const CostTable table;
    return table.bits_[probability >> (kProbabilityBits - kCostBits)];
  }

 private:
  static constexpr int kCostBits = 12;
  CostTable() {
    for (uint32_t i = 0; i < (1u << kCostBits); ++i)
      bits_[i] = -std::log2((i + 0.5) / double(1u << kCostBits));
  }
  double bits_[1u << kCostBits];
};

class RangeEncoder {
 public:
  explicit RangeEncoder(std::vector<uint8_t>& out) : out_(out) {}

  bool bit(BitModel& model, bool value) {
    bitWithProbability(model.probabilityOfZero(), value);
    model.update(value);
    return value;
  }

  // A bit with P(0) = p0 / 2^15 from elsewhere (a mixer); no model update.
  bool bitWithProbability(uint32_t p0, bool value) {
    const uint32_t bound = (range_ >> kProbabilityBits) * p0;
    if (measuring_) cost_ += CostTable::bits(value ? kProbabilityOne - p0 : p0);
    if (value) {
      low_ += bound;
      range_ -= bound;
    } else {
      range_ = bound;
    }
    normalize();
    return value;
  }

  // Equiprobable value in [0, count), count >= 1.
  uint32_t uniform(uint32_t value, uint32_t count) {
    if (count > kMaxUniformCount) {
      const uint32_t highCount = ((count - 1) >> 16) + 1;
      const uint32_t high = value >> 16;
      uniformSmall(high, highCount);
      uniformSmall(value & 0xffff, high + 1 == highCount ? count - (high << 16) : 0x10000);
      return value;
    }
    uniformSmall(value, count);
    return value;
  }

  // Ends the block: writes the fewest bytes that identify a value inside the
  // final interval, given that the decoder reads zeros past the end.
  void finish() {
    const uint64_t high = low_ + range_ - 1;
    for (int shift = 32; shift >= 0; --shift) {
      const uint64_t mask = (uint64_t(1) << shift) - 1;
      const uint64_t rounded = (low_ + mask) & ~mask;
      if (rounded <= high) {
        low_ = rounded;
        break;
      }
    }
    for (int i = 0; i < 5; ++i) shiftLow();
    while (out_.size() > start_ && out_.back() == 0) out_.pop_back();
  }

  // Starts a new block at the current end of the output.
  void restart() {
    low_ = 0;
    range_ = 0xffffffffu;
    cache_ = 0;
    started_ = false;
    pendingBytes_ = 0;
    start_ = out_.size();
  }

  size_t blockBytes() const { return out_.size() - start_ + pendingBytes_; }
  void setMeasuring(bool on) { measuring_ = on; }
  double cost() const { return cost_; }
  void resetCost() { cost_ = 0; }

 private:
  static constexpr uint32_t kMaxUniformCount = 0x10000;
  static constexpr uint32_t kTop = 1u << 24;

  void uniformSmall(uint32_t value, uint32_t count) {
    if (measuring_) cost_ += std::log2(double(count));
    range_ /= count;
    low_ += uint64_t(range_) * value;
    normalize();
  }

  void normalize() {
    while (range_ < kTop) {
      range_ <<= 8;
      shiftLow();
    }
  }

  // Moves the top byte of `low_` towards the output. Bytes of 0xff are held
  // back (counted in pendingBytes_) until a carry is ruled in or out. The
  // very first byte of a block is always 0 and is never written.
  void shiftLow() {
    if (uint32_t(low_) < 0xff000000u || (low_ >> 32) != 0) {
      const uint8_t carry = uint8_t(low_ >> 32);
      if (started_) out_.push_back(uint8_t(cache_ + carry));
      for (; pendingBytes_ > 0; --pendingBytes_) out_.push_back(uint8_t(0xff + carry));
      cache_ = uint8_t(low_ >> 24);
      started_ = true;
    } else {
      ++pendingBytes_;
    }
    low_ = (low_ & 0x00ffffffu) << 8;
  }

  std::vector<uint8_t>& out_;
  size_t start_ = 0;
  uint64_t low_ = 0;
  uint32_t range_ = 0xffffffffu;
  uint8_t cache_ = 0;
  bool started_ = false;
  uint64_t pendingBytes_ = 0;
  bool measuring_ = false;
  double cost_ = 0;
};

class RangeDecoder {
 public:
  void start(const uint8_t* data, size_t size) {
    next_ = data;
    end_ = data + size;
    range_ = 0xffffffffu;
    code_ = 0;
    invalid_ = false;
    for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | nextByte();
  }

  // Inlined always, as every decision of the decoder passes here: clang
  // (the WebAssembly build) left these calls out of line.
  [[gnu::always_inline]] bool bit(BitModel& model, bool /*unused*/ = false) {
    const bool value = bitWithProbability(model.probabilityOfZero());
    model.update(value);
    return value;
  }

  [[gnu::always_inline]] bool bitWithProbability(uint32_t p0, bool /*unused*/ = false) {
    const uint32_t bound = (range_ >> kProbabilityBits) * p0;
    // A 1 takes [bound, range) and moves the code down by bound, a 0 keeps
    // [0, bound); written as selects, as the bit is hard to predict.
    const bool value = code_ >= bound;
    code_ -= value ? bound : 0u;
    range_ = value ? range_ - bound : bound;
    if (measuring_) cost_ += CostTable::bits(value ? kProbabilityOne - p0 : p0);
    normalize();
    return value;
  }

  uint32_t uniform(uint32_t /*unused*/, uint32_t count) {
    if (count > kMaxUniformCount) {
      const uint32_t highCount = ((count - 1) >> 16) + 1;
      const uint32_t high = uniformSmall(highCount);
      return (high << 16) | uniformSmall(high + 1 == highCount ? count - (high << 16) : 0x10000);
    }
    return uniformSmall(count);
  }

  // True once a value decoded outside its range: the data is corrupt.
  bool invalid() const { return invalid_; }
  // Bytes read beyond the end of the block (the encoder trims trailing zeros,
  // so a few are normal).
  size_t bytesPastEnd() const { return pastEnd_; }
  void setMeasuring(bool on) { measuring_ = on; }
  double cost() const { return cost_; }
  void resetCost() { cost_ = 0; }

 private:
  static constexpr uint32_t kMaxUniformCount = 0x10000;
  static constexpr uint32_t kTop = 1u << 24;

  uint32_t uniformSmall(uint32_t count) {
    if (measuring_) cost_ += std::log2(double(count));
    range_ /= count;
    uint32_t value = code_ / range_;
    if (value >= count) {
      invalid_ = true;
      value = count - 1;
    }
    code_ -= range_ * value;
    normalize();
    return value;
  }

  uint8_t nextByte() {
    if (next_ < end_) return *next_++;
    ++pastEnd_;
    return 0;
  }

  void normalize() {
    while (range_ < kTop) {
      range_ <<= 8;
      code_ = (code_ << 8) | nextByte();
    }
  }

  const uint8_t* next_ = nullptr;
  const uint8_t* end_ = nullptr;
  uint32_t range_ = 0xffffffffu;
  uint32_t code_ = 0;
  size_t pastEnd_ = 0;
  bool invalid_ = false;
  bool measuring_ = false;
  double cost_ = 0;
};

}  // namespace kdmesh
