// A GL context that cannot be created is a clear error, never a crash.
#include "pixelgym/render/context.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace pixelgym::render {
namespace {

using ::testing::HasSubstr;

// Sets an environment variable for the length of a scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    if (old != nullptr) old_ = old;
    had_ = old != nullptr;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (had_) {
      ::setenv(name_.c_str(), old_.c_str(), 1);
    } else {
      ::unsetenv(name_.c_str());
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::string old_;
  bool had_ = false;
};

std::string creation_error() {
  try {
    Context context;
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(ContextTest, AGalliumDriverOsMesaCannotLoadIsRefusedNotACrash) {
  // The first context of this process: Mesa 22 crashed in OSMesaCreateContextAttribs here.
  const ScopedEnv driver("GALLIUM_DRIVER", "bogus");
  EXPECT_THAT(creation_error(),
              HasSubstr("GALLIUM_DRIVER is \"bogus\", which libOSMesa cannot draw with"));
}

TEST(ContextTest, AVersionCappedBelowThreeThreeIsRefusedNamingTheOverride) {
  const ScopedEnv version("MESA_GL_VERSION_OVERRIDE", "3.0");
  const std::string error = creation_error();
  EXPECT_THAT(error, HasSubstr("could not create an OpenGL 3.3 core context"));
  EXPECT_THAT(error, HasSubstr("MESA_GL_VERSION_OVERRIDE=3.0 caps the version below 3.3"));
}

TEST(ContextTest, TheNamedSoftwareDriversWork) {
  const ScopedEnv driver("GALLIUM_DRIVER", "llvmpipe");
  Context context;
  EXPECT_THAT(context.description(), HasSubstr("llvmpipe"));
}

}  // namespace
}  // namespace pixelgym::render
