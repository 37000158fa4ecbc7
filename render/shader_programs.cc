#include "pixelgym/render/shader_programs.h"

#include <stdexcept>
#include <string>

namespace pixelgym::render {
namespace {

// The fraction of light a point receives, from the shadow map; spliced into the fragment
// shaders that receive shadows (at "@SHADOW@").
constexpr const char* kShadowLookup = R"(
float lit_fraction() {
  vec3 p = light_position.xyz / light_position.w * 0.5 + 0.5;
  // Outside the casters' footprint nothing can shade it; beyond their far side (the floor under
  // them) it compares as the farthest depth.
  if (p.x <= 0.0 || p.x >= 1.0 || p.y <= 0.0 || p.y >= 1.0) return 1.0;
  p.z = min(p.z, 1.0);
  // One linear-filtered lookup: the hardware compares the 2 x 2 nearest texels and blends.
  return texture(shadow_map, p);
}
)";

// The background's colour in a view direction: the sky's gradient or its image; spliced into the
// sky's fragment shader and the floor's (which shows it through when not opaque) at "@SKY@".
constexpr const char* kSkyColor = R"(
uniform vec3 horizon;
uniform vec3 zenith;
uniform bool sky_use_image;
uniform sampler2D sky_image;
uniform float sky_span;  // radians one copy of the image spans, seen from the camera
vec3 sky_color(vec3 ray) {
  vec3 d = normalize(ray);
  if (sky_use_image) {
    // On the face of a cube around the camera that the ray meets, one copy of the image centred
    // on the face's axis (the horizon at mid-height on the side faces); copies mirrored at their
    // edges meet the next face's without a seam.
    vec3 a = abs(d);
    vec2 face = a.z >= max(a.x, a.y) ? d.xy / a.z
              : a.x >= a.y ? vec2(-sign(d.x) * d.y, d.z) / a.x
                           : vec2(sign(d.y) * d.x, d.z) / a.y;
    vec2 uv = 0.5 + 0.5 * face / tan(0.5 * sky_span);
    return texture(sky_image, vec2(uv.x, 1.0 - uv.y)).rgb;
  }
  float elevation = clamp(d.z, 0.0, 1.0);
  return mix(horizon, zenith, sqrt(elevation));
}
)";

constexpr const char* kLitVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 part_color;
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
uniform mat4 light_matrix;
out vec3 world_position;
out vec3 world_normal;
out vec2 texcoord;
out vec4 light_position;
out vec4 vertex_color;
void main() {
  vec4 world = model * vec4(position, 1.0);
  vertex_color = part_color;
  world_position = world.xyz;
  world_normal = normal_matrix * normal;
  texcoord = uv;
  light_position = light_matrix * world;
  gl_Position = view_projection * world;
}
)";

constexpr const char* kLitFragment = R"(#version 330 core
in vec3 world_position;
in vec3 world_normal;
in vec2 texcoord;
in vec4 light_position;
in vec4 vertex_color;
uniform vec4 base_color;
uniform float specular;
uniform float shininess;
uniform vec3 to_light;
uniform vec3 light_color;
uniform vec3 ambient;
uniform vec3 camera_position;
uniform bool use_texture;
uniform sampler2D albedo;
uniform bool use_shadows;
uniform sampler2DShadow shadow_map;
uniform bool mirrored;  // a negative scale turns the winding, and so gl_FrontFacing, around
uniform vec3 color_offset;
out vec4 fragment;

@SHADOW@

void main() {
  vec3 n = normalize(world_normal);
  if (gl_FrontFacing == mirrored) n = -n;  // seen from behind: light the side in view
  // A mesh part's own colour, or the instance's when the part has none (alpha < 0).
  vec3 color = vertex_color.a >= 0.0 ? vertex_color.rgb : base_color.rgb;
  if (use_texture) color *= texture(albedo, texcoord).rgb;
  if (color_offset != vec3(0.0)) color = clamp(color + color_offset, 0.0, 1.0);
  float diffuse = max(dot(n, to_light), 0.0);
  vec3 view = normalize(camera_position - world_position);
  float highlight = diffuse > 0.0 ? pow(max(dot(n, normalize(to_light + view)), 0.0), shininess) : 0.0;
  float light = use_shadows ? lit_fraction() : 1.0;
  vec3 shaded = color * (ambient + light_color * diffuse * light) + light_color * specular * highlight * light;
  fragment = vec4(clamp(shaded, 0.0, 1.0), 1.0);
}
)";

