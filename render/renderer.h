// Renderer: draws a Scene from a Camera into RGB, depth and segmentation images.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pixelgym/render/camera.h"
#include "pixelgym/render/context.h"
#include "pixelgym/render/scene.h"

namespace pixelgym::render {

/// Where `Renderer::render` writes, and the image size the buffers hold: `width` x `height`
/// pixels, row-major with row 0 at the top; it must equal the camera's. Each pointer may be null
/// to skip that output.
struct RenderTargets {
  /// Pixels per row of every buffer.
  int width = 0;
  /// Rows of every buffer.
  int height = 0;
  /// 3 bytes per pixel, RGB.
  std::uint8_t* rgb = nullptr;
  /// Distance along the camera's viewing axis (-z) in metres; camera.far_m where nothing is drawn.
  float* depth = nullptr;
  /// The Instance::segmentation_id of the surface seen; 0 for the sky, -1 for the floor.
  std::int32_t* segmentation = nullptr;
};

/// A GL context, with everything drawn with it, that several Renderers share, drawing one after
/// another: the renderers constructed with it (`Renderer(group)`) draw with its context instead of
/// one of their own. They share the compiled shader programs, the meshes and textures uploaded (by
/// MeshData address and texture path, so envs of one task upload each mesh once), the framebuffers
/// a frame is drawn in, the shadow map, and the cached backgrounds (by camera and scene settings,
/// up to 16 per image size) and the skies they were drawn over (by camera orientation and sky).
/// Every frame sets all the GL state it draws with and redraws every pixel it reads, so a
/// renderer's frames are byte-identical to those of a renderer with a context of its own. Meshes
/// and textures stay until the group and all its renderers are gone. Its context is of copy
/// `mesa_copy()` of Mesa (see MesaCopy). Why share: docs/design-notes.md, "Rendering".
///
/// Threads: the renderers sharing a context must never draw (or be made or destroyed) at the same
/// time: give one group to renderers that one thread runs in turn (or several threads, one after
/// the other). The GL context is created by the first renderer made with the group, on that
/// renderer's thread, and destroyed with the last of the group and its renderers.
class ContextGroup {
 public:
  /// Throws std::invalid_argument for mesa_copy < 0.
  explicit ContextGroup(int mesa_copy = 0, GlBackend backend = GlBackend::kAuto);
  /// Drops the group's share of the context; the renderers made with it keep theirs.
  ~ContextGroup();
  ContextGroup(const ContextGroup&) = delete;
  ContextGroup& operator=(const ContextGroup&) = delete;

  /// The GL implementation its context comes from.
  GlBackend backend() const { return backend_; }
  /// The copy of Mesa its context is made in, as asked (Context::mesa_copy says which it got).
  int mesa_copy() const { return mesa_copy_; }
  /// Whether a renderer has created the GL context yet.
  bool created() const { return state_ != nullptr; }

  /// The context and programs (opaque outside the renderer): created on the first call, current
  /// on the calling thread on return. For Renderer.
  struct State;
  std::shared_ptr<State> state();

 private:
  GlBackend backend_;
  int mesa_copy_;
  std::shared_ptr<State> state_;
};

/// Turns scenes into pixels with its own OpenGL context (or a ContextGroup's). Meshes and textures
/// are uploaded on first use and kept for later frames (keyed by MeshData address, kept alive by
/// the renderer, and by texture path).
///
/// Threading: a Renderer is used by one thread at a time, any thread, one after the other (made,
/// drawn and destroyed on different threads if need be: its context is bound only during each
/// call, see Context); different renderers can draw concurrently in different threads. The same
/// scene and camera give identical bytes on one machine and one Mesa build.
class Renderer {
 public:
  /// Draws with a context of its own, of copy `mesa_copy` of Mesa (see MesaCopy). Throws
  /// std::runtime_error when the GL context cannot be created or the shaders do not build,
  /// std::invalid_argument for mesa_copy < 0.
  explicit Renderer(GlBackend backend = GlBackend::kAuto, int mesa_copy = 0);
  /// Draws with `group`'s context (created now if it is the group's first renderer), which it
  /// keeps alive: the group object itself may go first. Throws as above.
  explicit Renderer(ContextGroup& group);
  /// Drops its share of the context: a context of its own is destroyed with everything drawn
  /// with it, a group's with the last of the group and its renderers.
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws `scene` as seen by `camera` into `targets`. Throws std::invalid_argument for an invalid
  /// camera, targets whose width and height differ from the camera's (naming both), more MSAA
  /// samples than the GL offers, or an instance without a mesh; std::runtime_error for a texture
  /// that cannot be read.
  void render(const Scene& scene, const Camera& camera, const RenderTargets& targets);

  /// The GL implementation in use (Context::description).
  std::string description();

  /// The most MSAA samples a camera may ask of this renderer (Context::max_samples, GL_MAX_SAMPLES
  /// of its context): 4 on llvmpipe.
  int max_samples() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pixelgym::render
