// Pieces shared by the format readers and writers of kdmesh/io.h.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "kdmesh/io.h"

namespace kdmesh::io::detail {

// ---------------------------------------------------------------------------
// Input bytes
// ---------------------------------------------------------------------------

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// A run of bytes held in memory.
struct Bytes {
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// Bytes read front to back: from memory, or from a file in blocks, so that a
// binary body is read without holding the whole file.
class ByteStream {
 public:
  // The `size` bytes at `data`, which are bytes `offset` on of the input.
  ByteStream(const uint8_t* data, size_t size, uint64_t offset);
  // Bytes `offset` to `end` of `file`; a read error sets `*readError` to
  // errno and ends the stream early.
  ByteStream(std::FILE* file, uint64_t offset, uint64_t end, int* readError);
  // Moving keeps the block (and the pointers into it); a copy would not.
  ByteStream(ByteStream&&) = default;
  ByteStream(const ByteStream&) = delete;
  ByteStream& operator=(const ByteStream&) = delete;

  // The next `count` bytes (at most kBlockBytes), or nullptr when fewer
  // remain.
  const uint8_t* take(size_t count);
  // Moves past `count` bytes; false when fewer remain.
  bool skip(uint64_t count);
  // Offset of the next byte in the input, for messages.
  uint64_t offset() const {
    return windowOffset_ + static_cast<uint64_t>(cursor_ - window_);
  }
  uint64_t remaining() const { return end_ - offset(); }

  static constexpr size_t kBlockBytes = size_t{1} << 20;

 private:
  bool refill(size_t count);

  std::FILE* file_ = nullptr;
  int* readError_ = nullptr;
  std::vector<uint8_t> buffer_;  // a file's current block
  const uint8_t* window_;        // the bytes held: [window_, limit_)
  const uint8_t* cursor_;
  const uint8_t* limit_;
  uint64_t windowOffset_;        // input offset of window_
  uint64_t end_;                 // input offset of the end
};

// What a reader reads: a buffer, or a file read as the reader asks, so that
// a binary format can be streamed and a file of the wrong kind refused on
// its first bytes.
class Input {
 public:
  static constexpr size_t kHeadBytes = size_t{1} << 16;

  Input(const uint8_t* data, size_t size);
  // Opens `path`; `missing` tells whether it failed because the file does
  // not exist.
  static Status open(const std::string& path, Input& input,
                     bool* missing = nullptr);
  Input() = default;
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  // The first kHeadBytes bytes, or all if fewer. The bytes that head() and
  // whole() give stay valid as long as the Input.
  Bytes head();
  // Whether head() holds every byte.
  bool headIsWhole();
  // Every byte; a file is read now, in one allocation when it is a regular
  // file (whose size is known).
  Bytes whole();
  // The size in bytes. A file that is not regular (a pipe) is read whole
  // first to learn it.
  uint64_t size();
  // The bytes from `offset` on; a regular file is read in blocks.
  ByteStream stream(uint64_t offset);
  // The error of a failed read from the file, or success.
  Status readError() const;

 private:
  FilePtr file_;
  std::string path_;
  bool sized_ = false;        // a regular file whose size_ is known
  uint64_t size_ = 0;
  std::vector<uint8_t> head_;
  bool haveHead_ = false;
  std::vector<uint8_t> all_;  // a file read whole
  Bytes whole_;               // valid once known
  bool haveWhole_ = false;
  int readError_ = 0;         // errno of a failed read
};

// "`action` `path`: " and the text of errno value `error`.
Status fileError(const char* action, const std::string& path, int error);

// ---------------------------------------------------------------------------
// Reading text
// ---------------------------------------------------------------------------

struct TextSyntax {
  bool commaSeparates = false;  // XYZ files are often CSV
  bool hashComments = false;    // '#' starts a comment that runs to line end
};

// Splits text into lines and whitespace-separated tokens without copying.
// Lines end in LF, CRLF or CR alone; '\r' also counts as whitespace.
class TextScanner {
 public:
  TextScanner(const uint8_t* data, size_t size, TextSyntax syntax = {});

  // Moves to the next line; false at the end of the input.
  bool nextLine();
  // Moves to the next line that holds a token, past blank and comment lines;
  // false at the end of the input.
  bool nextContentLine();
  // The next token of the current line; false when the line has no more.
  bool nextToken(std::string_view& token);
  // The next token, moving over line ends; false at the end of the input.
  bool nextTokenAcrossLines(std::string_view& token);

  size_t lineNumber() const { return line_; }
  // Byte offset at which the line after the current one starts.
  size_t nextLineOffset() const { return static_cast<size_t>(next_ - begin_); }
  size_t remainingBytes() const { return static_cast<size_t>(end_ - cursor_); }

 private:
  bool isSeparator(char c) const {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' ||
           (c == ',' && syntax_.commaSeparates);
  }
  bool endsToken(char c) const {
    return isSeparator(c) || (c == '#' && syntax_.hashComments);
  }

