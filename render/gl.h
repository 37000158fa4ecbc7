// Private: the OpenGL declarations, for render/*.cc only (never included by a public header).
//
// Every GL function the renderer calls goes through the function table of the library copy whose
// context is current on the calling thread (see render/mesa_copy.h): `glClear(...)` below is
// `current_gl().Clear(...)`. Copies are separate loads of libOSMesa, so the same GL entry point
// differs between them; the table is set by Context::make_current. A GL function used in render/
// must be in PIXELGYM_GL_FUNCTIONS: a call to one that is not would bypass the table and reach
// copy 0 whatever context is current (the test RenderLibrary.CallsGlOnlyThroughTheTable fails then:
// it lists the gl* symbols the render library references directly).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/gl.h>  // NOLINT: first, with GL_GLEXT_PROTOTYPES
#include <GL/glext.h>

#include <string>

/// X(Name) for every glName the renderer calls.
#define PIXELGYM_GL_FUNCTIONS(X)    \
  X(ActiveTexture)                  \
  X(AttachShader)                   \
  X(BindBuffer)                     \
  X(BindFramebuffer)                \
  X(BindRenderbuffer)               \
  X(BindTexture)                    \
  X(BindVertexArray)                \
  X(BlitFramebuffer)                \
  X(BufferData)                     \
  X(CheckFramebufferStatus)         \
  X(Clear)                          \
  X(ClearBufferiv)                  \
  X(CompileShader)                  \
  X(CreateProgram)                  \
  X(CreateShader)                   \
  X(DeleteBuffers)                  \
  X(DeleteFramebuffers)             \
  X(DeleteProgram)                  \
  X(DeleteRenderbuffers)            \
  X(DeleteShader)                   \
  X(DeleteTextures)                 \
  X(DeleteVertexArrays)             \
  X(DepthFunc)                      \
  X(DepthMask)                      \
  X(Disable)                        \
  X(DrawArrays)                     \
  X(DrawBuffer)                     \
  X(DrawElements)                   \
  X(DrawElementsBaseVertex)         \
  X(Enable)                         \
  X(EnableVertexAttribArray)        \
  X(FramebufferRenderbuffer)        \
  X(FramebufferTexture2D)           \
  X(FrontFace)                      \
  X(GenBuffers)                     \
  X(GenFramebuffers)                \
  X(GenRenderbuffers)               \
  X(GenTextures)                    \
  X(GenVertexArrays)                \
  X(GenerateMipmap)                 \
  X(GetIntegerv)                    \
  X(GetProgramInfoLog)              \
  X(GetProgramiv)                   \
  X(GetShaderInfoLog)               \
  X(GetShaderiv)                    \
  X(GetString)                      \
  X(GetUniformLocation)             \
  X(LinkProgram)                    \
  X(PixelStorei)                    \
  X(PolygonOffset)                  \
  X(ReadBuffer)                     \
  X(ReadPixels)                     \
  X(RenderbufferStorage)            \
  X(RenderbufferStorageMultisample) \
  X(ShaderSource)                   \
  X(TexImage2D)                     \
  X(TexParameteri)                  \
  X(Uniform1f)                      \
  X(Uniform1i)                      \
  X(Uniform3fv)                     \
  X(Uniform4fv)                     \
  X(UniformMatrix3fv)               \
  X(UniformMatrix4fv)               \
  X(UseProgram)                     \
  X(VertexAttribPointer)            \
  X(Viewport)

