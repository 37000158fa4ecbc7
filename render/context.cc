#include "pixelgym/render/context.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "pixelgym/render/context_impl.h"
#include "pixelgym/render/gl.h"

namespace pixelgym::render {

thread_local const GlFunctions* current_gl_functions = nullptr;

GlBackend parse_gl_backend(const std::string& name, const std::string& who) {
  if (name == "auto") return GlBackend::kAuto;
  if (name == "osmesa") return GlBackend::kOSMesa;
  if (name == "egl") return GlBackend::kEgl;
  throw std::invalid_argument(who + " must be auto, egl or osmesa, got \"" + name + "\"");
}

std::string gl_backend_name(GlBackend backend) {
  switch (backend) {
    case GlBackend::kOSMesa:
      return "osmesa";
    case GlBackend::kEgl:
      return "egl";
    case GlBackend::kAuto:
      break;
  }
  return "auto";
}

bool gl_backend_built(GlBackend backend) {
#if PIXELGYM_HAS_OSMESA
  (void)backend;
  return true;
#else
  return backend != GlBackend::kOSMesa;
#endif
}

GlBackend requested_gl_backend(GlBackend backend) {
  if (backend != GlBackend::kAuto) return backend;
  const char* variable = std::getenv("PIXELGYM_GL");
  if (variable == nullptr || *variable == '\0') return GlBackend::kAuto;
  return parse_gl_backend(variable, "PIXELGYM_GL");
}

namespace {

std::unique_ptr<ContextImpl> make_impl(GlBackend backend, int mesa_copy) {
  if (mesa_copy < 0) {
    throw std::invalid_argument("Context: mesa_copy must be >= 0, got " +
                                std::to_string(mesa_copy));
  }
  return backend == GlBackend::kEgl ? make_egl_context() : make_osmesa_context(mesa_copy);
}

}  // namespace

Context::Context(GlBackend backend, int mesa_copy) : backend_(requested_gl_backend(backend)) {
  if (backend_ != GlBackend::kAuto) {
    impl_ = make_impl(backend_, mesa_copy);
  } else {
    // The first that works, each one's reason said when none does.
    std::string reasons;
    for (const GlBackend candidate : {GlBackend::kOSMesa, GlBackend::kEgl}) {
      try {
        impl_ = make_impl(candidate, mesa_copy);
        backend_ = candidate;
        break;
      } catch (const std::runtime_error& error) {
        reasons += "\n  " + gl_backend_name(candidate) + ": " + error.what();
      }
    }
    if (impl_ == nullptr) {
      throw std::runtime_error(
          "Context: no OpenGL backend works here (render_backend=auto tried osmesa, then egl):" +
          reasons);
    }
  }
  current_gl_functions = &impl_->gl();
}

Context::~Context() = default;

void Context::make_current() {
  impl_->make_current();
  current_gl_functions = &impl_->gl();
}

void Context::release() { impl_->release(); }

bool Context::is_current() const { return impl_->is_current(); }

int Context::mesa_copy() const { return impl_->mesa_copy(); }

Context::Scope::Scope(Context& context)
    : context_(context), was_current_(context.is_current()), previous_gl_(current_gl_functions) {
  context_.make_current();
}

Context::Scope::~Scope() {
  if (!was_current_) context_.release();
  current_gl_functions = static_cast<const GlFunctions*>(previous_gl_);
}

std::string Context::description() {
  const Scope scope(*this);
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer != nullptr ? renderer : "?") + ", " +
         (version != nullptr ? version : "?");
}

int Context::max_samples() {
  const Scope scope(*this);
  GLint samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &samples);
  return samples;
}

}  // namespace pixelgym::render
