#include "vertex_split.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace kdmesh {

bool lessOthers(const uint32_t* a, const uint32_t* b, int count) {
  for (int i = 0; i < count; ++i)
    if (a[i] != b[i]) return a[i] < b[i];
  return false;
}

namespace {

// Number of vertices of the simplex with a smaller id than `vertex`: the
// position `vertex` would take in the ascending tuple.
int rankOf(const uint32_t* vertices, int arity, uint32_t vertex) {
  int rank = 0;
  for (int i = 0; i < arity; ++i) rank += vertices[i] < vertex;
  return rank;
}

// The sort key of a simplex's other vertices when it has one or two (the
// order of lessOthers).
uint64_t othersKey(const uint32_t* others, int count) {
  return count == 1 ? others[0] : uint64_t(others[0]) << 32 | others[1];
}

// A key above every key that sortDistinctKeys() sorts.
constexpr uint64_t kPaddingKey = ~uint64_t(0);
constexpr int kNetworkKeys = 8;

// Sorts keys[0..n) ascending. The keys are distinct, and when n is at most
// kNetworkKeys, keys[n..kNetworkKeys) hold kPaddingKey, which sorts last: all
// kNetworkKeys then go through a fixed network of 19 compare-exchanges
// (Knuth's for eight inputs), minima and maxima with no branch on the keys
// or on n, where an insertion sort mispredicts about once per key.
void sortDistinctKeys(uint64_t* keys, int n) {
  if (n > kNetworkKeys) {
    std::sort(keys, keys + n);
    return;
  }
  static_assert(kNetworkKeys == 8);
  uint64_t k[kNetworkKeys];
  std::copy_n(keys, kNetworkKeys, k);
  // By masks: GCC compiles std::min and std::max of these keys to branches.
  auto order = [&k](int a, int b) {
    const uint64_t x = k[a], y = k[b];
    const uint64_t swap = (x ^ y) & (uint64_t(0) - uint64_t(y < x));
    k[a] = x ^ swap;
    k[b] = y ^ swap;
  };
  order(0, 2), order(1, 3), order(4, 6), order(5, 7);
  order(0, 4), order(1, 5), order(2, 6), order(3, 7);
  order(0, 1), order(2, 3), order(4, 5), order(6, 7);
  order(2, 4), order(3, 5);
  order(1, 4), order(3, 6);
  order(1, 2), order(3, 4), order(5, 6);
  std::copy_n(k, kNetworkKeys, keys);
}

}  // namespace

int splitBalance(uint32_t population, uint32_t first, bool geometric) {
  if (!geometric) return 0;
  const uint32_t second = population - first;
  if (population == 2) return 1;
  if (first <= 2 || second <= 2) return first == 1 ? 2 : second == 1 ? 3 : first == 2 ? 4 : 5;
  // The lower half's share below 0.35, up to 0.65 or above, compared exactly.
  const uint64_t scaledFirst = uint64_t(first) * 20, scaledPopulation = population;
  return scaledFirst < 7 * scaledPopulation ? 6 : scaledFirst <= 13 * scaledPopulation ? 7 : 8;
}

// Sorts star[first, last), the entries of dimension d, by their other
// vertices. A star's lists are short and arrive in no useful order: placing
// each entry at its rank (how many keys are smaller, counted over a fixed
// eight so that the count's loop always runs alike) takes no branch on the
// keys, where a comparison sort mispredicts about once per entry.
void sortStarEntries(std::vector<StarEntry>& star, size_t first, size_t last, int d) {
  constexpr size_t kRanked = 8;
  const size_t n = last - first;
  if (d > 2 || n > kRanked) {
    std::sort(star.begin() + std::ptrdiff_t(first), star.begin() + std::ptrdiff_t(last),
              [d](const StarEntry& a, const StarEntry& b) { return lessOthers(a.others, b.others, d); });
    return;
  }
  uint64_t keys[kRanked];
  for (size_t i = 0; i < kRanked; ++i) keys[i] = i < n ? othersKey(star[first + i].others, d) : ~uint64_t(0);
  StarEntry ranked[kRanked];
  for (size_t i = 0; i < n; ++i) {
    size_t rank = 0;
    for (size_t j = 0; j < kRanked; ++j) rank += keys[j] < keys[i];
    ranked[rank] = star[first + i];
  }
  std::copy(ranked, ranked + n, star.begin() + std::ptrdiff_t(first));
}

void gatherStar(SimplexStore& store, uint32_t v, std::vector<StarEntry>& star,
                std::array<size_t, 5>& begin) {
  star.clear();
  StarEntry entry{};
  entry.simplex = entry.copy = entry.added = kNoSimplex;
  star.push_back(entry);
  begin[0] = 0;
  for (int d = 1; d <= SimplexStore::kMaxDimension; ++d) {
    begin[size_t(d)] = star.size();
    store.forEachIncident(d, v, [&](uint32_t simplex, uint32_t position) {
      entry.simplex = simplex;
      entry.dimension = uint8_t(d);
      entry.position = uint8_t(position);
      const uint32_t* vertices = store.vertices(d, simplex);
      // Every vertex is written and the count advanced past all but v's:
      // no branch on where v lies in the tuple.
      uint32_t others[4];
      int n = 0;
      for (int i = 0; i <= d; ++i) {
        others[n] = vertices[i];
        n += i != int(position);
      }
      std::copy_n(others, 3, entry.others);
      sortFewVertices(entry.others, n);
      star.push_back(entry);
    });
    sortStarEntries(star, begin[size_t(d)], star.size(), d);
  }
  begin[4] = star.size();
}

