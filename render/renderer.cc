#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "render/gl.h"
#include "render/image_io.h"

namespace pixelgym::render {
namespace {

// --- shaders ---------------------------------------------------------------------------------

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
out vec4 fragment;

@SHADOW@

void main() {
  vec3 n = normalize(world_normal);
  if (gl_FrontFacing == mirrored) n = -n;  // seen from behind: light the side in view
  // A mesh part's own colour, or the instance's when the part has none (alpha < 0).
  vec3 color = vertex_color.a >= 0.0 ? vertex_color.rgb : base_color.rgb;
  if (use_texture) color *= texture(albedo, texcoord).rgb;
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
uniform vec3 horizon;
uniform vec3 zenith;
out vec4 fragment;
void main() {
  float elevation = clamp(normalize(ray).z, 0.0, 1.0);
  fragment = vec4(mix(horizon, zenith, sqrt(elevation)), 1.0);
}
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
out vec4 fragment;

@SHADOW@

void main() {
  // The checker averaged over the pixel's footprint (a box filter integrated in closed form),
  // so that distant tiles blend smoothly instead of flickering into moire.
  vec2 p = floor_position / tile;
  vec2 w = fwidth(p) + 1e-4;
  vec2 i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
  vec3 color = mix(color_a, color_b, 0.5 - 0.5 * i.x * i.y);
  float light = use_shadows ? lit_fraction() : 1.0;
  fragment = vec4(clamp(color * (ambient + direct * light), 0.0, 1.0), 1.0);
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

GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("Renderer: shader does not compile: ") + log);
  }
  return shader;
}

// `source` with the shared shadow lookup spliced in.
std::string with_shadow_lookup(const char* source) {
  std::string text = source;
  const std::string marker = "@SHADOW@";
  const std::size_t at = text.find(marker);
  if (at != std::string::npos) text.replace(at, marker.size(), kShadowLookup);
  return text;
}

GLuint link(const char* vertex, const char* fragment) {
  const GLuint program = glCreateProgram();
  const GLuint v = compile(GL_VERTEX_SHADER, vertex);
  const GLuint f = compile(GL_FRAGMENT_SHADER, fragment);
  glAttachShader(program, v);
  glAttachShader(program, f);
  glLinkProgram(program);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("Renderer: shaders do not link: ") + log);
  }
  return program;
}

// Uniform locations of the lit program, looked up once.
struct LitUniforms {
  GLint model, normal_matrix, view_projection, light_matrix, base_color, specular, shininess,
      to_light, light_color, ambient, camera_position, use_texture, albedo, use_shadows, shadow_map,
      mirrored;
};

struct FloorUniforms {
  GLint model, view_projection, light_matrix, tile, color_a, color_b, ambient, direct, use_shadows,
      shadow_map;
};

// Floats per arena vertex: position 3, normal 3, texture coordinate 2, part colour 4.
constexpr int kArenaStride = 12;

// Polygon offsets of the floor and of the shadowed floor footprints drawn over it.
constexpr float kFloorDepthOffset = 1.0F;
constexpr float kFootprintDepthOffset = 0.5F;

struct GpuMesh {
  std::shared_ptr<const MeshData> keep_alive;
  GLint base_vertex = 0;          // of its first vertex in the arena
  std::uint32_t first_index = 0;  // of its first index in the arena
  std::uint32_t index_count = 0;
  float radius = 0.0F;         // of a sphere about the origin that holds every vertex
  Eigen::AlignedBox3f bounds;  // in mesh coordinates
};

// Render targets for one image size and sample count.
struct Target {
  GLuint framebuffer = 0;  // what is drawn into (multisampled when samples > 0)
  GLuint color = 0;
  GLuint depth = 0;
  GLuint resolve_framebuffer = 0;  // single-sampled copy to read from when multisampled
  GLuint resolve_color = 0;
  GLuint resolve_depth = 0;
};

struct SegmentationTarget {
  GLuint framebuffer = 0;
  GLuint ids = 0;
  GLuint depth = 0;
};

void check_framebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error(std::string("Renderer: ") + what + " framebuffer incomplete (status " +
                             std::to_string(status) + ")");
  }
}

GLuint make_renderbuffer(GLenum format, int width, int height, int samples) {
  GLuint renderbuffer = 0;
  glGenRenderbuffers(1, &renderbuffer);
  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffer);
  if (samples > 0) {
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
  } else {
    glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
  }
  return renderbuffer;
}

int shadow_map_size(const Camera& camera) {
  // About one shadow texel per image pixel, as a power of two in [128, 2048]: a shadow map larger
  // than the image costs more to clear and sample than it shows.
  int size = 128;
  while (size < std::max(camera.width, camera.height) && size < 2048) size *= 2;
  return size;
}

Eigen::Matrix4f orthographic(float left, float right, float bottom, float top, float near_m,
                             float far_m) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m(0, 0) = 2.0F / (right - left);
  m(1, 1) = 2.0F / (top - bottom);
  m(2, 2) = -2.0F / (far_m - near_m);
  m(0, 3) = -(right + left) / (right - left);
  m(1, 3) = -(top + bottom) / (top - bottom);
  m(2, 3) = -(far_m + near_m) / (far_m - near_m);
  return m;
}

