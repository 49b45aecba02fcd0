// Writes the mutated streams of tests/native/mutations.h to files, with the
// native decoder's verdict on each, for the WebAssembly mutation suite
// (tests/js/mutations.test.mjs), which must reach the same verdicts.
//
//   kdmesh_write_mutations DIR [COUNT]
//
// DIR/0.kdm ... DIR/(COUNT-1).kdm, and DIR/verdicts.json: one record per
// stream, {"file", "kind", "code" ("ok" or the error code's name),
// "vertices", "triangles"} (the decoded counts; 0 after an error).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "mutations.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s DIR [COUNT]\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  const int count = argc == 3 ? std::atoi(argv[2]) : 600;
  if (count <= 0) {
    std::fprintf(stderr, "COUNT must be a positive number\n");
    return 2;
  }
  using namespace kdmesh;
  const std::vector<test::MutatedStream> streams = test::mutatedStreams(test::mutationSubject(), count, 29);
  if (streams.empty()) {
    std::fprintf(stderr, "the honest stream did not decode\n");
    return 1;
  }
  std::ofstream verdicts(dir + "/verdicts.json");
  verdicts << "[\n";
  for (size_t i = 0; i < streams.size(); ++i) {
    const std::string file = std::to_string(i) + ".kdm";
    std::ofstream out(dir + "/" + file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(streams[i].bytes.data()), std::streamsize(streams[i].bytes.size()));
    Complex decoded;
    const Status s = decode(streams[i].bytes.data(), streams[i].bytes.size(), decoded);
    verdicts << "  {\"file\": \"" << file << "\", \"kind\": \"" << streams[i].kind << "\", \"code\": \""
             << (s.ok() ? "ok" : errorCodeName(s.code)) << "\", \"vertices\": " << (s.ok() ? decoded.vertexCount() : 0)
             << ", \"triangles\": " << (s.ok() ? decoded.simplexCount(2) : 0) << "}"
             << (i + 1 < streams.size() ? ",\n" : "\n");
    if (!out) {
      std::fprintf(stderr, "cannot write %s/%s\n", dir.c_str(), file.c_str());
      return 1;
    }
  }
  verdicts << "]\n";
  return verdicts ? 0 : 1;
}
