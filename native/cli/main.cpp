// kdmesh command-line tool: encode, decode and inspect .kdm streams.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cctype>
#include <cinttypes>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "kdmesh/gltf.h"
#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"

namespace {

using Clock = std::chrono::steady_clock;

bool gQuiet = false;
// Whether a progress line is on screen; anything else printed to stderr must
// clear it first, or the message would start in the middle of that line.
bool gProgressShown = false;

void clearProgress() {
  if (!gProgressShown) return;
  std::fprintf(stderr, "\r%-16s\r", "");
  gProgressShown = false;
}

// "1 vertex", "2 vertices".
std::string counted(size_t count, const char* one, const char* many) {
  return std::to_string(count) + " " + (count == 1 ? one : many);
}

// Error messages are one line, whatever the text they quote, and reach the
// terminal without control characters: line breaks become spaces, the rest
// (escape sequences, say) \xHH.
std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n' || c == '\r') {
      out += ' ';
    } else if (byte < 0x20 || byte == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += {'\\', 'x', kHex[byte >> 4], kHex[byte & 15]};
    } else {
      out += c;
    }
  }
  return out;
}

int fail(const std::string& message) {
  clearProgress();
  std::fprintf(stderr, "kdmesh: error: %s\n", oneLine(message).c_str());
  return 1;
}

int fail(const kdmesh::Status& status, const std::string& context) {
  return fail(context + ": " + status.message + " [" + kdmesh::errorCodeName(status.code) + "]");
}

void note(const std::string& message) {
  if (gQuiet) return;
  clearProgress();
  std::fprintf(stderr, "kdmesh: %s\n", message.c_str());
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool writeBytes(const std::string& path, const std::vector<uint8_t>& bytes, std::string& error) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  if (!out) {
    error = "cannot write " + path;
    return false;
  }
  return true;
}

// Prints "phase NN%" on one stderr line, at most once per percent, when
// stderr is a terminal (a log file would collect every update).
class ProgressLine {
 public:
  void update(const char* phase, double fraction) {
    if (gQuiet || !terminal_) return;
    const int percent = int(fraction * 100);
    if (phase == phase_ && percent == percent_) return;
    phase_ = phase;
    percent_ = percent;
    std::fprintf(stderr, "\r%-10s %3d%%", phase, percent);
    gProgressShown = true;
  }
  ~ProgressLine() { clearProgress(); }

 private:
  const bool terminal_ = isatty(fileno(stderr)) != 0;
  const char* phase_ = nullptr;
  int percent_ = -1;
};

// One note per kind of input simplex the encoder dropped (see InputRepairs).
void reportRepairs(const std::string& input, const kdmesh::InputRepairs& repairs) {
  static const char* const kNames[4][2] = {
      {"point", "points"}, {"edge", "edges"}, {"triangle", "triangles"}, {"tetrahedron", "tetrahedra"}};
  for (int d = 0; d < 4; ++d) {
    const auto count = [&](uint64_t value, const char* why) {
      if (value > 0) note(input + ": dropped " + counted(value, kNames[d][0], kNames[d][1]) + " " + why);
    };
    count(repairs.degenerate[size_t(d)], "with a repeated vertex");
    count(repairs.duplicate[size_t(d)], "listed twice");
    count(repairs.redundant[size_t(d)],
          d == 0 ? "on vertices of other simplices (implied)" : "that are faces of other listed simplices (implied)");
  }
}

struct EncodeArgs {
  std::string input, output;
  int bits = 16;
  bool exact = false;
  size_t chunkBytes = 16 * 1024;
  bool pointsOnly = false;
  bool weld = false;
  // Encoder memory limit in bytes; 0 for none, kMachineMemory for three
  // quarters of the machine's memory.
  static constexpr uint64_t kMachineMemory = UINT64_MAX;
  uint64_t maxMemory = kMachineMemory;
  bool bitsGiven = false;  // --bits on the command line: glTF positions go to the grid
  bool fallback = false;
  bool kdmFiles = false;
  int attributeBits = 0;
  int normalBits = 0;
  bool fastDecode = false;
};

// Three quarters of the machine's physical memory, or 0 (no limit) where
// the system does not say.
uint64_t defaultMemoryLimit() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  return uint64_t(pages) * uint64_t(pageSize) / 4 * 3;
}

