// Fixed-capacity vector for the runtime modules (wayside, onboard): the storage is
// allocated once by Allocate() (during initialisation, e.g. Ground::Create) and never
// again; PushBack beyond the capacity is refused (returns false), never reallocates.
//
// Runtime module rules: no exceptions (allocation uses nothrow new and reports failure
// with a bool), no heap after initialisation, bounded loops.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>

namespace railproof::core {

// @implements REQ-MB-021
template <typename T>
class FixedVector {
 public:
  FixedVector() noexcept = default;
  FixedVector(const FixedVector&) = delete;
  FixedVector& operator=(const FixedVector&) = delete;
  FixedVector(FixedVector&&) noexcept = default;
  FixedVector& operator=(FixedVector&&) noexcept = default;
  ~FixedVector() = default;

  // Allocates storage for `capacity` elements (value-initialised) and empties the vector.
  // Only to be called during initialisation. Returns false if the allocation failed.
  [[nodiscard]] bool Allocate(std::size_t capacity) noexcept {
    data_.reset();
    size_ = 0;
    capacity_ = 0;
    if (capacity == 0) {
      return true;
    }
    data_.reset(new (std::nothrow) T[capacity]());
    if (!data_) {
      return false;  // GCOVR_EXCL_LINE defensive: out of memory at initialisation
    }
    capacity_ = capacity;
    return true;
  }

  // Allocates storage for `capacity` elements (only during initialisation) and copies `src`
  // into it. False if the allocation failed or `src` does not fit.
  [[nodiscard]] bool AssignFrom(std::span<const T> src, std::size_t capacity) noexcept {
    if (src.size() > capacity || !Allocate(capacity)) {
      return false;
    }
    for (std::size_t i = 0; i < src.size(); ++i) {
      data_[i] = src[i];
    }
    size_ = src.size();
    return true;
  }

  // Appends `value`; false (and no change) if the vector is full.
  [[nodiscard]] bool PushBack(const T& value) noexcept {
    if (size_ >= capacity_) {
      return false;
    }
    data_[size_] = value;
    ++size_;
    return true;
  }

  // Sets the size to n (<= capacity; elements keep their old values). False if n > capacity.
  [[nodiscard]] bool Resize(std::size_t n) noexcept {
    if (n > capacity_) {
      return false;
    }
    size_ = n;
    return true;
  }

  // Removes the element at index i, keeping the order of the others (O(size)).
  void EraseAt(std::size_t i) noexcept {
    if (i >= size_) {
      return;
    }
    for (std::size_t k = i + 1; k < size_; ++k) {
      data_[k - 1] = data_[k];
    }
    --size_;
  }

  void Clear() noexcept { size_ = 0; }

  [[nodiscard]] std::size_t Size() const noexcept { return size_; }
  [[nodiscard]] std::size_t Capacity() const noexcept { return capacity_; }
  [[nodiscard]] bool Empty() const noexcept { return size_ == 0; }
  [[nodiscard]] bool Full() const noexcept { return size_ >= capacity_; }

  // Unchecked access: callers keep i < Size().
  T& operator[](std::size_t i) noexcept { return data_[i]; }
  const T& operator[](std::size_t i) const noexcept { return data_[i]; }

  T* begin() noexcept { return data_.get(); }
  T* end() noexcept { return data_.get() + size_; }
  const T* begin() const noexcept { return data_.get(); }
  const T* end() const noexcept { return data_.get() + size_; }

  [[nodiscard]] std::span<T> Span() noexcept { return {data_.get(), size_}; }
  [[nodiscard]] std::span<const T> Span() const noexcept { return {data_.get(), size_}; }

 private:
  std::unique_ptr<T[]> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace railproof::core
