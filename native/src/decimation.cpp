#include "decimation.h"

#include <algorithm>
#include <string>

#include "labels.h"
#include "vertex_split.h"

namespace kdmesh {
namespace {

const char* const kSimplexName[4] = {"point", "edge", "triangle", "tetrahedron"};

bool hasRepeatedVertex(const uint32_t* v, int arity) {
  for (int i = 0; i < arity; ++i)
    for (int j = i + 1; j < arity; ++j)
      if (v[i] == v[j]) return true;
  return false;
}

// The closure's simplices of one dimension in the order the build meets
// them: each as its tuple (in the listed or face order of its vertices) and
// the listed simplex it is (its index in the complex's list), or kNoSimplex
// for a face of a higher simplex.
struct Candidates {
  LargeArray<uint32_t> tuples;
  LargeArray<uint32_t> listed;
};

// Scratch bits of a record byte under construction; the final byte holds
// only code and targets.
constexpr uint8_t kHasCopy = 0x40, kHasAdded = 0x80;

// Merges record per-split runs last split first; this lays them out in split
// order. reversed holds split k's run at offset (total - begin[k + 1]).
template <class T>
void layOutInSplitOrder(const std::vector<T>& reversed, const std::vector<uint64_t>& length, std::vector<T>& out,
                        std::vector<uint64_t>& begin) {
  const size_t splits = length.size();
  begin.resize(splits + 1);
  out.resize(reversed.size());
  uint64_t at = 0;
  for (size_t k = 0; k < splits; ++k) {
    begin[k] = at;
    at += length[k];
  }
  begin[splits] = at;
  for (size_t k = 0; k < splits; ++k) {
    const uint64_t from = at - begin[k + 1];
    std::copy(reversed.begin() + std::ptrdiff_t(from), reversed.begin() + std::ptrdiff_t(from + length[k]),
              out.begin() + std::ptrdiff_t(begin[k]));
  }
}

}  // namespace

namespace {

// A counting sort: calls place(i, slot) for each item i in 0..count-1
// whose key(i) is below `keys` (others are left out), slots numbered in the
// order of keys, items of one key in their own order. Returns where each
// key's items start, then their end (keys + 1 values).
template <class Key, class Place>
std::vector<uint32_t> countingSort(size_t count, size_t keys, Key&& key, Place&& place) {
  std::vector<uint32_t> start(keys + 1, 0);
  for (size_t i = 0; i < count; ++i)
    if (const size_t k = key(i); k < keys) ++start[k + 1];
  for (size_t k = 0; k < keys; ++k) start[k + 1] += start[k];
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for (size_t i = 0; i < count; ++i)
    if (const size_t k = key(i); k < keys) place(i, next[k]++);
  return start;
}

// firstWithSameVertices() for tuples of kArity vertices. Each tuple becomes
// a record of its vertices but the least, ascending, and its index; the
// records are placed by least vertex (a counting sort, which keeps their
// order), and each vertex's records are sorted by the rest, equal sets by
// index, so that a run of one vertex set starts with its first tuple. The
// records, not indices into the tuples, are what moves: sorting indices
// read the tuples at random, a cache miss per comparison on large inputs.
template <size_t kArity>
LargeArray<uint32_t> firstWithSameVerticesOf(const LargeArray<uint32_t>& tuples, uint32_t vertexCount) {
  using Record = std::array<uint32_t, kArity>;  // [kArity - 1]: the tuple's index
  const size_t count = tuples.size() / kArity;
  if (count == 0) return {};
  LargeArray<Record> records(count);
  const std::vector<uint32_t> start = countingSort(
      count, vertexCount,
      [&tuples](size_t i) { return size_t(*std::min_element(&tuples[i * kArity], &tuples[i * kArity] + kArity)); },
      [&](size_t i, uint32_t slot) {
        std::array<uint32_t, kArity> v;
        std::copy_n(tuples.begin() + std::ptrdiff_t(i * kArity), kArity, v.begin());
        sortFewVertices(v.data(), int(kArity));
        Record& record = records[slot];
        std::copy_n(v.begin() + 1, kArity - 1, record.begin());
        record[kArity - 1] = uint32_t(i);
      });
  LargeArray<uint32_t> first(count);
  auto sameSet = [](const Record& a, const Record& b) { return std::equal(a.begin(), a.end() - 1, b.begin()); };
  for (size_t v = 0; v < vertexCount; ++v) {
    const auto begin = records.begin() + std::ptrdiff_t(start[v]);
    const auto end = records.begin() + std::ptrdiff_t(start[v + 1]);
    if (end - begin > 1) std::sort(begin, end);
    for (auto run = begin; run != end;) {
      auto past = run + 1;
      while (past != end && sameSet(*run, *past)) ++past;
      for (auto it = run; it != past; ++it) first[(*it)[kArity - 1]] = (*run)[kArity - 1];
      run = past;
    }
  }
  return first;
}

}  // namespace

LargeArray<uint32_t> firstWithSameVertices(const LargeArray<uint32_t>& tuples, int arity, uint32_t vertexCount) {
  switch (arity) {
    case 2:
      return firstWithSameVerticesOf<2>(tuples, vertexCount);
    case 3:
      return firstWithSameVerticesOf<3>(tuples, vertexCount);
    default:
      return firstWithSameVerticesOf<4>(tuples, vertexCount);
  }
}

Status buildInputComplex(const Complex& complex, const std::vector<uint32_t>& ids,
                         const std::vector<uint32_t>& kdRank, SimplexStore& store, InputSummary& summary) {
  const size_t n = complex.vertexCount();
  summary = InputSummary{};
  store.reset(uint32_t(n), true);
  std::vector<int32_t> table = labelTable(complex);
  if (!table.empty()) store.enableLabels();
  const std::vector<uint32_t>* lists[4] = {&complex.points, &complex.edges, &complex.triangles,
                                           &complex.tetrahedra};
  for (int d = 0; d <= 3; ++d) {
    const std::vector<uint32_t>& list = *lists[d];
    if (list.size() % size_t(d + 1) != 0)
      return Status::error(ErrorCode::InvalidInput,
                           std::string(kSimplexName[d]) + " indices are not a multiple of " +
                               std::to_string(d + 1));
    for (size_t i = 0; i < list.size(); ++i)
      if (list[i] >= n)
        return Status::error(ErrorCode::InvalidInput,
                             std::string(kSimplexName[d]) + " " + std::to_string(i / size_t(d + 1)) +
                                 " refers to vertex " + std::to_string(list[i]) + ", but there are " +
                                 std::to_string(n) + " vertices");
  }
  // Per dimension, the listed simplices after the faces of the dimension
  // above, each face after the simplex it bounds and in the order of the
  // vertex left out: the first simplex of each vertex set is kept. So a
  // listed face of a listed simplex is recognised (and counted redundant)
  // whatever the order of the lists, and faces appear in the order a walk
  // of the lists that added each missing face at once would add them.
  std::array<Candidates, 4> candidates;
  for (int d = 3; d >= 1; --d) {
    const size_t arity = size_t(d + 1);
    Candidates& mine = candidates[size_t(d)];
    const size_t faces = d < 3 ? candidates[size_t(d) + 1].listed.size() * (arity + 1) : 0;
    mine.tuples.reserve((faces + lists[d]->size() / arity) * arity);
    mine.listed.reserve(faces + lists[d]->size() / arity);
    if (d < 3) {
      const Candidates& above = candidates[size_t(d) + 1];
      for (size_t at = 0; at < above.tuples.size(); at += arity + 1)
        for (size_t skip = 0; skip <= arity; ++skip) {
          for (size_t i = 0; i <= arity; ++i)
            if (i != skip) mine.tuples.push_back(above.tuples[at + i]);
          mine.listed.push_back(kNoSimplex);
        }
    }
    const std::vector<uint32_t>& list = *lists[d];
    for (size_t i = 0; i < list.size(); i += arity) {
      uint32_t v[4];
      for (size_t j = 0; j < arity; ++j) v[j] = ids[list[i + j]];
      if (hasRepeatedVertex(v, d + 1)) {
        ++summary.repairs.degenerate[size_t(d)];
        continue;
      }
      mine.tuples.insert(mine.tuples.end(), v, v + arity);
      mine.listed.push_back(uint32_t(i / arity));
    }
  }
  for (int d = 3; d >= 1; --d) {
    Candidates& mine = candidates[size_t(d)];
    const size_t arity = size_t(d + 1);
    const LargeArray<uint32_t> first = firstWithSameVertices(mine.tuples, d + 1, uint32_t(n));
    for (size_t c = 0; c < first.size(); ++c)
      if (first[c] != c && mine.listed[c] != kNoSimplex)
        ++(mine.listed[first[c]] != kNoSimplex ? summary.repairs.duplicate : summary.repairs.redundant)[size_t(d)];
    // The kept simplices by the kd-tree rank of their first vertex in that
    // order (a counting sort): the simplices of a cell, at any level of the
    // tree, then lie together in the pools, where the decimation walks
    // them cell by cell, fine to coarse.
    auto leastRank = [&](size_t c) {
      uint32_t least = kdRank[mine.tuples[c * arity]];
      for (size_t i = 1; i < arity; ++i) least = std::min(least, kdRank[mine.tuples[c * arity + i]]);
      return least;
    };
    size_t kept = 0;
    for (size_t c = 0; c < first.size(); ++c) kept += first[c] == c;
    LargeArray<uint32_t> addOrder(kept);
    countingSort(
        first.size(), n, [&](size_t c) { return first[c] == c ? size_t(leastRank(c)) : n; },
        [&](size_t c, uint32_t slot) { addOrder[slot] = uint32_t(c); });
    // The pool at its final size at once, not grown by doubling.
    store.setCapacity(d, kNoSimplex, uint32_t(addOrder.size()));
    for (const uint32_t c : addOrder) {
      const uint32_t listed = mine.listed[c];
      const uint32_t* tuple = &mine.tuples[c * arity];
      if (listed == kNoSimplex) {
        store.add(d, tuple, 0);
        continue;
      }
      const uint32_t label =
          table.empty()
              ? kNoLabel
              : uint32_t(std::lower_bound(table.begin(), table.end(), labelOf(complex, d, listed)) - table.begin());
      store.add(d, tuple, SimplexStore::kMeaningful, label);
      ++summary.maximal[size_t(d)];
      summary.maxDimension = std::max(summary.maxDimension, d);
    }
    mine = Candidates{};  // the faces below were listed already
  }
  for (uint32_t point : complex.points)
    if (store.hasIncident(1, ids[point])) ++summary.repairs.redundant[0];
  if (!table.empty()) {
    // Only labels of kept simplices go to the stream's table.
    std::vector<uint32_t> renamed(table.size(), 0);
    for (int d = 1; d <= 3; ++d)
      for (uint32_t s = 0; s < store.size(d); ++s)
        if (store.label(d, s) != kNoLabel) renamed[store.label(d, s)] = 1;
    uint32_t kept = 0;
    for (size_t i = 0; i < table.size(); ++i) {
      const bool used = renamed[i] != 0;
      renamed[i] = kept;
      if (used) table[kept++] = table[i];
    }
    table.resize(kept);
    for (int d = 1; d <= 3; ++d)
      for (uint32_t s = 0; s < store.size(d); ++s)
        if (store.label(d, s) != kNoLabel) store.label(d, s) = renamed[store.label(d, s)];
    summary.labelTable = std::move(table);
  }
  for (uint32_t v = 0; v < n; ++v) summary.maximal[0] += !store.hasIncident(1, v);
  return Status::success();
}

void decimate(SimplexStore& store, const std::vector<VertexSplitIds>& splits,
              SplitRecords& records, const std::function<void(double)>& progress) {
  std::array<std::vector<uint8_t>, 4> scratch;  // record bytes under construction
  for (int d = 1; d <= 3; ++d) scratch[size_t(d)].assign(store.size(d), 0);
  // With labels, the labels of each simplex's copy and added simplex.
  const bool labelled = store.labelled();
  std::array<std::vector<uint32_t>, 4> copyLabel, addedLabel;
  if (labelled)
    for (int d = 1; d <= 3; ++d) {
      copyLabel[size_t(d)].assign(store.size(d), kNoLabel);
      addedLabel[size_t(d)].assign(store.size(d), kNoLabel);
    }
  // A simplex whose label is free takes the label of the simplex that the
  // decoder makes from it: it is then that simplex's likely prediction.
  auto inherit = [&store](int d, uint32_t simplex, uint32_t label) {
    uint32_t& mine = store.label(d, simplex);
    if (mine == kNoLabel) mine = label;
  };
  // Every simplex a merge looks up holds v1 and was in v1's star before
  // the merge (see below): it is looked up there, by binary search.
  std::vector<uint32_t> star2;
  std::vector<StarEntry> starOfKept, takenOver;
  std::array<size_t, 5> beginOfKept{};
  // The simplex of v1's star before the merge with these other vertices
  // (ascending, `dimension` of them), or kNoSimplex.
  auto findAroundKept = [&](int dimension, const uint32_t* others) {
    const StarEntry* entry = findInStar(starOfKept, beginOfKept, dimension, others);
    return entry ? entry->simplex : kNoSimplex;
  };
  // The vertices of a simplex but `skip` and `skipToo`, ascending (at most
  // three; `out` has room for the four that sortFewVertices() can order).
  auto othersBut = [&store](int d, uint32_t simplex, uint32_t skip, uint32_t skipToo, uint32_t (&out)[4]) {
    const uint32_t* v = store.vertices(d, simplex);
    int n = 0;
    for (int i = 0; i <= d; ++i)
      if (v[i] != skip && v[i] != skipToo) out[n++] = v[i];
    sortFewVertices(out, n);
  };
  records.bytes.clear();
  // Merges are recorded last split first, into `reversed`; each split's
  // length turns into its forward `begin` at the end.
  std::vector<uint64_t> recordLength(splits.size()), labelLength(labelled ? splits.size() : 0);
  std::vector<uint8_t> reversed;
  std::vector<uint32_t> reversedLabels;

  // Every kPrefetchBatch merges, the stars of the next ones' two vertices
  // are prefetched (SimplexStore::prefetchStars()).
  constexpr size_t kPrefetchBatch = 32;
  uint32_t comingVertices[2 * kPrefetchBatch];
  for (size_t k = splits.size(); k-- > 0;) {
    if (progress && (k & 0xffff) == 0) progress(1.0 - double(k) / double(splits.size()));
    if ((splits.size() - 1 - k) % kPrefetchBatch == 0) {
      size_t count = 0;
      for (size_t j = k + 1; j-- > 0 && count < 2 * kPrefetchBatch;) {
        comingVertices[count++] = splits[j].kept;
        comingVertices[count++] = splits[j].added;
      }
      store.prefetchStars(comingVertices, count);
    }
    const uint32_t v1 = splits[k].kept, v2 = splits[k].added;
    // A simplex of v2 with v1 loses v2 and its face without v2 holds v1;
    // one without v1 takes v1 for v2 and its twin, if any, holds v1. Both
    // lookups find simplices that hold v1 but not v2, and none of the merge's
    // changes makes or kills one: v1's star before the merge answers them.
    gatherStar(store, v1, starOfKept, beginOfKept);
    takenOver.clear();  // v2's simplices that take v1 for v2, by dimension
    const bool joined = findAroundKept(1, &v2) != kNoSimplex;
    uint32_t joiningLabel = kNoLabel;  // of the edge v1 v2

    for (int d = 1; d <= 3; ++d) {
      star2.clear();
      store.forEachIncident(d, v2, [&](uint32_t s, uint32_t) { star2.push_back(s); });
      store.detach(d, v2);
      for (const uint32_t s : star2) {
        const uint32_t* sv = store.vertices(d, s);
        const bool meaningful = store.flags(d, s) & SimplexStore::kMeaningful;
        const uint8_t target = d >= 2 && meaningful ? split_record::target(store.parity(d, s)) : 0;
        if (containsVertex(sv, d + 1, v1)) {
          // S = S' ∪ {v1, v2}: the decoder makes it by coding S' as 4.
          if (d >= 2) {
            uint32_t faceOthers[4];
            othersBut(d, s, v1, v2, faceOthers);
            const uint32_t parent = findAroundKept(d - 1, faceOthers);
            scratch[size_t(d - 1)][parent] |=
                uint8_t(kHasAdded | (target << split_record::kNewTargetShift));
            if (labelled) {
              addedLabel[size_t(d - 1)][parent] = store.label(d, s);
              inherit(d - 1, parent, store.label(d, s));
            }
          } else if (labelled) {
            joiningLabel = store.label(d, s);
          }
          store.kill(d, s);
          continue;
        }
        uint32_t twinOthers[4];
        othersBut(d, s, v2, v2, twinOthers);
        const uint32_t twin = findAroundKept(d, twinOthers);
        if (twin == kNoSimplex) {
          // Only v2 has it: code 2.
          const uint32_t position = uint32_t(std::find(sv, sv + d + 1, v2) - sv);
          store.setVertex(d, s, position, v1);
          store.link(d, s, position);
          scratch[size_t(d)][s] = 1;
          StarEntry& entry = takenOver.emplace_back();
          entry.simplex = s;
          entry.dimension = uint8_t(d);
          std::copy_n(twinOthers, 3, entry.others);
          continue;
        }
        // Both have it: code 3 (or 4, marked by the simplex one dimension up).
        scratch[size_t(d)][twin] |= uint8_t(kHasCopy | (target << split_record::kCopyTargetShift));
        if (labelled) {
          copyLabel[size_t(d)][twin] = store.label(d, s);
          inherit(d, twin, store.label(d, s));
        }
        uint8_t& twinFlags = store.flags(d, twin);
        if (d >= 2 && meaningful && !(twinFlags & SimplexStore::kMeaningful)) {
          // The coarse simplex takes the orientation of the one that matters.
          uint32_t merged[4];
          std::copy(sv, sv + d + 1, merged);
          *std::find(merged, merged + d + 1, v2) = v1;
          const int wanted = tupleParity(merged, d + 1) ^ ((store.flags(d, s) & SimplexStore::kFlipped) ? 1 : 0);
          if (store.parity(d, twin) != wanted) twinFlags ^= SimplexStore::kFlipped;
          twinFlags |= SimplexStore::kMeaningful;
        }
        store.kill(d, s);
      }
    }

    const size_t first = reversed.size();
    reversed.push_back(joined ? 3 : 2);
    const size_t firstLabel = reversedLabels.size();
    if (labelled && joined) reversedLabels.push_back(joiningLabel);
    auto record = [&](int d, uint32_t simplex) {
      uint8_t& bits = scratch[size_t(d)][simplex];
      const uint8_t code = (bits & kHasAdded) ? 3 : (bits & kHasCopy) ? 2 : (bits & split_record::kCodeMask);
      reversed.push_back(uint8_t(code | (bits & 0x3c)));
      if (labelled) {
        if (bits & kHasCopy) reversedLabels.push_back(copyLabel[size_t(d)][simplex]);
        if (bits & kHasAdded) reversedLabels.push_back(addedLabel[size_t(d)][simplex]);
      }
      bits = 0;
    };
    // One record per simplex of v1's star after the merge, in canonical
    // order: the simplices of its star before the merge that do not hold v2
    // (those that did were killed), merged with those taken over from v2.
    for (size_t d = 1, taken = 0; d <= 3; ++d) {
      const size_t takenFrom = taken;
      while (taken < takenOver.size() && takenOver[taken].dimension == d) ++taken;
      sortStarEntries(takenOver, takenFrom, taken, int(d));
      size_t next = takenFrom;
      for (size_t i = beginOfKept[d]; i < beginOfKept[d + 1]; ++i) {
        const StarEntry& kept = starOfKept[i];
        if (containsVertex(kept.others, int(d), v2)) continue;
        for (; next < taken && lessOthers(takenOver[next].others, kept.others, int(d)); ++next)
          record(int(d), takenOver[next].simplex);
        record(int(d), kept.simplex);
      }
      for (; next < taken; ++next) record(int(d), takenOver[next].simplex);
    }
    recordLength[k] = reversed.size() - first;
    if (labelled) labelLength[k] = reversedLabels.size() - firstLabel;
  }

  layOutInSplitOrder(reversed, recordLength, records.bytes, records.begin);
  if (labelled) layOutInSplitOrder(reversedLabels, labelLength, records.labels, records.labelBegin);
}

}  // namespace kdmesh