// A binary search whose steps are conditional moves, not branches: which
// half holds the entry is a coin toss for the branch predictor.
const StarEntry* findInStar(const std::vector<StarEntry>& star, const std::array<size_t, 5>& begin, int dimension,
                            const uint32_t* others) {
  if (dimension == 0) return &star[0];
  const StarEntry* base = star.data() + begin[size_t(dimension)];
  size_t count = begin[size_t(dimension) + 1] - begin[size_t(dimension)];
  if (count == 0) return nullptr;
  if (dimension == 3) {  // three other vertices: no 64-bit key
    while (count > 1) {
      const size_t half = count / 2;
      base = lessOthers(others, base[half].others, 3) ? base : base + half;
      count -= half;
    }
    return std::equal(others, others + 3, base->others) ? base : nullptr;
  }
  const uint64_t key = othersKey(others, dimension);
  while (count > 1) {  // the entry, if present, is in base[0..count)
    const size_t half = count / 2;
    base = othersKey(base[half].others, dimension) <= key ? base + half : base;
    count -= half;
  }
  return othersKey(base->others, dimension) == key ? base : nullptr;
}

const VertexSplitter::Entry* VertexSplitter::findFace(int dimension, const uint32_t* others) const {
  return findInStar(star_, begin_, dimension, others);
}

uint8_t VertexSplitter::possibleCodes(const Entry& entry) const {
  const int d = entry.dimension;
  if (d == 0) return 0b1100;
  uint8_t possible = d == SimplexStore::kMaxDimension ? 0b0111 : 0b1111;
  if (d == 2) {  // linkFans found the two edges through v, or left a mark
    if (entry.links[0] == kNoSimplex) return 0;
    return possible & kAllowedBy[star_[entry.links[0]].code] & kAllowedBy[star_[entry.links[1]].code];
  }
  // Every face of the simplex through v: drop one of the other vertices.
  for (int skip = 0; skip < d; ++skip) {
    uint32_t faceOthers[3];
    int n = 0;
    for (int i = 0; i < d; ++i)
      if (i != skip) faceOthers[n++] = entry.others[i];
    const Entry* face = findFace(d - 1, faceOthers);
    if (face == nullptr) return 0;
    possible &= kAllowedBy[face->code];
  }
  return possible;
}

int directionBucket(double cosine) {
  static constexpr double kBounds[3] = {0.2, 0.45, 0.7};
  return countAtMost(std::fabs(cosine), kBounds);
}

// Where each edge's other vertex lies against the split: the cosine of the
// angle between the split axis and the direction from v's cell centre to
// it (negative: towards v's half, positive: towards v2's), and its length.
void VertexSplitter::measureEdges(uint32_t v, int level) {
  const size_t first = begin_[1], last = begin_[2];
  halfWidth_ = 0;
  if (!geometry_.geometric(level)) return;
  halfWidth_ = 1.0 / geometry_.inverseHalfWidth(level);
  cosines_.resize(last - first);
  lengths_.resize(last - first);
  const int axis = geometry_.axis(level);
  double from[3];
  geometry_.centreOf(v, from);
  double meanLength = 0;
  for (size_t i = first; i < last; ++i) {
    double to[3], squared = 0;
    geometry_.centreOf(star_[i].others[0], to);
    for (int a = 0; a < 3; ++a) {
      to[a] -= from[a];
      squared += to[a] * to[a];
    }
    const double length = std::sqrt(squared);
    lengths_[i - first] = length;
    meanLength += length;
    cosines_[i - first] = squared > 0 ? to[axis] / length : 0;
  }
  meanLength_ = last > first ? meanLength / double(last - first) : 0;
}

// The two edges that become triangles (code 4) of an edge expansion lie
// where the fan crosses the split plane, hence whether a fan neighbour lies
// on the other side, and which of the two is closer to the plane. Those two
// are also the apexes of the triangles on the new edge v v2, which lie
// close to it: a neighbour farther from v than the star's mean is less
// likely cut (the paper's Delaunay criterion, coarsely).
// Class 0: no geometry (splits of coincident vertices).
void VertexSplitter::classifyEdges() {
  const size_t first = begin_[1], last = begin_[2];
  if (halfWidth_ == 0) {
    for (size_t i = first; i < last; ++i) star_[i].geometry = 0;
    return;
  }
  statistics_.edgeCodesByDirection += last - first;
  // In a tetrahedral mesh an edge has many fan neighbours and no crossing
  // to speak of; what tells a cut edge there is its length against the
  // cell: a neighbour within a cell width or so of v lies near the split
  // plane's patch between v and v2, which the crossing class does not see.
  if (begin_[4] > begin_[3]) {
    for (size_t i = first; i < last; ++i) {
      // Length in half widths of the cell along the split axis.
      static constexpr double kReachBounds[2] = {2, 3};
      const int reach = countAtMost(lengths_[i - first] / halfWidth_, kReachBounds);
      star_[i].geometry = uint8_t(1 + reach * 8 + directionBucket(cosines_[i - first]));
    }
    return;
  }
  for (size_t i = first; i < last; ++i) {
    const double cosine = cosines_[i - first], magnitude = std::fabs(cosine);
    // Between a fan neighbour on v's side and one on v2's side lies a cut
    // edge: likely the one of the two closer to the split plane.
    int crossing = 0;
    for (const uint32_t neighbour : star_[i].links) {
      if (neighbour == kNoSimplex) continue;
      const double theirs = cosines_[neighbour - first];
      if ((theirs > 0) == (cosine > 0)) continue;
      crossing = magnitude <= std::fabs(theirs) ? 1 : std::max(crossing, 2);
      if (crossing == 1) break;
    }
    const bool longer = lengths_[i - first] > meanLength_;
    star_[i].geometry = uint8_t(1 + ((longer * 3 + crossing) * 2 + (cosine > 0)) * 4 + directionBucket(cosine));
  }
}

