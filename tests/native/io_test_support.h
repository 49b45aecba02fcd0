// Helpers shared by the file-format tests (test_io.cpp, test_io_formats.cpp).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "kdmesh/io.h"

namespace kdmesh::test {

inline uint32_t bitsOf(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

inline float floatOf(uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

inline std::vector<uint32_t> bitsOf(const std::vector<float>& values) {
  std::vector<uint32_t> bits(values.size());
  for (size_t i = 0; i < values.size(); ++i) bits[i] = bitsOf(values[i]);
  return bits;
}

inline std::vector<uint8_t> bytesOf(const std::string& text) {
  return std::vector<uint8_t>(text.begin(), text.end());
}

// "\n" -> "\r\n".
inline std::string crlf(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

struct ReadResult {
  Status status;
  Complex complex;
  io::Notes notes;

  bool hasNote(const std::string& part) const {
    for (const std::string& note : notes) {
      if (note.find(part) != std::string::npos) return true;
    }
    return false;
  }
};

inline std::string joined(const io::Notes& notes) {
  std::string all;
  for (const std::string& note : notes) all += "[" + note + "] ";
  return all;
}

inline ReadResult readBytes(io::Format format, const std::vector<uint8_t>& bytes, bool weld = false) {
  ReadResult result;
  io::ReadOptions options;
  options.weld = weld;
  result.status = io::readMemory(format, bytes.data(), bytes.size(), result.complex,
                                 result.notes, options);
  return result;
}

inline ReadResult readText(io::Format format, const std::string& text, bool weld = false) {
  return readBytes(format, bytesOf(text), weld);
}

inline ReadResult readPath(const std::filesystem::path& path, bool weld = false) {
  ReadResult result;
  io::ReadOptions options;
  options.weld = weld;
  result.status = io::readFile(path.string(), result.complex, result.notes, options);
  return result;
}

// A unique directory under the system temp directory, removed afterwards.
class TempDir {
 public:
  TempDir() {
    std::random_device random;
    path_ = std::filesystem::temp_directory_path() /
            ("kdmesh_io_test_" +
             std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "_" +
             std::to_string(random()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void writeWhole(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline void writeWhole(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  writeWhole(path, std::string(bytes.begin(), bytes.end()));
}

inline std::string readWhole(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Writes `complex` in `format` to memory and reads it back.
inline ReadResult writeThenRead(io::Format format, const Complex& complex,
                                const io::WriteOptions& options = {}) {
  std::vector<uint8_t> bytes;
  const Status written = io::writeMemory(format, complex, bytes, options);
  EXPECT_TRUE(written.ok()) << written.message;
  return readBytes(format, bytes);
}

// A failed read: an InvalidInput status whose one-line message contains
// every one of `parts`, and an emptied complex.
inline void expectFailure(const ReadResult& result, const std::vector<const char*>& parts) {
  ASSERT_FALSE(result.status.ok()) << "read succeeded with " << result.complex.vertexCount()
                                   << " vertices";
  EXPECT_EQ(result.status.code, ErrorCode::InvalidInput) << result.status.message;
  EXPECT_EQ(result.status.message.find('\n'), std::string::npos) << result.status.message;
  for (const char* part : parts) {
    EXPECT_NE(result.status.message.find(part), std::string::npos)
        << "message '" << result.status.message << "' lacks '" << part << "'";
  }
  EXPECT_EQ(result.complex.vertexCount(), 0u);
  EXPECT_FALSE(result.complex.hasSimplices());
}

inline void expectValidIndices(const Complex& c) {
  ASSERT_EQ(c.positions.size() % 3, 0u);
  EXPECT_EQ(c.edges.size() % 2, 0u);
  EXPECT_EQ(c.triangles.size() % 3, 0u);
  EXPECT_EQ(c.tetrahedra.size() % 4, 0u);
  for (const auto* list : {&c.points, &c.edges, &c.triangles, &c.tetrahedra}) {
    for (uint32_t index : *list) ASSERT_LT(index, c.vertexCount());
  }
}

}  // namespace kdmesh::test
