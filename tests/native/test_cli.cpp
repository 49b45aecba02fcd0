// The kdmesh command-line tool, run as a separate process in a temporary
// directory: round trips through every output format, progressive prefixes,
// info output, and error handling (exit code, one-line message, no crash).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "complexes.h"
#include "kdmesh/io.h"
#include "shapes.h"
#include "test_support.h"

#ifndef KDMESH_CLI_PATH
#error "KDMESH_CLI_PATH must name the kdmesh executable"
#endif

namespace kdmesh::test {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exitCode = -1;
  int signal = 0;  // non-zero when the process died of a signal
  std::string out, err;
};

std::string readWhole(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<uint8_t> readBytes(const fs::path& path) {
  const std::string s = readWhole(path);
  return std::vector<uint8_t>(s.begin(), s.end());
}

void writeWhole(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

void writeBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// What a terminal shows of some stderr text: each line from its last '\r'
// on, blank lines dropped.
std::vector<std::string> visibleLines(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    const size_t cr = line.rfind('\r');
    if (cr != std::string::npos) line = line.substr(cr + 1);
    if (line.find_first_not_of(' ') != std::string::npos) lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "kdmesh_cli_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr) << std::strerror(errno);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  fs::path at(const std::string& name) const { return dir_ / name; }

  // Runs the tool in the temporary directory with `args` (file names
  // relative to it). exec replaces the shell, so that a crash shows as a
  // signal rather than as the shell's exit code.
  // `launcher`: a command that runs the CLI (say, /usr/bin/time), or none.
  CliRun run(const std::string& args, const std::string& launcher = "") const {
    const std::string out = at("stdout.txt").string(), err = at("stderr.txt").string();
    const std::string command = "cd '" + dir_.string() + "' && exec " + launcher + " '" KDMESH_CLI_PATH "' " +
                                args + " <" "/dev/null >'" + out + "' 2>'" + err + "'";
    const int status = std::system(command.c_str());
    CliRun r;
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    r.out = readWhole(out);
    r.err = readWhole(err);
    return r;
  }

  // What /usr/bin/time measured of a run.
  struct Usage {
    long residentKilobytes = 0;  // peak
    double seconds = 0;          // wall time
  };

  // Runs the tool under /usr/bin/time, which writes `usage`.
  CliRun runMeasured(const std::string& args, Usage& usage) const {
    const CliRun r = run(args, "/usr/bin/time -f '%M %e' -o usage.txt");
    // GNU time puts "Command exited with non-zero status 1" before the figures.
    const std::string text = readWhole(at("usage.txt"));
    std::istringstream figures(text.substr(text.find_last_of('\n', text.size() - 2) + 1));
    figures >> usage.residentKilobytes >> usage.seconds;
    EXPECT_GT(usage.residentKilobytes, 500) << text;  // a process at all
    return r;
  }

  // `head`, then zeros up to `size` bytes: a sparse file, which takes no
  // disk and no time to write.
  void writeSparse(const std::string& name, const std::string& head, uintmax_t size) const {
    writeWhole(at(name), head);
    fs::resize_file(at(name), size);
  }

  // A successful run: exit 0, which the message shows otherwise.
  CliRun runOk(const std::string& args) const {
    CliRun r = run(args);
    EXPECT_EQ(r.exitCode, 0) << "kdmesh " << args << "\nstderr: " << r.err;
    return r;
  }

  // A failed run: a non-zero exit code, not a crash, and one line on stderr
  // starting with "kdmesh: error:". Returns that line.
  std::string expectError(const std::string& args) const {
    const CliRun r = run(args);
    EXPECT_EQ(r.signal, 0) << "kdmesh " << args << " crashed";
    EXPECT_GT(r.exitCode, 0) << "kdmesh " << args;
    EXPECT_LT(r.exitCode, 128) << "kdmesh " << args;
    const std::vector<std::string> lines = visibleLines(r.err);
    EXPECT_EQ(lines.size(), 1u) << "kdmesh " << args << "\nstderr: " << r.err;
    if (lines.empty()) return {};
    EXPECT_EQ(lines.back().rfind("kdmesh: error:", 0), 0u)
        << "kdmesh " << args << "\nstderr: " << r.err;
    EXPECT_FALSE(r.err.empty() || r.err.back() != '\n') << "unterminated: " << r.err;
    return lines.back();
  }

  Complex readModel(const std::string& name) const {
    Complex c;
    io::Notes notes;
    const Status status = io::readFile(at(name).string(), c, notes);
    EXPECT_TRUE(status.ok()) << name << ": " << status.message;
    return c;
  }

  void writeModel(const std::string& name, const Complex& c) const {
    const Status status = io::writeFile(at(name).string(), c);
    ASSERT_TRUE(status.ok()) << name << ": " << status.message;
  }

  fs::path dir_;
};

// A cloud with floats that text output and exact coding must not disturb.
std::vector<float> awkwardCloud(size_t n, uint32_t seed) {
  std::vector<float> p = clusteredCloud(n, seed);
  const float awkward[] = {-0.0f, 0.0f,     1e-45f,  FLT_MIN,  -1e-30f, 0.123456791f,
                           1e30f, -3e38f, 16777215.0f, std::nextafter(1.0f, 2.0f),
                           1.0f / 3.0f, 0.1f};
  for (size_t i = 0; i + 2 < std::size(awkward); i += 3) {
    p.insert(p.end(), awkward + i, awkward + i + 3);
  }
  return p;
}

TEST_F(CliTest, HelpExitsZeroAndListsTheCommands) {
  const CliRun r = runOk("--help");
  EXPECT_EQ(r.signal, 0);
  for (const char* command : {"encode", "decode", "info"}) {
    EXPECT_NE(r.out.find(command), std::string::npos) << r.out;
  }
  const CliRun encodeHelp = runOk("encode --help");
  for (const char* option : {"--bits", "--exact", "--output"}) {
    EXPECT_NE(encodeHelp.out.find(option), std::string::npos) << encodeHelp.out;
  }
}

TEST_F(CliTest, ExactRoundTripThroughEveryOutputFormatIsBitExact) {
  const std::vector<float> input = awkwardCloud(4000, 31);
  writeModel("cloud.ply", pointCloud(input));
  writeModel("cloud.xyz", pointCloud(input));
  for (const char* source : {"cloud.ply", "cloud.xyz"}) {
    SCOPED_TRACE(source);
    runOk(std::string("encode ") + source + " -o exact.kdm --exact");
    for (const char* output : {"out.ply", "out.obj", "out.xyz", "out.off"}) {
      SCOPED_TRACE(output);
      runOk(std::string("decode exact.kdm -o ") + output);
      const Complex decoded = readModel(output);
      EXPECT_EQ(sortedBitPatterns(decoded.positions), sortedBitPatterns(input));
      EXPECT_FALSE(decoded.hasSimplices());
    }
    runOk("decode exact.kdm --ascii -o ascii.ply");
    EXPECT_EQ(readWhole(at("ascii.ply")).rfind("ply\nformat ascii 1.0\n", 0), 0u);
    EXPECT_EQ(sortedBitPatterns(readModel("ascii.ply").positions), sortedBitPatterns(input));
  }
}

TEST_F(CliTest, ExactKeepsFloat64CoordinatesAndGridRoundsThemWithANote) {
  // Doubles below float32 precision, as Medit version 2 and PLY double.
  writeWhole(at("m.mesh"),
             "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0.1 0 0 1\n1 0.30000000000000004 0 1\n"
             "0 1 1e-300 1\n0 0 1.0000000000000002 1\nTetrahedra\n1\n1 2 3 4 0\nEnd\n");
  runOk("encode m.mesh -o m.kdm --exact");
  EXPECT_NE(runOk("info m.kdm").out.find("exact float64"), std::string::npos);
  for (const char* output : {"out.mesh", "out.ply"}) {
    SCOPED_TRACE(output);
    runOk(std::string("decode m.kdm -o ") + output);
    runOk(std::string("encode ") + output + " -o again.kdm --exact");
    runOk("decode again.kdm -o again.mesh");
    const std::string text = readWhole(at("again.mesh"));
    EXPECT_EQ(text.rfind("MeshVersionFormatted 2", 0), 0u) << text;
    for (const char* value : {"0.1 ", "0.30000000000000004", "1e-300", "1.0000000000000002"})
      EXPECT_NE(text.find(value), std::string::npos) << value << " in " << text;
  }
  const CliRun grid = runOk("encode m.mesh -o grid.kdm");
  EXPECT_NE(grid.err.find("rounded to float32"), std::string::npos) << grid.err;
  EXPECT_NE(runOk("info grid.kdm").out.find("grid"), std::string::npos);
}

TEST_F(CliTest, GridRoundTripIsWithinHalfAStep) {
  const std::vector<float> input = sphereSurface(5000, 32);
  writeModel("sphere.ply", pointCloud(input));
  runOk("encode sphere.ply -o grid.kdm --bits 12");
  const std::vector<uint8_t> stream = readBytes(at("grid.kdm"));
  Decoder decoder;
  ASSERT_TRUE(decoder.push(stream.data(), stream.size()).ok());
  ASSERT_TRUE(decoder.finish().ok());
  const Header& h = decoder.header();
  EXPECT_EQ(h.bits, 12);
  ASSERT_GT(h.step, 0);
  // Where the format puts every input coordinate: its nearest grid line.
  std::vector<float> expected(input.size());
  for (size_t i = 0; i < input.size(); ++i) {
    const size_t a = i % 3;
    const double q = std::llround((double(input[i]) - h.origin[a]) / h.step);
    expected[i] = float(h.origin[a] + q * h.step);
    ASSERT_LE(std::abs(double(expected[i]) - input[i]),
              h.step * 0.5 * (1 + 1e-9) + std::abs(double(input[i])) * 1.2e-7);
  }
  for (const char* output : {"grid.ply", "grid.obj", "grid.xyz"}) {
    SCOPED_TRACE(output);
    runOk(std::string("decode grid.kdm -o ") + output);
    const Complex decoded = readModel(output);
    ASSERT_EQ(decoded.vertexCount(), input.size() / 3);
    EXPECT_EQ(sortedBitPatterns(decoded.positions), sortedBitPatterns(expected));
  }
}

TEST_F(CliTest, DecodingAPrefixGivesACoarserCloud) {
  const std::vector<float> input = uniformCloud(5000, 33);
  writeModel("cloud.xyz", pointCloud(input));
  runOk("encode cloud.xyz -o cloud.kdm --bits 14");
  const std::vector<uint8_t> stream = readBytes(at("cloud.kdm"));
  ASSERT_GT(stream.size(), 4000u);
  size_t previous = 0;
  for (size_t bytes : {size_t{1200}, size_t{4000}, stream.size(), stream.size() + 100}) {
    SCOPED_TRACE(bytes);
    runOk("decode cloud.kdm --bytes " + std::to_string(bytes) + " -o coarse.xyz");
    const Complex coarse = readModel("coarse.xyz");
    EXPECT_GE(coarse.vertexCount(), 1u);
    EXPECT_LE(coarse.vertexCount(), input.size() / 3);
    EXPECT_GE(coarse.vertexCount(), previous);  // more bytes, finer model
    previous = coarse.vertexCount();
    if (bytes < stream.size()) {
      EXPECT_LT(coarse.vertexCount(), input.size() / 3);
      // Every input point lies within the decoder's error bound of the
      // coarse model.
      Decoder decoder;
      ASSERT_TRUE(decoder.push(stream.data(), bytes).ok());
      const double bound = decoder.errorBound();
      EXPECT_EQ(decoder.snapshot().vertexCount(), coarse.vertexCount());
      EXPECT_LE(maxNearestDistance(input, coarse.positions, bound * 1.001 + 1e-6),
                bound * 1.001 + 1e-6);
    } else {
      EXPECT_EQ(coarse.vertexCount(), input.size() / 3);
    }
  }
}

// A prefix of a surface holds edges where triangles collapsed, and one of
// a tetrahedral mesh triangles and edges: written to a format that cannot
// hold them, it keeps what the format holds and says what it left out. A
// complete model that the format cannot hold is still an error.
TEST_F(CliTest, APrefixKeepsWhatItsOutputFormatHolds) {
  writeModel("grid.ply", gridWithHoles(40));
  runOk("-q encode grid.ply -o grid.kdm --chunk-bytes 256");
  writeModel("block.mesh", tetrahedralBlock(4, 7));
  runOk("-q encode block.mesh -o block.kdm --chunk-bytes 256");
  struct Case {
    const char *stream, *output, *leftOut;
  };
  for (const Case& c : {Case{"grid.kdm", "coarse.off", "edges"}, Case{"grid.kdm", "coarse.xyz", "triangles"},
                        Case{"block.kdm", "coarse.obj", "tetrahedra"}, Case{"grid.kdm", "coarse.node", "triangles"}}) {
    SCOPED_TRACE(std::string(c.stream) + " -> " + c.output);
    Decoder decoder;
    const std::vector<uint8_t> stream = [&] {
      const std::string text = readWhole(at(c.stream));
      return std::vector<uint8_t>(text.begin(), text.end());
    }();
    ASSERT_TRUE(decoder.push(stream.data(), stream.size()).ok());
    // The first chunk boundary whose prefix holds what the format cannot.
    size_t cut = 0;
    Complex expected;
    for (const ChunkInfo& chunk : decoder.chunks()) {
      Decoder prefix;
      ASSERT_TRUE(prefix.push(stream.data(), chunk.offset).ok());
      expected = prefix.snapshot();
      const std::string leftOut = c.leftOut;
      if (!(leftOut == "edges" ? expected.edges : leftOut == "triangles" ? expected.triangles : expected.tetrahedra)
               .empty()) {
        cut = chunk.offset;
        break;
      }
    }
    ASSERT_GT(cut, 0u);
    const CliRun r = runOk(std::string("decode ") + c.stream + " -o " + c.output + " --bytes " + std::to_string(cut));
    EXPECT_NE(r.err.find("left out"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.leftOut), std::string::npos) << r.err;
    // What was kept is the prefix's, vertex for vertex.
    const Complex written = readModel(c.output);
    EXPECT_EQ(written.vertexCount(), expected.vertexCount());
    if (std::string(c.output) == "coarse.off") {
      EXPECT_EQ(written.triangles.size(), expected.triangles.size());
    }
    if (std::string(c.output) == "coarse.node") {
      EXPECT_TRUE(written.triangles.empty() && written.edges.empty());
    }
  }
  EXPECT_NE(expectError("decode grid.kdm -o whole.xyz").find("XYZ holds only points"), std::string::npos);
}

TEST_F(CliTest, InfoPrintsHeaderFieldsAndBitsPerVertex) {
  writeModel("cloud.ply", pointCloud(torusSurface(3000, 34)));
  runOk("-q encode cloud.ply -o cloud.kdm --bits 10");
  const size_t size = fs::file_size(at("cloud.kdm"));

  const CliRun text = runOk("info cloud.kdm");
  EXPECT_NE(text.out.find("vertices        3000\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(std::to_string(size) + " bytes"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("grid, 10 bits"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("bits/vertex"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("chunks"), std::string::npos) << text.out;

  const CliRun json = runOk("info --json cloud.kdm");
  const std::string& j = json.out;
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j.front(), '{');
  EXPECT_EQ(j[j.find_last_not_of(" \n")], '}');
  EXPECT_EQ(std::count(j.begin(), j.end(), '{'), std::count(j.begin(), j.end(), '}'));
  EXPECT_EQ(std::count(j.begin(), j.end(), '['), std::count(j.begin(), j.end(), ']'));
  EXPECT_EQ(j.find("inf"), std::string::npos);
  EXPECT_EQ(j.find("nan"), std::string::npos);
  for (const char* key : {"version", "bytes", "vertexCount", "maxDimension", "simplexCounts",
                          "quantization", "bits", "axisBits", "bitsPerVertex", "total",
                          "geometry", "levels", "cells", "geometryBits", "chunks"}) {
    EXPECT_NE(j.find("\"" + std::string(key) + "\":"), std::string::npos) << key << "\n" << j;
  }
  auto number = [&j](const char* key) {
    const size_t at = j.find("\"" + std::string(key) + "\":");
    if (at == std::string::npos) return std::nan("");
    return std::strtod(j.c_str() + at + std::strlen(key) + 3, nullptr);
  };
  EXPECT_EQ(number("vertexCount"), 3000.0);
  EXPECT_EQ(number("bytes"), double(size));
  EXPECT_EQ(number("bits"), 10.0);
  EXPECT_NEAR(number("total"), 8.0 * double(size) / 3000.0, 1e-9);
  EXPECT_GT(number("geometry"), 0.0);
  EXPECT_LT(number("geometry"), number("total"));
  EXPECT_NE(j.find("\"quantization\": \"grid\""), std::string::npos);

  runOk("encode cloud.ply -o exact.kdm --exact");
  const CliRun exact = runOk("info --json exact.kdm");
  EXPECT_NE(exact.out.find("\"quantization\": \"float32\""), std::string::npos) << exact.out;
}

// --fast-decode codes a mesh without neighbourhood predictions: the header
// says so, and the stream decodes to the same model as the default one.
TEST_F(CliTest, FastDecodeStreamsSayHowTheyPredictAndDecodeAlike) {
  writeModel("torus.ply", torusMesh(20, 30));
  runOk("-q encode torus.ply -o default.kdm --bits 12");
  runOk("-q encode torus.ply -o fast.kdm --bits 12 --fast-decode");
  EXPECT_NE(runOk("info default.kdm").out.find("predictions     from the decoded neighbourhood\n"), std::string::npos);
  EXPECT_NE(runOk("info fast.kdm").out.find("predictions     along the split axis (--fast-decode)\n"),
            std::string::npos);
  EXPECT_NE(runOk("info --json fast.kdm").out.find("\"fastDecode\": true"), std::string::npos);
  runOk("-q decode default.kdm -o default.ply");
  runOk("-q decode fast.kdm -o fast.ply");
  EXPECT_EQ(canonicalForm(readModel("fast.ply")), canonicalForm(readModel("default.ply")));
  EXPECT_NE(runOk("encode --help").out.find("--fast-decode"), std::string::npos);
}

// --levels adds a row per kd-tree level, whose last byte estimate is
// about the stream's size.
TEST_F(CliTest, InfoLevelsListsEveryLevel) {
  writeModel("torus.obj", torusMesh(12, 20));
  runOk("-q encode torus.obj -o torus.kdm --bits 10");
  const CliRun plain = runOk("info torus.kdm");
  EXPECT_EQ(plain.out.find("cell side"), std::string::npos) << plain.out;
  const CliRun text = runOk("info --levels torus.kdm");
  const std::string& out = text.out;
  const size_t depthAt = out.find("kd-tree levels  ");
  ASSERT_NE(depthAt, std::string::npos) << out;
  const int depth = std::atoi(out.c_str() + depthAt + 16);
  const size_t tableAt = out.find("cell side");
  ASSERT_NE(tableAt, std::string::npos) << out;
  std::istringstream rows(out.substr(out.find('\n', tableAt) + 1));
  std::string row;
  int levels = 0;
  double lastBytes = 0;
  while (std::getline(rows, row) && row.rfind("chunks", 0) != 0) {
    std::istringstream fields(row);
    int level;
    std::string axis, cells, side, geometry, connectivity;
    ASSERT_TRUE(fields >> level >> axis >> cells >> side >> geometry >> connectivity >> lastBytes) << row;
    EXPECT_EQ(level, levels);
    ++levels;
  }
  EXPECT_GE(levels, depth);
  const double size = double(fs::file_size(at("torus.kdm")));
  EXPECT_GT(lastBytes, 0.9 * size);
  EXPECT_LE(lastBytes, size);
}

TEST_F(CliTest, QuietSuppressesProgressAndStatistics) {
  writeModel("cloud.xyz", pointCloud(uniformCloud(2000, 35)));
  const CliRun loud = runOk("encode cloud.xyz -o a.kdm");
  EXPECT_NE(loud.err.find("2000 vertices"), std::string::npos) << loud.err;
  for (const char* args : {"-q encode cloud.xyz -o b.kdm", "--quiet encode cloud.xyz -o c.kdm",
                           "encode -q cloud.xyz -o d.kdm", "encode cloud.xyz -o e.kdm --quiet"}) {
    const CliRun quiet = runOk(args);
    EXPECT_EQ(quiet.err, "") << args;
    EXPECT_EQ(quiet.out, "") << args;
  }
  EXPECT_EQ(readBytes(at("a.kdm")), readBytes(at("e.kdm")));
  const CliRun loudDecode = runOk("decode a.kdm -o a.ply");
  EXPECT_NE(loudDecode.err.find("2000 vertices"), std::string::npos) << loudDecode.err;
  EXPECT_EQ(runOk("-q decode a.kdm -o b.ply").err, "");
  EXPECT_EQ(runOk("decode a.kdm -o c.ply -q").err, "");
  // Notes about the input are statistics too.
  writeWhole(at("extra.xyz"), "1 2 3 255 0 0\n4 5 6 0 255 0\n");
  EXPECT_NE(runOk("encode extra.xyz -o f.kdm").err.find("extra columns"), std::string::npos);
  EXPECT_EQ(runOk("encode extra.xyz -o f.kdm -q").err, "");
}

TEST_F(CliTest, MissingMalformedAndUnknownInputsFailWithOneLine) {
  writeModel("cloud.xyz", pointCloud(uniformCloud(500, 36)));
  runOk("-q encode cloud.xyz -o good.kdm");

  EXPECT_NE(expectError("encode missing.ply -o x.kdm").find("missing.ply"), std::string::npos);
  EXPECT_NE(expectError("decode missing.kdm -o x.ply").find("missing.kdm"), std::string::npos);
  EXPECT_NE(expectError("info missing.kdm").find("missing.kdm"), std::string::npos);

  writeWhole(at("bad.xyz"), "1 2 3\n4 5 six\n");
  EXPECT_NE(expectError("encode bad.xyz -o x.kdm").find("line 2"), std::string::npos);
  writeWhole(at("bad.ply"), "ply\nformat ascii 1.0\nelement vertex 99999\nproperty float x\n");
  expectError("encode bad.ply -o x.kdm");
  writeWhole(at("empty.obj"), "");
  expectError("encode empty.obj -o x.kdm");
  writeWhole(at("nothing.obj"), "# no vertices\n");
  expectError("encode nothing.obj -o x.kdm");
  // Read fine, refused by the encoder after its progress line has started.
  writeWhole(at("nan.xyz"), "1 2 3\n4 nan 6\n");
  EXPECT_NE(expectError("encode nan.xyz -o x.kdm").find("NaN"), std::string::npos);
  EXPECT_FALSE(fs::exists(at("x.kdm")));

  fs::copy_file(at("cloud.xyz"), at("cloud.foo"));
  EXPECT_NE(expectError("encode cloud.foo -o x.kdm").find("cloud.foo"), std::string::npos);
  EXPECT_NE(expectError("decode good.kdm -o out.foo").find("out.foo"), std::string::npos);
  EXPECT_FALSE(fs::exists(at("out.foo")));
  expectError("decode good.kdm -o noextension");
  expectError("decode cloud.xyz -o out.ply");  // not a kdmesh stream
  expectError("info cloud.xyz");
}

// A PLY or VTK file of another kind is refused after its first block: a
// sparse 2 GB file, 'ply' not its first line, was read whole (2.3 GB
// resident) before it was refused.
constexpr uintmax_t kTwoGigabytes = uintmax_t(2) << 30;
constexpr long kMemoryBoundKilobytes = 256 << 10;

TEST_F(CliTest, LargeFilesOfAnotherKindAreRefusedWithoutReadingThem) {
  for (const char* name : {"big.ply", "big.vtk"}) {
    SCOPED_TRACE(name);
    writeSparse(name, "solid not really\n", kTwoGigabytes);
    Usage usage;
    const CliRun r = runMeasured(std::string("encode ") + name + " -o x.kdm", usage);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("not a"), std::string::npos) << r.err;
    EXPECT_LT(usage.residentKilobytes, kMemoryBoundKilobytes) << "peak resident memory";
    fs::remove(at(name));
  }
}

// The 84 bytes that start a binary STL declaring `triangles` triangles.
std::string stlPrefix(uint32_t triangles) {
  std::string prefix(84, '\0');
  for (int i = 0; i < 4; ++i) prefix[80 + i] = char(triangles >> (8 * i));
  return prefix;
}

// An all-zero binary STL of 2 GiB whose count is honest: 42,949,671
// triangles whose corners are all (0,0,0). Streamed and welded as it is
// read, it takes memory for one vertex and no triangle; the bound on time
// is for a loaded machine, far above what the work takes.
TEST_F(CliTest, ATwoGigabyteAllZeroStlWeldsInLittleMemory) {
  const uint32_t triangles = uint32_t((kTwoGigabytes - 84) / 50);
  writeSparse("zeros.stl", stlPrefix(triangles), 84 + uintmax_t(50) * triangles);
  Usage usage;
  const CliRun r = runMeasured("encode --weld zeros.stl -o zeros.kdm", usage);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("(128849013 -> 1 vertex)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("dropped 42949671 simplices that welding left"), std::string::npos) << r.err;
  EXPECT_LT(usage.residentKilobytes, kMemoryBoundKilobytes) << "peak resident memory";
  EXPECT_LT(usage.seconds, 150.0) << "wall time";
  fs::remove(at("zeros.stl"));
}

// Without --weld an all-zero STL keeps three vertices per triangle: its
// encoding would take about 2.9 GB here, so a 1 GiB limit refuses it once
// read, before the encoder allocates anything.
TEST_F(CliTest, AnEncodeOverTheMemoryLimitIsRefusedBeforeAllocating) {
  const uint32_t triangles = uint32_t(((uintmax_t(256) << 20) - 84) / 50);
  writeSparse("zeros.stl", stlPrefix(triangles), 84 + uintmax_t(50) * triangles);
  Usage usage;
  const CliRun r = runMeasured("encode zeros.stl -o zeros.kdm --max-memory 1GB", usage);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("needs about 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than the limit of 1024 MiB (--max-memory raises it) [limit-exceeded]"),
            std::string::npos)
      << r.err;
  EXPECT_LT(usage.residentKilobytes, 1L << 20) << "peak resident memory";
  EXPECT_FALSE(fs::exists(at("zeros.kdm")));
  fs::remove(at("zeros.stl"));
}

// A binary STL whose count needs more bytes than the file has is refused on
// its first 84 bytes; one with bytes after its triangles reads the
// triangles alone. Neither reads the rest of its 2 GiB.
TEST_F(CliTest, BinaryStlCountsAreCheckedAgainstTheSizeBeforeReading) {
  writeSparse("lying.stl", stlPrefix(0xffffffffu), kTwoGigabytes);
  Usage usage;
  const CliRun lying = runMeasured("encode lying.stl -o x.kdm", usage);
  EXPECT_EQ(lying.exitCode, 1) << lying.err;
  EXPECT_NE(lying.err.find("declares 4294967295 triangles"), std::string::npos) << lying.err;
  EXPECT_NE(lying.err.find("truncated"), std::string::npos) << lying.err;
  EXPECT_LT(usage.residentKilobytes, kMemoryBoundKilobytes) << "peak resident memory";
  fs::remove(at("lying.stl"));

  writeSparse("short.stl", stlPrefix(1), kTwoGigabytes);
  const CliRun trailing = runMeasured("encode short.stl -o x.kdm", usage);
  EXPECT_EQ(trailing.exitCode, 0) << trailing.err;
  EXPECT_NE(trailing.err.find("ignored 2147483514 bytes after the triangles"), std::string::npos)
      << trailing.err;
  EXPECT_LT(usage.residentKilobytes, kMemoryBoundKilobytes) << "peak resident memory";
  fs::remove(at("short.stl"));
}

// A binary PLY body is streamed: 2 GiB after its elements are not read.
TEST_F(CliTest, ABinaryPlyBodyIsStreamed) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int32_t face[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(corners), sizeof corners);
  ply += '\3';
  ply.append(reinterpret_cast<const char*>(face), sizeof face);
  const uintmax_t trailing = kTwoGigabytes - ply.size();
  writeSparse("tail.ply", ply, kTwoGigabytes);
  Usage usage;
  const CliRun r = runMeasured("encode tail.ply -o x.kdm", usage);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("ignored " + std::to_string(trailing) + " bytes after the last PLY element"),
            std::string::npos)
      << r.err;
  EXPECT_LT(usage.residentKilobytes, kMemoryBoundKilobytes) << "peak resident memory";
  fs::remove(at("tail.ply"));
}