// Triangles between two cut edges. In an edge expansion of a
// tetrahedral mesh the cut edges go to the link of the new edge v v2, a
// cycle that passes each of them twice: of the triangles between two cut
// edges, those coded 4 (making the tetrahedra around v v2) are two per cut
// edge. Counting them for each cut edge makes some codes nearly certain:
// an edge with two already rules out more, an edge with as many candidates
// left as it lacks forces them. Returns how many there are (a surface's
// edge expansion has none unless its two cut edges share a triangle).
size_t VertexSplitter::countPairedTriangles() {
  size_t paired = 0;
  for (size_t t = begin_[2]; t < begin_[3]; ++t) {
    const Entry& triangle = star_[t];
    if (triangle.links[0] == kNoSimplex) continue;
    Entry& first = star_[triangle.links[0]];
    Entry& second = star_[triangle.links[1]];
    if (first.code < 3 || second.code < 3) continue;
    ++first.pairedTriangles;
    ++second.pairedTriangles;
    ++paired;
  }
  return paired;
}

// How far a triangle between two cut edges is from a forced code: for each
// edge, the candidates it has left beyond the code-4 triangles it lacks (0
// once it has its two); the lesser. kUnpaired for other triangles.
int VertexSplitter::pairingSlack(const Entry& triangle) const {
  if (triangle.links[0] == kNoSimplex) return kUnpaired;
  const Entry& first = star_[triangle.links[0]];
  const Entry& second = star_[triangle.links[1]];
  if (first.code < 3 || second.code < 3) return kUnpaired;
  auto slack = [](const Entry& edge) {
    const int lacking = std::max(0, 2 - int(edge.addedTriangles));
    return lacking == 0 ? 0 : int(edge.pairedTriangles) - lacking;
  };
  return std::min(slack(first), slack(second));
}

// Brings the most constrained of the triangles still to be coded to
// codingOrder_[step]: each code-4 decision there tightens the others.
// split() stops calling it once the paired triangles are coded (the rest
// keep their order), so a split costs O(paired × triangles) here.
void VertexSplitter::takeMostConstrainedTriangle(size_t step) {
  size_t best = step;
  int bestSlack = pairingSlack(star_[codingOrder_[step]]);
  // A bounded look-ahead: a star with thousands of paired triangles would
  // otherwise scan them all at each step.
  const size_t end = std::min(begin_[3], step + 1 + kPairingLookAhead);
  for (size_t k = step + 1; k < end && bestSlack > 0; ++k) {
    const int slack = pairingSlack(star_[codingOrder_[k]]);
    if (slack < bestSlack) {
      best = k;
      bestSlack = slack;
    }
  }
  std::swap(codingOrder_[step], codingOrder_[best]);
}

void VertexSplitter::orderCodes(bool geometric) {
  codingOrder_.resize(star_.size());
  for (size_t i = 0; i < star_.size(); ++i) codingOrder_[i] = uint32_t(i);
  if (!geometric) return;
  // A stable sort (edges at equal angles keep their canonical order) by
  // descending steepness. Stars are short: an insertion sort, without a
  // buffer; a long one (an edge in 100,000 triangles makes one) would take
  // it quadratic time, so it goes to std::stable_sort, which orders alike
  // when no cosine is NaN (with one, the insertion sort's order is kept).
  const size_t first = begin_[1], last = begin_[2];
  auto steepness = [this, first](uint32_t edge) { return std::fabs(cosines_[edge - first]); };
  if (last - first > kLongStar &&
      std::none_of(cosines_.begin(), cosines_.begin() + std::ptrdiff_t(last - first),
                   [](double c) { return std::isnan(c); })) {
    std::stable_sort(codingOrder_.begin() + std::ptrdiff_t(first), codingOrder_.begin() + std::ptrdiff_t(last),
                     [&](uint32_t a, uint32_t b) { return steepness(a) > steepness(b); });
    return;
  }
  for (size_t i = first + 1; i < last; ++i) {
    const uint32_t edge = codingOrder_[i];
    const double steepness = std::fabs(cosines_[edge - first]);
    size_t j = i;
    for (; j > first && std::fabs(cosines_[codingOrder_[j - 1] - first]) < steepness; --j)
      codingOrder_[j] = codingOrder_[j - 1];
    codingOrder_[j] = edge;
  }
}

// Edges of the star that share a triangle are fan neighbours: around a
// manifold vertex the codes run 1...1 4 2...2 4 along the fan, so the codes
// already given to an edge's fan neighbours say much about its own. Each
// edge links the first two (a manifold fan has no more); the full lists
// are made only for stars where some edge has more.
void VertexSplitter::linkFans() {
  for (size_t i = begin_[1]; i < begin_[3]; ++i) {
    star_[i].fanCodes = star_[i].addedTriangles = 0;
    star_[i].pairedTriangles = 0;
    star_[i].links[0] = star_[i].links[1] = kNoSimplex;
  }
  crowdedLinks_ = 0;
  // Fills the first free link, or counts the edge as crowded; written as
  // selects, as which link is free varies from edge to edge.
  auto link = [this](uint32_t from, uint32_t to) {
    uint32_t* links = star_[from].links;
    const bool firstFree = links[0] == kNoSimplex;
    const bool secondFree = !firstFree & (links[1] == kNoSimplex);
    links[0] = firstFree ? to : links[0];
    links[1] = secondFree ? to : links[1];
    crowdedLinks_ += !firstFree & !secondFree;
  };
  // A triangle's edges through v are found by their other vertex in
  // edgeTo_, which each split fills for its own edges: an entry left by an
  // earlier split names no edge of this star to that vertex.
  if (edgeTo_.size() < store_.vertexCapacity()) edgeTo_.resize(store_.vertexCapacity());
  for (size_t i = begin_[1]; i < begin_[2]; ++i) edgeTo_[star_[i].others[0]] = uint32_t(i);
  auto edgeTo = [this](uint32_t vertex) {
    const uint32_t i = edgeTo_[vertex];
    return i >= begin_[1] && i < begin_[2] && star_[i].others[0] == vertex ? i : kNoSimplex;
  };
  for (size_t i = begin_[2]; i < begin_[3]; ++i) {
    const uint32_t a = edgeTo(star_[i].others[0]), b = edgeTo(star_[i].others[1]);
    if (a == kNoSimplex || b == kNoSimplex) continue;
    star_[i].links[0] = a;
    star_[i].links[1] = b;
    link(a, b);
    link(b, a);
  }
  // Most stars (those of surfaces) have no edge in more than two
  // triangles: their links list every fan neighbour already.
  if (!crowdedFans()) {
    indexFan();
    return;
  }
  fanSize_ = 0;
  const size_t edges = begin_[2] - begin_[1];
  fanStart_.assign(edges + 1, 0);
  for (size_t i = begin_[2]; i < begin_[3]; ++i) {
    if (star_[i].links[0] == kNoSimplex) continue;
    ++fanStart_[star_[i].links[0] - begin_[1] + 1];
    ++fanStart_[star_[i].links[1] - begin_[1] + 1];
  }
  for (size_t e = 0; e < edges; ++e) fanStart_[e + 1] += fanStart_[e];
  fanList_.resize(fanStart_[edges]);
  fanFill_.assign(fanStart_.begin(), fanStart_.end() - 1);
  for (size_t i = begin_[2]; i < begin_[3]; ++i) {
    const uint32_t a = star_[i].links[0], b = star_[i].links[1];
    if (a == kNoSimplex) continue;
    fanList_[fanFill_[a - begin_[1]]++] = b;
    fanList_[fanFill_[b - begin_[1]]++] = a;
  }
}