void reportGltf(const std::string& output, const kdmesh::gltf::Summary& summary, const char* verb, double seconds) {
  if (gQuiet) return;
  std::fprintf(stderr, "%s: %s of %s, %s, %" PRIu64 " stream bytes [%s %.3fs]\n", output.c_str(),
               counted(summary.streams, "stream", "streams").c_str(),
               counted(summary.primitives, "primitive", "primitives").c_str(),
               counted(size_t(summary.vertices), "vertex", "vertices").c_str(), summary.streamBytes, verb, seconds);
}

// A glTF scene: every primitive becomes a kdmesh stream (kdmesh/gltf.h),
// positions bit for bit unless --bits is given.
int runEncodeGltf(const EncodeArgs& args) {
  const auto start = Clock::now();
  kdmesh::gltf::EncodeOptions options;
  options.stream.exact = args.exact || !args.bitsGiven;
  options.stream.bits = args.bits;
  options.stream.chunkBytes = args.chunkBytes;
  options.stream.fastDecode = args.fastDecode;
  options.stream.maxMemoryBytes =
      args.maxMemory == EncodeArgs::kMachineMemory ? defaultMemoryLimit() : args.maxMemory;
  options.fallback = args.fallback;
  options.separateStreams = args.kdmFiles;
  kdmesh::io::Notes notes;
  kdmesh::gltf::Summary summary;
  const kdmesh::Status s = kdmesh::gltf::encodeFile(args.input, args.output, options, notes, &summary);
  for (const std::string& n : notes) note(args.input + ": " + n);
  if (!s.ok()) return fail(s, "cannot encode " + args.input);
  reportGltf(args.output, summary, "encode", secondsSince(start));
  return 0;
}

int runEncode(const EncodeArgs& args) {
  if (kdmesh::gltf::isGltfPath(args.input) || kdmesh::gltf::isGltfPath(args.output)) {
    if (!kdmesh::gltf::isGltfPath(args.input) || !kdmesh::gltf::isGltfPath(args.output))
      return fail("a glTF scene encodes to a glTF scene: give .glb or .gltf for both input and output");
    if (args.pointsOnly || args.weld) return fail("--points-only and --weld do not apply to glTF scenes");
    return runEncodeGltf(args);
  }
  if (args.fallback || args.kdmFiles) return fail("--fallback and --kdm-files apply to glTF scenes only");
  const auto start = Clock::now();
  kdmesh::Complex complex;
  kdmesh::io::Notes notes;
  kdmesh::io::ReadOptions readOptions;
  readOptions.weld = args.weld;
  readOptions.keepDoubles = args.exact;  // float64 coordinates make a float64 stream
  if (auto s = kdmesh::io::readFile(args.input, complex, notes, readOptions); !s.ok())
    return fail(s, args.input);
  for (const std::string& n : notes) note(args.input + ": " + n);
  if (args.pointsOnly && complex.hasSimplices()) {
    note("--points-only: dropping " + counted(complex.simplexCount(1), "edge", "edges") + ", " +
         counted(complex.simplexCount(2), "triangle", "triangles") + ", " +
         counted(complex.simplexCount(3), "tetrahedron", "tetrahedra"));
    complex.edges.clear();
    complex.triangles.clear();
    complex.tetrahedra.clear();
  }
  const double readSeconds = secondsSince(start);

  kdmesh::EncodeOptions options;
  options.bits = args.bits;
  options.exact = args.exact;
  options.chunkBytes = args.chunkBytes;
  options.fastDecode = args.fastDecode;
  options.maxMemoryBytes = args.maxMemory == EncodeArgs::kMachineMemory ? defaultMemoryLimit() : args.maxMemory;
  options.attributeBits = args.attributeBits;
  options.normalBits = args.normalBits;
  ProgressLine progress;
  options.progress = [&](const kdmesh::EncodeProgress& p) { progress.update(p.phase, p.fraction); };
  const auto encodeStart = Clock::now();
  kdmesh::EncodeResult result = kdmesh::encode(complex, options);
  const double encodeSeconds = secondsSince(encodeStart);
  if (result.status.code == kdmesh::ErrorCode::LimitExceeded)
    result.status.message += " (--max-memory raises it)";
  if (!result.status.ok()) return fail(result.status, "cannot encode " + args.input);
  std::string error;
  if (!writeBytes(args.output, result.bytes, error)) return fail(error);
  reportRepairs(args.input, result.repairs);
  if (!gQuiet) {
    const double n = double(complex.vertexCount());
    std::fprintf(stderr,
                 "%s: %s, %s -> %zu bytes, %.3f bits/vertex (connectivity %.3f, "
                 "geometry %.3f) [read %.3fs, encode %.3fs]\n",
                 args.output.c_str(), counted(complex.vertexCount(), "vertex", "vertices").c_str(),
                 counted(complex.simplexCount(1) + complex.simplexCount(2) + complex.simplexCount(3), "simplex",
                         "simplices")
                     .c_str(),
                 result.bytes.size(), 8.0 * double(result.bytes.size()) / n,
                 result.cost.connectivityBits / n, result.cost.geometryBits / n, readSeconds,
                 encodeSeconds);
  }
  return 0;
}