// A full-screen triangle whose fragments find their view ray's elevation for the sky gradient.
constexpr const char* kSkyVertex = R"(#version 330 core
uniform mat4 inverse_view_projection;
out vec3 ray;
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
  vec4 far_point = inverse_view_projection * vec4(corner, 1.0, 1.0);
  vec4 near_point = inverse_view_projection * vec4(corner, -1.0, 1.0);
  ray = far_point.xyz / far_point.w - near_point.xyz / near_point.w;
  gl_Position = vec4(corner, 1.0, 1.0);
}
)";

constexpr const char* kSkyFragment = R"(#version 330 core
in vec3 ray;
out vec4 fragment;
@SKY@
void main() { fragment = vec4(sky_color(ray), 1.0); }
)";

// The floor: flat, so its light (ambient + diffuse, from the CPU) is one value per frame; only the
// filtered checker and the shadow vary per pixel.
constexpr const char* kFloorVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 model;
uniform mat4 view_projection;
uniform mat4 light_matrix;
out vec2 floor_position;
out vec4 light_position;
void main() {
  vec4 world = model * vec4(position, 1.0);
  floor_position = world.xy;
  light_position = light_matrix * world;
  gl_Position = view_projection * world;
}
)";

constexpr const char* kFloorFragment = R"(#version 330 core
in vec2 floor_position;
in vec4 light_position;
uniform float tile;
uniform vec3 color_a;
uniform vec3 color_b;
uniform vec3 ambient;
uniform vec3 direct;
uniform bool use_shadows;
uniform sampler2DShadow shadow_map;
uniform bool use_image;
uniform sampler2D floor_image;
uniform float opacity;
uniform vec3 camera_position;
uniform float floor_height;
out vec4 fragment;

@SHADOW@
@SKY@

void main() {
  float light = use_shadows ? lit_fraction() : 1.0;
  if (use_image) {
    vec3 color = texture(floor_image, floor_position / (2.0 * tile)).rgb * color_a;
    fragment = vec4(clamp(color * (ambient + direct * light), 0.0, 1.0), 1.0);
  } else {
  // The checker averaged over the pixel's footprint (a box filter integrated in closed form),
  // so that distant tiles blend smoothly instead of flickering into moire.
  vec2 p = floor_position / tile;
  vec2 w = fwidth(p) + 1e-4;
  vec2 i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
  vec3 color = mix(color_a, color_b, 0.5 - 0.5 * i.x * i.y);
  fragment = vec4(clamp(color * (ambient + direct * light), 0.0, 1.0), 1.0);
  }
  if (opacity < 1.0) {
    vec3 behind = sky_color(vec3(floor_position, floor_height) - camera_position);
    fragment.rgb = mix(behind, fragment.rgb, opacity);
  }
}
)";

constexpr const char* kDepthVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 model_view_projection;
void main() { gl_Position = model_view_projection * vec4(position, 1.0); }
)";

constexpr const char* kDepthFragment = R"(#version 330 core
void main() {}
)";

constexpr const char* kSegmentationFragment = R"(#version 330 core
uniform int segmentation_id;
out int fragment;
void main() { fragment = segmentation_id; }
)";

GlShader compile(GLenum type, const char* source) {
  GlShader shader(glCreateShader(type));
  glShaderSource(shader.get(), 1, &source, nullptr);
  glCompileShader(shader.get());
  GLint ok = 0;
  glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader.get(), sizeof log, nullptr, log);
    throw std::runtime_error(std::string("Renderer: shader does not compile: ") + log);
  }
  return shader;
}

// `source` with the shared shadow lookup and sky colour spliced in.
std::string with_shared_code(const char* source) {
  std::string text = source;
  for (const auto& [marker, code] : {std::pair<std::string, const char*>{"@SHADOW@", kShadowLookup},
                                     std::pair<std::string, const char*>{"@SKY@", kSkyColor}}) {
    const std::size_t at = text.find(marker);
    if (at != std::string::npos) text.replace(at, marker.size(), code);
  }
  return text;
}