bool VertexSplitter::gatherClosedFan(uint32_t v) {
  constexpr int kMax = kLeanFanEdges;
  static_assert(kMax >= kNetworkKeys);
  if (store_.hasIncident(3, v)) return false;
  // The edges, in canonical order (by their other vertex): keys of the
  // other vertex and the list position, sorted.
  const SimplexStore::Lists edges = store_.lists(1);
  uint64_t edgeKeys[kMax];
  std::fill_n(edgeKeys, kNetworkKeys, kPaddingKey);
  uint32_t edgeSlots[kMax];
  int n = 0;
  for (uint32_t slot = edges.heads[v]; slot != kNoSimplex; slot = edges.next[slot]) {
    if (!edges.alive(slot >> 1)) continue;
    if (n == kMax) return false;
    edgeKeys[n] = uint64_t(edges.vertices[slot ^ 1]) << 8 | uint64_t(n);
    edgeSlots[n++] = slot;
  }
  if (n < 3) return false;
  sortDistinctKeys(edgeKeys, n);
  if (edgeTo_.size() < store_.vertexCapacity()) edgeTo_.resize(store_.vertexCapacity());
  // The entries as gatherStar() leaves them (the triangles' below), then
  // the links and the fan order as linkFans() and indexFan() make them.
  star_.resize(size_t(1 + 2 * n));
  StarEntry entry{};
  entry.simplex = entry.copy = entry.added = kNoSimplex;
  star_[0] = entry;
  entry.links[0] = entry.links[1] = kNoSimplex;
  for (int e = 0; e < n; ++e) {
    const uint32_t other = uint32_t(edgeKeys[e] >> 8), slot = edgeSlots[edgeKeys[e] & 0xff];
    edgeTo_[other] = uint32_t(1 + e);
    StarEntry& edge = star_[size_t(1 + e)];
    edge = entry;
    edge.simplex = slot >> 1;
    edge.dimension = 1;
    edge.position = uint8_t(slot & 1);
    edge.others[0] = other;
  }
  // The star index of the edge to `vertex`, or kNoSimplex.
  auto edgeTo = [&](uint32_t vertex) {
    const uint32_t i = edgeTo_[vertex];
    return i - 1 < uint32_t(n) && edgeKeys[i - 1] >> 8 == vertex ? i : kNoSimplex;
  };
  // The triangles, each by the star indices of its two edges through v.
  // Their canonical order (by their other vertices) is that of these index
  // pairs, smaller first: keys of the pair and the list position, sorted.
  const SimplexStore::Lists triangles = store_.lists(2);
  uint64_t triangleKeys[kMax];
  std::fill_n(triangleKeys, kNetworkKeys, kPaddingKey);
  uint32_t triangleSlots[kMax];
  int t = 0;
  for (uint32_t slot = triangles.heads[v]; slot != kNoSimplex; slot = triangles.next[slot]) {
    const uint32_t triangle = slot / 3;
    if (!triangles.alive(triangle)) continue;
    if (t == n) return false;  // more triangles than edges: no closed fan
    const uint32_t* tuple = triangles.vertices + size_t(triangle) * 3;
    const uint32_t position = slot - triangle * 3;
    const uint32_t a = edgeTo(tuple[position == 0 ? 1 : 0]), b = edgeTo(tuple[position == 2 ? 1 : 2]);
    if (a == kNoSimplex || b == kNoSimplex || a == b) return false;
    // The smaller index first, by arithmetic: which one it is is a coin toss.
    const uint32_t swap = (a ^ b) & (0u - uint32_t(b < a));
    triangleKeys[t] = uint64_t(a ^ swap) << 16 | uint64_t(b ^ swap) << 8 | uint64_t(t);
    triangleSlots[t++] = slot;
  }
  if (t != n) return false;
  sortDistinctKeys(triangleKeys, n);
  // Each triangle links its two edges, in canonical order as linkFans()
  // does; a fan has two links per edge and no more. Which link is free is
  // counted per edge, not tested.
  uint8_t linked[kMax + 1] = {};
  bool room = true;
  auto link = [&](uint32_t from, uint32_t to) {
    star_[from].links[linked[from] != 0] = to;
    room &= linked[from] < 2;
    ++linked[from];
  };
  for (int k = 0; k < n; ++k) {
    const uint64_t key = triangleKeys[k];
    const uint32_t a = uint32_t(key >> 16), b = uint32_t(key >> 8) & 0xff, slot = triangleSlots[key & 0xff];
    StarEntry& triangle = star_[size_t(1 + n + k)];
    triangle = entry;
    triangle.simplex = slot / 3;
    triangle.dimension = 2;
    triangle.position = uint8_t(slot - triangle.simplex * 3);
    triangle.others[0] = star_[a].others[0];
    triangle.others[1] = star_[b].others[0];
    triangle.links[0] = a;
    triangle.links[1] = b;
    link(a, b);
    link(b, a);
  }
  if (!room) return false;
  begin_ = {0, 1, size_t(1 + n), size_t(1 + 2 * n), size_t(1 + 2 * n)};
  crowdedLinks_ = 0;
  indexFan();
  if (fanSize_ == 0) return false;
#ifdef KDMESH_CHECK_FANS
  // The general path must find the same star.
  const std::vector<StarEntry> lean = star_;
  const std::vector<uint32_t> leanOrder = fanOrder_;
  gatherStar(store_, v, star_, begin_);
  linkFans();
  if (fanSize_ != n || fanOrder_ != leanOrder || star_.size() != lean.size()) std::abort();
  for (size_t i = 0; i < lean.size(); ++i) {
    const StarEntry &a = lean[i], &b = star_[i];
    const bool sameOthers = std::equal(a.others, a.others + a.dimension, b.others);
    const bool sameLinks = a.dimension == 0 || (a.links[0] == b.links[0] && a.links[1] == b.links[1]);
    if (a.simplex != b.simplex || a.dimension != b.dimension || a.position != b.position || !sameOthers ||
        !sameLinks || (a.dimension == 1 && a.fanIndex != b.fanIndex))
      std::abort();
  }
#endif
  return true;
}

