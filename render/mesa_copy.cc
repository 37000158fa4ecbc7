#include "pixelgym/render/mesa_copy.h"

#include <dlfcn.h>
#include <malloc.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include "pixelgym/render/context_impl.h"
#if PIXELGYM_HAS_OSMESA
#include "pixelgym/render/gl_library.h"
#endif

namespace pixelgym::render {

namespace {

// glibc's link namespaces (DL_NNS), the base one included.
constexpr int kMostCopies = 16;
constexpr int kDefaultCopies = 8;

#if PIXELGYM_HAS_OSMESA
thread_local unsigned copies_ready_here = 1U;  // bit k: init_thread of copy k ran on this thread
#endif

}  // namespace

void default_llvmpipe_threads() {
  static std::once_flag once;
  std::call_once(once, [] {
    // Read by llvmpipe when it creates a screen (on a copy's first context, or an EGL display's),
    // and by private copies from the environment they are loaded with: see Context's comment.
    if (std::getenv("LP_NUM_THREADS") == nullptr) setenv("LP_NUM_THREADS", "0", 0);
  });
}

#if PIXELGYM_HAS_OSMESA
namespace {

// Copy 0's file, by its soname (OSMesa's since Mesa 10). Loaded at run time rather than linked, so
// a machine without it starts and draws with EGL, and asking for OSMesa says what to install.
constexpr const char* kOSMesaLibrary = "libOSMesa.so.8";

// Fills `library`'s OSMesa entry points and GL table from `lookup` (name -> address, null when
// missing). Returns the first name missing, or "".
template <typename Lookup>
std::string load_entry_points(GlLibrary& library, Lookup lookup) {
  std::string missing;
  const auto symbol = [&](const char* name) {
    void* address = lookup(name);
    if (address == nullptr && missing.empty()) missing = name;
    return address;
  };
  library.create_context_attribs = reinterpret_cast<decltype(library.create_context_attribs)>(
      symbol("OSMesaCreateContextAttribs"));
  library.make_current =
      reinterpret_cast<decltype(library.make_current)>(symbol("OSMesaMakeCurrent"));
  library.get_current_context =
      reinterpret_cast<decltype(library.get_current_context)>(symbol("OSMesaGetCurrentContext"));
  library.destroy_context =
      reinterpret_cast<decltype(library.destroy_context)>(symbol("OSMesaDestroyContext"));
  auto* get_proc_address =
      reinterpret_cast<OSMESAproc (*)(const char*)>(symbol("OSMesaGetProcAddress"));
  if (!missing.empty()) return missing;
  return load_gl_functions(library.gl, get_proc_address);
}

// Copy 0: libOSMesa loaded into the process's global scope, as a linked library would be. Its
// entry points are looked up there (RTLD_DEFAULT), so a function the program itself defines
// first (a test counting contexts) is the one called, as with a linked library. Throws
// std::runtime_error naming the package when the library does not load.
std::unique_ptr<GlLibrary> load_base(void*& handle) {
  handle = ::dlopen(kOSMesaLibrary, RTLD_NOW | RTLD_GLOBAL);  // never closed, as private copies
  if (handle == nullptr) {
    const char* error = ::dlerror();
    throw std::runtime_error(
        std::string("Context: cannot load ") + kOSMesaLibrary + " (" +
        (error != nullptr ? error : "dlopen failed") +
        "); install libosmesa6 (Debian and Ubuntu package name; Mesa 25.1 and later no longer "
        "ship OSMesa), or draw with EGL: render_backend=egl");
  }
  auto library = std::make_unique<GlLibrary>();
  const std::string missing =
      load_entry_points(*library, [](const char* name) { return ::dlsym(RTLD_DEFAULT, name); });
  if (!missing.empty()) {
    throw std::runtime_error(std::string("Context: ") + kOSMesaLibrary + " has no " + missing);
  }
  return library;
}

// The file copy 0 was loaded from (found through its OSMesaGetProcAddress, which no test
// interposes).
std::string base_library_file(void* base_handle) {
  Dl_info info{};
  void* address = ::dlsym(base_handle, "OSMesaGetProcAddress");
  if (address == nullptr || ::dladdr(address, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

// A private copy comes with a libc of its own, and two of its malloc's defaults cost here:
// - It cannot grow its heap with brk (only the process's first libc may), so its blocks above
//   the mmap threshold are mapped and unmapped on every frame that allocates one: 0.45 page
//   faults per cart-pole step, which made a private copy 7-10% slower than copy 0 (page faults
//   are dear on a VM). A fixed threshold at glibc's largest default (32 MiB, what the dynamic
//   threshold may grow to) keeps those blocks in the heap: no faults per frame, the speed of
//   copy 0 (measured in thread CPU time).
// - It never learns that a thread ended (only the first libc's thread exit runs), so the arena a
//   worker thread was given is never handed to the next thread: every vector env made and closed
//   left an arena behind, 6-13 MB of resident memory per cycle. One arena per copy (threads
//   drawing with one copy take turns with its lock anyway) leaves no arena per thread. (Each
//   thread's cache of freed blocks, tcache, cannot be turned off here, and is left behind too when
//   the thread ends: vector envs run on threads that are kept and reused, WorkerThreads.)
// Each is left alone when the user tunes it through the environment, which the copy's libc reads
// as well.
void tune_copy_malloc(void* handle) {
  auto* copy_mallopt = reinterpret_cast<int (*)(int, int)>(::dlsym(handle, "mallopt"));
  if (copy_mallopt == nullptr) return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const auto tuned = [&](const char* variable, const char* tunable) {
    return std::getenv(variable) != nullptr ||
           (tunables != nullptr && std::strstr(tunables, tunable) != nullptr);
  };
  if (!tuned("MALLOC_MMAP_THRESHOLD_", "mmap_threshold")) {
    copy_mallopt(M_MMAP_THRESHOLD, 32 << 20);
  }
  if (!tuned("MALLOC_ARENA_MAX", "arena_max")) copy_mallopt(M_ARENA_MAX, 1);
}

// A private copy, or null with `why` set; `handle` is set once the library is loaded.
std::unique_ptr<GlLibrary> load_private(int copy, const std::string& file, std::string& why,
                                        void*& handle) {
  if (file.empty()) {
    why = "cannot find the file libOSMesa was loaded from (dladdr failed)";
    return nullptr;
  }
  // Never closed: contexts of the copy may live until the process ends, and unloading LLVM is
  // not something Mesa supports.
  handle = ::dlmopen(LM_ID_NEWLM, file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* error = ::dlerror();
    why = "dlmopen(" + file + ") failed: " + (error != nullptr ? error : "no reason given");
    return nullptr;
  }
  auto library = std::make_unique<GlLibrary>();
  library->copy = copy;
  library->init_thread = reinterpret_cast<void (*)()>(::dlsym(handle, "__ctype_init"));
  if (library->init_thread == nullptr) {
    why = file + " has no __ctype_init";
    return nullptr;
  }
  tune_copy_malloc(handle);
  const std::string missing =
      load_entry_points(*library, [handle](const char* name) { return ::dlsym(handle, name); });
  if (!missing.empty()) {
    why = file + " has no " + missing;
    return nullptr;
  }
  return library;
}

struct Copies {
  std::mutex mutex;
  std::array<std::unique_ptr<GlLibrary>, kMostCopies> loaded;
  std::array<std::string, kMostCopies> why_not;
  // dlopen's of copy 0 (once loaded), dlmopen's of the private copies loaded.
  std::array<void*, kMostCopies> handles{};
  bool fallback_reported = false;
};

Copies& copies() {
  static Copies* all = new Copies();  // never destroyed: contexts may outlive static destructors
  return *all;
}

// The library of `copy` (already taken modulo max_copies()), loading it if need be; copy 0's on
// failure.
const GlLibrary& library(int copy) {
  Copies& all = copies();
  const std::lock_guard<std::mutex> lock(all.mutex);
  const auto index = static_cast<std::size_t>(copy);
  // A failure is not kept: a later context tries again (after libosmesa6 was installed, say).
  if (all.loaded[0] == nullptr) all.loaded[0] = load_base(all.handles[0]);
  if (all.loaded[index] == nullptr && all.why_not[index].empty()) {
    std::string why;
    all.loaded[index] =
        load_private(copy, base_library_file(all.handles[0]), why, all.handles[index]);
    if (all.loaded[index] == nullptr) {
      all.why_not[index] = why;
      if (!all.fallback_reported) {
        all.fallback_reported = true;
        std::fprintf(stderr,
                     "pixelgym: could not load private copy %d of libOSMesa (%s); contexts asking "
                     "for it use copy 0: the same frames, drawn in turn with its other contexts\n",
                     copy, why.c_str());
      }
    }
  }
  return all.loaded[index] != nullptr ? *all.loaded[index] : *all.loaded[0];
}

}  // namespace
#else
constexpr const char* kBuiltWithout =
    "this pixelgym was built without OSMesa (configured with -DPIXELGYM_OSMESA=OFF): it draws "
    "with EGL (render_backend=egl)";
#endif

int MesaCopy::max_copies() {
  const char* text = std::getenv("PIXELGYM_MESA_COPIES");
  if (text == nullptr || *text == '\0') return kDefaultCopies;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < 1 || value > kMostCopies) {
    throw std::invalid_argument(
        "PIXELGYM_MESA_COPIES must be a whole number from 1 to " + std::to_string(kMostCopies) +
        " (the most copies of Mesa, copy 0 included), got \"" + text + "\"");
  }
  return static_cast<int>(value);
}

int MesaCopy::resolve(int copy) {
  if (copy < 0) {
    throw std::invalid_argument("MesaCopy::resolve: copy must be >= 0, got " +
                                std::to_string(copy));
  }
  default_llvmpipe_threads();
#if PIXELGYM_HAS_OSMESA
  return library(copy % max_copies()).copy;
#else
  max_copies();  // refuses a PIXELGYM_MESA_COPIES it cannot read, as with OSMesa
  return 0;
#endif
}

#if PIXELGYM_HAS_OSMESA
bool MesaCopy::loaded(int copy) {
  if (copy < 0 || copy >= kMostCopies) return false;
  Copies& all = copies();
  const std::lock_guard<std::mutex> lock(all.mutex);
  return all.loaded[static_cast<std::size_t>(copy)] != nullptr;
}

std::string MesaCopy::why_not(int copy) {
  if (copy < 0 || copy >= kMostCopies) return "";
  Copies& all = copies();
  const std::lock_guard<std::mutex> lock(all.mutex);
  return all.why_not[static_cast<std::size_t>(copy)];
}

std::size_t MesaCopy::private_malloc_in_use() {
  Copies& all = copies();
  const std::lock_guard<std::mutex> lock(all.mutex);
  std::size_t total = 0;
  for (std::size_t copy = 1; copy < all.loaded.size(); ++copy) {
    if (all.loaded[copy] == nullptr || all.handles[copy] == nullptr) continue;
    // dlsym through the library's handle finds its libc's mallinfo2 (a dependency's symbol).
    auto* copy_mallinfo2 =
        reinterpret_cast<struct mallinfo2 (*)()>(::dlsym(all.handles[copy], "mallinfo2"));
    if (copy_mallinfo2 == nullptr) continue;
    const struct mallinfo2 info = copy_mallinfo2();
    total += info.uordblks + info.hblkhd;
  }
  return total;
}

void prepare_thread(const GlLibrary& library) {
  const unsigned bit = 1U << static_cast<unsigned>(library.copy);
  if ((copies_ready_here & bit) == 0) {
    library.init_thread();
    copies_ready_here |= bit;
  }
}

const GlLibrary& library_for_new_context(int copy) {
  if (copy < 0) {
    throw std::invalid_argument("Context: mesa_copy must be >= 0, got " + std::to_string(copy));
  }
  default_llvmpipe_threads();
  return library(copy % MesaCopy::max_copies());
}

#else
bool MesaCopy::loaded(int /*copy*/) { return false; }

std::string MesaCopy::why_not(int copy) {
  return copy < 0 || copy >= kMostCopies ? "" : kBuiltWithout;
}

std::size_t MesaCopy::private_malloc_in_use() { return 0; }
#endif

}  // namespace pixelgym::render