Eigen::Matrix4f look_from(const Eigen::Vector3f& eye, const Eigen::Vector3f& direction) {
  const Eigen::Vector3f back = -direction.normalized();
  const Eigen::Vector3f helper =
      std::abs(back.z()) > 0.9F ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f right = helper.cross(back).normalized();
  const Eigen::Vector3f up = back.cross(right);
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
  view.block<1, 3>(0, 0) = right.transpose();
  view.block<1, 3>(1, 0) = up.transpose();
  view.block<1, 3>(2, 0) = back.transpose();
  view(0, 3) = -right.dot(eye);
  view(1, 3) = -up.dot(eye);
  view(2, 3) = -back.dot(eye);
  return view;
}

Eigen::Matrix4f model_matrix(const Instance& instance) {
  Eigen::Affine3f model = Eigen::Affine3f(instance.X_world_instance.matrix());
  model.scale(instance.scale);
  return model.matrix();
}

}  // namespace

struct Renderer::Impl {
  explicit Impl(GlBackend backend) : context(backend) {
    lit = link(kLitVertex, with_shadow_lookup(kLitFragment).c_str());
    sky = link(kSkyVertex, kSkyFragment);
    depth_only = link(kDepthVertex, kDepthFragment);
    segmentation = link(kDepthVertex, kSegmentationFragment);
    const auto at = [this](const char* name) { return glGetUniformLocation(lit, name); };
    u = {at("model"),       at("normal_matrix"), at("view_projection"), at("light_matrix"),
         at("base_color"),  at("specular"),      at("shininess"),       at("to_light"),
         at("light_color"), at("ambient"),       at("camera_position"), at("use_texture"),
         at("albedo"),      at("use_shadows"),   at("shadow_map"),      at("mirrored")};
    floor_program = link(kFloorVertex, with_shadow_lookup(kFloorFragment).c_str());
    const auto floor_at = [this](const char* name) {
      return glGetUniformLocation(floor_program, name);
    };
    fu = {floor_at("model"),     floor_at("view_projection"), floor_at("light_matrix"),
          floor_at("tile"),      floor_at("color_a"),         floor_at("color_b"),
          floor_at("ambient"),   floor_at("direct"),          floor_at("use_shadows"),
          floor_at("shadow_map")};
    depth_mvp = glGetUniformLocation(depth_only, "model_view_projection");
    sky_inverse_view_projection = glGetUniformLocation(sky, "inverse_view_projection");
    sky_horizon = glGetUniformLocation(sky, "horizon");
    sky_zenith = glGetUniformLocation(sky, "zenith");
    glGenVertexArrays(1, &empty_vao);
    glGenVertexArrays(1, &arena_vao);
    glBindVertexArray(arena_vao);
    glGenBuffers(1, &arena_vbo);
    glGenBuffers(1, &arena_ebo);
    glBindBuffer(GL_ARRAY_BUFFER, arena_vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, arena_ebo);
    constexpr GLsizei kStride = kArenaStride * sizeof(float);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<void*>(0));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kStride,
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, kStride,
                          reinterpret_cast<void*>(6 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, kStride,
                          reinterpret_cast<void*>(8 * sizeof(float)));
    glEnableVertexAttribArray(3);
    // The floor: a large square (its checker pattern comes from world coordinates).
    auto floor_mesh = std::make_shared<MeshData>();
    const float half = 500.0F;
    floor_mesh->positions = {
        {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
    floor_mesh->normals.assign(4, Eigen::Vector3f::UnitZ());
    floor_mesh->indices = {0, 1, 2, 0, 2, 3};
    floor = std::move(floor_mesh);
    // A white texel for untextured draws, so that the sampler always has a complete texture.
    glGenTextures(1, &white_texture);
    glBindTexture(GL_TEXTURE_2D, white_texture);
    const unsigned char white[4] = {255, 255, 255, 255};
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, white);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glFrontFace(GL_CW);  // the flipped projection mirrors the winding
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  }

  ~Impl() {
    context.make_current();
    glDeleteVertexArrays(1, &arena_vao);
    if (caster_vao != 0) {
      glDeleteVertexArrays(1, &caster_vao);
      const GLuint caster_buffers[] = {caster_vbo, caster_ebo};
      glDeleteBuffers(2, caster_buffers);
    }
    if (footprint_vao != 0) {
      glDeleteVertexArrays(1, &footprint_vao);
      const GLuint footprint_buffers[] = {footprint_vbo, footprint_ebo};
      glDeleteBuffers(2, footprint_buffers);
    }
    const GLuint buffers[] = {arena_vbo, arena_ebo};
    glDeleteBuffers(2, buffers);
    for (auto& [key, target] : targets) {
      const GLuint framebuffers[] = {target.framebuffer, target.resolve_framebuffer};
      glDeleteFramebuffers(2, framebuffers);
      const GLuint renderbuffers[] = {target.color, target.depth, target.resolve_color,
                                      target.resolve_depth};
      glDeleteRenderbuffers(4, renderbuffers);
    }
    for (auto& [key, target] : backgrounds) {
      glDeleteFramebuffers(1, &target.framebuffer);
      const GLuint renderbuffers[] = {target.color, target.depth};
      glDeleteRenderbuffers(2, renderbuffers);
    }
    for (auto& [key, target] : segmentation_targets) {
      glDeleteFramebuffers(1, &target.framebuffer);
      const GLuint renderbuffers[] = {target.ids, target.depth};
      glDeleteRenderbuffers(2, renderbuffers);
    }
    for (auto& [path, texture] : textures) glDeleteTextures(1, &texture);
    glDeleteTextures(1, &white_texture);
    if (shadow_framebuffer != 0) glDeleteFramebuffers(1, &shadow_framebuffer);
    if (shadow_texture != 0) glDeleteTextures(1, &shadow_texture);
    glDeleteVertexArrays(1, &empty_vao);
    for (GLuint program : {lit, sky, depth_only, segmentation, floor_program})
      glDeleteProgram(program);
  }