// Numbers the edges around the fan when the star's edges form one closed
// fan (each in two triangles, one cycle); fanSize_ is 0 otherwise.
void VertexSplitter::indexFan() {
  fanSize_ = 0;
  firstCut_ = -1;
  const size_t first = begin_[1], last = begin_[2];
  if (last - first < 3 || last - first > 255) return;
  // Links are mutual (linkFans() made each both ways, none dropped), so
  // the edge the walk came from is one of the two links and the next is
  // the other: their exclusive or without the previous one. Starting as
  // if from links[1] walks on to links[0]. An edge with one link ends the
  // walk (no closed fan); one the walk does not reach leaves it short.
  const size_t edges = last - first;
  fanOrder_.resize(edges);
  uint32_t previous = star_[first].links[1], at = uint32_t(first);
  size_t walked = 0;
  do {
    if (star_[at].links[1] == kNoSimplex) return;
    star_[at].fanIndex = uint8_t(walked);
    fanOrder_[walked++] = at;
    const uint32_t next = star_[at].links[0] ^ star_[at].links[1] ^ previous;
    previous = at;
    at = next;
  } while (at != first && walked < edges);
  if (at == first && walked == edges) fanSize_ = int(edges);
}

int VertexSplitter::cutBand(int position, int cut) const {
  const int apart = std::abs(position - cut);
  const int distance = std::min(apart, fanSize_ - apart), half = fanSize_ / 2;
  return std::clamp(distance - half + 4, 1, 4);  // 4 from half on, 3 and 2 just below
}

int VertexSplitter::fanSlot(const Entry& triangle) const {
  const int a = star_[triangle.links[0]].fanIndex, b = star_[triangle.links[1]].fanIndex;
  return fanNext(a) == b ? a : b;
}

// The star is one closed fan (closedFanStar()): its records make an edge
// expansion when the vertex is coded 4 and exactly two edges are, the other
// edges are coded 1 or 2, alike along each arc between the two and
// different on the two arcs, and each triangle goes where its arc's edges
// go (an arc without edges: where the other arc's do not).
bool VertexSplitter::recordsFormFanExpansion() const {
  auto code = [](const Entry& entry) { return (entry.record & split_record::kCodeMask) + 1; };
  if (code(star_[0]) != 4) return false;
  const int n = fanSize_;
  int cuts[2], found = 0;
  for (int k = 0; k < n; ++k) {
    const int c = code(star_[fanOrder_[size_t(k)]]);
    if (c == 3) return false;
    if (c != 4) continue;
    if (found == 2) return false;
    cuts[found++] = k;
  }
  if (found != 2) return false;
  // sides[0]: the arc from the first cut to the second, sides[1]: the other.
  int sides[2] = {0, 0};
  for (int k = 0; k < n; ++k) {
    if (k == cuts[0] || k == cuts[1]) continue;
    const int c = code(star_[fanOrder_[size_t(k)]]);
    int& side = sides[k > cuts[0] && k < cuts[1] ? 0 : 1];
    if (side != 0 && side != c) return false;
    side = c;
  }
  if (sides[0] == 0) sides[0] = 3 - sides[1];
  if (sides[1] == 0) sides[1] = 3 - sides[0];
  if (sides[0] + sides[1] != 3) return false;
  for (size_t t = begin_[2]; t < begin_[3]; ++t) {
    const int slot = fanSlot(star_[t]);
    if (code(star_[t]) != sides[slot >= cuts[0] && slot < cuts[1] ? 0 : 1]) return false;
  }
  return true;
}

namespace {

// Edge classes of runClass(), VertexSplitter::kRunClasses in all.
constexpr int kOpenFanClasses = 32;               // fan codes × in 3+ triangles × v v2 joined
constexpr int kUncodedFan = kOpenFanClasses;      // a closed fan with no code yet
constexpr int kRunBase = kUncodedFan + 1;         // 6 pairs of end codes × 4 run shapes
constexpr int kPairBase = kRunBase + 24;          // two candidates between a 1 and a 2: 3 × 3

// A vertex's edges, counted up to 16: enough to compare two valences, and
// a hub's long list is not walked at every split of its neighbours.
int cappedValence(const SimplexStore& store, uint32_t vertex) {
  int edges = 0;
  store.forEachIncident(1, vertex, [&edges](uint32_t, uint32_t) { return ++edges == 16; });
  return edges;
}

}  // namespace