struct DecodeArgs {
  std::string input, output;
  uint64_t bytes = 0;  // 0: the whole file
  bool asciiPly = false;
};

// A prefix of a stream holds simplices of lower dimension than the complete
// model (edges where triangles collapsed, triangles where tetrahedra did):
// written to a format that cannot hold some dimension, it keeps what the
// format holds. Returns what it left out, e.g. "1,204 edges", or "".
std::string keepWhatTheFormatHolds(kdmesh::io::Format format, kdmesh::Complex& complex) {
  using kdmesh::io::Format;
  // Which of edges, triangles and tetrahedra the format's writer takes.
  bool holds[3] = {true, true, true};
  switch (format) {
    case Format::Obj: holds[2] = false; break;
    case Format::Off: holds[0] = holds[2] = false; break;
    case Format::Xyz: holds[0] = holds[1] = holds[2] = false; break;
    case Format::TetGen: holds[0] = holds[1] = false; break;
    default: break;
  }
  std::vector<uint32_t>* lists[3] = {&complex.edges, &complex.triangles, &complex.tetrahedra};
  static const char* const kNames[3][2] = {{"edge", "edges"}, {"triangle", "triangles"}, {"tetrahedron", "tetrahedra"}};
  std::string dropped;
  for (int d = 0; d < 3; ++d) {
    if (holds[d] || lists[d]->empty()) continue;
    const size_t count = lists[d]->size() / size_t(d + 2);
    dropped += (dropped.empty() ? "" : ", ") + std::to_string(count) + " " + kNames[d][count > 1];
    lists[d]->clear();
  }
  if (dropped.empty()) return dropped;
  // The vertices in no simplex kept are the complex's points now.
  std::vector<uint8_t> used(complex.vertexCount(), 0);
  for (const std::vector<uint32_t>* list : lists)
    for (const uint32_t v : *list) used[v] = 1;
  complex.points.clear();
  for (uint32_t v = 0; v < used.size(); ++v)
    if (!used[v]) complex.points.push_back(v);
  return dropped;
}

int runDecodeGltf(const DecodeArgs& args) {
  if (!kdmesh::gltf::isGltfPath(args.output)) return fail("a glTF scene decodes to a glTF scene: give a .glb or .gltf output");
  if (args.bytes > 0) return fail("--bytes applies to .kdm streams only");
  const auto start = Clock::now();
  kdmesh::io::Notes notes;
  kdmesh::gltf::Summary summary;
  const kdmesh::Status s = kdmesh::gltf::decodeFile(args.input, args.output, notes, &summary);
  for (const std::string& n : notes) note(args.input + ": " + n);
  if (!s.ok()) return fail(s, "cannot decode " + args.input);
  reportGltf(args.output, summary, "decode", secondsSince(start));
  return 0;
}

