#include "render/context.h"

#include <GL/osmesa.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "render/gl.h"

namespace pixelgym::render {
namespace {

void default_llvmpipe_threads() {
  static std::once_flag once;
  std::call_once(once, [] {
    // Read by llvmpipe when it creates its screen, on the first context: see Context's comment.
    if (std::getenv("LP_NUM_THREADS") == nullptr) setenv("LP_NUM_THREADS", "0", 0);
  });
}

}  // namespace

struct Context::Impl {
  OSMesaContext context = nullptr;
  // OSMesa needs a framebuffer to make a context current; rendering goes to framebuffer objects,
  // so this one is a single pixel.
  std::vector<unsigned char> dummy = std::vector<unsigned char>(4);
};

Context::Context(GlBackend backend) : backend_(backend), impl_(std::make_unique<Impl>()) {
  default_llvmpipe_threads();
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
  impl_->context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (impl_->context == nullptr) {
    throw std::runtime_error(
        "Context: OSMesa could not create an OpenGL 3.3 core context (OSMesaCreateContextAttribs "
        "failed; is libOSMesa from Mesa < 25.1 installed, and does llvmpipe load?)");
  }
  make_current();
}

Context::~Context() {
  if (impl_->context != nullptr) OSMesaDestroyContext(impl_->context);
}

void Context::make_current() {
  if (is_current()) return;
  if (!OSMesaMakeCurrent(impl_->context, impl_->dummy.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw std::runtime_error("Context: OSMesaMakeCurrent failed");
  }
}

void Context::release() {
  // OSMesa's way to unbind: no context and no buffer.
  if (is_current()) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
}

bool Context::is_current() const { return OSMesaGetCurrentContext() == impl_->context; }

Context::Scope::Scope(Context& context) : context_(context), was_current_(context.is_current()) {
  context_.make_current();
}

Context::Scope::~Scope() {
  if (!was_current_) context_.release();
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