// Around a manifold vertex an edge expansion's codes run 1…1 c 2…2 c along
// the fan (c: a cut edge, coded 4), so the codes already given around the
// fan say much about an uncoded edge: the run of uncoded edges that holds
// it lies between two coded ends, and a run between a 1 and a 2 holds a
// cut, which the immediate fan neighbours' codes alone do not say. Once a
// cut is known, the other lies about half way around (×kCutBands: how far
// this edge is from it). A star that is not one closed fan is classed by the immediate
// fan neighbours' codes, by whether the edge is in three or more
// triangles, and by whether v and v2 are joined.
int VertexSplitter::runClass(const Entry& edge, int cutEdges, bool mirrored) {
  static_assert(kPairBase + 9 == kRunClasses);
  if (fanSize_ == 0) {
    const size_t e = size_t(&edge - star_.data()) - begin_[1];
    const bool crowdedEdge = crowdedFans() && fanStart_[e + 1] - fanStart_[e] > 2;
    return mirrorSet(edge.fanCodes, mirrored) + 8 * crowdedEdge + 16 * (star_[0].code == 4);
  }
  // The code (0: 1, 1: 2, 2: cut) and distance of the nearest coded edge
  // each way around; -1 when none is coded yet.
  auto endOf = [&](int step, int& distance) {
    int at = edge.fanIndex;
    for (distance = 1; distance < fanSize_; ++distance) {
      at = step > 0 ? fanNext(at) : fanPrevious(at);
      const uint8_t code = star_[fanOrder_[size_t(at)]].code;
      if (code != 0) return std::min(code - 1, 2);
    }
    return -1;
  };
  ++statistics_.closedFanEdgeCodes;
  int before, after;
  const int a = endOf(-1, before);
  if (a < 0) return kUncodedFan;
  const int b = endOf(1, after);
  const int band = cutEdges == 1 ? cutBand(edge.fanIndex, firstCut_) : 0;
  const int low = std::min(a, b), high = std::max(a, b);
  const int ends = low == 0 ? high : low == 1 ? 2 + high : 5;  // 1-1 1-2 1-c 2-2 2-c c-c
  const int run = before + after - 1;
  int shape;
  if (ends == 1 && run == 2 && halfWidth_ > 0) {
    // Two uncoded edges between a 1 and a 2, one of them cut: the two
    // choices triangulate the quadrilateral v e o v2 (e this edge, o the
    // other, v and v2 taken at the centres of their halves) with the
    // diagonal from e to the far half or from o to the near one; the
    // shorter is the likelier (the Delaunay criterion). A cut neighbour
    // gains an edge, and meshes keep valences even: the one with fewer
    // edges is the likelier cut.
    const bool besideOne = (before == 1 ? a : b) == 0;
    const uint32_t other = fanOrder_[size_t(before == 1 ? fanNext(edge.fanIndex) : fanPrevious(edge.fanIndex))];
    const size_t e = size_t(&edge - star_.data()) - begin_[1], o = size_t(other) - begin_[1];
    const double alongE = cosines_[e] * lengths_[e], alongO = cosines_[o] * lengths_[o];
    const double preference = lengths_[e] * lengths_[e] - lengths_[o] * lengths_[o] +
                              (besideOne ? -halfWidth_ : halfWidth_) * (alongE + alongO);
    const double tie = 0.1 * halfWidth_ * halfWidth_;
    const int leaning = preference < -tie ? 0 : preference > tie ? 2 : 1;
    const int mine = cappedValence(store_, edge.others[0]), theirs = cappedValence(store_, star_[other].others[0]);
    shape = kPairBase + leaning * 3 + (mine < theirs ? 0 : mine == theirs ? 1 : 2);
    ++statistics_.cutCandidatePairs;
  } else {
    const int form = run == 1 ? 0 : run == 2 ? 1 : std::min(before, after) == 1 ? 2 : 3;
    shape = kRunBase + ends * 4 + form;
  }
  return band * kRunClasses + shape;
}

// Whether v and v2 are joined: a star that is one closed fan is that of an
// edge collapse, nearly always; one whose edges are in three or more
// triangles is that of two vertices that met in a cell without an edge
// between them, the more often the more such edges (classes by the extra
// fan neighbours, 0..4 and more); and whether the cell held two vertices
// (rather than one model for all).
int VertexSplitter::vertexClass(int balance) const {
  const int shape = fanSize_ > 0 ? 0 : 1 + std::min(crowdedLinks_, 4);
  return shape * 2 + (balance == 1);
}

// A triangle v a b by the directions of a and b (classifyEdges): on the
// same side of the split plane or not, and how close each is to it. Its
// edges va and vb exist (possibleCodes checked), so linkFans linked them.
int VertexSplitter::triangleClass(const Entry& triangle) const {
  const double ca = cosines_[triangle.links[0] - begin_[1]];
  const double cb = cosines_[triangle.links[1] - begin_[1]];
  static constexpr double kBounds[2] = {0.2, 0.45};
  auto bucket = [](double c) { return countAtMost(std::fabs(c), kBounds); };
  const int low = std::min(bucket(ca), bucket(cb)), high = std::max(bucket(ca), bucket(cb));
  return ((ca > 0) == (cb > 0)) * 9 + low * 3 + high;
}

