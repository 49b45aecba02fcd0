// Mutated streams for the hostile-input tests: an honest stream with one
// kind of change each and every checksum made valid again, so that the
// decoder's own checks, not the checksums, must catch them. The native
// suite decodes them in test_stream.cpp; tests/tools/write_mutations.cpp
// writes them to files for the WebAssembly suite.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "complexes.h"
#include "container.h"
#include "kdmesh/kdmesh.h"

namespace kdmesh::test {

// The honest stream the mutations start from: a 16 × 28 torus at 10 bits
// in chunks of 256 bytes.
inline std::vector<uint8_t> mutationSubject() {
  EncodeOptions options;
  options.bits = 10;
  options.chunkBytes = 256;
  return encode(torusMesh(16, 28), options).bytes;
}

struct MutatedStream {
  std::string kind;  // "header", "chunk order" or "payload"
  std::vector<uint8_t> bytes;
};

// `count` mutations of `bytes` (a valid stream), in turn: a header field
// set to a small or random value (counts, extents, body size, chunk count,
// grid bits, dimension, step); two chunks swapped (or one of them dropped)
// with checksums for their new places; payload bytes replaced.
inline std::vector<MutatedStream> mutatedStreams(const std::vector<uint8_t>& bytes, int count, uint32_t seed) {
  Decoder reference;
  if (!reference.push(bytes.data(), bytes.size()).ok() || !reference.complete()) return {};
  const std::vector<ChunkInfo> chunks = reference.chunks();
  const Header honest = reference.header();
  std::mt19937 rng(seed);
  std::vector<MutatedStream> out;
  for (int trial = 0; trial < count; ++trial) {
    std::vector<uint8_t> body(bytes.begin() + honest.headerBytes, bytes.end());
    Header h = honest;
    std::string kind;
    switch (trial % 3) {
      case 0: {
        kind = "header";
        const uint32_t value = rng() % 4 == 0 ? rng() : rng() % 64;
        switch (rng() % 8) {
          case 0: h.vertexCount = value; break;
          case 1: h.simplexCounts[rng() % 4] = value; break;
          case 2: h.gridMax[rng() % 3] = value; break;
          case 3: h.bodyBytes = value; break;
          case 4: h.chunkCount = value; break;
          case 5: h.bits = uint8_t(value); break;
          case 6: h.maxDimension = uint8_t(value % 4); break;
          default: h.step = std::ldexp(double(value), int(rng() % 200) - 100); break;
        }
        break;
      }
      case 1: {
        kind = "chunk order";
        const size_t a = rng() % chunks.size(), b = rng() % chunks.size();
        std::vector<std::vector<uint8_t>> pieces;
        for (size_t i = 0; i < chunks.size(); ++i) {
          const size_t begin = chunks[i].offset - honest.headerBytes;
          const size_t end = i + 1 < chunks.size() ? chunks[i + 1].offset - honest.headerBytes : body.size();
          pieces.emplace_back(body.begin() + std::ptrdiff_t(begin), body.begin() + std::ptrdiff_t(end));
        }
        std::swap(pieces[a], pieces[b]);
        if (rng() % 2) pieces.erase(pieces.begin() + std::ptrdiff_t(b));
        body.clear();
        for (uint32_t i = 0; i < pieces.size(); ++i) {
          std::vector<uint8_t>& piece = pieces[i];
          const size_t checked = piece.size() - kChunkChecksumBytes;
          writeChunkChecksum(piece.data(), checked, i, piece.data() + checked);
          body.insert(body.end(), piece.begin(), piece.end());
        }
        break;
      }
      default: {
        kind = "payload";
        for (uint32_t i = 0; i < chunks.size(); ++i) {
          uint8_t* chunk = body.data() + (chunks[i].offset - honest.headerBytes);
          const size_t checked = chunks[i].frameBytes - kChunkChecksumBytes + chunks[i].payloadBytes;
          for (size_t k = chunks[i].frameBytes - kChunkChecksumBytes; k < checked; ++k)
            if (rng() % 16 == 0) chunk[k] = uint8_t(rng());
          writeChunkChecksum(chunk, checked, i, chunk + checked);
        }
      }
    }
    uint8_t header[kMaxHeaderBytes];
    MutatedStream mutated{kind, std::vector<uint8_t>(header, header + writeHeader(h, header))};
    mutated.bytes.insert(mutated.bytes.end(), body.begin(), body.end());
    out.push_back(std::move(mutated));
  }
  return out;
}

}  // namespace kdmesh::test
