#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "io/io_internal.h"

namespace kdmesh::io::detail {

// ---------------------------------------------------------------------------
// TextScanner
// ---------------------------------------------------------------------------

TextScanner::TextScanner(const uint8_t* data, size_t size, TextSyntax syntax)
    : begin_(reinterpret_cast<const char*>(data)),
      end_(begin_ + size),
      cursor_(begin_),
      lineEnd_(begin_),
      next_(begin_),
      syntax_(syntax) {
  // Editors on some systems start text files with a UTF-8 byte order mark.
  if (size >= 3 && std::memcmp(begin_, "\xEF\xBB\xBF", 3) == 0) cursor_ = lineEnd_ = next_ = begin_ + 3;
}

bool TextScanner::nextLine() {
  if (next_ == end_) {
    cursor_ = lineEnd_ = end_;
    return false;
  }
  cursor_ = next_;
  const void* newline = std::memchr(cursor_, '\n', end_ - cursor_);
  lineEnd_ = newline ? static_cast<const char*>(newline) : end_;
  next_ = newline ? lineEnd_ + 1 : end_;
  // A carriage return not followed by the newline ends the line by itself
  // (files written with CR line endings alone).
  if (const void* cr = std::memchr(cursor_, '\r', lineEnd_ - cursor_)) {
    const char* at = static_cast<const char*>(cr);
    if (at + 1 != lineEnd_) {
      lineEnd_ = at;
      next_ = at + 1;
    }
  }
  ++line_;
  return true;
}

bool TextScanner::nextContentLine() {
  while (nextLine()) {
    while (cursor_ < lineEnd_ && isSeparator(*cursor_)) ++cursor_;
    if (cursor_ < lineEnd_ && !(syntax_.hashComments && *cursor_ == '#')) {
      return true;
    }
  }
  return false;
}

bool TextScanner::nextToken(std::string_view& token) {
  while (cursor_ < lineEnd_ && isSeparator(*cursor_)) ++cursor_;
  if (cursor_ == lineEnd_ || (syntax_.hashComments && *cursor_ == '#')) {
    cursor_ = lineEnd_;
    return false;
  }
  const char* start = cursor_;
  while (cursor_ < lineEnd_ && !endsToken(*cursor_)) ++cursor_;
  token = std::string_view(start, cursor_ - start);
  return true;
}

bool TextScanner::nextTokenAcrossLines(std::string_view& token) {
  while (!nextToken(token)) {
    if (!nextLine()) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// Numbers
// ---------------------------------------------------------------------------

namespace {

// from_chars rejects the '+' that many writers put in front of numbers.
std::string_view withoutPlus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' &&
      token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// Power of ten of the leading digit of a decimal number in from_chars syntax,
// saturated far beyond float range.
int64_t decimalMagnitude(std::string_view number) {
  size_t i = number[0] == '-' ? 1 : 0;
  int64_t integerDigits = 0;
  for (; i < number.size() && isDigit(number[i]); ++i) {
    if (integerDigits > 0 || number[i] != '0') ++integerDigits;
  }
  int64_t fractionZeros = 0;
  if (i < number.size() && number[i] == '.') {
    bool significant = integerDigits > 0;
    for (++i; i < number.size() && isDigit(number[i]); ++i) {
      significant = significant || number[i] != '0';
      if (!significant) ++fractionZeros;
    }
  }
  int64_t magnitude =
      integerDigits > 0 ? integerDigits - 1 : -(fractionZeros + 1);
  if (i < number.size() && (number[i] == 'e' || number[i] == 'E')) {
    std::string_view exponentText = withoutPlus(number.substr(i + 1));
    int64_t exponent = 0;
    auto result = std::from_chars(
        exponentText.data(), exponentText.data() + exponentText.size(),
        exponent);
    if (result.ec == std::errc::result_out_of_range) {
      exponent = exponentText[0] == '-' ? -(int64_t{1} << 40)
                                        : (int64_t{1} << 40);
    }
    magnitude += exponent;
  }
  return magnitude;
}

// from_chars reports a value beyond the type's range without giving one;
// rounding to nearest takes it to infinity when too large and to zero when
// too small.
template <class Real>
Real roundOutOfRange(std::string_view number) {
  Real magnitude = decimalMagnitude(number) >= 0
                       ? std::numeric_limits<Real>::infinity()
                       : Real(0);
  return number[0] == '-' ? -magnitude : magnitude;
}

// A float or double, rounded once from the decimal text.
template <class Real>
bool parseReal(std::string_view token, Real& value) {
  token = withoutPlus(token);
  const char* end = token.data() + token.size();
  auto [stop, error] = std::from_chars(token.data(), end, value);
  if (stop != end) return false;
  if (error == std::errc::result_out_of_range) {
    value = roundOutOfRange<Real>(token);
    return true;
  }
  return error == std::errc();
}

// Whether the decimal `token`, whose float32 rounding is `rounded`, says
// more than the shortest decimal of `rounded` does. Up to 6 significant
// digits never do (float32 keeps 6 decimal digits), which spares the
// comparison for most files.
bool beyondFloat32(std::string_view token, float rounded) {
  int digits = 0;
  bool leading = true;
  for (const char c : token) {
    if (c == 'e' || c == 'E') break;
    if (!isDigit(c) || (leading && c == '0')) continue;
    leading = false;
    ++digits;
  }
  if (digits <= 6) return false;
  double value = 0, shortest = 0;
  char text[32];
  const auto printed = std::to_chars(text, text + sizeof text, rounded);
  parseReal(token, value);
  parseReal(std::string_view(text, size_t(printed.ptr - text)), shortest);
  return !(value == shortest) && !(std::isnan(value) && std::isnan(shortest));
}

}  // namespace

bool parseFloat(std::string_view token, float& value) { return parseReal(token, value); }
bool parseDouble(std::string_view token, double& value) { return parseReal(token, value); }

bool parseInteger(std::string_view token, int64_t& value) {
  token = withoutPlus(token);
  const char* end = token.data() + token.size();
  auto [stop, error] = std::from_chars(token.data(), end, value);
  return stop == end && error == std::errc();
}

bool parseCount(std::string_view token, uint64_t& value) {
  token = withoutPlus(token);
  const char* end = token.data() + token.size();
  auto [stop, error] = std::from_chars(token.data(), end, value);
  return stop == end && error == std::errc();
}

bool parseCoordinate(std::string_view token, float& value, std::vector<double>* exact, bool* beyondFloat) {
  if (!parseFloat(token, value)) return false;
  if (exact) {
    double precise = 0;
    parseDouble(token, precise);
    exact->push_back(precise);
  }
  if (beyondFloat && !*beyondFloat) *beyondFloat = beyondFloat32(token, value);
  return true;
}

Status readPositionLine(TextScanner& scanner, std::vector<float>& positions,
                        bool& extraColumns, std::vector<double>* exact, bool* beyondFloat) {
  float xyz[3];
  std::string_view token;
  for (int axis = 0; axis < 3; ++axis) {
    if (!scanner.nextToken(token)) {
      return lineError(scanner.lineNumber(),
                       "vertex has " + std::to_string(axis) +
                           " coordinates, needs 3");
    }
    if (!parseCoordinate(token, xyz[axis], exact, beyondFloat)) {
      return lineError(scanner.lineNumber(),
                       quoted(token) + " is not a number");
    }
  }
  positions.insert(positions.end(), xyz, xyz + 3);
  extraColumns = scanner.nextToken(token);
  return Status::success();
}

void settleDoubles(Complex& out, bool beyondFloat, bool keepDoubles, Notes& notes) {
  if (beyondFloat && keepDoubles) {
    for (size_t i = 0; i < out.positions.size(); ++i) out.positions[i] = static_cast<float>(out.positions64[i]);
  } else {
    out.positions64.clear();
  }
  if (beyondFloat && !keepDoubles)
    notes.push_back("coordinates with more digits than float32 holds were rounded to float32 (exact encoding keeps them)");
}

std::string quoted(std::string_view token) {
  constexpr size_t kMaxShown = 40;
  // A file's bytes go to a terminal: anything but printable ASCII is shown
  // as \xHH, so no escape sequence or control character gets through.
  std::string shown = "'";
  for (const char c : token.substr(0, kMaxShown)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f && byte != '\\') {
      shown += c;
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      shown += {'\\', 'x', kHex[byte >> 4], kHex[byte & 15]};
    }
  }
  return shown + (token.size() > kMaxShown ? "...'" : "'");
}

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

Status inputError(std::string message) {
  return Status::error(ErrorCode::InvalidInput, std::move(message));
}

Status lineError(size_t line, const std::string& message) {
  return inputError("line " + std::to_string(line) + ": " + message);
}

bool takeFromBudget(uint64_t count, uint64_t minBytesEach, uint64_t& budget) {
  if (minBytesEach == 0) return true;
  if (count > budget / minBytesEach) return false;
  budget -= count * minBytesEach;
  return true;
}

// ---------------------------------------------------------------------------
// Attribute values
// ---------------------------------------------------------------------------

namespace {

// The range of an integer type's values.
void integerRange(AttributeType type, int64_t& low, int64_t& high) {
  switch (type) {
    case AttributeType::UInt8: low = 0, high = 0xff; break;
    case AttributeType::Int8: low = -0x80, high = 0x7f; break;
    case AttributeType::UInt16: low = 0, high = 0xffff; break;
    case AttributeType::Int16: low = -0x8000, high = 0x7fff; break;
    case AttributeType::UInt32: low = 0, high = 0xffffffffll; break;
    default: low = -0x80000000ll, high = 0x7fffffffll; break;
  }
}

}  // namespace

bool parseAttributeValue(std::string_view token, AttributeType type, uint8_t* out) {
  if (type == AttributeType::Float32) {
    float value;
    if (!parseFloat(token, value)) return false;
    std::memcpy(out, &value, 4);
    return true;
  }
  int64_t value, low, high;
  integerRange(type, low, high);
  if (!parseInteger(token, value) || value < low || value > high) return false;
  const uint32_t bits = static_cast<uint32_t>(value);
  std::memcpy(out, &bits, attributeTypeBytes(type));  // little-endian, as every target
  return true;
}

bool narrowestIntegerType(const std::vector<int64_t>& values, AttributeType& type) {
  int64_t least = 0, most = 0;
  for (const int64_t v : values) least = std::min(least, v), most = std::max(most, v);
  for (const AttributeType t : {AttributeType::UInt8, AttributeType::Int8, AttributeType::UInt16,
                                AttributeType::Int16, AttributeType::UInt32, AttributeType::Int32}) {
    int64_t low, high;
    integerRange(t, low, high);
    if (least >= low && most <= high) {
      type = t;
      return true;
    }
  }
  return false;
}

VertexAttribute integerAttribute(std::string name, AttributeType type, const std::vector<int64_t>& values) {
  VertexAttribute a{std::move(name), type, 1, {}, {}};
  const size_t bytes = attributeTypeBytes(type);
  a.values.resize(values.size() * bytes);
  for (size_t i = 0; i < values.size(); ++i) {
    const uint32_t bits = static_cast<uint32_t>(values[i]);
    std::memcpy(&a.values[i * bytes], &bits, bytes);
  }
  return a;
}

const VertexAttribute* findAttribute(const Complex& complex, std::string_view name) {
  for (const VertexAttribute& a : complex.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

// ---------------------------------------------------------------------------
// Polygons and notes
// ---------------------------------------------------------------------------

void PolygonSplit::append(const uint32_t* polygon, size_t size,
                          std::vector<uint32_t>& out) {
  for (size_t i = 1; i + 1 < size; ++i) {
    out.insert(out.end(), {polygon[0], polygon[i], polygon[i + 1]});
  }
  if (size > 3) {
    ++polygons;
    triangles += size - 2;
  }
}

void PolygonSplit::addNote(Notes& notes) const {
  if (polygons == 0) return;
  notes.push_back("split " + counted(polygons, "polygon", "polygons") +
                  " with more than 3 vertices into " +
                  counted(triangles, "triangle", "triangles"));
}

std::string counted(uint64_t count, std::string_view one, std::string_view many) {
  return std::to_string(count) + " " + std::string(count == 1 ? one : many);
}

void addCountNote(Notes& notes, std::string_view before, uint64_t count,
                  std::string_view one, std::string_view many,
                  std::string_view after) {
  if (count == 0) return;
  notes.push_back(std::string(before) + counted(count, one, many) + std::string(after));
}

// ---------------------------------------------------------------------------
// TextOut
// ---------------------------------------------------------------------------

void TextOut::separate() {
  if (!lineStart_) out_.push_back(' ');
  lineStart_ = false;
}

TextOut& TextOut::word(std::string_view text) {
  separate();
  out_.insert(out_.end(), text.begin(), text.end());
  return *this;
}

TextOut& TextOut::real(float value) {
  char buffer[32];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return word(std::string_view(buffer, result.ptr - buffer));
}

TextOut& TextOut::real(double value) {
  char buffer[40];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return word(std::string_view(buffer, result.ptr - buffer));
}

TextOut& TextOut::point(const Complex& complex, size_t vertex) {
  if (complex.positions64.empty()) {
    const float* xyz = &complex.positions[3 * vertex];
    return real(xyz[0]).real(xyz[1]).real(xyz[2]);
  }
  const double* xyz = &complex.positions64[3 * vertex];
  return real(xyz[0]).real(xyz[1]).real(xyz[2]);
}

TextOut& TextOut::integer(uint64_t value) {
  char buffer[24];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return word(std::string_view(buffer, result.ptr - buffer));
}

TextOut& TextOut::signedInteger(int64_t value) {
  char buffer[24];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return word(std::string_view(buffer, result.ptr - buffer));
}

TextOut& TextOut::value(AttributeType type, const uint8_t* bytes) {
  uint32_t bits = 0;
  std::memcpy(&bits, bytes, attributeTypeBytes(type));  // little-endian, as every target
  switch (type) {
    case AttributeType::Float32: {
      float f;
      std::memcpy(&f, &bits, 4);
      return real(f);
    }
    case AttributeType::Int8: return signedInteger(int8_t(bits));
    case AttributeType::Int16: return signedInteger(int16_t(bits));
    case AttributeType::Int32: return signedInteger(int32_t(bits));
    default: return integer(bits);
  }
}

TextOut& TextOut::endLine() {
  out_.push_back('\n');
  lineStart_ = true;
  return *this;
}

}  // namespace kdmesh::io::detail
