// Private to render/: what a Context holds, one implementation per GL backend (render/context.h).
#pragma once

#include <memory>

#include "pixelgym/render/context.h"
#include "pixelgym/render/gl.h"

namespace pixelgym::render {

/// A created context of one backend.
struct ContextImpl {
  virtual ~ContextImpl() = default;
  /// Binds the context on the calling thread (cheap when it already is); throws
  /// std::runtime_error naming the backend's error.
  virtual void make_current() = 0;
  /// Unbinds it from the calling thread if it is current there.
  virtual void release() = 0;
  virtual bool is_current() const = 0;
  /// The copy of Mesa it is from (EGL: 0).
  virtual int mesa_copy() const { return 0; }
  /// Its GL entry points, which make_current() installs as the thread's table.
  virtual const GlFunctions& gl() const = 0;
};

/// An OSMesa context of copy `mesa_copy` (render/mesa_copy.h), current on return. Throws
/// std::runtime_error naming why it cannot be made (what to install when libOSMesa is missing),
/// std::invalid_argument for mesa_copy < 0.
std::unique_ptr<ContextImpl> make_osmesa_context(int mesa_copy);

/// An EGL context on the display PIXELGYM_EGL_DEVICE selects (see Context), current on return.
/// Throws std::runtime_error naming why it cannot be made (what to install when libEGL or Mesa's
/// EGL driver is missing), std::invalid_argument for a PIXELGYM_EGL_DEVICE that names no device.
std::unique_ptr<ContextImpl> make_egl_context();

/// The display EGL contexts are made on ("EGL surfaceless (Mesa)", "EGL device 1
/// (/dev/dri/renderD129)"), opened on the first call. Throws as make_egl_context.
std::string egl_display_name();

/// Sets LP_NUM_THREADS=0 unless it is set (see Context), once per process: before the first
/// context of any backend.
void default_llvmpipe_threads();

}  // namespace pixelgym::render