namespace pixelgym::render {

/// One GL library's entry points: a copy of libOSMesa's (OSMesaGetProcAddress of that copy), or
/// EGL's (eglGetProcAddress).
struct GlFunctions {
#define PIXELGYM_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  PIXELGYM_GL_FUNCTIONS(PIXELGYM_GL_MEMBER)
#undef PIXELGYM_GL_MEMBER
};

/// What a GL library's get-proc-address gives (OSMesaGetProcAddress, eglGetProcAddress).
using GlProc = void (*)();

/// Fills `gl` with `get_proc_address("glName")` for every function of the table; returns the
/// first name it gave null for, or "" when it gave them all.
template <typename GetProcAddress>
std::string load_gl_functions(GlFunctions& gl, GetProcAddress get_proc_address) {
#define PIXELGYM_GL_LOAD(name)                                                 \
  gl.name = reinterpret_cast<decltype(gl.name)>(get_proc_address("gl" #name)); \
  if (gl.name == nullptr) return "gl" #name;
  PIXELGYM_GL_FUNCTIONS(PIXELGYM_GL_LOAD)
#undef PIXELGYM_GL_LOAD
  return "";
}

/// The table of the copy whose context was last made current on this thread (Context sets it).
extern thread_local const GlFunctions* current_gl_functions;

/// The calling thread's table: a context must have been made current on this thread first (the
/// pointer is null before).
inline const GlFunctions& current_gl() { return *current_gl_functions; }

}  // namespace pixelgym::render

/// The entry point glName of the current thread's table; each glName below expands to it.
#define PIXELGYM_GL(name) (::pixelgym::render::current_gl().name)
#define glActiveTexture PIXELGYM_GL(ActiveTexture)
#define glAttachShader PIXELGYM_GL(AttachShader)
#define glBindBuffer PIXELGYM_GL(BindBuffer)
#define glBindFramebuffer PIXELGYM_GL(BindFramebuffer)
#define glBindRenderbuffer PIXELGYM_GL(BindRenderbuffer)
#define glBindTexture PIXELGYM_GL(BindTexture)
#define glBindVertexArray PIXELGYM_GL(BindVertexArray)
#define glBlitFramebuffer PIXELGYM_GL(BlitFramebuffer)
#define glBufferData PIXELGYM_GL(BufferData)
#define glCheckFramebufferStatus PIXELGYM_GL(CheckFramebufferStatus)
#define glClear PIXELGYM_GL(Clear)
#define glClearBufferiv PIXELGYM_GL(ClearBufferiv)
#define glCompileShader PIXELGYM_GL(CompileShader)
#define glCreateProgram PIXELGYM_GL(CreateProgram)
#define glCreateShader PIXELGYM_GL(CreateShader)
#define glDeleteBuffers PIXELGYM_GL(DeleteBuffers)
#define glDeleteFramebuffers PIXELGYM_GL(DeleteFramebuffers)
#define glDeleteProgram PIXELGYM_GL(DeleteProgram)
#define glDeleteRenderbuffers PIXELGYM_GL(DeleteRenderbuffers)
#define glDeleteShader PIXELGYM_GL(DeleteShader)
#define glDeleteTextures PIXELGYM_GL(DeleteTextures)
#define glDeleteVertexArrays PIXELGYM_GL(DeleteVertexArrays)
#define glDepthFunc PIXELGYM_GL(DepthFunc)
#define glDepthMask PIXELGYM_GL(DepthMask)
#define glDisable PIXELGYM_GL(Disable)
#define glDrawArrays PIXELGYM_GL(DrawArrays)
#define glDrawBuffer PIXELGYM_GL(DrawBuffer)
#define glDrawElements PIXELGYM_GL(DrawElements)
#define glDrawElementsBaseVertex PIXELGYM_GL(DrawElementsBaseVertex)
#define glEnable PIXELGYM_GL(Enable)
#define glEnableVertexAttribArray PIXELGYM_GL(EnableVertexAttribArray)
#define glFramebufferRenderbuffer PIXELGYM_GL(FramebufferRenderbuffer)
#define glFramebufferTexture2D PIXELGYM_GL(FramebufferTexture2D)
#define glFrontFace PIXELGYM_GL(FrontFace)
#define glGenBuffers PIXELGYM_GL(GenBuffers)
#define glGenFramebuffers PIXELGYM_GL(GenFramebuffers)
#define glGenRenderbuffers PIXELGYM_GL(GenRenderbuffers)
#define glGenTextures PIXELGYM_GL(GenTextures)
#define glGenVertexArrays PIXELGYM_GL(GenVertexArrays)
#define glGenerateMipmap PIXELGYM_GL(GenerateMipmap)
#define glGetIntegerv PIXELGYM_GL(GetIntegerv)
#define glGetProgramInfoLog PIXELGYM_GL(GetProgramInfoLog)
#define glGetProgramiv PIXELGYM_GL(GetProgramiv)
#define glGetShaderInfoLog PIXELGYM_GL(GetShaderInfoLog)
#define glGetShaderiv PIXELGYM_GL(GetShaderiv)
#define glGetString PIXELGYM_GL(GetString)
#define glGetUniformLocation PIXELGYM_GL(GetUniformLocation)
#define glLinkProgram PIXELGYM_GL(LinkProgram)
#define glPixelStorei PIXELGYM_GL(PixelStorei)
#define glPolygonOffset PIXELGYM_GL(PolygonOffset)
#define glReadBuffer PIXELGYM_GL(ReadBuffer)
#define glReadPixels PIXELGYM_GL(ReadPixels)
#define glRenderbufferStorage PIXELGYM_GL(RenderbufferStorage)
#define glRenderbufferStorageMultisample PIXELGYM_GL(RenderbufferStorageMultisample)
#define glShaderSource PIXELGYM_GL(ShaderSource)
#define glTexImage2D PIXELGYM_GL(TexImage2D)
#define glTexParameteri PIXELGYM_GL(TexParameteri)
#define glUniform1f PIXELGYM_GL(Uniform1f)
#define glUniform1i PIXELGYM_GL(Uniform1i)
#define glUniform3fv PIXELGYM_GL(Uniform3fv)
#define glUniform4fv PIXELGYM_GL(Uniform4fv)
#define glUniformMatrix3fv PIXELGYM_GL(UniformMatrix3fv)
#define glUniformMatrix4fv PIXELGYM_GL(UniformMatrix4fv)
#define glUseProgram PIXELGYM_GL(UseProgram)
#define glVertexAttribPointer PIXELGYM_GL(VertexAttribPointer)
#define glViewport PIXELGYM_GL(Viewport)
