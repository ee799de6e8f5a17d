// The global operator new and delete, and C's malloc, calloc and realloc, replaced for one program so that
// allocation_counter.hpp can count allocations. malloc, calloc and realloc add one to a relaxed atomic
// counter and call glibc's own (__libc_malloc, …), whose free frees them; each form of new takes its
// memory from malloc (counted there) or, over-aligned, from aligned_alloc (counted in new); every delete
// frees it. Under AddressSanitizer the sanitizer owns malloc: only new is counted (counts_malloc()).
#include "support/allocation_counter.hpp"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define IMPETUS_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define IMPETUS_COUNT_MALLOC 0
#endif
#endif
#ifndef IMPETUS_COUNT_MALLOC
#define IMPETUS_COUNT_MALLOC 1
#endif

namespace {

std::atomic<std::uint64_t> g_count{0};

void count() noexcept { g_count.fetch_add(1, std::memory_order_relaxed); }

}  // namespace

#if IMPETUS_COUNT_MALLOC
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);

void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  count();
  return __libc_realloc(p, size);
}
}
#endif

namespace {

void* counted(std::size_t size, std::size_t alignment) {
  const bool over_aligned = alignment > alignof(std::max_align_t);
  if (!IMPETUS_COUNT_MALLOC || over_aligned) count();  // else malloc counts it
  if (size == 0) size = 1;
  void* p = over_aligned
                ? std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment)
                : std::malloc(size);
  return p;
}

void* counted_or_throw(std::size_t size, std::size_t alignment) {
  void* p = counted(size, alignment);
  if (!p) throw std::bad_alloc();
  return p;
}

}  // namespace

namespace impetus::bench {
std::uint64_t allocations() noexcept { return g_count.load(std::memory_order_relaxed); }
bool counts_malloc() noexcept { return IMPETUS_COUNT_MALLOC != 0; }
}  // namespace impetus::bench

void* operator new(std::size_t size) { return counted_or_throw(size, alignof(std::max_align_t)); }
void* operator new[](std::size_t size) { return counted_or_throw(size, alignof(std::max_align_t)); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_or_throw(size, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return counted_or_throw(size, static_cast<std::size_t>(a)); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted(size, alignof(std::max_align_t)); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted(size, alignof(std::max_align_t)); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return counted(size, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
