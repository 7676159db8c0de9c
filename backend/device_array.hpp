// The owning array in backend memory, written once for every backend. A backend supplies a
// memory-space policy `Space` with static functions:
//   void* allocate(std::size_t bytes)          (throws DeviceError when out of memory)
//   void release(void* p)
//   void to_device(void* dst, const void* src, std::size_t bytes)   host -> backend
//   void to_host(void* dst, const void* src, std::size_t bytes)     backend -> host
//   void within(void* dst, const void* src, std::size_t bytes)      backend -> backend
//   template <class T> void fill(T* p, std::size_t n, T value)
// Each backend names its own `DeviceArray<T> = BasicDeviceArray<T, ItsSpace>`; the different
// Space types keep the two backends' symbols apart.
#pragma once
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "backend/view.hpp"

namespace mw {

// Contents are uninitialised after resize (callers fill what they need); copies between the host
// and the backend are explicit.
template <class T, class Space>
class BasicDeviceArray {
   public:
    BasicDeviceArray() = default;
    explicit BasicDeviceArray(std::size_t n) { resize(n); }
    BasicDeviceArray(const BasicDeviceArray&) = delete;
    BasicDeviceArray& operator=(const BasicDeviceArray&) = delete;
    BasicDeviceArray(BasicDeviceArray&& other) noexcept { swap(other); }
    BasicDeviceArray& operator=(BasicDeviceArray&& other) noexcept {
        swap(other);
        return *this;
    }
    ~BasicDeviceArray() { release(); }

    void swap(BasicDeviceArray& other) noexcept {
        std::swap(ptr_, other.ptr_);
        std::swap(size_, other.size_);
        std::swap(capacity_, other.capacity_);
    }
    // Grows the allocation only when needed, so a per-step resize to the same size is free.
    void resize(std::size_t n) {
        if (n > capacity_) {
            release();
            ptr_ = static_cast<T*>(Space::allocate(n * sizeof(T)));
            capacity_ = n;
        }
        size_ = n;
    }
    void release() {
        if (ptr_) Space::release(ptr_);
        ptr_ = nullptr;
        size_ = capacity_ = 0;
    }
    std::size_t size() const { return size_; }
    std::size_t capacity() const { return capacity_; }
    std::size_t bytes() const { return capacity_ * sizeof(T); }
    bool empty() const { return size_ == 0; }
    View<T> view() { return View<T>{ptr_, size_}; }
    View<const T> view() const { return View<const T>{ptr_, size_}; }
    View<const T> cview() const { return View<const T>{ptr_, size_}; }

    void upload(const T* host, std::size_t n) {
        resize(n);
        if (n) Space::to_device(ptr_, host, n * sizeof(T));
    }
    void upload(const std::vector<T>& host) { upload(host.data(), host.size()); }
    void download(T* host, std::size_t n) const {
        const std::size_t count = std::min(n, size_);
        if (count) Space::to_host(host, ptr_, count * sizeof(T));
    }
    void download(std::vector<T>& host) const {
        host.resize(size_);
        download(host.data(), size_);
    }
    std::vector<T> to_host() const {
        std::vector<T> host;
        download(host);
        return host;
    }
    // A handful of values to or from the host (counters), not a stream.
    void download_range(T* host, std::size_t first, std::size_t n) const {
        if (n) Space::to_host(host, ptr_ + first, n * sizeof(T));
    }
    void upload_range(const T* host, std::size_t first, std::size_t n) {
        if (n) Space::to_device(ptr_ + first, host, n * sizeof(T));
    }
    void fill(const T& value) { Space::fill(ptr_, size_, value); }
    // resize(n), then every element set to value.
    void assign(std::size_t n, const T& value) {
        resize(n);
        fill(value);
    }
    void copy_from(const BasicDeviceArray& other) {
        resize(other.size_);
        if (size_) Space::within(ptr_, other.ptr_, size_ * sizeof(T));
    }

   private:
    T* ptr_ = nullptr;
    std::size_t size_ = 0;
    std::size_t capacity_ = 0;
};

}  // namespace mw
