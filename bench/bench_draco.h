// Draco, measured the way the benchmarks measure kdmesh: encode and decode
// in this process, warm medians.
#pragma once

#include <type_traits>

#include "bench_common.h"
#include "draco/compression/decode.h"
#include "draco/compression/encode.h"

namespace bench {

// Encodes a draco::PointCloud or draco::Mesh at `bits` of position
// quantization and compression `level` (draco_encoder's -cl: speed 10 -
// level), then decodes it; `decodedCount` receives the points (clouds) or
// faces (meshes) that came back.
template <class Geometry>
Measurement measureDraco(const Geometry& geometry, int bits, int level, int runs, size_t& decodedCount) {
  constexpr bool kMesh = std::is_same_v<Geometry, draco::Mesh>;
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  encoder.SetSpeedOptions(10 - level, 10 - level);
  draco::EncoderBuffer buffer;
  Measurement m;
  m.encodeSeconds = medianSeconds(runs, [&] {
    buffer.Clear();
    draco::Status status;
    if constexpr (kMesh)
      status = encoder.EncodeMeshToBuffer(geometry, &buffer);
    else
      status = encoder.EncodePointCloudToBuffer(geometry, &buffer);
    if (!status.ok()) fail("draco encode: " + status.error_msg_string());
  });
  m.bytes = buffer.size();
  m.decodeSeconds = medianSeconds(runs, [&] {
    draco::DecoderBuffer input;
    input.Init(buffer.data(), buffer.size());
    draco::Decoder decoder;
    if constexpr (kMesh) {
      auto decoded = decoder.DecodeMeshFromBuffer(&input);
      if (!decoded.ok()) fail("draco decode: " + decoded.status().error_msg_string());
      decodedCount = decoded.value()->num_faces();
    } else {
      auto decoded = decoder.DecodePointCloudFromBuffer(&input);
      if (!decoded.ok()) fail("draco decode: " + decoded.status().error_msg_string());
      decodedCount = decoded.value()->num_points();
    }
  });
  return m;
}

}  // namespace bench
