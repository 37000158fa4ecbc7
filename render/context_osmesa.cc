// Context's OSMesa backend: a context of one copy of libOSMesa (render/mesa_copy.h).
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/render/context_impl.h"
#include "pixelgym/render/gl.h"
#if PIXELGYM_HAS_OSMESA
#include "pixelgym/render/gl_library.h"
#endif

namespace pixelgym::render {
#if PIXELGYM_HAS_OSMESA
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

class OSMesaContextImpl final : public ContextImpl {
 public:
  explicit OSMesaContextImpl(int mesa_copy) {
    check_gallium_driver();
    library_ = &library_for_new_context(mesa_copy);
    prepare_thread(*library_);
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
    context_ = library_->create_context_attribs(attributes, nullptr);
    if (context_ == nullptr) {
      const char* version = std::getenv("MESA_GL_VERSION_OVERRIDE");
      std::string reason =
          "Context: OSMesa could not create an OpenGL 3.3 core context "
          "(OSMesaCreateContextAttribs failed; is libOSMesa from Mesa < 25.1 installed, and does "
          "llvmpipe load?";
      if (version != nullptr) {
        reason += std::string(" MESA_GL_VERSION_OVERRIDE=") + version +
                  " caps the version below 3.3: unset it";
      }
      throw std::runtime_error(reason + ")");
    }
    make_current();
  }

  ~OSMesaContextImpl() override {
    prepare_thread(*library_);
    library_->destroy_context(context_);
  }
  OSMesaContextImpl(const OSMesaContextImpl&) = delete;
  OSMesaContextImpl& operator=(const OSMesaContextImpl&) = delete;

  void make_current() override {
    prepare_thread(*library_);
    if (!is_current() && !library_->make_current(context_, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      throw std::runtime_error("Context: OSMesaMakeCurrent failed");
    }
  }

  void release() override {
    // OSMesa's way to unbind: no context and no buffer.
    prepare_thread(*library_);
    if (is_current()) library_->make_current(nullptr, nullptr, 0, 0, 0);
  }

  bool is_current() const override {
    prepare_thread(*library_);
    return library_->get_current_context() == context_;
  }

  int mesa_copy() const override { return library_->copy; }
  const GlFunctions& gl() const override { return library_->gl; }

 private:
  const GlLibrary* library_ = nullptr;
  OSMesaContext context_ = nullptr;
  // OSMesa needs a framebuffer to make a context current; rendering goes to framebuffer objects,
  // so this one is a single pixel.
  std::vector<unsigned char> dummy_ = std::vector<unsigned char>(4);
};

}  // namespace

std::unique_ptr<ContextImpl> make_osmesa_context(int mesa_copy) {
  return std::make_unique<OSMesaContextImpl>(mesa_copy);
}
#else
std::unique_ptr<ContextImpl> make_osmesa_context(int /*mesa_copy*/) {
  throw std::runtime_error(
      "Context: this pixelgym was built without OSMesa (configured with -DPIXELGYM_OSMESA=OFF, "
      "for a Mesa that no longer ships it): use render_backend=egl");
}
#endif

}  // namespace pixelgym::render
