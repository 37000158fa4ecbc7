// Heap allocation counting for tests, attributed by call stack to the library that asked.
//
// Include this header in exactly ONE source file of a test executable: it defines the C
// allocator (malloc, calloc, realloc, memalign, aligned_alloc, posix_memalign, forwarded to
// glibc's __libc_* entry points; glibc lets an executable define them, and shared libraries such
// as Bullet, Mesa and OpenCV then resolve to these too) and every form of the global operator
// new / delete on top of it. So it sees every heap allocation of the process: pixelgym's own, the
// C++ library's, Eigen's (aligned_malloc -> malloc), Bullet's (btAlignedAlloc -> malloc),
// Mesa's and OpenCV's. It does not see memory taken with mmap or sbrk directly, or stack growth.
//
// Counting is on only inside `count_allocations(body)`. Each allocation counted is attributed by
// its call stack (backtrace + dladdr):
// - kMesa: a frame in libOSMesa, libLLVM, libgallium or libglapi, or, through EGL, in a DRI
//   driver (swrast_dri.so), libEGL* or libGLdispatch (llvmpipe mallocs while it draws: state
//   validation and draw setup, which no caller can avoid);
// - else kOpenCv: a frame in libopencv_* (cv::resize's scratch tables, for one);
// - else kBullet: a frame in Bullet's collision or dynamics libraries (libBullet*: the
//   dispatcher's algorithm for a new pair of compound shapes, solver arrays growing). Not
//   libLinearMath alone: btAlignedObjectArray growth reached from pixelgym's own code passes
//   only through it, and that is pixelgym's;
// - else kPixelgym: pixelgym's own code, with the C++ library and Eigen inlined into it.
// An operator new is counted as a `new` and, as it takes its memory from malloc, as a malloc.
#pragma once

#include <dlfcn.h>
#include <execinfo.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>

namespace pixelgym::testing {

/// Who asked for an allocation (see the file comment).
enum class AllocOwner { kPixelgym = 0, kMesa = 1, kOpenCv = 2, kBullet = 3 };

/// Allocations counted, by kind and owner.
struct AllocCounts {
  std::array<long, 4> news{};     // operator new, every form
  std::array<long, 4> mallocs{};  // the C allocator (operator new's included)

  long news_of(AllocOwner owner) const { return news[static_cast<std::size_t>(owner)]; }
  long mallocs_of(AllocOwner owner) const { return mallocs[static_cast<std::size_t>(owner)]; }
  long news_total() const { return news[0] + news[1] + news[2] + news[3]; }
  long mallocs_total() const { return mallocs[0] + mallocs[1] + mallocs[2] + mallocs[3]; }
  AllocCounts& operator+=(const AllocCounts& other) {
    for (std::size_t i = 0; i < 4; ++i) {
      news[i] += other.news[i];
      mallocs[i] += other.mallocs[i];
    }
    return *this;
  }
};

namespace alloc_detail {

// Process-wide: a test instrument, switched on only around the code under test.
inline std::atomic<bool> counting{false};
inline std::array<std::atomic<long>, 4> news{};
inline std::array<std::atomic<long>, 4> mallocs{};
inline thread_local bool in_hook = false;

inline AllocOwner owner_of_caller() {
  void* frames[64];
  const int depth = backtrace(frames, 64);
  AllocOwner owner = AllocOwner::kPixelgym;
  for (int i = 0; i < depth; ++i) {
    Dl_info info;
    if (dladdr(frames[i], &info) == 0 || info.dli_fname == nullptr) continue;
    const char* name = info.dli_fname;
    if (std::strstr(name, "libOSMesa") != nullptr || std::strstr(name, "libLLVM") != nullptr ||
        std::strstr(name, "libgallium") != nullptr || std::strstr(name, "libglapi") != nullptr ||
        std::strstr(name, "_dri.so") != nullptr || std::strstr(name, "libEGL") != nullptr ||
        std::strstr(name, "libGLdispatch") != nullptr) {
      return AllocOwner::kMesa;
    }
    if (std::strstr(name, "libopencv") != nullptr) {
      owner = AllocOwner::kOpenCv;
    } else if (std::strstr(name, "libBullet") != nullptr && owner == AllocOwner::kPixelgym) {
      owner = AllocOwner::kBullet;
    }
  }
  return owner;
}

inline void count(std::array<std::atomic<long>, 4>& counters) {
  if (!counting.load(std::memory_order_relaxed) || in_hook) return;
  in_hook = true;
  counters[static_cast<std::size_t>(owner_of_caller())].fetch_add(1);
  in_hook = false;
}

// backtrace() loads libgcc's unwinder (allocating) on its first call: do that before counting.
inline const bool unwinder_loaded = [] {
  void* frames[4];
  return backtrace(frames, 4) > 0;
}();

inline void* counted_new(std::size_t size) {
  count(news);
  if (void* pointer = std::malloc(size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}

inline void* counted_aligned_new(std::size_t size, std::align_val_t alignment) {
  count(news);
  const auto align = static_cast<std::size_t>(alignment);
  if (void* pointer = std::aligned_alloc(align, (size + align - 1) / align * align)) return pointer;
  throw std::bad_alloc();
}

}  // namespace alloc_detail

/// Runs `body` and returns the allocations made meanwhile (on any thread).
template <typename Body>
AllocCounts count_allocations(Body&& body) {
  for (auto& counter : alloc_detail::news) counter = 0;
  for (auto& counter : alloc_detail::mallocs) counter = 0;
  alloc_detail::counting = true;
  body();
  alloc_detail::counting = false;
  AllocCounts counts;
  for (std::size_t i = 0; i < 4; ++i) {
    counts.news[i] = alloc_detail::news[i];
    counts.mallocs[i] = alloc_detail::mallocs[i];
  }
  return counts;
}

}  // namespace pixelgym::testing

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);

void* malloc(std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  return __libc_realloc(pointer, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  pixelgym::testing::alloc_detail::count(pixelgym::testing::alloc_detail::mallocs);
  void* pointer = __libc_memalign(alignment, size);
  if (pointer == nullptr) return ENOMEM;
  *out = pointer;
  return 0;
}
void free(void* pointer) noexcept { __libc_free(pointer); }
}

void* operator new(std::size_t size) { return pixelgym::testing::alloc_detail::counted_new(size); }
void* operator new[](std::size_t size) {
  return pixelgym::testing::alloc_detail::counted_new(size);
}
void* operator new(std::size_t size, const std::nothrow_t& /*tag*/) noexcept {
  try {
    return pixelgym::testing::alloc_detail::counted_new(size);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  return pixelgym::testing::alloc_detail::counted_aligned_new(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return pixelgym::testing::alloc_detail::counted_aligned_new(size, alignment);
}
// The replaced operator new takes its memory from malloc, so free is the matching release; GCC
// cannot see that across the replacement and warns.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* pointer) noexcept { std::free(pointer); }
void operator delete[](void* pointer) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::size_t /*size*/) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::size_t /*size*/) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::align_val_t /*alignment*/) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::align_val_t /*alignment*/) noexcept {
  std::free(pointer);
}
void operator delete(void* pointer, std::size_t /*size*/, std::align_val_t /*alignment*/) noexcept {
  std::free(pointer);
}
void operator delete[](void* pointer, std::size_t /*size*/,
                       std::align_val_t /*alignment*/) noexcept {
  std::free(pointer);
}
#pragma GCC diagnostic pop
