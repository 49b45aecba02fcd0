// Helpers shared by the in-process benchmarks.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"

namespace bench {

[[noreturn]] inline void fail(const std::string& message) {
  std::fprintf(stderr, "kdmesh bench: %s\n", message.c_str());
  std::exit(1);
}

// Median wall time of `runs` calls after one warm-up call, in seconds.
template <typename Body>
double medianSeconds(int runs, Body&& body) {
  body();
  std::vector<double> times;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    body();
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

inline kdmesh::Complex readModel(const std::string& path) {
  kdmesh::Complex complex;
  kdmesh::io::Notes notes;
  if (kdmesh::Status status = kdmesh::io::readFile(path, complex, notes); !status.ok())
    fail(path + ": " + status.message);
  return complex;
}

inline std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// One codec on one model: stream size and warm median times.
struct Measurement {
  size_t bytes = 0;
  double encodeSeconds = 0;
  double decodeSeconds = 0;
};

struct Arguments {
  int runs = 7;
  std::vector<int> bits;
  std::vector<std::string> models;
};

inline Arguments parseArguments(int argc, char** argv, const char* usage) {
  Arguments args;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--runs" && i + 1 < argc) {
      args.runs = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "--bits" && i + 1 < argc) {
      args.bits.push_back(std::atoi(argv[++i]));
    } else if (arg == "--help" || arg == "-h") {
      std::printf("%s\n", usage);
      std::exit(0);
    } else {
      args.models.push_back(arg);
    }
  }
  if (args.models.empty()) fail("no model given (try --help)");
  if (args.bits.empty()) args.bits.push_back(12);
  return args;
}

}  // namespace bench