// Runs the tool with an address-space limit far below what the lying counts
// below would reserve, so that reserving before checking fails visibly (as
// [limit-exceeded]). AddressSanitizer maps terabytes of shadow memory and
// cannot run under such a limit: there, only the messages are checked.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define KDMESH_ADDRESS_SANITIZER 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define KDMESH_ADDRESS_SANITIZER 1
#endif
std::string addressSpaceLimit() {
#if defined(KDMESH_ADDRESS_SANITIZER)
  return "";
#else
  return "prlimit --as=" + std::to_string(512 << 20) + " --";
#endif
}

// Counts in a header that the rest of the file cannot hold are refused
// before anything is reserved for them, in every format that has counts:
// each would reserve gigabytes.
TEST_F(CliTest, HeaderCountsBeyondTheFileReserveNothing) {
  const std::string vtk = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  const std::string vtk5 = "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  const std::string plyVertices =
      " 1.0\nelement vertex 2147483648\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  writeWhole(at("pair.node"), "1 3 0 0\n1 0 0 0\n");
  const struct {
    const char* name;
    std::string text;
    const char* expected;
  } lies[] = {
      {"binary.ply", "ply\nformat binary_little_endian" + plyVertices + std::string(24, '\0'),
       "more than the rest of the file"},
      {"ascii.ply", "ply\nformat ascii" + plyVertices + "0 0 0\n", "more than the rest of the file"},
      {"faces.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
       "property float y\nproperty float z\nelement face 1000000000\n"
       "property list uchar int vertex_indices\nend_header\n" + std::string(40, '\0'),
       "more than the rest of the file"},
      {"lie.off", "OFF\n1000000000 1000000000 0\n0 0 0\n", "more than the rest of the file"},
      {"lie.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices 1000000000\n0 0 0 0\n",
       "more than the rest of the file"},
      {"lie.node", "1000000000 3 0 0\n1 0 0 0\n", "more than the rest of the file"},
      {"pair.ele", "1000000000 4 0\n1 1 1 1 1\n", "more than the rest of the file"},
      {"points.vtk", vtk + "POINTS 1000000000 float\n0 0 0\n", "more than the rest of the file"},
      {"cells.vtk", vtk + "POINTS 1 float\n0 0 0\nCELLS 1000000000 2000000000\n1 0\n",
       "more than the rest of the file"},
      {"offsets.vtk", vtk5 + "POINTS 1 float\n0 0 0\nCELLS 1000000000 1000000000\nOFFSETS vtktypeint64\n0\n",
       "more than the rest of the file"},
      {"lie.stl", stlPrefix(1u << 30) + std::string(50, '\0'), "truncated"},
  };
  for (const auto& lie : lies) {
    SCOPED_TRACE(lie.name);
    writeWhole(at(lie.name), lie.text);
    const CliRun r = run(std::string("encode ") + lie.name + " -o x.kdm", addressSpaceLimit());
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find(lie.expected), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("limit-exceeded"), std::string::npos) << r.err;
  }
}

