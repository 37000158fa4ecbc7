#include "pixelgym/render/context.h"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_library.h"

namespace pixelgym::render {

struct Context::Impl {
  const GlLibrary* library = nullptr;
  OSMesaContext context = nullptr;
  // OSMesa needs a framebuffer to make a context current; rendering goes to framebuffer objects,
  // so this one is a single pixel.
  std::vector<unsigned char> dummy = std::vector<unsigned char>(4);
};

namespace {

// libOSMesa draws with a software Gallium driver, and with GALLIUM_DRIVER naming one it cannot
// load (say "bogus", or a GPU's) Mesa 22's OSMesaCreateContextAttribs crashes (a null call in
// glLabelObjectEXT) instead of failing: refused here first.
void check_gallium_driver() {
  const char* driver = std::getenv("GALLIUM_DRIVER");
  if (driver == nullptr || *driver == '\0') return;
  const std::string name = driver;
  if (name == "llvmpipe" || name == "softpipe") return;
  throw std::runtime_error("Context: GALLIUM_DRIVER is \"" + name +
                           "\", which libOSMesa cannot draw with (it draws with llvmpipe or "
                           "softpipe, and crashes on any other); unset GALLIUM_DRIVER or set it to "
                           "llvmpipe");
}

}  // namespace

Context::Context(GlBackend backend, int mesa_copy)
    : backend_(backend), impl_(std::make_unique<Impl>()) {
  check_gallium_driver();
  impl_->library = &library_for_new_context(mesa_copy);
  prepare_thread(*impl_->library);
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            0,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  impl_->context = impl_->library->create_context_attribs(attributes, nullptr);
  if (impl_->context == nullptr) {
    const char* version = std::getenv("MESA_GL_VERSION_OVERRIDE");
    std::string reason =
        "Context: OSMesa could not create an OpenGL 3.3 core context (OSMesaCreateContextAttribs "
        "failed; is libOSMesa from Mesa < 25.1 installed, and does llvmpipe load?";
    if (version != nullptr) {
      reason += std::string(" MESA_GL_VERSION_OVERRIDE=") + version +
                " caps the version below 3.3: unset it";
    }
    throw std::runtime_error(reason + ")");
  }
  make_current();
}

Context::~Context() {
  if (impl_->context == nullptr) return;
  prepare_thread(*impl_->library);
  impl_->library->destroy_context(impl_->context);
}

void Context::make_current() {
  prepare_thread(*impl_->library);
  if (!is_current() &&
      !impl_->library->make_current(impl_->context, impl_->dummy.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw std::runtime_error("Context: OSMesaMakeCurrent failed");
  }
  current_gl_functions = &impl_->library->gl;
}

void Context::release() {
  // OSMesa's way to unbind: no context and no buffer.
  prepare_thread(*impl_->library);
  if (is_current()) impl_->library->make_current(nullptr, nullptr, 0, 0, 0);
}

bool Context::is_current() const {
  prepare_thread(*impl_->library);
  return impl_->library->get_current_context() == impl_->context;
}

int Context::mesa_copy() const { return impl_->library->copy; }

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
