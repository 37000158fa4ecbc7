// Private to render/: the renderer's GLSL programs, built once per context, with their uniform
// locations looked up once.
#pragma once

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_object.h"

namespace pixelgym::render {

/// Compiles and links a vertex and a fragment shader. Throws std::runtime_error with the GL's log
/// when either does not compile or they do not link.
GlProgram link_program(const char* vertex_source, const char* fragment_source);

/// Instances: Blinn-Phong with the shadow lookup, a per-vertex part colour and an optional
/// texture.
struct LitProgram {
  /// The linked program; each GLint below is the location of the uniform of its name (-1 until
  /// looked up, or when the shader does not use it). The same for the structs below.
  GlProgram program;
  GLint model = -1, normal_matrix = -1, view_projection = -1, light_matrix = -1, base_color = -1,
        specular = -1, shininess = -1, to_light = -1, light_color = -1, ambient = -1,
        camera_position = -1, use_texture = -1, albedo = -1, use_shadows = -1, shadow_map = -1,
        mirrored = -1, color_offset = -1;
};

/// The uniforms of the shared sky colour (the sky's gradient or image) in a program that has it.
struct SkyUniforms {
  GLint horizon = -1, zenith = -1, use_image = -1, image = -1, span = -1;
};

/// The floor: a box-filtered checker, lit once per frame, with the shadow lookup.
struct FloorProgram {
  GlProgram program;
  GLint model = -1, view_projection = -1, light_matrix = -1, tile = -1, color_a = -1, color_b = -1,
        ambient = -1, direct = -1, use_shadows = -1, shadow_map = -1, use_image = -1, image = -1,
        opacity = -1, camera_position = -1, height = -1;
  SkyUniforms sky;
};

/// The sky: a full-screen triangle (no vertex data) with a vertical gradient or an image.
struct SkyProgram {
  GlProgram program;
  GLint inverse_view_projection = -1;
  SkyUniforms sky;
};

/// Depth only (the shadow map): positions through one matrix.
struct DepthProgram {
  GlProgram program;
  GLint model_view_projection = -1;
};

/// Segmentation: the depth program's vertices, one integer id per draw.
struct SegmentationProgram {
  GlProgram program;
  GLint model_view_projection = -1, segmentation_id = -1;
};

/// Every program the renderer draws with. Needs a current context; throws std::runtime_error
/// when a shader does not build.
struct ShaderPrograms {
  /// Builds every program and looks up its uniforms.
  ShaderPrograms();

  LitProgram lit;
  FloorProgram floor;
  SkyProgram sky;
  DepthProgram depth;
  SegmentationProgram segmentation;
};

}  // namespace pixelgym::render
