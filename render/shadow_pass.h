// Private to render/: the shadow map (the casters' depth seen from the light) and the floor
// rectangles that receive shadows.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_object.h"
#include "pixelgym/render/mesh_arena.h"
#include "pixelgym/render/scene.h"
#include "pixelgym/render/shader_programs.h"

namespace pixelgym::render {

/// The shadow map and the per-frame buffer of caster triangles drawn into it.
class ShadowPass {
 public:
  /// Creates the caster buffers (a context must be current); the map comes with the first draw.
  ShadowPass();

  /// Renders the depth of every instance that casts a shadow, through `light` (world to the
  /// shadow map's clip space, from `fit_light_projection`), into a map of `size` x `size` texels.
  /// `drawn[i]` is the mesh the camera draws `scene.instances[i]` with; casters use one level of
  /// detail coarser when there is one (soft, low-resolution shadows need less geometry). Leaves
  /// the caster vertex array bound.
  void draw(const Scene& scene, const std::vector<const GpuMesh*>& drawn,
            const Eigen::Matrix4f& light, int size, const DepthProgram& program);

  /// The depth texture, compared on lookup (a sampler2DShadow); 0 before the first draw.
  GLuint shadow_map() const { return map_texture_.get(); }

 private:
  void ensure_map(int size);

  GlFramebuffer map_framebuffer_;
  GlTexture map_texture_;
  int map_size_ = 0;
  GlVertexArray caster_vertex_array_;
  GlBuffer caster_vertex_buffer_;
  GlBuffer caster_index_buffer_;
  // Per-frame scratch, kept so that frames allocate nothing once warm.
  std::vector<float> caster_positions_;             // world positions of every caster's vertices
  std::vector<std::uint32_t> caster_indices_;       // closed casters', then the open ones'
  std::vector<std::uint32_t> open_caster_indices_;  // the open ones', before they are appended
};

/// The floor rectangles that can hold shadows (see `shadow_footprints`) as triangles in a small
/// stream buffer of their own, drawn with the floor program (position only).
class ShadowFootprints {
 public:
  /// Creates the stream buffers and vertex array (a context must be current).
  ShadowFootprints();

  /// Replaces the buffer's triangles with two per rectangle (in floor coordinates: z = 0 before
  /// the floor's height is applied) and returns what to draw with `vertex_array()` bound.
  const GpuMesh& upload(const std::vector<Eigen::AlignedBox2f>& rectangles);
  /// The vertex array to bind when drawing what upload() returned.
  GLuint vertex_array() const { return vertex_array_.get(); }

 private:
  GlVertexArray vertex_array_;
  GlBuffer vertex_buffer_;
  GlBuffer index_buffer_;
  std::vector<float> vertices_;         // 3 floats each: x, y, 0
  std::vector<std::uint32_t> indices_;  // 0, 1, 2, ... as long as the longest frame's
  GpuMesh mesh_;
};

}  // namespace pixelgym::render
