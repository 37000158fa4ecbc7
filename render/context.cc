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
  if (OSMesaGetCurrentContext() == impl_->context) return;
  if (!OSMesaMakeCurrent(impl_->context, impl_->dummy.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw std::runtime_error("Context: OSMesaMakeCurrent failed");
  }
}

std::string Context::description() {
  make_current();
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer != nullptr ? renderer : "?") + ", " +
         (version != nullptr ? version : "?");
}

int Context::max_samples() {
  make_current();
  GLint samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &samples);
  return samples;
}

}  // namespace pixelgym::render