  const char* begin_;
  const char* end_;
  const char* cursor_;   // inside the current line
  const char* lineEnd_;  // the line ending of the current line, or end_
  const char* next_;     // start of the next line
  size_t line_ = 0;
  TextSyntax syntax_;
};

// Whole-token parsers: false unless every character of the token is used.
// Floats are rounded once, directly to float32; "nan" and "inf" are accepted
// because the encoder reports them with the offending vertex.
bool parseFloat(std::string_view token, float& value);
// The same rounded to double, for float64 coordinates (ReadOptions::keepDoubles).
bool parseDouble(std::string_view token, double& value);
bool parseInteger(std::string_view token, int64_t& value);
bool parseCount(std::string_view token, uint64_t& value);

// A decimal coordinate: its float32 rounding in `value`; with `exact`, its
// double appended there; with `beyondFloat`, set when the decimal says more
// than float32 holds (its double differs from the double of the shortest
// decimal of its float32 rounding: "0.1" is a float32 coordinate). False if
// the token is not a number.
bool parseCoordinate(std::string_view token, float& value, std::vector<double>* exact, bool* beyondFloat);
// Reads "x y z" from the rest of the current line onto `positions`. Returns
// in `extraColumns` whether more tokens follow (w, colours, normals), which
// the callers ignore with a note. With `exact`, also appends each
// coordinate's double there; `beyondFloat` as parseCoordinate().
Status readPositionLine(TextScanner& scanner, std::vector<float>& positions,
                        bool& extraColumns, std::vector<double>* exact = nullptr,
                        bool* beyondFloat = nullptr);
// After a text reader's last position line (read with `exact` =
// &out.positions64 when keeping doubles): keeps the doubles only when some
// coordinate needs them, so that a float32 file stays one, with positions
// their float32 roundings; without `keepDoubles`, notes the rounding.
void settleDoubles(Complex& out, bool beyondFloat, bool keepDoubles, Notes& notes);

// `what` for an error message: the token in quotes, shortened if long.
std::string quoted(std::string_view token);

// ASCII letters compared without regard to case (keywords of STL, Medit and
// VTK files are written in either).
bool equalsIgnoringCase(std::string_view a, std::string_view b);

Status inputError(std::string message);
Status lineError(size_t line, const std::string& message);

// Before reserving memory for `count` items declared by a file, checks that
// the unread bytes could hold them at `minBytesEach` apiece, and takes them
// from `budget` (the unread byte count, plus one for a missing final newline).
bool takeFromBudget(uint64_t count, uint64_t minBytesEach, uint64_t& budget);

// ---------------------------------------------------------------------------
// Attribute values in text (VTK, TetGen, Medit)
// ---------------------------------------------------------------------------

// Parses `token` as one value of `type` into `out` (its bytes in memory
// order): an integer must be whole and fit the type; a float is rounded to
// float32 (NaN and infinities included).
bool parseAttributeValue(std::string_view token, AttributeType type, uint8_t* out);

// The narrowest integer type that holds every one of `values`, unsigned
// before signed (uint8, int8, uint16, ...); false when no 32-bit type does.
bool narrowestIntegerType(const std::vector<int64_t>& values, AttributeType& type);

// A one-component attribute of `type` with `values`, which fit it.
VertexAttribute integerAttribute(std::string name, AttributeType type, const std::vector<int64_t>& values);

// The attribute of `complex` named `name`, or nullptr.
const VertexAttribute* findAttribute(const Complex& complex, std::string_view name);

// ---------------------------------------------------------------------------
// Polygons
// ---------------------------------------------------------------------------

// Counts polygons split into triangles so that one note can report them.
struct PolygonSplit {
  size_t polygons = 0;
  size_t triangles = 0;

  // Appends the polygon as a fan of triangles around its first vertex.
  void append(const uint32_t* polygon, size_t size,
              std::vector<uint32_t>& triangles);
  void addNote(Notes& notes) const;
};

// "1 triangle", "2 triangles": the count and the noun it agrees with.
std::string counted(uint64_t count, std::string_view one, std::string_view many);

// Adds the note `before` counted(count, one, many) `after` when count > 0,
// as in "ignored extra columns on " 12 " vertex line(s)" "".
void addCountNote(Notes& notes, std::string_view before, uint64_t count,
                  std::string_view one, std::string_view many,
                  std::string_view after = {});

// ---------------------------------------------------------------------------
// Writing text
// ---------------------------------------------------------------------------

// Appends space-separated fields and line ends to a byte buffer. Floats use
// the shortest decimal form that reads back to the same float32 bits,
// doubles the same for float64 bits (at most 17 significant digits).
class TextOut {
 public:
  explicit TextOut(std::vector<uint8_t>& out) : out_(out) {}

  TextOut& word(std::string_view text);
  TextOut& real(float value);
  TextOut& real(double value);
  // The coordinates of `vertex`: its doubles when the complex has
  // positions64, else its floats.
  TextOut& point(const Complex& complex, size_t vertex);
  TextOut& integer(uint64_t value);
  TextOut& signedInteger(int64_t value);
  // One attribute value of `type`, from its bytes in memory order.
  TextOut& value(AttributeType type, const uint8_t* bytes);
  TextOut& endLine();

 private:
  void separate();

