// Private to render/: one loaded copy of libOSMesa and its entry points (see render/mesa_copy.h).
#pragma once

#include <GL/osmesa.h>

#include "pixelgym/render/gl.h"

namespace pixelgym::render {

/// The OSMesa functions of one copy, and its GL table.
struct GlLibrary {
  /// Which copy this is (see MesaCopy).
  int copy = 0;
  /// That copy's OSMesaCreateContextAttribs, OSMesaMakeCurrent, OSMesaGetCurrentContext and
  /// OSMesaDestroyContext.
  OSMesaContext (*create_context_attribs)(const int*, OSMesaContext) = nullptr;
  GLboolean (*make_current)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  OSMesaContext (*get_current_context)() = nullptr;
  void (*destroy_context)(OSMesaContext) = nullptr;
  /// A private copy's own C library sets a thread's ctype tables (isalpha and friends, which LLVM
  /// uses when it compiles shaders) only on the thread that loaded it; other threads crash there
  /// until this, glibc's __ctype_init of that copy, has run on them. Null for copy 0.
  void (*init_thread)() = nullptr;
  /// The copy's GL entry points.
  GlFunctions gl;
};

/// Readies the calling thread for calls into `library` (see init_thread): a bit test after the
/// first call per thread and copy. Context calls it before every call into OSMesa.
void prepare_thread(const GlLibrary& library);

/// The library a context of Mesa copy `copy` uses: MesaCopy::resolve(copy), loaded if need be.
/// Sets LP_NUM_THREADS first (see Context). Throws std::invalid_argument for copy < 0.
/// Thread-safe.
const GlLibrary& library_for_new_context(int copy);

}  // namespace pixelgym::render