int runDecode(const DecodeArgs& args) {
  if (kdmesh::gltf::isGltfPath(args.input)) return runDecodeGltf(args);
  std::vector<uint8_t> bytes;
  if (auto s = kdmesh::io::readBytes(args.input, bytes); !s.ok()) return fail(s, args.input);
  const bool prefix = args.bytes > 0 && args.bytes < bytes.size();
  if (prefix) bytes.resize(size_t(args.bytes));
  kdmesh::Complex complex;
  const auto start = Clock::now();
  if (auto s = kdmesh::decode(bytes.data(), bytes.size(), complex, prefix); !s.ok())
    return fail(s, args.input);
  const double seconds = secondsSince(start);
  kdmesh::io::WriteOptions writeOptions;
  writeOptions.asciiPly = args.asciiPly;
  const kdmesh::io::Format outputFormat = kdmesh::io::formatFromPath(args.output);
  std::string formatName = kdmesh::io::formatName(outputFormat);
  for (char& c : formatName) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (prefix) {
    const std::string dropped = keepWhatTheFormatHolds(outputFormat, complex);
    if (!dropped.empty()) note(args.output + ": left out " + dropped + " of the prefix, which " + formatName + " cannot hold");
  }
  // Attributes the output format cannot hold are left out, with a note
  // (glTF paths, of no io::Format, keep them).
  if (outputFormat != kdmesh::io::Format::Unknown) {
    std::string names;
    std::vector<kdmesh::VertexAttribute> kept;
    for (kdmesh::VertexAttribute& a : complex.attributes) {
      if (kdmesh::io::holdsAttribute(outputFormat, a)) kept.push_back(std::move(a));
      else names += (names.empty() ? "" : ", ") + oneLine(a.name);
    }
    complex.attributes = std::move(kept);
    if (!names.empty())
      note(args.output + ": left out the vertex attributes " + names + ", which " + formatName + " cannot hold");
  }
  const bool gltfOutput = kdmesh::gltf::isGltfPath(args.output);
  if (!complex.labels.empty() &&
      (gltfOutput || (!kdmesh::io::holdsLabels(outputFormat) && outputFormat != kdmesh::io::Format::Unknown))) {
    note(args.output + ": left out the simplex labels, which " + (gltfOutput ? std::string("glTF") : formatName) +
         " cannot hold");
    complex.labels = {};
  }
  if (gltfOutput) {
    kdmesh::io::Notes notes;
    const kdmesh::Status s = kdmesh::gltf::writeComplexScene(args.output, complex, notes);
    for (const std::string& n : notes) note(args.output + ": " + n);
    if (!s.ok()) return fail(s, args.output);
  } else if (auto s = kdmesh::io::writeFile(args.output, complex, writeOptions); !s.ok()) {
    return fail(s, args.output);
  }
  if (!gQuiet)
    std::fprintf(stderr, "%s: %zu vertices from %zu bytes%s [decode %.3fs]\n", args.output.c_str(),
                 complex.vertexCount(), bytes.size(), prefix ? " (prefix)" : "", seconds);
  return 0;
}

// A JSON string's contents: attribute names are printable ASCII (the
// decoder checks), so only quotes and backslashes need escaping.
std::string jsonEscaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

const char* codingName(const kdmesh::AttributeQuantization& q) {
  switch (q.kind) {
    case kdmesh::AttributeQuantization::Uniform: return "uniform";
    case kdmesh::AttributeQuantization::Octahedral: return "octahedral";
    case kdmesh::AttributeQuantization::GeometricOctahedral: return "geometric-octahedral";
    default: return "exact";
  }
}

// JSON has no inf or nan: those (from an empty model) print as null.
std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// How many distinct labels the simplices of a complex carry.
size_t distinctLabels(const kdmesh::Complex& complex) {
  std::vector<int32_t> labels;
  for (int d = 1; d <= 3; ++d) labels.insert(labels.end(), complex.labels.of(d).begin(), complex.labels.of(d).end());
  std::sort(labels.begin(), labels.end());
  return size_t(std::unique(labels.begin(), labels.end()) - labels.begin());
}

