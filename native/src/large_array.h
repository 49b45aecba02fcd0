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

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
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

// An array of plain values that grows at its end only, for the hottest
// appends (the simplex pools): push_back() is a compare and a store, and
// only a growth calls out, where WebAssembly's compiler left every
// std::vector::push_back a call. Reserved memory is not touched until
// written; allocations are advised as LargeArray's.
template <class T>
class GrowingArray {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  GrowingArray() = default;
  GrowingArray(GrowingArray&& other) noexcept { swap(other); }
  GrowingArray& operator=(GrowingArray&& other) noexcept {
    GrowingArray taken(std::move(other));
    swap(taken);
    return *this;
  }
  GrowingArray(const GrowingArray&) = delete;
  GrowingArray& operator=(const GrowingArray&) = delete;
  ~GrowingArray() { std::free(data_); }

  size_t size() const { return size_; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

  void reserve(size_t capacity) {
    if (capacity > capacity_) reallocate(capacity);
  }
  void push_back(T value) {
    if (size_ == capacity_) grow(1);
    data_[size_++] = value;
  }
  // Appends `count` values left for the caller to write through the
  // returned pointer: one compare for all of them.
  T* extend(size_t count) {
    if (capacity_ - size_ < count) grow(count);
    T* at = data_ + size_;
    size_ += count;
    return at;
  }

 private:
  [[gnu::noinline]] void grow(size_t count) { reallocate(std::max<size_t>({16, capacity_ * 2, size_ + count})); }
  void reallocate(size_t capacity) {
    T* data = static_cast<T*>(std::malloc(capacity * sizeof(T)));
    // As std::vector's: an exception, or without exceptions (the
    // WebAssembly build) an abort.
#if defined(__cpp_exceptions)
    if (data == nullptr) throw std::bad_alloc();
#else
    if (data == nullptr) std::abort();
#endif
    adviseHugePages(data, capacity * sizeof(T));
    if (size_ > 0) std::memcpy(data, data_, size_ * sizeof(T));
    std::free(data_);
    data_ = data;
    capacity_ = capacity;
  }
  void swap(GrowingArray& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
  }

  T* data_ = nullptr;
  size_t size_ = 0, capacity_ = 0;
};

}  // namespace kdmesh
