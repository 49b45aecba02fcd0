// Arrays that grow with the model (simplex pools, per-vertex state): on
// Linux, allocations of several megabytes ask for transparent huge pages.
//
// A model of a million triangles touches a hundred megabytes or more while
// it is coded, and every fresh 4 KiB page costs a page fault. Advised with
// MADV_HUGEPAGE before it is first touched, an allocation faults in 2 MiB at
// a time, and its accesses miss the TLB less. The advice is only advice:
// where the kernel has huge pages off (or on other systems, and in
// WebAssembly) the arrays are ordinary allocations.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace kdmesh {

// Advises the kernel to back the whole pages of [data, data + bytes) with
// huge pages when the range spans at least kHugePageAdviceBytes; no-op
// elsewhere.
void adviseHugePages(void* data, size_t bytes);
constexpr size_t kHugePageAdviceBytes = size_t(4) << 20;

// std::allocator, advising its large allocations (adviseHugePages()).
template <class T>
struct LargeArrayAllocator {
  using value_type = T;
  LargeArrayAllocator() = default;
  template <class U>
  LargeArrayAllocator(const LargeArrayAllocator<U>&) {}
  T* allocate(size_t count) {
    T* data = std::allocator<T>().allocate(count);
    adviseHugePages(data, count * sizeof(T));
    return data;
  }
  void deallocate(T* data, size_t count) { std::allocator<T>().deallocate(data, count); }
  template <class U>
  bool operator==(const LargeArrayAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const LargeArrayAllocator<U>&) const { return false; }
};

template <class T>
using LargeArray = std::vector<T, LargeArrayAllocator<T>>;

}  // namespace kdmesh