  // Adds a mesh to the arena: every mesh shares one vertex buffer, one index buffer and one
  // vertex array, so that drawing another mesh changes no GL state but offsets (llvmpipe
  // revalidates much of its state when the vertex array changes, which dominated small frames).
  const GpuMesh& upload(const std::shared_ptr<const MeshData>& mesh) {
    auto found = meshes.find(mesh.get());
    if (found != meshes.end()) return found->second;
    GpuMesh gpu;
    gpu.keep_alive = mesh;
    gpu.base_vertex = static_cast<GLint>(arena_vertices.size() / kArenaStride);
    gpu.first_index = static_cast<std::uint32_t>(arena_indices.size());
    // Each part's colour goes into its vertices, so that a mesh is one draw whatever its number
    // of materials; alpha -1 marks "the instance's colour".
    std::vector<Eigen::Vector4f> colors(mesh->positions.size(), Eigen::Vector4f(0, 0, 0, -1));
    for (const MeshData::Part& part : mesh->parts) {
      if (!part.has_color) continue;
      for (std::uint32_t k = part.first_index; k < part.first_index + part.index_count; ++k) {
        colors[mesh->indices[k]] = part.rgba;
      }
    }
    for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
      const Eigen::Vector3f& p = mesh->positions[i];
      const Eigen::Vector3f n =
          i < mesh->normals.size() ? mesh->normals[i] : Eigen::Vector3f::UnitZ();
      const Eigen::Vector2f t =
          i < mesh->texcoords.size() ? mesh->texcoords[i] : Eigen::Vector2f::Zero();
      const Eigen::Vector4f& c = colors[i];
      arena_vertices.insert(arena_vertices.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), t.x(),
                                                   t.y(), c.x(), c.y(), c.z(), c.w()});
      gpu.radius = std::max(gpu.radius, p.norm());
      gpu.bounds.extend(p);
    }
    arena_indices.insert(arena_indices.end(), mesh->indices.begin(), mesh->indices.end());
    arena_dirty = true;
    gpu.index_count = static_cast<std::uint32_t>(mesh->indices.size());
    return meshes.emplace(mesh.get(), std::move(gpu)).first->second;
  }

  // Sends the arena to the GPU when meshes were added since the last frame.
  void sync_arena() {
    glBindVertexArray(arena_vao);
    if (!arena_dirty) return;
    glBindBuffer(GL_ARRAY_BUFFER, arena_vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(arena_vertices.size() * sizeof(float)),
                 arena_vertices.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, arena_ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(arena_indices.size() * sizeof(std::uint32_t)),
                 arena_indices.data(), GL_STATIC_DRAW);
    arena_dirty = false;
  }

  void bind_albedo(GLuint handle) {
    if (bound_albedo == handle) return;
    glBindTexture(GL_TEXTURE_2D, handle);
    bound_albedo = handle;
  }

  GLuint texture(const std::string& path) {
    auto found = textures.find(path);
    if (found != textures.end()) return found->second;
    Image image;
    try {
      image = read_png(path);
    } catch (const std::runtime_error& error) {
      throw std::runtime_error(std::string("Renderer: texture cannot be used: ") + error.what());
    }
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(image.width) *
                                   static_cast<std::size_t>(image.height) * 4);
    for (std::size_t p = 0; p < rgba.size() / 4; ++p) {
      const std::uint8_t* source =
          image.pixels.data() + p * static_cast<std::size_t>(image.channels);
      for (std::size_t c = 0; c < 3; ++c)
        rgba[p * 4 + c] = image.channels >= 3 ? source[c] : source[0];
      rgba[p * 4 + 3] = image.channels == 4 ? source[3] : 255;
    }
    GLuint handle = 0;
    glGenTextures(1, &handle);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, handle);
    bound_albedo = handle;
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    textures.emplace(path, handle);
    return handle;
  }

  // Colour and depth renderbuffers of the camera's size and samples, plus a single-sampled
  // copy to read from when `resolvable` and multisampled.
  static Target make_target(const Camera& camera, bool resolvable, const char* what) {
    Target t;
    glGenFramebuffers(1, &t.framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    t.color = make_renderbuffer(GL_RGBA8, camera.width, camera.height, camera.msaa_samples);
    t.depth =
        make_renderbuffer(GL_DEPTH_COMPONENT24, camera.width, camera.height, camera.msaa_samples);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t.color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t.depth);
    check_framebuffer(what);
    if (resolvable && camera.msaa_samples > 0) {
      glGenFramebuffers(1, &t.resolve_framebuffer);
      glBindFramebuffer(GL_FRAMEBUFFER, t.resolve_framebuffer);
      t.resolve_color = make_renderbuffer(GL_RGBA8, camera.width, camera.height, 0);
      t.resolve_depth = make_renderbuffer(GL_DEPTH_COMPONENT24, camera.width, camera.height, 0);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                t.resolve_color);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                t.resolve_depth);
      check_framebuffer("resolve");
    }
    return t;
  }

  // The frame being drawn, by size and samples.
  Target& target(const Camera& camera) {
    const auto key = std::make_tuple(camera.width, camera.height, camera.msaa_samples);
    auto found = targets.find(key);
    if (found != targets.end()) return found->second;
    return targets.emplace(key, make_target(camera, true, "colour")).first->second;
  }

  // The cached background (sky and unshadowed floor), by size and samples.
  Target& background_target(const Camera& camera) {
    const auto key = std::make_tuple(camera.width, camera.height, camera.msaa_samples);
    auto found = backgrounds.find(key);
    if (found != backgrounds.end()) return found->second;
    return backgrounds.emplace(key, make_target(camera, false, "background")).first->second;
  }

  SegmentationTarget& segmentation_target(const Camera& camera) {
    const auto key = std::make_pair(camera.width, camera.height);
    auto found = segmentation_targets.find(key);
    if (found != segmentation_targets.end()) return found->second;
    SegmentationTarget t;
    glGenFramebuffers(1, &t.framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    t.ids = make_renderbuffer(GL_R32I, camera.width, camera.height, 0);
    t.depth = make_renderbuffer(GL_DEPTH_COMPONENT24, camera.width, camera.height, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, t.ids);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t.depth);
    check_framebuffer("segmentation");
    return segmentation_targets.emplace(key, t).first->second;
  }

  void ensure_shadow_map(int size) {
    if (shadow_size == size) return;
    if (shadow_framebuffer == 0) {
      glGenFramebuffers(1, &shadow_framebuffer);
      glGenTextures(1, &shadow_texture);
    }
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT,
                 GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_texture, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    check_framebuffer("shadow");
    shadow_size = size;
  }

  // Renders the casters' depth from the light; returns the matrix from world to shadow-map clip.
  Eigen::Matrix4f shadow_pass(const Scene& scene, const std::vector<const GpuMesh*>& gpu,
                              int size) {
    // The light looks along its direction; its orthographic box is fitted to the casters'
    // extent in light space, so that the shadow map's texels and the receivers' lookups are
    // spent only where shadows can fall.
    const Eigen::Vector3f direction = scene.light.direction.normalized();
    const Eigen::Matrix4f light_view = look_from(Eigen::Vector3f::Zero(), direction);
    Eigen::Vector3f low = Eigen::Vector3f::Constant(1e30F);
    Eigen::Vector3f high = Eigen::Vector3f::Constant(-1e30F);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& instance = scene.instances[i];
      if (!instance.casts_shadow) continue;
      const Eigen::Matrix4f to_light_space = light_view * model_matrix(instance);
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3f p =
            gpu[i]->bounds.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner));
        const Eigen::Vector3f q = (to_light_space * p.homogeneous()).head<3>();
        low = low.cwiseMin(q);
        high = high.cwiseMax(q);
      }
    }
    if (low.x() > high.x()) return Eigen::Matrix4f::Zero();  // nothing casts
    // A flat caster (a sheet facing the light, or seen edge-on) has no extent along some axis;
    // give it half a millimetre each way so that the projection stays finite.
    for (int axis = 0; axis < 3; ++axis) {
      if (high[axis] - low[axis] < 1e-4F) {
        low[axis] -= 5e-4F;
        high[axis] += 5e-4F;
      }
    }
    // Light space looks down -z: the casters lie between depths -high.z() and -low.z().
    const Eigen::Matrix4f light =
        orthographic(low.x(), high.x(), low.y(), high.y(), -high.z(), -low.z()) * light_view;

    ensure_shadow_map(size);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_framebuffer);
    glViewport(0, 0, size, size);
    glClear(GL_DEPTH_BUFFER_BIT);
    glUseProgram(depth_only);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2.0F, 4.0F);  // slope-scaled bias against shadow acne
    // Every caster in at most two draws: llvmpipe's cost per draw call outweighs transforming
    // the casters' vertices here (the depth pass needs positions only). Closed casters come
    // first and are drawn with their faces turned away from the light culled: the map keeps the
    // nearest depth, which is always a face turned toward the light, and llvmpipe's cost here is
    // in filling triangles (culling halves the arm's shadow pass).
    caster_positions.clear();
    caster_indices.clear();
    open_caster_indices.clear();
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      if (!scene.instances[i].casts_shadow) continue;
      // Soft, low-resolution shadows need less geometry than the camera: one level coarser.
      const GpuMesh& drawn = *gpu[i];
      const GpuMesh& mesh =
          drawn.keep_alive->low_detail != nullptr ? upload(drawn.keep_alive->low_detail) : drawn;
      const Eigen::Matrix4f model = model_matrix(scene.instances[i]);
      const auto first = static_cast<std::uint32_t>(caster_positions.size() / 3);
      for (const Eigen::Vector3f& position : mesh.keep_alive->positions) {
        const Eigen::Vector4f p = model * position.homogeneous();
        caster_positions.insert(caster_positions.end(), {p.x(), p.y(), p.z()});
      }
      std::vector<std::uint32_t>& indices =
          cullable(scene.instances[i], *mesh.keep_alive) ? caster_indices : open_caster_indices;
      for (std::uint32_t index : mesh.keep_alive->indices) indices.push_back(first + index);
    }
    const std::size_t culled_index_count = caster_indices.size();
    caster_indices.insert(caster_indices.end(), open_caster_indices.begin(),
                          open_caster_indices.end());
    if (caster_vao == 0) {
      glGenVertexArrays(1, &caster_vao);
      glBindVertexArray(caster_vao);
      glGenBuffers(1, &caster_vbo);
      glGenBuffers(1, &caster_ebo);
      glBindBuffer(GL_ARRAY_BUFFER, caster_vbo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, caster_ebo);
      glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float),
                            reinterpret_cast<void*>(0));
      glEnableVertexAttribArray(0);
    }
    glBindVertexArray(caster_vao);
    glBindBuffer(GL_ARRAY_BUFFER, caster_vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(caster_positions.size() * sizeof(float)),
                 caster_positions.data(), GL_STREAM_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, caster_ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(caster_indices.size() * sizeof(std::uint32_t)),
                 caster_indices.data(), GL_STREAM_DRAW);
    glUniformMatrix4fv(depth_mvp, 1, GL_FALSE, light.data());
    glFrontFace(GL_CCW);  // the light's projection is not flipped
    if (culled_index_count > 0) {
      glEnable(GL_CULL_FACE);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(culled_index_count), GL_UNSIGNED_INT,
                     nullptr);
      glDisable(GL_CULL_FACE);
    }
    if (caster_indices.size() > culled_index_count) {
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(caster_indices.size() - culled_index_count),
                     GL_UNSIGNED_INT,
                     reinterpret_cast<void*>(culled_index_count * sizeof(std::uint32_t)));
    }
    glFrontFace(GL_CW);  // back to the camera's flipped projection
    glBindVertexArray(arena_vao);
    glDisable(GL_POLYGON_OFFSET_FILL);
    // Clip [-1, 1] to texture [0, 1] happens in the shader.
    return light;
  }

  static void draw_all(const GpuMesh& mesh) {
    glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(mesh.index_count), GL_UNSIGNED_INT,
                             reinterpret_cast<void*>(static_cast<std::uintptr_t>(mesh.first_index) *
                                                     sizeof(std::uint32_t)),
                             mesh.base_vertex);
  }

  // Picks the coarse version of a mesh for instances small on screen.
  const std::shared_ptr<const MeshData>& detail_for(const Instance& instance,
                                                    const Camera& camera) const {
    const MeshData& mesh = *instance.mesh;
    if (mesh.low_detail == nullptr) return instance.mesh;
    const float distance =
        (instance.X_world_instance.translation() - camera.X_world_camera.translation()).norm();
    const float size = std::min(std::abs(instance.scale.x()), std::abs(instance.scale.y())) *
                       mesh.low_detail_radius;
    const float pixels_per_metre =
        0.5F * static_cast<float>(camera.height) /
        (std::tan(camera.fov_y_deg * 3.14159265F / 360.0F) * std::max(distance, 1e-3F));
    return size * pixels_per_metre < mesh.low_detail_below_px ? mesh.low_detail : instance.mesh;
  }

  // Whether an instance's faces turned away from the viewer may be culled: a closed mesh, not
  // mirrored by its scale (a mirror turns its winding inside out).
  static bool cullable(const Instance& instance, const MeshData& mesh) {
    return mesh.closed && instance.scale.prod() > 0.0F;
  }

  void draw_instances(const Scene& scene, const std::vector<const GpuMesh*>& gpu) {
    glUseProgram(lit);
    bool culling = false;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& instance = scene.instances[i];
      if (cullable(instance, *gpu[i]->keep_alive) != culling) {
        culling = !culling;
        if (culling) {
          glEnable(GL_CULL_FACE);
        } else {
          glDisable(GL_CULL_FACE);
        }
      }
      const Eigen::Matrix4f model = model_matrix(instance);
      const Eigen::Matrix3f normal_matrix = model.block<3, 3>(0, 0).inverse().transpose();
      glUniformMatrix4fv(u.model, 1, GL_FALSE, model.data());
      glUniformMatrix3fv(u.normal_matrix, 1, GL_FALSE, normal_matrix.data());
      glUniform1f(u.specular, instance.material.specular);
      glUniform1f(u.shininess, instance.material.shininess);
      const bool textured = !instance.material.texture_path.empty();
      glUniform1i(u.use_texture, textured ? 1 : 0);
      glUniform1i(u.mirrored, instance.scale.prod() < 0.0F ? 1 : 0);
      bind_albedo(textured ? texture(instance.material.texture_path) : white_texture);
      glUniform4fv(u.base_color, 1, instance.material.base_color.data());
      draw_all(*gpu[i]);
    }
    glDisable(GL_CULL_FACE);
  }

  // `depth_offset` pushes the floor back (polygon offset factor and units) so that shapes resting
  // on it never fight it for depth.
  void draw_floor(const Scene& scene, const Eigen::Matrix4f& view_projection,
                  const Eigen::Matrix4f& light_matrix, bool use_shadows, const GpuMesh& mesh,
                  float depth_offset) {
    Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
    model(2, 3) = scene.floor.height_m;
    const Eigen::Vector3f to_light = -scene.light.direction.normalized();
    const Eigen::Vector3f direct = scene.light.color * std::max(0.0F, to_light.z());
    glUseProgram(floor_program);
    glBindVertexArray(&mesh == &footprint_mesh ? footprint_vao : arena_vao);
    glUniformMatrix4fv(fu.model, 1, GL_FALSE, model.data());
    glUniformMatrix4fv(fu.view_projection, 1, GL_FALSE, view_projection.data());
    glUniformMatrix4fv(fu.light_matrix, 1, GL_FALSE, light_matrix.data());
    glUniform1f(fu.tile, scene.floor.tile_m);
    glUniform3fv(fu.color_a, 1, scene.floor.color_a.data());
    glUniform3fv(fu.color_b, 1, scene.floor.color_b.data());
    glUniform3fv(fu.ambient, 1, scene.light.ambient.data());
    glUniform3fv(fu.direct, 1, direct.data());
    glUniform1i(fu.use_shadows, use_shadows ? 1 : 0);
    glUniform1i(fu.shadow_map, 1);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(depth_offset, depth_offset);
    draw_all(mesh);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindVertexArray(arena_vao);
  }

  // Rectangles of floor (in floor coordinates, z = 0 before the floor's height is applied) that
  // hold every shadow: each caster's bounding box projected along the light onto the floor.
  // Returns null when no shadow reaches the floor. The rectangles live in a small dynamic
  // buffer of their own.
  const GpuMesh* shadow_footprints(const Scene& scene, const std::vector<const GpuMesh*>& gpu) {
    const Eigen::Vector3f direction = scene.light.direction.normalized();
    if (direction.z() > -1e-3F) return nullptr;  // light from below the horizon casts none on it
    const float h = scene.floor.height_m;
    footprint_vertices.clear();
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& instance = scene.instances[i];
      if (!instance.casts_shadow) continue;
      const Eigen::Matrix4f model = model_matrix(instance);
      Eigen::AlignedBox2f rect;
      bool above = false;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3f p =
            (model * gpu[i]
                         ->bounds.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner))
                         .homogeneous())
                .head<3>();
        above = above || p.z() > h;
        const Eigen::Vector3f on_floor = p - direction * ((p.z() - h) / direction.z());
        rect.extend(on_floor.head<2>());
      }
      if (!above) continue;  // entirely below the floor
      const Eigen::Vector2f lo = rect.min();
      const Eigen::Vector2f hi = rect.max();
      const float quad[6][2] = {{lo.x(), lo.y()}, {hi.x(), lo.y()}, {hi.x(), hi.y()},
                                {lo.x(), lo.y()}, {hi.x(), hi.y()}, {lo.x(), hi.y()}};
      for (const auto& v : quad)
        footprint_vertices.insert(footprint_vertices.end(), {v[0], v[1], 0, 0, 0, 1, 0, 0});
    }
    if (footprint_vertices.empty()) return nullptr;
    if (footprint_vao == 0) {
      glGenVertexArrays(1, &footprint_vao);
      glBindVertexArray(footprint_vao);
      glGenBuffers(1, &footprint_vbo);
      glGenBuffers(1, &footprint_ebo);
      glBindBuffer(GL_ARRAY_BUFFER, footprint_vbo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, footprint_ebo);
      constexpr GLsizei kStride = 8 * sizeof(float);
      glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<void*>(0));
      glEnableVertexAttribArray(0);
    }
    glBindVertexArray(footprint_vao);
    glBindBuffer(GL_ARRAY_BUFFER, footprint_vbo);
    glBufferData(GL_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(footprint_vertices.size() * sizeof(float)),
                 footprint_vertices.data(), GL_STREAM_DRAW);
    const auto count = static_cast<std::uint32_t>(footprint_vertices.size() / 8);
    if (footprint_indices.size() < count) {
      footprint_indices.resize(count);
      for (std::uint32_t k = 0; k < count; ++k) footprint_indices[k] = k;
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, footprint_ebo);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)),
                   footprint_indices.data(), GL_STATIC_DRAW);
    }
    footprint_mesh.index_count = count;
    footprint_mesh.base_vertex = 0;
    footprint_mesh.first_index = 0;
    return &footprint_mesh;
  }

  // The sky at the far plane: depth-tested against what is already drawn (so only its visible
  // pixels are shaded), writing no depth.
  void draw_sky(const Scene& scene, const Eigen::Matrix4f& view_projection) {
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glUseProgram(sky);
    const Eigen::Matrix4f inverse = view_projection.inverse();
    glUniformMatrix4fv(sky_inverse_view_projection, 1, GL_FALSE, inverse.data());
    glUniform3fv(sky_horizon, 1, scene.sky.horizon.data());
    glUniform3fv(sky_zenith, 1, scene.sky.zenith.data());
    glDrawArrays(GL_TRIANGLES, 0, 3);  // positions come from gl_VertexID; the arena is bound
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
  }

  // Everything the background (sky and floor without shadows) depends on.
  static std::vector<float> background_key(const Scene& scene, const Camera& camera,
                                           const Eigen::Matrix4f& view_projection) {
    std::vector<float> key(view_projection.data(), view_projection.data() + 16);
    const auto add = [&key](const auto& v) {
      key.insert(key.end(), v.data(), v.data() + v.size());
    };
    add(camera.X_world_camera.translation());
    add(scene.light.direction);
    add(scene.light.color);
    add(scene.light.ambient);
    add(scene.floor.color_a);
    add(scene.floor.color_b);
    add(scene.sky.horizon);
    add(scene.sky.zenith);
    key.insert(key.end(),
               {scene.floor.enabled ? 1.0F : 0.0F, scene.floor.height_m, scene.floor.tile_m,
                static_cast<float>(camera.width), static_cast<float>(camera.height),
                static_cast<float>(camera.msaa_samples)});
    return key;
  }

  void render(const Scene& scene, const Camera& camera, const RenderTargets& out) {
    camera.validate();
    context.make_current();
    if (camera.msaa_samples > max_samples) {
      throw std::invalid_argument("Renderer: msaa_samples " + std::to_string(camera.msaa_samples) +
                                  " is more than this OpenGL offers: at most " +
                                  std::to_string(max_samples) + " (" + context.description() + ")");
    }
    std::vector<const GpuMesh*> gpu(scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      if (scene.instances[i].mesh == nullptr) {
        throw std::invalid_argument("Renderer: instance " + std::to_string(i) + " has no mesh");
      }
      gpu[i] = &upload(detail_for(scene.instances[i], camera));
    }
    upload(floor);
    sync_arena();
    bound_albedo = 0;  // texture creation and the shadow map may have changed unit 0's binding
    const Eigen::Matrix4f view_projection = camera.projection_matrix() * camera.view_matrix();

    // Every pass depth-tests (without it GL writes no depth, and a shadow map would stay empty).
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    Eigen::Matrix4f light_matrix = Eigen::Matrix4f::Zero();
    const int map_size = shadow_map_size(camera);
    if (scene.shadows) light_matrix = shadow_pass(scene, gpu, map_size);
    const bool use_shadows = scene.shadows && light_matrix(3, 3) != 0.0F;

    glUseProgram(lit);
    const Eigen::Vector3f to_light = -scene.light.direction.normalized();
    const Eigen::Vector3f eye = camera.X_world_camera.translation();
    glUniformMatrix4fv(u.view_projection, 1, GL_FALSE, view_projection.data());
    glUniformMatrix4fv(u.light_matrix, 1, GL_FALSE, light_matrix.data());
    glUniform3fv(u.to_light, 1, to_light.data());
    glUniform3fv(u.light_color, 1, scene.light.color.data());
    glUniform3fv(u.ambient, 1, scene.light.ambient.data());
    glUniform3fv(u.camera_position, 1, eye.data());
    glUniform1i(u.use_shadows, use_shadows ? 1 : 0);
    glUniform1i(u.albedo, 0);
    glUniform1i(u.shadow_map, 1);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, use_shadows ? shadow_texture : 0);
    glActiveTexture(GL_TEXTURE0);

    // The sky and the unshadowed floor depend only on the camera and the scene's settings: they
    // are drawn once into a background image and copied in each frame. Shadows can only fall
    // inside the casters' footprints on the floor, so with shadows on, only those rectangles of
    // floor are drawn again (same shader, now with the shadow lookup). Every frame, the first
    // included, takes this path, so a scene always gives the same bytes.
    Target& t = target(camera);
    Target& background = background_target(camera);
    const std::vector<float> key = background_key(scene, camera, view_projection);
    if (key != background_keys[background.framebuffer]) {
      glBindFramebuffer(GL_FRAMEBUFFER, background.framebuffer);
      glViewport(0, 0, camera.width, camera.height);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      if (scene.floor.enabled)
        draw_floor(scene, view_projection, light_matrix, false, meshes.at(floor.get()),
                   kFloorDepthOffset);
      draw_sky(scene, view_projection);
      background_keys[background.framebuffer] = key;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, background.framebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, t.framebuffer);
    glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                      GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    glViewport(0, 0, camera.width, camera.height);
    if (use_shadows && scene.floor.enabled) {
      const GpuMesh* footprints = shadow_footprints(scene, gpu);
      if (footprints != nullptr) {
        // Footprints overlap (a tall arm casts long ones). Drawn a little nearer than the cached
        // floor (and still behind the instances), the first footprint over a pixel passes the
        // depth test and the ones after it tie and fail: each floor pixel is shaded once.
        draw_floor(scene, view_projection, light_matrix, true, *footprints, kFootprintDepthOffset);
      }
    }
    draw_instances(scene, gpu);

    GLuint read_from = t.framebuffer;
    if (camera.msaa_samples > 0) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, t.framebuffer);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, t.resolve_framebuffer);
      glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                        GL_COLOR_BUFFER_BIT, GL_LINEAR);
      glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                        GL_DEPTH_BUFFER_BIT, GL_NEAREST);
      read_from = t.resolve_framebuffer;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, read_from);
    if (out.rgb != nullptr) {
      // RGBA is the renderbuffer's own layout: reading it and packing RGB here is faster than
      // Mesa's conversion.
      const std::size_t count =
          static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
      readback.resize(count * 4);
      glReadPixels(0, 0, camera.width, camera.height, GL_RGBA, GL_UNSIGNED_BYTE, readback.data());
      for (std::size_t p = 0; p < count; ++p) {
        out.rgb[p * 3] = readback[p * 4];
        out.rgb[p * 3 + 1] = readback[p * 4 + 1];
        out.rgb[p * 3 + 2] = readback[p * 4 + 2];
      }
    }
    if (out.depth != nullptr) {
      glReadPixels(0, 0, camera.width, camera.height, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth);
      const float n = camera.near_m;
      const float f = camera.far_m;
      const std::size_t count =
          static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
      for (std::size_t p = 0; p < count; ++p) {
        const float ndc = 2.0F * out.depth[p] - 1.0F;
        out.depth[p] = out.depth[p] >= 1.0F ? f : 2.0F * n * f / ((f + n) - ndc * (f - n));
      }
    }
    if (out.segmentation != nullptr) {
      render_segmentation(scene, camera, view_projection, gpu, meshes.at(floor.get()),
                          out.segmentation);
    }
  }

  void render_segmentation(const Scene& scene, const Camera& camera,
                           const Eigen::Matrix4f& view_projection,
                           const std::vector<const GpuMesh*>& gpu, const GpuMesh& floor_mesh,
                           std::int32_t* out) {
    SegmentationTarget& t = segmentation_target(camera);
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    glViewport(0, 0, camera.width, camera.height);
    const GLint background[4] = {0, 0, 0, 0};
    glClearBufferiv(GL_COLOR, 0, background);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glUseProgram(segmentation);
    const GLint mvp = glGetUniformLocation(segmentation, "model_view_projection");
    const GLint id = glGetUniformLocation(segmentation, "segmentation_id");
    if (scene.floor.enabled) {
      Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
      model(2, 3) = scene.floor.height_m;
      const Eigen::Matrix4f m = view_projection * model;
      glUniformMatrix4fv(mvp, 1, GL_FALSE, m.data());
      glUniform1i(id, -1);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.0F, 1.0F);
      draw_all(floor_mesh);
      glDisable(GL_POLYGON_OFFSET_FILL);
    }
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Eigen::Matrix4f m = view_projection * model_matrix(scene.instances[i]);
      glUniformMatrix4fv(mvp, 1, GL_FALSE, m.data());
      glUniform1i(id, scene.instances[i].segmentation_id);
      draw_all(*gpu[i]);
    }
    glReadPixels(0, 0, camera.width, camera.height, GL_RED_INTEGER, GL_INT, out);
  }

  Context context;
  GLuint lit = 0;
  GLuint sky = 0;
  GLuint depth_only = 0;
  GLuint segmentation = 0;
  LitUniforms u{};
  std::vector<float> arena_vertices;  // 8 floats per vertex: position, normal, texture coordinate
  std::vector<std::uint32_t> arena_indices;
  bool arena_dirty = false;
  GLuint arena_vao = 0;
  GLuint arena_vbo = 0;
  GLuint arena_ebo = 0;
  GLuint bound_albedo = 0;  // on texture unit 0, to skip redundant binds
  std::vector<float> footprint_vertices;
  std::vector<std::uint32_t> footprint_indices;
  GpuMesh footprint_mesh;
  GLuint footprint_vao = 0;
  std::vector<float> caster_positions;  // world positions of every caster's vertices, per frame
  std::vector<std::uint32_t> caster_indices;       // closed casters', then the open ones'
  std::vector<std::uint32_t> open_caster_indices;  // scratch
  GLuint caster_vao = 0;
  GLuint caster_vbo = 0;
  GLuint caster_ebo = 0;
  GLint depth_mvp = -1;
  GLuint footprint_vbo = 0;
  GLuint footprint_ebo = 0;
  GLuint floor_program = 0;
  FloorUniforms fu{};
  GLuint empty_vao = 0;
  GLuint white_texture = 0;
  std::shared_ptr<const MeshData> floor;
  std::unordered_map<const MeshData*, GpuMesh> meshes;
  std::map<std::string, GLuint> textures;
  std::map<std::tuple<int, int, int>, Target> targets;
  std::map<std::tuple<int, int, int>, Target> backgrounds;
  std::map<GLuint, std::vector<float>> background_keys;  // by background framebuffer
  std::vector<std::uint8_t> readback;
  std::map<std::pair<int, int>, SegmentationTarget> segmentation_targets;
  GLuint shadow_framebuffer = 0;
  GLuint shadow_texture = 0;
  int shadow_size = 0;
  GLint max_samples = 0;
  GLint sky_inverse_view_projection = -1;
  GLint sky_horizon = -1;
  GLint sky_zenith = -1;
};

Renderer::Renderer(GlBackend backend) : impl_(std::make_unique<Impl>(backend)) {}

Renderer::~Renderer() = default;

void Renderer::render(const Scene& scene, const Camera& camera, const RenderTargets& targets) {
  impl_->render(scene, camera, targets);
}

std::string Renderer::description() { return impl_->context.description(); }

}  // namespace pixelgym::render
