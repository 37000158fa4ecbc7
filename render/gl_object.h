// Private to render/: move-only owners of OpenGL object names (buffers, vertex arrays, textures,
// framebuffers, renderbuffers, programs, shaders), deleted in their destructors.
//
// An owner must be destroyed while the context that created it is current: the renderer makes
// its context current in its destructor, before its members (these owners) go.
#pragma once

#include <utility>

#include "pixelgym/render/gl.h"

namespace pixelgym::render {

/// Owns one OpenGL object name; `Delete` frees it. 0 means "none" (OpenGL never hands out 0).
template <void (*Delete)(GLuint)>
class GlObject {
 public:
  /// Owns nothing.
  GlObject() = default;
  /// Takes ownership of `name` (0 for none).
  explicit GlObject(GLuint name) : name_(name) {}
  /// Deletes the object, if any (its context must be current).
  ~GlObject() { reset(); }
  /// Takes `other`'s name, leaving it empty.
  GlObject(GlObject&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  /// Deletes this one's object, if any, then takes `other`'s name, leaving it empty.
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  /// The name, for GL calls; 0 when empty.
  GLuint get() const { return name_; }
  /// True when it owns an object.
  explicit operator bool() const { return name_ != 0; }
  /// Deletes the object now (when there is one).
  void reset() {
    if (name_ != 0) Delete(name_);
    name_ = 0;
  }

 private:
  GLuint name_ = 0;
};

/// The deleters of the owners below: each frees one name with the matching glDelete* call.
namespace gl_delete {
inline void buffer(GLuint name) { glDeleteBuffers(1, &name); }
inline void vertex_array(GLuint name) { glDeleteVertexArrays(1, &name); }
inline void texture(GLuint name) { glDeleteTextures(1, &name); }
inline void framebuffer(GLuint name) { glDeleteFramebuffers(1, &name); }
inline void renderbuffer(GLuint name) { glDeleteRenderbuffers(1, &name); }
inline void program(GLuint name) { glDeleteProgram(name); }
inline void shader(GLuint name) { glDeleteShader(name); }
}  // namespace gl_delete

/// Owners of one buffer, vertex array, texture, framebuffer, renderbuffer, program or shader.
using GlBuffer = GlObject<gl_delete::buffer>;
using GlVertexArray = GlObject<gl_delete::vertex_array>;
using GlTexture = GlObject<gl_delete::texture>;
using GlFramebuffer = GlObject<gl_delete::framebuffer>;
using GlRenderbuffer = GlObject<gl_delete::renderbuffer>;
using GlProgram = GlObject<gl_delete::program>;
using GlShader = GlObject<gl_delete::shader>;

/// New, unbound objects (glGen*).
inline GlBuffer make_buffer() {
  GLuint name = 0;
  glGenBuffers(1, &name);
  return GlBuffer(name);
}
inline GlVertexArray make_vertex_array() {
  GLuint name = 0;
  glGenVertexArrays(1, &name);
  return GlVertexArray(name);
}
inline GlTexture make_texture() {
  GLuint name = 0;
  glGenTextures(1, &name);
  return GlTexture(name);
}
inline GlFramebuffer make_framebuffer() {
  GLuint name = 0;
  glGenFramebuffers(1, &name);
  return GlFramebuffer(name);
}

/// A renderbuffer with storage of `format` at a size, multisampled when `samples` > 0; left bound
/// to GL_RENDERBUFFER.
inline GlRenderbuffer make_renderbuffer(GLenum format, int width, int height, int samples) {
  GLuint name = 0;
  glGenRenderbuffers(1, &name);
  glBindRenderbuffer(GL_RENDERBUFFER, name);
  if (samples > 0) {
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  } else {
    glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
  }
  return GlRenderbuffer(name);
}

}  // namespace pixelgym::render
