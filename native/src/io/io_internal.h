// Pieces shared by the format readers and writers of kdmesh/io.h.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "kdmesh/io.h"

namespace kdmesh::io::detail {

// ---------------------------------------------------------------------------
// Reading text
// ---------------------------------------------------------------------------

struct TextSyntax {
  bool commaSeparates = false;  // XYZ files are often CSV
  bool hashComments = false;    // '#' starts a comment that runs to line end
};

// Splits text into lines and whitespace-separated tokens without copying.
// '\r' counts as whitespace, so CRLF files need no special case.
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
  const char* lineEnd_;  // the '\n' ending the current line, or end_
  const char* next_;     // start of the next line
  size_t line_ = 0;
  TextSyntax syntax_;
};

// Whole-token parsers: false unless every character of the token is used.
// Floats are rounded once, directly to float32; "nan" and "inf" are accepted
// because the encoder reports them with the offending vertex.
bool parseFloat(std::string_view token, float& value);
bool parseInteger(std::string_view token, int64_t& value);
bool parseCount(std::string_view token, uint64_t& value);

// Reads "x y z" from the rest of the current line onto `positions`. Returns
// in `extraColumns` whether more tokens follow (w, colours, normals), which
// the callers ignore with a note.
Status readPositionLine(TextScanner& scanner, std::vector<float>& positions,
                        bool& extraColumns);

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

// Adds the note `before` count `after` when count > 0, as in
// "ignored extra columns on " 12 " vertex lines".
void addCountNote(Notes& notes, const char* before, size_t count,
                  const char* after);

// ---------------------------------------------------------------------------
// Writing text
// ---------------------------------------------------------------------------

// Appends space-separated fields and line ends to a byte buffer. Floats use
// the shortest decimal form that reads back to the same float32 bits.
class TextOut {
 public:
  explicit TextOut(std::vector<uint8_t>& out) : out_(out) {}

  TextOut& word(std::string_view text);
  TextOut& real(float value);
  // The three coordinates at `xyz`.
  TextOut& point(const float* xyz) { return real(xyz[0]).real(xyz[1]).real(xyz[2]); }
  TextOut& integer(uint64_t value);
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
Status readPly(const uint8_t* data, size_t size, Complex& out, Notes& notes);
// The first line of a PLY or legacy VTK file, checked on the file's first
// bytes before the rest is read: a file of another kind is refused without
// reading all of it.
Status checkPlySignature(const uint8_t* head, size_t size);
Status checkVtkSignature(const uint8_t* head, size_t size);
Status readObj(const uint8_t* data, size_t size, Complex& out, Notes& notes);
Status readOff(const uint8_t* data, size_t size, Complex& out, Notes& notes);
Status readXyz(const uint8_t* data, size_t size, Complex& out, Notes& notes);
Status readStl(const uint8_t* data, size_t size, Complex& out, Notes& notes);
Status readMedit(const uint8_t* data, size_t size, Complex& out, Notes& notes);
Status readVtk(const uint8_t* data, size_t size, Complex& out, Notes& notes);
// A TetGen .node file; `firstIndex` receives the number of its first point
// (0 or 1), which the .ele file counts from too.
Status readTetgenNode(const uint8_t* data, size_t size, Complex& out,
                      Notes& notes, uint32_t& firstIndex);
// A TetGen .ele file whose nodes are the `out.vertexCount()` vertices already
// read, numbered from `firstIndex`.
Status readTetgenEle(const uint8_t* data, size_t size, uint32_t firstIndex,
                     Complex& out, Notes& notes);

// Merges vertices with bit-identical positions (ReadOptions::weld).
void weldVertices(Complex& complex, Notes& notes);

// Writers receive a complex whose array sizes and indices are valid.
Status writePly(const Complex& complex, std::vector<uint8_t>& out,
                const WriteOptions& options);
Status writeObj(const Complex& complex, std::vector<uint8_t>& out);
Status writeOff(const Complex& complex, std::vector<uint8_t>& out);
Status writeXyz(const Complex& complex, std::vector<uint8_t>& out);
Status writeMedit(const Complex& complex, std::vector<uint8_t>& out);
Status writeVtk(const Complex& complex, std::vector<uint8_t>& out);
// The .node file, after checking that the complex has nothing but vertices
// and tetrahedra; the .ele file (which may list no tetrahedra).
Status writeTetgenNode(const Complex& complex, std::vector<uint8_t>& out);
Status writeTetgenEle(const Complex& complex, std::vector<uint8_t>& out);

// True when every listed point is a vertex used by no simplex, so a format
// without explicit points loses nothing by dropping the list: such vertices
// read back as isolated points anyway.
bool pointsAreImplicit(const Complex& complex);

}  // namespace kdmesh::io::detail
