// Context: an off-screen OpenGL 3.3 core context.
#pragma once

#include <memory>
#include <string>

namespace pixelgym::render {

/// Which OpenGL implementation a context comes from.
enum class GlBackend {
  /// PIXELGYM_GL when it is set (auto, egl or osmesa), else the first that works of OSMesa and
  /// EGL, in that order.
  kAuto,
  /// Mesa's off-screen GL (libOSMesa, llvmpipe): no display, no GPU; rasterizes in parallel with
  /// private copies of Mesa (render/mesa_copy.h). Mesa 25.1 and later no longer ship it.
  kOSMesa,
  /// EGL without a display: a GPU's EGL device where one exists, else Mesa's surfaceless platform
  /// on llvmpipe (the same pixels as OSMesa). PIXELGYM_EGL_DEVICE picks a device: its index among
  /// EGL's devices, cuda:N (the device of CUDA number N), surfaceless, or auto (the default).
  kEgl,
};

/// "auto", "osmesa" or "egl". Throws std::invalid_argument naming `who`, the three names and
/// what was given for any other text.
GlBackend parse_gl_backend(const std::string& name, const std::string& who);
/// The name parse_gl_backend reads.
std::string gl_backend_name(GlBackend backend);
/// Whether this build can draw with `backend`: all but kOSMesa in a build configured with
/// -DPIXELGYM_OSMESA=OFF (then kAuto means EGL).
bool gl_backend_built(GlBackend backend);
/// `backend` with kAuto replaced by what PIXELGYM_GL names (kAuto when it is unset, empty or
/// "auto"). Throws std::invalid_argument for a PIXELGYM_GL that parse_gl_backend refuses.
GlBackend requested_gl_backend(GlBackend backend);

struct ContextImpl;

/// An RAII OpenGL 3.3 core context. One context belongs to one renderer and is used by one
/// thread at a time (any thread, one after the other); contexts in different threads are
/// independent.
///
/// Threads: a thread that made a context current keeps it bound until it calls `release()` (or
/// binds another). While bound there, no other thread may use or destroy it: Mesa flushes the
/// old context of a thread that binds another, and reads it, freed or not, on the next
/// `make_current` of that thread (a crash when another thread destroyed it). So a thread that is
/// done with a context for now releases it, as `Scope` does; Renderer binds its context only
/// for the length of each call.
///
/// Copies of Mesa: a context is created in the copy of libOSMesa its constructor is given (copy
/// 0, the linked library, by default). Contexts of different copies
/// rasterize in parallel; those of one copy take turns (see render/mesa_copy.h).
///
/// llvmpipe threads: Mesa's software rasterizer starts LP_NUM_THREADS worker threads per context
/// (by default one per core). For the small images of pixel observations they cost more than they
/// give (docs/design-notes.md, "Rendering"), so the first context pixelgym creates in a process
/// sets LP_NUM_THREADS=0 unless the variable is already set. Set it yourself (e.g. to the core
/// count) before the first render to override this.
class Context {
 public:
  /// Creates a context of `backend` (OSMesa: of copy `mesa_copy` of Mesa, see MesaCopy, taken
  /// modulo max_copies(); EGL has one copy), current on the calling thread. Throws
  /// std::runtime_error naming the backend and its reason when it cannot be created (kAuto: each
  /// backend's), what to install when a library is missing; std::invalid_argument for
  /// mesa_copy < 0 and a PIXELGYM_GL or PIXELGYM_EGL_DEVICE it cannot read.
  explicit Context(GlBackend backend = GlBackend::kAuto, int mesa_copy = 0);
  /// Destroys the context, on any thread, provided no other thread has it current.
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  /// Makes this context current on the calling thread (cheap when it already is).
  void make_current();
  /// Unbinds this context from the calling thread if it is current there; does nothing
  /// otherwise.
  void release();

  /// Binds `context` on this thread for the scope's life and then releases it, unless it was
  /// already current here when the scope began (then it stays bound).
  class Scope {
   public:
    /// Makes `context` current on the calling thread; `context` must outlive the scope.
    explicit Scope(Context& context);
    /// Releases the context unless it was current when the scope began, and restores the GL
    /// function table in use before.
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    Context& context_;
    bool was_current_;
    const void* previous_gl_;  // the GL table in use before (render/gl.h)
  };
  /// True when this context is current on the calling thread.
  bool is_current() const;
  /// The implementation it was created with: kOSMesa or kEgl, never kAuto.
  GlBackend backend() const { return backend_; }
  /// The copy of Mesa the context is from (see MesaCopy): the one it was created for, or 0 when
  /// that one could not be loaded (EGL: 0).
  int mesa_copy() const;
  /// GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile)
  /// Mesa 22.3.6". Binds the context for the call (as Scope).
  std::string description();
  /// GL_MAX_SAMPLES: the most samples per pixel a multisampled render target (and so
  /// Camera::msaa_samples) may have in this context; 4 on llvmpipe. Binds the context for the
  /// call (as Scope).
  int max_samples();

 private:
  GlBackend backend_;
  std::unique_ptr<ContextImpl> impl_;  // render/context_impl.h
};

}  // namespace pixelgym::render