// After a split, the simplices around v and v2 are exactly the star's
// simplices and their copies and additions: the neighbours that orient the
// new ones are found there without walking the vertex lists.
const std::vector<uint32_t>& VertexSplitter::around(int dimension) {
  std::vector<uint32_t>& list = around_[size_t(dimension)];
  if (aroundReady_[size_t(dimension)]) return list;
  aroundReady_[size_t(dimension)] = true;
  list.clear();
  for (size_t i = begin_[size_t(dimension) - 1]; i < begin_[size_t(dimension) + 1]; ++i) {
    const StarEntry& entry = star_[i];
    if (entry.dimension == dimension) {
      list.push_back(entry.simplex);
      if (entry.copy != kNoSimplex) list.push_back(entry.copy);
    } else if (entry.added != kNoSimplex) {
      list.push_back(entry.added);
    }
  }
  // Large stars get an index of their simplices' facets with, per facet,
  // how many decided simplices induce each orientation on it: a vote then
  // reads the counts of its simplex's facets instead of polling the star.
  std::vector<FacetEntry>& facets = facets_[size_t(dimension)];
  facets.clear();
  if (list.size() > kIndexedStar) {
    for (const uint32_t simplex : list)
      for (int skip = 0; skip <= dimension; ++skip)
        facets.push_back({facetKey(dimension, simplex, skip), {0, 0}});
    std::sort(facets.begin(), facets.end(),
              [](const FacetEntry& a, const FacetEntry& b) { return a.key < b.key; });
    for (const uint32_t simplex : list)
      if (!(store_.flags(dimension, simplex) & SimplexStore::kUndecided)) countDecided(dimension, simplex);
  }
  return list;
}

VertexSplitter::FacetEntry& VertexSplitter::facetOf(int dimension, uint32_t simplex, int skip) {
  std::vector<FacetEntry>& facets = facets_[size_t(dimension)];
  const FacetKey key = facetKey(dimension, simplex, skip);
  // The first entry of the facet's run holds its counts; every simplex of
  // the list has its facets in the index.
  return *std::lower_bound(facets.begin(), facets.end(), key,
                           [](const FacetEntry& entry, const FacetKey& k) { return entry.key < k; });
}

// The orientation a simplex induces on its facet without the vertex at
// `skip`: its parity and the rank of that vertex.
int VertexSplitter::inducedSign(int dimension, uint32_t simplex, int skip) const {
  const uint32_t* v = store_.vertices(dimension, simplex);
  return store_.parity(dimension, simplex) ^ (rankOf(v, dimension + 1, v[skip]) & 1);
}

void VertexSplitter::countDecided(int dimension, uint32_t simplex) {
  for (int skip = 0; skip <= dimension; ++skip)
    ++facetOf(dimension, simplex, skip).decided[inducedSign(dimension, simplex, skip)];
}

bool VertexSplitter::isFaceOfHigher(int dimension, uint32_t simplex) {
  // A complex without simplices one dimension up (a surface's has no
  // tetrahedra) has nothing to look up.
  if (dimension >= SimplexStore::kMaxDimension || store_.size(dimension + 1) == 0) return false;
  // around() lists at most two simplices per star entry: a smaller star
  // gets no index.
  if (star_.size() * 2 > kIndexedStar) {
    around(dimension + 1);
    const std::vector<FacetEntry>& facets = facets_[size_t(dimension) + 1];
    if (!facets.empty()) {
      const FacetKey key = facetKey(dimension, simplex, dimension + 1);
      const auto at = std::lower_bound(facets.begin(), facets.end(), key,
                                       [](const FacetEntry& entry, const FacetKey& k) { return entry.key < k; });
      return at != facets.end() && !(key < at->key);
    }
  }
  const uint32_t* mine = store_.vertices(dimension, simplex);
  return std::as_const(store_).forEachIncident(dimension + 1, newVertex_, [&](uint32_t candidate, uint32_t) {
    const uint32_t* theirs = store_.vertices(dimension + 1, candidate);
    bool all = true;
    for (int i = 0; i <= dimension; ++i) all &= containsVertex(theirs, dimension + 2, mine[i]);
    return all;
  });
}

// The vertices of a simplex but the one at `skip` (all of them when `skip`
// is past the last; at most three either way), ascending, as one key: the
// first two ids in one word, the third, or 0, in the other.
VertexSplitter::FacetKey VertexSplitter::facetKey(int dimension, uint32_t simplex, int skip) const {
  const uint32_t* v = store_.vertices(dimension, simplex);
  uint32_t facet[4] = {0, 0, 0, 0};  // room for the four sortFewVertices() can order
  int n = 0;
  for (int i = 0; i <= dimension; ++i)
    if (i != skip) facet[n++] = v[i];
  sortFewVertices(facet, n);
  return {uint64_t(facet[0]) << 32 | facet[1], facet[2]};
}

// The vote of predictFlip for simplices of kArity vertices, the arity known
// at compile time so that the comparisons unroll without branches. A
// neighbour is a decided simplex one vertex apart (sharing a facet), and
// it votes for the orientation that makes the two consistent: 1 flip, -1
// keep, 0 for a simplex that is no decided neighbour.
template <int kArity>
int VertexSplitter::neighbourVote(uint32_t simplex, int myParity, uint32_t other) const {
  constexpr int kDimension = kArity - 1;
  if (other == simplex || (store_.flags(kDimension, other) & SimplexStore::kUndecided)) return 0;
  const uint32_t* mine = store_.vertices(kDimension, simplex);
  const uint32_t* theirs = store_.vertices(kDimension, other);
  // Neighbours share all vertices but one each; most candidates share
  // only the split's vertex, so theirs are looked at only after mine.
  int mineShared = 0, theirsShared = 0;  // bit i: vertex i is in the other
  for (int i = 0; i < kArity; ++i) mineShared |= int(containsVertex(theirs, kArity, mine[i])) << i;
  constexpr int kAll = (1 << kArity) - 1;
  const int mineOnly = kAll ^ mineShared;
  if (mineOnly & (mineOnly - 1) || mineOnly == 0) return 0;  // not exactly one vertex apart
  for (int i = 0; i < kArity; ++i) theirsShared |= int(containsVertex(mine, kArity, theirs[i])) << i;
  const int theirsOnly = kAll ^ theirsShared;
  // Orientation each induces on the shared facet; consistent neighbours
  // induce opposite ones.
  const int mySign = myParity ^ (rankOf(mine, kArity, mine[__builtin_ctz(unsigned(mineOnly))]) & 1);
  const int theirSign =
      store_.parity(kDimension, other) ^ (rankOf(theirs, kArity, theirs[__builtin_ctz(unsigned(theirsOnly))]) & 1);
  return mySign == theirSign ? 1 : -1;
}