int runInfo(const std::string& input, bool json, bool perLevel) {
  std::vector<uint8_t> bytes;
  if (auto s = kdmesh::io::readBytes(input, bytes); !s.ok()) return fail(s, input);
  kdmesh::DecoderOptions options;
  options.measureCost = true;
  kdmesh::Decoder decoder(options);
  if (auto s = decoder.push(bytes.data(), bytes.size()); !s.ok()) return fail(s, input);
  if (auto s = decoder.finish(); !s.ok()) return fail(s, input);
  const kdmesh::Header& h = decoder.header();
  const double n = h.vertexCount;
  const kdmesh::CodingCost cost = decoder.cost();
  const kdmesh::ConnectivityStatistics stats = decoder.statistics();
  const bool grid = h.quantization == kdmesh::Quantization::Grid;
  if (json) {
    std::printf("{\n  \"version\": %u,\n  \"bytes\": %zu,\n  \"vertexCount\": %u,\n",
                unsigned(h.version), bytes.size(), h.vertexCount);
    std::printf("  \"maxDimension\": %u,\n  \"simplexCounts\": [%u, %u, %u, %u],\n",
                unsigned(h.maxDimension), h.simplexCounts[0], h.simplexCounts[1],
                h.simplexCounts[2], h.simplexCounts[3]);
    std::printf("  \"quantization\": \"%s\",\n  \"bits\": %u,\n", grid ? "grid" : h.float64() ? "float64" : "float32",
                unsigned(h.bits));
    std::printf("  \"axisBits\": [%d, %d, %d],\n", h.axisBits(0), h.axisBits(1), h.axisBits(2));
    std::printf("  \"fastDecode\": %s,\n", h.fastDecode ? "true" : "false");
    if (grid)
      std::printf("  \"origin\": [%s, %s, %s],\n  \"step\": %s,\n", jsonNumber(h.origin[0]).c_str(),
                  jsonNumber(h.origin[1]).c_str(), jsonNumber(h.origin[2]).c_str(),
                  jsonNumber(h.step).c_str());
    const kdmesh::Complex final = decoder.snapshot();
    std::printf("  \"labels\": {\"distinct\": %zu, \"bitsPerVertex\": %s},\n", distinctLabels(final),
                jsonNumber(cost.labelBits / n).c_str());
    std::printf("  \"attributes\": [");
    for (size_t a = 0; a < final.attributes.size(); ++a)
      std::printf("%s{\"name\": \"%s\", \"type\": \"%s\", \"components\": %u, \"coding\": \"%s\", "
                  "\"codingBits\": %u, \"bitsPerVertex\": %s}",
                  a ? ", " : "", jsonEscaped(final.attributes[a].name).c_str(),
                  kdmesh::attributeTypeName(final.attributes[a].type), unsigned(final.attributes[a].components),
                  codingName(final.attributes[a].quantization), unsigned(final.attributes[a].quantization.bits),
                  jsonNumber(cost.attributeBits[a] / n).c_str());
    std::printf("],\n");
    std::printf("  \"bitsPerVertex\": {\"total\": %s, \"geometry\": %s, \"connectivity\": %s},\n",
                jsonNumber(8.0 * double(bytes.size()) / n).c_str(),
                jsonNumber(cost.geometryBits / n).c_str(),
                jsonNumber(cost.connectivityBits / n).c_str());
    std::printf("  \"operators\": {\"vertexSplits\": %" PRIu64 ", \"edgeExpansions\": %" PRIu64
                ", \"fanExpansions\": %" PRIu64 ", \"codes\": [",
                stats.vertexSplits, stats.edgeExpansions, stats.fanExpansions);
    for (int d = 0; d < 4; ++d)
      std::printf("%s[%" PRIu64 ", %" PRIu64 ", %" PRIu64 ", %" PRIu64 "]", d ? ", " : "", stats.codes[d][0],
                  stats.codes[d][1], stats.codes[d][2], stats.codes[d][3]);
    std::printf("], \"orientationBits\": %" PRIu64 ", \"orientationMispredicted\": %" PRIu64 "},\n",
                stats.orientationBits, stats.orientationMispredicted);
    std::printf("  \"predictions\": {\"edgeCodesByDirection\": %" PRIu64 ", \"countPredictions\": %" PRIu64
                ", \"positionPredictions\": %" PRIu64 ", \"parallelogramPredictions\": %" PRIu64
                ", \"pairedTriangles\": %" PRIu64 ", \"closedFanEdgeCodes\": %" PRIu64
                ", \"cutCandidatePairs\": %" PRIu64 ", \"refinedNeighbourPredictions\": %" PRIu64 ", \"proxyPredictions\": %" PRIu64 "},\n",
                stats.edgeCodesByDirection, stats.countPredictions, stats.positionPredictions,
                stats.parallelogramPredictions, stats.pairedTriangles, stats.closedFanEdgeCodes,
                stats.cutCandidatePairs, stats.refinedNeighbourPredictions, stats.proxyPredictions);
    std::printf("  \"levels\": [");
    for (size_t i = 0; i < cost.levels.size(); ++i)
      std::printf("%s\n    {\"axis\": %d, \"cells\": %u, \"geometryBits\": %s, \"connectivityBits\": %s}",
                  i ? "," : "", cost.levels[i].axis, cost.levels[i].cells,
                  jsonNumber(cost.levels[i].geometryBits).c_str(), jsonNumber(cost.levels[i].connectivityBits).c_str());
    std::printf("\n  ],\n");
    std::printf("  \"chunks\": [");
    const auto& chunks = decoder.chunks();
    for (size_t i = 0; i < chunks.size(); ++i)
      std::printf("%s\n    {\"offset\": %" PRIu64 ", \"payloadBytes\": %u, \"splits\": %u}",
                  i ? "," : "", chunks[i].offset, chunks[i].payloadBytes, chunks[i].splitCount);
    std::printf("\n  ]\n}\n");
    return 0;
  }
  std::printf("kdmesh stream, format version %u, %zu bytes\n", unsigned(h.version), bytes.size());
  std::printf("vertices        %u\n", h.vertexCount);
  std::printf("simplices       %u points, %u edges, %u triangles, %u tetrahedra (max dim %u)\n",
              h.simplexCounts[0], h.simplexCounts[1], h.simplexCounts[2], h.simplexCounts[3],
              unsigned(h.maxDimension));
  if (grid)
    std::printf("quantization    grid, %u bits (x %d, y %d, z %d), step %.9g, origin (%.9g, %.9g, %.9g)\n",
                unsigned(h.bits), h.axisBits(0), h.axisBits(1), h.axisBits(2), h.step, h.origin[0],
                h.origin[1], h.origin[2]);
  else
    std::printf("quantization    exact %s (x %d, y %d, z %d bits of float32 image%s)\n",
                h.float64() ? "float64" : "float32", h.axisBits(0), h.axisBits(1), h.axisBits(2),
                h.float64() ? ", then residuals" : "");
  std::printf("kd-tree levels  %d\n", h.depth());
  if (h.maxDimension > 0)
    std::printf("predictions     %s\n", h.fastDecode ? "along the split axis (--fast-decode)"
                                                      : "from the decoded neighbourhood");
  double attributeBits = 0;
  for (const double bits : cost.attributeBits) attributeBits += bits;
  std::printf("bits/vertex     %.3f total: %.3f geometry, %.3f connectivity, %.3f attributes, %.3f labels, "
              "%.3f container\n",
              8.0 * double(bytes.size()) / n, cost.geometryBits / n, cost.connectivityBits / n, attributeBits / n,
              cost.labelBits / n,
              (8.0 * double(bytes.size()) - cost.geometryBits - cost.connectivityBits - attributeBits - cost.labelBits) /
                  n);
  const kdmesh::Complex final = decoder.snapshot();
  if (h.labelled) {
    const size_t simplices = final.labels.edges.size() + final.labels.triangles.size() + final.labels.tetrahedra.size();
    std::printf("labels          %zu distinct, %.3f bits/vertex, %.3f bits/simplex\n", distinctLabels(final),
                cost.labelBits / n, simplices ? cost.labelBits / double(simplices) : 0.0);
  }
  for (size_t a = 0; a < final.attributes.size(); ++a)
    std::printf("%s%s (%u %s, %s%s) %.3f bits/vertex\n", a == 0 ? "attributes      " : "                ",
                oneLine(final.attributes[a].name).c_str(), unsigned(final.attributes[a].components),
                kdmesh::attributeTypeName(final.attributes[a].type), codingName(final.attributes[a].quantization),
                final.attributes[a].quantization.bits
                    ? (" " + std::to_string(final.attributes[a].quantization.bits) + " bits").c_str()
                    : "",
                cost.attributeBits[a] / n);
  if (h.maxDimension > 0) {
    // As the paper's Table 1: which operator undid each of the n - 1 merges.
    std::printf("operators       %" PRIu64 " vertex splits (%.1f %% of %u merges), of which %" PRIu64
                " (%.1f %%) edge expansions\n",
                stats.vertexSplits, n > 1 ? 100.0 * double(stats.vertexSplits) / (n - 1) : 0.0,
                h.vertexCount - 1, stats.edgeExpansions,
                stats.vertexSplits ? 100.0 * double(stats.edgeExpansions) / double(stats.vertexSplits) : 0.0);
    if (stats.fanExpansions > 0)
      std::printf("                %" PRIu64 " edge expansions coded by their fan's two cuts\n", stats.fanExpansions);
    static const char* const kNames[4] = {"vertex", "edge", "triangle", "tetrahedron"};
    for (int d = 0; d < 4; ++d) {
      const auto& c = stats.codes[size_t(d)];
      if (c[0] + c[1] + c[2] + c[3] == 0) continue;
      std::printf("  %-11s   codes 1/2/3/4: %" PRIu64 " / %" PRIu64 " / %" PRIu64 " / %" PRIu64 "\n",
                  kNames[d], c[0], c[1], c[2], c[3]);
    }
    std::printf("  orientation   %" PRIu64 " decisions, %" PRIu64 " mispredicted\n", stats.orientationBits,
                stats.orientationMispredicted);
    std::printf("predictions     %" PRIu64 " edge codes by split direction, %" PRIu64
                " cell counts and %" PRIu64 " one-vertex splits from the neighbourhood (%" PRIu64
                " of them with parallelograms, %" PRIu64 " with neighbours split at the level already, %" PRIu64
                " of vertices in no simplex from the vertex they split from), %" PRIu64
                " triangles by pairing, %" PRIu64 " edge codes by their run around a closed fan (%" PRIu64
                " of two cut candidates)\n",
                stats.edgeCodesByDirection, stats.countPredictions, stats.positionPredictions,
                stats.parallelogramPredictions, stats.refinedNeighbourPredictions, stats.proxyPredictions,
                stats.pairedTriangles,
                stats.closedFanEdgeCodes, stats.cutCandidatePairs);
  }
  if (perLevel) {
    // How the bits build up level by level: a prefix of the stream that
    // reaches a level holds about the header and the bits coded so far.
    std::printf("levels          bits per vertex by kd-tree level; bytes: header and bits coded through the level\n");
    std::printf("  %5s %4s %10s %12s %9s %12s %10s\n", "level", "axis", "cells", "cell side", "geometry",
                "connectivity", "bytes");
    double bitsSoFar = 0;
    // Each level halves its axis's cells, from 2^axisBits grid steps.
    std::array<int, 3> bitsLeft{h.axisBits(0), h.axisBits(1), h.axisBits(2)};
    for (size_t i = 0; i < cost.levels.size(); ++i) {
      const kdmesh::LevelCost& level = cost.levels[i];
      bitsSoFar += level.geometryBits + level.connectivityBits;
      if (level.axis >= 0) --bitsLeft[size_t(level.axis)];
      char side[32] = "-";
      if (grid)
        std::snprintf(side, sizeof side, "%.4g",
                      std::ldexp(h.step, *std::max_element(bitsLeft.begin(), bitsLeft.end())));
      std::printf("  %5zu %4s %10u %12s %9.3f %12.3f %10.0f\n", i,
                  level.axis < 0 ? "-" : level.axis == 0 ? "x" : level.axis == 1 ? "y" : "z", level.cells, side,
                  level.geometryBits / n, level.connectivityBits / n, double(h.headerBytes) + bitsSoFar / 8);
    }
  }
  std::printf("chunks          %zu\n", decoder.chunks().size());
  std::printf("  %5s %10s %8s %10s\n", "chunk", "offset", "payload", "splits");
  for (size_t i = 0; i < decoder.chunks().size(); ++i) {
    const kdmesh::ChunkInfo& c = decoder.chunks()[i];
    std::printf("  %5zu %10" PRIu64 " %8u %10u\n", i, c.offset, c.payloadBytes, c.splitCount);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kdmesh: progressive lossless compression of point clouds and simplicial complexes"};
  app.require_subcommand(1);
  // Lets the subcommands pass options they do not know, such as --quiet, to
  // the main command: `kdmesh encode -q ...` works as well as `kdmesh -q encode ...`.
  // Inherited by the subcommands added below.
  app.fallthrough();
  app.add_flag("-q,--quiet", gQuiet, "No progress or statistics on stderr");

  EncodeArgs encodeArgs;
  CLI::App* encode = app.add_subcommand(
      "encode", "Compress a PLY, OBJ, OFF, XYZ, STL, Medit, TetGen or VTK file to .kdm, or the geometry of a glTF scene");
  encode->add_option("input", encodeArgs.input,
                     "Input file (.ply .obj .off .xyz .stl .mesh .node/.ele .vtk, or .glb .gltf)")
      ->required()
      ->check(CLI::ExistingFile);
  encode->add_option("-o,--output", encodeArgs.output, "Output .kdm file (.glb or .gltf for a glTF scene)")->required();
  auto* bits = encode->add_option("--bits", encodeArgs.bits,
                                  "Grid bits of the longest bounding-box axis (1-30)")
                   ->check(CLI::Range(1, 30))
                   ->capture_default_str();
  encode->add_flag("--exact", encodeArgs.exact,
                   "Keep every coordinate bit-exact (float64 ones of PLY double, Medit version 2 and "
                   "long OBJ decimals too)")
      ->excludes(bits);
  encode->add_option("--chunk-bytes", encodeArgs.chunkBytes,
                     "Largest chunk payload in bytes; the first chunks start at 1 KiB")
      ->check(CLI::Range(64, 1 << 26))
      ->capture_default_str();
  encode->add_option("--attr-bits", encodeArgs.attributeBits,
                     "Quantize float32 vertex attributes to N bits per component over each one's range "
                     "(1-24; lossy; default: exact)")
      ->check(CLI::Range(1, 24));
  encode->add_option("--normal-bits", encodeArgs.normalBits,
                     "Code the float32 x 3 attribute 'normal' as unit vectors in two N-bit octahedral "
                     "coordinates (2-16; lossy; default: exact, or --attr-bits); a surface's normals "
                     "come after its positions, predicted from its triangles")
      ->check(CLI::Range(2, 16));
  encode->add_flag("--fast-decode", encodeArgs.fastDecode,
                   "Predict vertices from their neighbours along the split axis only, not from the whole "
                   "decoded neighbourhood: meshes decode about twice as fast, in a larger stream "
                   "(docs/BENCHMARKS.md)");
  encode->add_flag("--points-only", encodeArgs.pointsOnly,
                   "Drop edges, triangles and tetrahedra and encode the vertices");
  encode->add_flag("--weld", encodeArgs.weld,
                   "Merge vertices with bit-identical positions (for STL triangle soups)");
  encode->add_option("--max-memory", encodeArgs.maxMemory,
                     "Refuse inputs whose encoding would take more memory than this (e.g. 4GB; 0: no "
                     "limit; default: three quarters of the machine's memory)")
      ->transform(CLI::AsSizeValue(false));
  encode->add_flag("--fallback", encodeArgs.fallback,
                   "glTF: keep the uncompressed accessors too, for loaders without the extension");
  encode->add_flag("--kdm-files", encodeArgs.kdmFiles,
                   "glTF: write each stream to a .kdm file next to the output, for pages to stream");

  DecodeArgs decodeArgs;
  CLI::App* decode = app.add_subcommand("decode", "Decompress a .kdm file (or a prefix of it)");
  decode->add_option("input", decodeArgs.input, "Input .kdm file, or a glTF scene with kdmesh streams")
      ->required()
      ->check(CLI::ExistingFile);
  decode->add_option("-o,--output", decodeArgs.output,
                     "Output file (.ply .obj .off .xyz .mesh .node .vtk .glb .gltf)")
      ->required();
  decode->add_option("--bytes", decodeArgs.bytes,
                     "Decode only the first N bytes: the model as a viewer sees it after N bytes");
  decode->add_flag("--ascii", decodeArgs.asciiPly, "Write ASCII instead of binary PLY");

  std::string infoInput;
  bool infoJson = false;
  CLI::App* info = app.add_subcommand("info", "Describe a .kdm file: header, chunks, bits per vertex");
  info->add_option("input", infoInput, "Input .kdm file")->required()->check(CLI::ExistingFile);
  info->add_flag("--json", infoJson, "Machine-readable output (lists the levels' bits)");
  bool infoLevels = false;
  info->add_flag("--levels", infoLevels,
                 "Bits per vertex of every kd-tree level, with the cell side it reaches and the bytes it takes");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and friends: CLI11 prints them and exits 0.
    if (e.get_exit_code() == 0) return app.exit(e);
    // Usage errors get the same one-line form as every other error.
    fail(std::string(e.what()) + " (run with --help for usage)");
    return e.get_exit_code();
  }
  try {
    encodeArgs.bitsGiven = bits->count() > 0;
    if (encode->parsed()) return runEncode(encodeArgs);
    if (decode->parsed()) return runDecode(decodeArgs);
    return runInfo(infoInput, infoJson, infoLevels);
  } catch (const std::bad_alloc&) {
    return fail(std::string("out of memory [") + kdmesh::errorCodeName(kdmesh::ErrorCode::LimitExceeded) + "]");
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}