// The file's bytes in an error or a note are escaped: no terminal escape
// sequence or control character reaches stderr.
TEST_F(CliTest, FileBytesInMessagesAreEscaped) {
  writeWhole(at("escape.xyz"), "1 2 3\n4 \x1b[31m\x07 6\n");
  const std::string line = expectError("encode escape.xyz -o x.kdm");
  EXPECT_NE(line.find("\\x1b[31m\\x07"), std::string::npos) << line;
  writeWhole(at("escape.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\x1b]0;title\x07 x\n");
  const CliRun r = runOk("encode escape.obj -o x.kdm");
  EXPECT_NE(r.err.find("\\x1b]0;title\\x07"), std::string::npos) << r.err;
  for (const std::string& output : {line, r.err, r.out})
    for (const char c : output) EXPECT_FALSE((unsigned char)c < 0x20 && c != '\n' && c != '\r') << int(c);
}

TEST_F(CliTest, CorruptedAndTruncatedStreamsFailWithOneLine) {
  writeModel("cloud.xyz", pointCloud(clusteredCloud(3000, 37)));
  runOk("-q encode cloud.xyz -o good.kdm --bits 16");
  const std::vector<uint8_t> good = readBytes(at("good.kdm"));
  ASSERT_GT(good.size(), 2000u);
  const size_t positions[] = {0, 10, 40, 60, good.size() / 2, good.size() - 1};
  for (size_t position : positions) {
    SCOPED_TRACE("flipped byte " + std::to_string(position));
    std::vector<uint8_t> bad = good;
    bad[position] ^= 0x20;
    writeBytes(at("bad.kdm"), bad);
    expectError("decode bad.kdm -o bad.ply");
    expectError("info bad.kdm");
    expectError("info --json bad.kdm");
  }
  for (size_t length : {size_t{0}, size_t{30}, size_t{60}, good.size() / 2, good.size() - 1}) {
    SCOPED_TRACE("truncated to " + std::to_string(length));
    writeBytes(at("short.kdm"), std::vector<uint8_t>(good.begin(), good.begin() + length));
    expectError("decode short.kdm -o short.ply");
    expectError("info short.kdm");
  }
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  writeBytes(at("long.kdm"), longer);
  expectError("decode long.kdm -o long.ply");
  expectError("info long.kdm");
}

TEST_F(CliTest, BadOptionsFailWithOneLine) {
  writeModel("cloud.xyz", pointCloud(uniformCloud(100, 38)));
  for (const char* args :
       {"encode cloud.xyz -o x.kdm --bits 0", "encode cloud.xyz -o x.kdm --bits 31",
        "encode cloud.xyz -o x.kdm --bits -3", "encode cloud.xyz -o x.kdm --bits twelve",
        "encode cloud.xyz -o x.kdm --bits 12 --exact", "encode cloud.xyz -o x.kdm --exact --bits 12",
        "encode cloud.xyz", "encode -o x.kdm", "encode cloud.xyz -o x.kdm --chunk-bytes 1",
        "encode cloud.xyz -o x.kdm --frobnicate", "encode cloud.xyz extra -o x.kdm", "",
        "compress cloud.xyz"}) {
    SCOPED_TRACE(args);
    expectError(args);
    EXPECT_FALSE(fs::exists(at("x.kdm")));
  }
  runOk("-q encode cloud.xyz -o x.kdm --bits 30");
  runOk("-q encode cloud.xyz -o y.kdm --bits 1");
  EXPECT_EQ(readModel("cloud.xyz").vertexCount(), 100u);
}

// File names are bytes: a name that is not UTF-8 (here with 0xFF and a
// space) must work as input and output, and appear in error messages as is.
TEST_F(CliTest, FileNamesThatAreNotUtf8Work) {
  const std::string input = "cloud \xff.xyz", output = "out \xfe.kdm", decoded = "back \xfd.xyz";
  Complex c;
  c.positions = {0.5f, 1.f, 2.f, -3.f, 4.f, 5.25f};
  writeModel(input, c);
  runOk("encode '" + input + "' -o '" + output + "' --exact -q");
  runOk("decode '" + output + "' -o '" + decoded + "' -q");
  EXPECT_EQ(readModel(decoded).positions.size(), 6u);
  const std::string line = expectError("encode 'missing \xff.obj' -o x.kdm");
  EXPECT_NE(line.find("\xff"), std::string::npos) << line;
}

}  // namespace
}  // namespace kdmesh::test