// The candidates' votes: flip when more vote to flip than to keep;
// voteClass 0 without a vote, 1 when all agree, 2 when they differ.
template <int kArity>
int VertexSplitter::voteOnFlip(uint32_t simplex, const std::vector<uint32_t>& candidates, int& voteClass) {
  constexpr int kDimension = kArity - 1;
  int keep = 0, flip = 0;
  if (facets_[size_t(kDimension)].empty()) {
    const int myParity = store_.parity(kDimension, simplex);
    for (const uint32_t other : candidates) {
      const int vote = neighbourVote<kArity>(simplex, myParity, other);
      flip += vote > 0;
      keep += vote < 0;
    }
  } else {
    // The same count: two distinct simplices share at most one facet, and
    // the simplex being decided is not counted yet.
    for (int skip = 0; skip < kArity; ++skip) {
      const std::array<uint32_t, 2>& decided = facetOf(kDimension, simplex, skip).decided;
      const int mySign = inducedSign(kDimension, simplex, skip);
      flip += int(decided[size_t(mySign)]);
      keep += int(decided[size_t(1 - mySign)]);
    }
  }
  voteClass = keep + flip == 0 ? 0 : (keep == 0 || flip == 0) ? 1 : 2;
  return flip > keep;
}

// A triangle made by the split shares an edge only with triangles at v or
// v2 after it, which are the star's triangles, their copies and the
// triangles that edges coded 4 added. Of those, a triangle added by the
// edge v c (it is v c v2) shares v v2 with the other added triangles, and
// v c or c v2 only with star triangles through the edge v c and their
// copies; the copy of a triangle v a b (it is v2 a b) shares a b with the
// triangle itself, and v2 a or v2 b only with star triangles through the
// edge v a or v b, their copies and the triangles that those edges added.
// The vote over these few counts the same neighbours as one over all
// (voteOnFlip() skips the triangle itself). A triangle's links are set
// here: possibleCodes() refused the split otherwise.
const std::vector<uint32_t>& VertexSplitter::triangleNeighbours(const Entry& from, bool isCopy) {
  neighbours_.clear();
  const uint32_t edgeA = isCopy ? from.links[0] : uint32_t(&from - star_.data());
  const uint32_t edgeB = isCopy ? from.links[1] : edgeA;
  for (size_t t = begin_[2]; t < begin_[3]; ++t) {
    const Entry& triangle = star_[t];
    const bool throughEdge = triangle.links[0] == edgeA || triangle.links[0] == edgeB ||
                             triangle.links[1] == edgeA || triangle.links[1] == edgeB;
    if (!throughEdge) continue;
    neighbours_.push_back(triangle.simplex);
    if (triangle.copy != kNoSimplex) neighbours_.push_back(triangle.copy);
  }
  if (isCopy) {
    for (const uint32_t edge : {edgeA, edgeB})
      if (star_[edge].added != kNoSimplex) neighbours_.push_back(star_[edge].added);
  } else {
    for (size_t e = begin_[1]; e < begin_[2]; ++e)
      if (star_[e].added != kNoSimplex) neighbours_.push_back(star_[e].added);
  }
  return neighbours_;
}

int VertexSplitter::predictFlip(int dimension, uint32_t simplex, const Entry& from, bool isCopy, int& voteClass) {
  // A fan expansion adds one triangle v c v2 per cut edge v c (its only
  // orientation decisions): it is oriented as the fan triangle through v c
  // that stays at v, the one of its two neighbours on the fan whose arc
  // went to v.
  // The two share the edge v c and nothing else (the fan triangle's third
  // vertex is an old neighbour of v, the new triangle's is v2, at the end
  // of its tuple), so the vote is the comparison of the orientations each
  // induces on v c, as neighbourVote() would find it.
  if (fanExpansionCoded_) {
    const int before = fanPrevious(from.fanIndex);
    const int at = from.fanIndex;
    const int slot = at ^ ((at ^ before) & -int(slotSides_[size_t(before)] == 1));
    const Entry& stays = star_[slotTriangles_[size_t(slot)]];
    const uint32_t* theirs = store_.vertices(2, stays.simplex);
    // Positions by table and the third by a mask: which one holds c is a
    // coin toss for the branch predictor.
    static constexpr int kAfter[3] = {1, 2, 0}, kBefore[3] = {2, 0, 1};
    const int afterV = kAfter[stays.position], beforeV = kBefore[stays.position];
    const int third = afterV ^ ((afterV ^ beforeV) & -int(theirs[afterV] == from.others[0]));
    const bool decided = !(store_.flags(2, stays.simplex) & SimplexStore::kUndecided);
    const bool flip = inducedSign(2, simplex, 2) == inducedSign(2, stays.simplex, third);
#ifdef KDMESH_CHECK_VOTES
    const int vote = neighbourVote<3>(simplex, store_.parity(2, simplex), stays.simplex);
    if (vote != (decided ? (flip ? 1 : -1) : 0)) std::abort();
#endif
    voteClass = decided;
    return decided & flip;
  }
  // Stars small enough to vote without the facet index (see around()).
  if (dimension == 2 && star_.size() * 2 <= kIndexedStar) {
    const int flip = voteOnFlip<3>(simplex, triangleNeighbours(from, isCopy), voteClass);
#ifdef KDMESH_CHECK_VOTES
    int pollClass = 0;
    if (voteOnFlip<3>(simplex, around(2), pollClass) != flip || pollClass != voteClass) std::abort();
#endif
    return flip;
  }
  const std::vector<uint32_t>& candidates = around(dimension);
  return dimension == 2 ? voteOnFlip<3>(simplex, candidates, voteClass)
                        : voteOnFlip<4>(simplex, candidates, voteClass);
}

}  // namespace kdmesh