  std::vector<uint8_t>& out_;
  bool lineStart_ = true;
};

// ---------------------------------------------------------------------------
// Formats
// ---------------------------------------------------------------------------

// Readers append to an empty `out`; readMemory clears it again on error.
// PLY streams a binary body from a file; its header may run past the first
// block of the input.
// With `keepDoubles` (ReadOptions), the PLY, OBJ, OFF, XYZ and Medit readers
// also fill out.positions64 when the file holds coordinates float32 does not
// (double properties, MeshVersionFormatted 2, decimals beyond float32),
// positions then being their float32 roundings; without, a note says they
// were rounded.
Status readPly(Input& input, Complex& out, Notes& notes, bool keepDoubles);
// The first line of a PLY or legacy VTK file, checked on the file's first
// bytes before the rest is read: a file of another kind is refused without
// reading all of it.
Status checkPlySignature(const uint8_t* head, size_t size);
Status checkVtkSignature(const uint8_t* head, size_t size);
Status readObj(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles);
Status readOff(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles);
Status readXyz(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles);
// STL streams a binary file, and welds as it reads when `weld` is set, so
// that a soup takes memory for its distinct vertices only.
Status readStl(Input& input, Complex& out, Notes& notes, bool weld);
Status readMedit(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles);
Status readVtk(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles);
// A TetGen .node file; `firstIndex` receives the number of its first point
// (0 or 1), which the .ele file counts from too. `keepDoubles` keeps
// coordinates written with more digits than float32 holds (as TetGen
// writes them) in positions64.
Status readTetgenNode(const uint8_t* data, size_t size, Complex& out,
                      Notes& notes, uint32_t& firstIndex, bool keepDoubles);
// A TetGen .ele file whose nodes are the `out.vertexCount()` vertices already
// read, numbered from `firstIndex`.
Status readTetgenEle(const uint8_t* data, size_t size, uint32_t firstIndex,
                     Complex& out, Notes& notes);

// ---------------------------------------------------------------------------
// Welding (ReadOptions::weld)
// ---------------------------------------------------------------------------

// Gives each position the index of the first vertex with the same bits,
// appending the position when it is new. The hash is drawn at random for
// every Welder from a strongly universal family (multiply-shift over the
// three 32-bit words), so no input makes it collide on purpose: the expected
// work per vertex stays small whatever the positions.
class Welder {
 public:
  // `positions` must start empty; the welded vertices are appended to it.
  explicit Welder(std::vector<float>& positions);
  uint32_t vertexAt(const float* xyz);

 private:
  size_t slotOf(const uint32_t* bits) const;
  void grow();

  static constexpr uint32_t kEmpty = 0xffffffffu;
  std::vector<float>& positions_;
  std::vector<uint32_t> slots_;  // vertex indices, kEmpty where none
  uint64_t multipliers_[4];
  int shift_ = 0;  // 64 - log2(table size)
};

// Removes the simplices of `indices` (`arity` vertices each) from the one
// starting at `first` on that have a repeated vertex; returns how many.
size_t dropRepeated(std::vector<uint32_t>& indices, size_t arity,
                    size_t first = 0);

// The notes of a weld of `before` vertices into `after` that dropped
// `dropped` simplices.
void addWeldNotes(Notes& notes, size_t before, size_t after, size_t dropped);

// Merges vertices with bit-identical positions in a complex read whole.
void weldVertices(Complex& complex, Notes& notes);

// Writers receive a complex whose array sizes and indices are valid.
Status writePly(const Complex& complex, std::vector<uint8_t>& out,
                const WriteOptions& options);
Status writeObj(const Complex& complex, std::vector<uint8_t>& out);
// Whether OBJ holds the attribute: `uv` (float32 × 2 or 3), `normal`
// (float32 × 3).
bool objHoldsAttribute(const VertexAttribute& attribute);
Status writeOff(const Complex& complex, std::vector<uint8_t>& out);
Status writeXyz(const Complex& complex, std::vector<uint8_t>& out);
Status writeMedit(const Complex& complex, std::vector<uint8_t>& out);
// Whether Medit holds the attribute: `ref`, an integer per vertex.
bool meditHoldsAttribute(const VertexAttribute& attribute);
Status writeVtk(const Complex& complex, std::vector<uint8_t>& out);
// Whether VTK holds the attribute: any whose name has no space.
bool vtkHoldsAttribute(const VertexAttribute& attribute);
// The .node file, after checking that the complex has nothing but vertices
// and tetrahedra; the .ele file (which may list no tetrahedra).
Status writeTetgenNode(const Complex& complex, std::vector<uint8_t>& out);
Status writeTetgenEle(const Complex& complex, std::vector<uint8_t>& out);
// Whether TetGen holds the attribute: `attribute` (float32 × 1..4, the
// point attributes) and `marker` (an integer per vertex, the boundary
// marker).
bool tetgenHoldsAttribute(const VertexAttribute& attribute);

// True when every listed point is a vertex used by no simplex, so a format
// without explicit points loses nothing by dropping the list: such vertices
// read back as isolated points anyway.
bool pointsAreImplicit(const Complex& complex);

}  // namespace kdmesh::io::detail