SkyUniforms look_up_sky(const GlProgram& program) {
  SkyUniforms sky;
  sky.horizon = glGetUniformLocation(program.get(), "horizon");
  sky.zenith = glGetUniformLocation(program.get(), "zenith");
  sky.use_image = glGetUniformLocation(program.get(), "sky_use_image");
  sky.image = glGetUniformLocation(program.get(), "sky_image");
  sky.span = glGetUniformLocation(program.get(), "sky_span");
  return sky;
}

}  // namespace

GlProgram link_program(const char* vertex_source, const char* fragment_source) {
  GlProgram program(glCreateProgram());
  {
    // The shaders are deleted at the end of this block: once linked, the program keeps them.
    const GlShader vertex = compile(GL_VERTEX_SHADER, vertex_source);
    const GlShader fragment = compile(GL_FRAGMENT_SHADER, fragment_source);
    glAttachShader(program.get(), vertex.get());
    glAttachShader(program.get(), fragment.get());
    glLinkProgram(program.get());
  }
  GLint ok = 0;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(program.get(), sizeof log, nullptr, log);
    throw std::runtime_error(std::string("Renderer: shaders do not link: ") + log);
  }
  return program;
}

ShaderPrograms::ShaderPrograms() {
  lit.program = link_program(kLitVertex, with_shared_code(kLitFragment).c_str());
  const auto lit_at = [this](const char* name) {
    return glGetUniformLocation(lit.program.get(), name);
  };
  lit.model = lit_at("model");
  lit.normal_matrix = lit_at("normal_matrix");
  lit.view_projection = lit_at("view_projection");
  lit.light_matrix = lit_at("light_matrix");
  lit.base_color = lit_at("base_color");
  lit.specular = lit_at("specular");
  lit.shininess = lit_at("shininess");
  lit.to_light = lit_at("to_light");
  lit.light_color = lit_at("light_color");
  lit.ambient = lit_at("ambient");
  lit.camera_position = lit_at("camera_position");
  lit.use_texture = lit_at("use_texture");
  lit.albedo = lit_at("albedo");
  lit.use_shadows = lit_at("use_shadows");
  lit.shadow_map = lit_at("shadow_map");
  lit.mirrored = lit_at("mirrored");
  lit.color_offset = lit_at("color_offset");

  floor.program = link_program(kFloorVertex, with_shared_code(kFloorFragment).c_str());
  const auto floor_at = [this](const char* name) {
    return glGetUniformLocation(floor.program.get(), name);
  };
  floor.model = floor_at("model");
  floor.view_projection = floor_at("view_projection");
  floor.light_matrix = floor_at("light_matrix");
  floor.tile = floor_at("tile");
  floor.color_a = floor_at("color_a");
  floor.color_b = floor_at("color_b");
  floor.ambient = floor_at("ambient");
  floor.direct = floor_at("direct");
  floor.use_shadows = floor_at("use_shadows");
  floor.shadow_map = floor_at("shadow_map");
  floor.use_image = floor_at("use_image");
  floor.image = floor_at("floor_image");
  floor.opacity = floor_at("opacity");
  floor.camera_position = floor_at("camera_position");
  floor.height = floor_at("floor_height");
  floor.sky = look_up_sky(floor.program);

  sky.program = link_program(kSkyVertex, with_shared_code(kSkyFragment).c_str());
  sky.inverse_view_projection = glGetUniformLocation(sky.program.get(), "inverse_view_projection");
  sky.sky = look_up_sky(sky.program);

  depth.program = link_program(kDepthVertex, kDepthFragment);
  depth.model_view_projection = glGetUniformLocation(depth.program.get(), "model_view_projection");

  segmentation.program = link_program(kDepthVertex, kSegmentationFragment);
  segmentation.model_view_projection =
      glGetUniformLocation(segmentation.program.get(), "model_view_projection");
  segmentation.segmentation_id =
      glGetUniformLocation(segmentation.program.get(), "segmentation_id");
}

}  // namespace pixelgym::render
