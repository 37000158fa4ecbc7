// Context's EGL backend: libEGL loaded at run time (a machine without it still runs OSMesa), a
// display chosen once per process (a GPU's EGL device, or Mesa's surfaceless platform on
// llvmpipe), and contexts current without a surface, drawing into framebuffer objects.
// No X11 types: this backend never opens a window.
#define EGL_NO_X11
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/render/context_impl.h"
#include "pixelgym/render/gl.h"

namespace pixelgym::render {
namespace {

constexpr const char* kInstallHint =
    "install libegl1 and libegl-mesa0, and libgl1-mesa-dri for llvmpipe (Debian and Ubuntu "
    "package names), or a GPU driver's EGL";

std::string error_name(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default:
      return "EGL error 0x" + [error] {
        char hex[16];
        std::snprintf(hex, sizeof hex, "%x", static_cast<unsigned>(error));
        return std::string(hex);
      }();
  }
}

bool has_extension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const std::size_t length = std::strlen(name);
  for (const char* at = std::strstr(extensions, name); at != nullptr;
       at = std::strstr(at + length, name)) {
    const bool starts = at == extensions || at[-1] == ' ';
    const bool ends = at[length] == '\0' || at[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

// libEGL's entry points, the display chosen and the GL table: made once, never destroyed
// (contexts may outlive static destructors, and eglTerminate would end every context).
struct Egl {
  PFNEGLGETPROCADDRESSPROC get_proc_address = nullptr;
  PFNEGLGETERRORPROC get_error = nullptr;
  PFNEGLQUERYSTRINGPROC query_string = nullptr;
  PFNEGLINITIALIZEPROC initialize = nullptr;
  PFNEGLBINDAPIPROC bind_api = nullptr;
  PFNEGLCHOOSECONFIGPROC choose_config = nullptr;
  PFNEGLCREATECONTEXTPROC create_context = nullptr;
  PFNEGLDESTROYCONTEXTPROC destroy_context = nullptr;
  PFNEGLMAKECURRENTPROC make_current = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC get_current_context = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = nullptr;
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string = nullptr;
  PFNEGLQUERYDEVICEATTRIBEXTPROC query_device_attrib = nullptr;

  EGLDisplay display = EGL_NO_DISPLAY;
  EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR where the display takes contexts without one
  std::string display_name;    // "surfaceless (Mesa)", "device 1 (/dev/dri/renderD129)"
  GlFunctions gl;

  std::string last_error() const { return error_name(get_error()); }
};

template <typename Function>
void load(void* library, const char* name, Function& function) {
  function = reinterpret_cast<Function>(::dlsym(library, name));
  if (function == nullptr) {
    throw std::runtime_error(std::string("Context: libEGL.so.1 has no ") + name + " (" +
                             kInstallHint + ")");
  }
}

template <typename Function>
void load_extension(const Egl& egl, const char* name, Function& function) {
  function = reinterpret_cast<Function>(egl.get_proc_address(name));
}

// What PIXELGYM_EGL_DEVICE asks for: "" (a GPU's device if any, else surfaceless),
// "surfaceless", a device index, or "cuda:N".
std::string device_request() {
  const char* text = std::getenv("PIXELGYM_EGL_DEVICE");
  return text == nullptr ? "" : text;
}

// A whole number >= 0 spelled in `text` from `start`, or -1.
long whole_number(const std::string& text, std::size_t start) {
  if (start >= text.size()) return -1;
  for (std::size_t i = start; i < text.size(); ++i) {
    if (text[i] < '0' || text[i] > '9' || i - start > 6) return -1;
  }
  return std::stol(text.substr(start));
}

std::string describe_device(const Egl& egl, EGLDeviceEXT device) {
  const char* extensions = egl.query_device_string(device, EGL_EXTENSIONS);
  if (has_extension(extensions, "EGL_MESA_device_software")) return "software (llvmpipe)";
  if (has_extension(extensions, "EGL_EXT_device_drm_render_node")) {
    const char* node = egl.query_device_string(device, EGL_DRM_RENDER_NODE_FILE_EXT);
    if (node != nullptr) return node;
  }
  if (has_extension(extensions, "EGL_EXT_device_drm")) {
    const char* file = egl.query_device_string(device, EGL_DRM_DEVICE_FILE_EXT);
    if (file != nullptr) return file;
  }
  return "a GPU";
}

bool is_software(const Egl& egl, EGLDeviceEXT device) {
  return has_extension(egl.query_device_string(device, EGL_EXTENSIONS), "EGL_MESA_device_software");
}

// The CUDA device number of an EGL device, or -1 (EGL_NV_device_cuda's EGL_CUDA_DEVICE_NV).
long cuda_number(const Egl& egl, EGLDeviceEXT device) {
  if (!has_extension(egl.query_device_string(device, EGL_EXTENSIONS), "EGL_NV_device_cuda")) {
    return -1;
  }
  EGLAttrib value = -1;
  constexpr EGLint kCudaDeviceNv = 0x323A;  // EGL_CUDA_DEVICE_NV
  if (egl.query_device_attrib(device, kCudaDeviceNv, &value) != EGL_TRUE) return -1;
  return static_cast<long>(value);
}

// Picks and initializes the display PIXELGYM_EGL_DEVICE asks for.
void open_display(Egl& egl) {
  const char* client = egl.query_string(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::vector<EGLDeviceEXT> devices;
  if (egl.query_devices != nullptr && egl.query_device_string != nullptr &&
      has_extension(client, "EGL_EXT_platform_device")) {
    EGLint count = 0;
    if (egl.query_devices(0, nullptr, &count) == EGL_TRUE && count > 0) {
      devices.resize(static_cast<std::size_t>(count));
      egl.query_devices(count, devices.data(), &count);
      devices.resize(static_cast<std::size_t>(count));
    }
  }
  const bool surfaceless = has_extension(client, "EGL_MESA_platform_surfaceless");
  std::string list;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    list += (i == 0 ? "" : ", ") + std::to_string(i) + ": " + describe_device(egl, devices[i]);
  }
  const std::string devices_said =
      devices.empty() ? "this machine's EGL offers no devices"
                      : "this machine's EGL offers " + std::to_string(devices.size()) + " device" +
                            (devices.size() == 1 ? "" : "s") + " (" + list + ")";

  const std::string request = device_request();
  long chosen = -1;  // a device index, or -1 for surfaceless
  if (request.empty() || request == "auto") {
    for (std::size_t i = 0; i < devices.size() && chosen < 0; ++i) {
      if (!is_software(egl, devices[i])) chosen = static_cast<long>(i);
    }
    if (chosen < 0 && !surfaceless) {
      if (devices.empty()) {
        throw std::runtime_error(
            "Context: EGL offers neither a device nor Mesa's surfaceless platform to draw "
            "without a display (" +
            std::string(kInstallHint) + ")");
      }
      chosen = 0;
    }
  } else if (request == "surfaceless") {
    if (!surfaceless) {
      throw std::invalid_argument(
          "PIXELGYM_EGL_DEVICE=surfaceless, but this machine's EGL has no "
          "EGL_MESA_platform_surfaceless (" +
          std::string(kInstallHint) + ")");
    }
  } else if (request.rfind("cuda:", 0) == 0) {
    const long cuda = whole_number(request, 5);
    for (std::size_t i = 0; i < devices.size() && cuda >= 0 && chosen < 0; ++i) {
      if (cuda_number(egl, devices[i]) == cuda) chosen = static_cast<long>(i);
    }
    if (chosen < 0) {
      throw std::invalid_argument(
          "PIXELGYM_EGL_DEVICE=" + request +
          " names no EGL device with that CUDA number (EGL_CUDA_DEVICE_NV): " + devices_said);
    }
  } else {
    chosen = whole_number(request, 0);
    if (chosen < 0 || chosen >= static_cast<long>(devices.size())) {
      throw std::invalid_argument(
          "PIXELGYM_EGL_DEVICE must be an EGL device index, cuda:N, surfaceless or auto, got \"" +
          request + "\": " + devices_said);
    }
  }

  if (chosen >= 0) {
    egl.display = egl.get_platform_display(EGL_PLATFORM_DEVICE_EXT,
                                           devices[static_cast<std::size_t>(chosen)], nullptr);
    egl.display_name = "EGL device " + std::to_string(chosen) + " (" +
                       describe_device(egl, devices[static_cast<std::size_t>(chosen)]) + ")";
  } else {
    egl.display =
        egl.get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    egl.display_name = "EGL surfaceless (Mesa)";
  }
  EGLint major = 0;
  EGLint minor = 0;
  if (egl.display == EGL_NO_DISPLAY || egl.initialize(egl.display, &major, &minor) != EGL_TRUE) {
    const char* driver = std::getenv("GALLIUM_DRIVER");
    throw std::runtime_error(
        "Context: EGL could not open " + egl.display_name + " (" + egl.last_error() + "; " +
        (driver != nullptr && *driver != '\0'
             ? "GALLIUM_DRIVER=" + std::string(driver) + " may name a driver Mesa cannot load"
             : std::string(kInstallHint)) +
        ")");
  }
  const char* extensions = egl.query_string(egl.display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    throw std::runtime_error("Context: " + egl.display_name +
                             " lacks EGL_KHR_surfaceless_context, which drawing without a window "
                             "needs");
  }
  if (egl.bind_api(EGL_OPENGL_API) != EGL_TRUE) {
    throw std::runtime_error(
        "Context: " + egl.display_name +
        " offers no desktop OpenGL (eglBindAPI(EGL_OPENGL_API) failed: " + egl.last_error() + ")");
  }
  const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLint configs = 0;
  if (egl.choose_config(egl.display, wanted, &egl.config, 1, &configs) != EGL_TRUE ||
      configs == 0) {
    if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
      throw std::runtime_error("Context: " + egl.display_name +
                               " has no config for desktop OpenGL");
    }
    egl.config = EGL_NO_CONFIG_KHR;
  }
}

// Loaded and opened on first use; a failure is not kept, so a later context tries again (after
// PIXELGYM_EGL_DEVICE was corrected, say).
Egl& egl() {
  static std::mutex mutex;
  static Egl* loaded = nullptr;
  static void* library = nullptr;
  const std::lock_guard<std::mutex> lock(mutex);
  if (loaded != nullptr) return *loaded;
  default_llvmpipe_threads();
  if (library == nullptr) library = ::dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* error = ::dlerror();
    throw std::runtime_error(std::string("Context: cannot load libEGL.so.1 (") +
                             (error != nullptr ? error : "dlopen failed") + "; " + kInstallHint +
                             ")");
  }
  auto made = std::make_unique<Egl>();
  Egl& e = *made;
  load(library, "eglGetProcAddress", e.get_proc_address);
  load(library, "eglGetError", e.get_error);
  load(library, "eglQueryString", e.query_string);
  load(library, "eglInitialize", e.initialize);
  load(library, "eglBindAPI", e.bind_api);
  load(library, "eglChooseConfig", e.choose_config);
  load(library, "eglCreateContext", e.create_context);
  load(library, "eglDestroyContext", e.destroy_context);
  load(library, "eglMakeCurrent", e.make_current);
  load(library, "eglGetCurrentContext", e.get_current_context);
  load_extension(e, "eglGetPlatformDisplayEXT", e.get_platform_display);
  load_extension(e, "eglQueryDevicesEXT", e.query_devices);
  load_extension(e, "eglQueryDeviceStringEXT", e.query_device_string);
  load_extension(e, "eglQueryDeviceAttribEXT", e.query_device_attrib);
  if (e.get_platform_display == nullptr) {
    throw std::runtime_error(
        "Context: libEGL.so.1 has no eglGetPlatformDisplayEXT (EGL_EXT_platform_base), which "
        "drawing without a display needs (" +
        std::string(kInstallHint) + ")");
  }
  open_display(e);
  const std::string missing = load_gl_functions(
      e.gl, [&e](const char* name) { return reinterpret_cast<GlProc>(e.get_proc_address(name)); });
  if (!missing.empty()) {
    throw std::runtime_error("Context: EGL gives no " + missing + " (eglGetProcAddress)");
  }
  loaded = made.release();  // never destroyed, as Egl says
  return *loaded;
}

// eglBindAPI is the calling thread's: a thread that never bound OpenGL would query (and
// release) its OpenGL ES context instead.
void bind_opengl(const Egl& e) { e.bind_api(EGL_OPENGL_API); }

class EglContextImpl final : public ContextImpl {
 public:
  EglContextImpl() : egl_(egl()) {
    bind_opengl(egl_);
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 3,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 3,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_NONE};
    context_ = egl_.create_context(egl_.display, egl_.config, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT) {
      throw std::runtime_error("Context: EGL could not create an OpenGL 3.3 core context on " +
                               egl_.display_name + " (eglCreateContext: " + egl_.last_error() +
                               ")");
    }
    make_current();
  }

  ~EglContextImpl() override {
    release();
    egl_.destroy_context(egl_.display, context_);
  }
  EglContextImpl(const EglContextImpl&) = delete;
  EglContextImpl& operator=(const EglContextImpl&) = delete;

  void make_current() override {
    if (is_current()) return;
    if (egl_.make_current(egl_.display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
      const EGLint error = egl_.get_error();
      throw std::runtime_error(
          "Context: eglMakeCurrent failed on " + egl_.display_name + " (" + error_name(error) +
          (error == EGL_BAD_ACCESS ? ": the context is current on another thread" : "") + ")");
    }
  }

  void release() override {
    if (is_current()) {
      egl_.make_current(egl_.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
  }

  bool is_current() const override {
    bind_opengl(egl_);
    return egl_.get_current_context() == context_;
  }

  const GlFunctions& gl() const override { return egl_.gl; }

 private:
  const Egl& egl_;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<ContextImpl> make_egl_context() { return std::make_unique<EglContextImpl>(); }

std::string egl_display_name() { return egl().display_name; }

}  // namespace pixelgym::render
