#include "pixelgym/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/lod.h"
#include "pixelgym/render/mesh_arena.h"
#include "pixelgym/render/render_target.h"
#include "pixelgym/render/shader_programs.h"
#include "pixelgym/render/shadow_fit.h"
#include "pixelgym/render/shadow_pass.h"
#include "pixelgym/render/texture_cache.h"
#include "pixelgym/render/transforms.h"

namespace pixelgym::render {
namespace {

// Polygon offsets of the floor and of the shadowed floor footprints drawn over it.
constexpr float kFloorDepthOffset = 1.0F;
constexpr float kFootprintDepthOffset = 0.5F;

// Half the side of the floor's square, m.
constexpr float kFloorHalfSide = 500.0F;

// The floor: a large square (its checker pattern comes from world coordinates).
std::shared_ptr<const MeshData> make_floor_mesh() {
  auto mesh = std::make_shared<MeshData>();
  const float half = kFloorHalfSide;
  mesh->positions = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
  mesh->normals.assign(4, Eigen::Vector3f::UnitZ());
  mesh->indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

// The floor is drawn pushed back (polygon offset, more the more it slants away from the camera)
// so that shapes resting on it win the depth test; that push would show in the depth image, up to
// a tenth of the distance at grazing angles. So wherever a pixel sees the floor plane or something
// behind it (which the opaque floor hides: it is the floor that is seen), its depth is set to the
// plane's own along that pixel's centre ray, in eye depth as read_depth gives it.
void exact_floor_depth(const Camera& camera, const Eigen::Matrix4f& view_projection, float height_m,
                       float* depth) {
  // In double: the far plane's points are tens of metres away, the depths wanted to a millimetre.
  const Eigen::Matrix4d unproject = view_projection.cast<double>().inverse();
  const Eigen::Vector4d depth_row = -camera.view_matrix().cast<double>().row(2).transpose();
  // Unprojected points are linear in the pixel's x before their division by w.
  const Eigen::Vector4d step_x = unproject.col(0);
  for (int y = 0; y < camera.height; ++y) {
    const double ndc_y = (2.0 * y + 1.0) / camera.height - 1.0;
    const Eigen::Vector4d near_row = unproject * Eigen::Vector4d(0.0, ndc_y, -1.0, 1.0);
    const Eigen::Vector4d far_row = unproject * Eigen::Vector4d(0.0, ndc_y, 1.0, 1.0);
    for (int x = 0; x < camera.width; ++x) {
      const double ndc_x = (2.0 * x + 1.0) / camera.width - 1.0;
      const Eigen::Vector4d near_h = near_row + ndc_x * step_x;
      const Eigen::Vector4d far_h = far_row + ndc_x * step_x;
      const Eigen::Vector3d near = near_h.head<3>() / near_h.w();
      const Eigen::Vector3d far = far_h.head<3>() / far_h.w();
      const double rise = far.z() - near.z();
      if (rise == 0.0) continue;
      const double t = (height_m - near.z()) / rise;
      if (!(t >= 0.0 && t <= 1.0)) continue;  // the plane is not between the clipping planes
      const Eigen::Vector3d hit = near + t * (far - near);
      if (std::abs(hit.x()) > kFloorHalfSide || std::abs(hit.y()) > kFloorHalfSide) continue;
      const auto plane_depth = static_cast<float>(depth_row.dot(hit.homogeneous()));
      float& seen = depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(camera.width) +
                          static_cast<std::size_t>(x)];
      if (seen > plane_depth) seen = plane_depth;
    }
  }
}

// Everything the background (sky and floor without shadows) depends on, written into `key`.
void background_key(const Scene& scene, const Camera& camera,
                    const Eigen::Matrix4f& view_projection, std::vector<float>& key) {
  key.assign(view_projection.data(), view_projection.data() + 16);
  const auto add = [&key](const auto& v) { key.insert(key.end(), v.data(), v.data() + v.size()); };
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
              scene.floor.opacity, scene.sky.image_span_deg, static_cast<float>(camera.width),
              static_cast<float>(camera.height), static_cast<float>(camera.msaa_samples)});
  // The images by serial, 16 bits to a float so that every serial is kept exactly.
  for (const auto* image : {scene.floor.image.get(), scene.sky.image.get()}) {
    const std::uint64_t serial = image == nullptr ? 0 : image->serial();
    for (int shift = 0; shift < 64; shift += 16) {
      key.push_back(static_cast<float>((serial >> shift) & 0xFFFFU));
    }
  }
}

// Texture units: 0 for instances' textures and the floor's image, 1 for the shadow map, this for
// the sky's image.
constexpr int kSkyImageUnit = 2;

constexpr float kRadiansPerDegree = 3.14159265358979F / 180.0F;

// Throws std::invalid_argument naming the setting for a floor opacity outside [0, 1] or a sky image
// span outside (0, 180) degrees.
void check_background(const Scene& scene) {
  if (!(scene.floor.opacity >= 0.0F && scene.floor.opacity <= 1.0F)) {
    throw std::invalid_argument("Renderer: floor.opacity must be in [0, 1], got " +
                                std::to_string(scene.floor.opacity));
  }
  if (!(scene.sky.image_span_deg > 0.0F && scene.sky.image_span_deg < 180.0F)) {
    throw std::invalid_argument("Renderer: sky.image_span_deg must be in (0, 180), got " +
                                std::to_string(scene.sky.image_span_deg));
  }
}

// Everything the sky depends on (the camera's orientation and projection, the sky's settings),
// written into `key`.
void sky_key(const Scene& scene, const Camera& camera, const Eigen::Matrix4f& turn_projection,
             std::vector<float>& key) {
  key.assign(turn_projection.data(), turn_projection.data() + 16);
  key.insert(key.end(), scene.sky.horizon.data(), scene.sky.horizon.data() + 3);
  key.insert(key.end(), scene.sky.zenith.data(), scene.sky.zenith.data() + 3);
  const std::uint64_t serial = scene.sky.image == nullptr ? 0 : scene.sky.image->serial();
  for (int shift = 0; shift < 64; shift += 16) {
    key.push_back(static_cast<float>((serial >> shift) & 0xFFFFU));
  }
  key.insert(key.end(),
             {scene.sky.image_span_deg, static_cast<float>(camera.width),
              static_cast<float>(camera.height), static_cast<float>(camera.msaa_samples)});
}

void check_sizes(const Camera& camera, const RenderTargets& targets) {
  if (targets.width != camera.width || targets.height != camera.height) {
    throw std::invalid_argument("Renderer: RenderTargets are " + std::to_string(targets.width) +
                                "x" + std::to_string(targets.height) +
                                " (width x height) but the camera's image is " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

// Colour targets by image width, height and MSAA samples.
using TargetKey = std::tuple<int, int, int>;

// The cached background image and what it was drawn from.
struct Background {
  ColorTarget target;
  std::vector<float> key;
  std::uint64_t last_used = 0;  // frame count
};

// Backgrounds kept per image size and sample count.
constexpr std::size_t kBackgroundsPerSize = 16;

}  // namespace

ContextGroup::ContextGroup(int mesa_copy, GlBackend backend)
    : backend_(backend), mesa_copy_(mesa_copy) {
  if (mesa_copy < 0) {
    throw std::invalid_argument("ContextGroup: mesa_copy must be >= 0, got " +
                                std::to_string(mesa_copy));
  }
}

ContextGroup::~ContextGroup() = default;

// Everything a renderer draws with: the GL context, the shader programs, the meshes, textures and
// framebuffers, and per-frame scratch. A Renderer of its own context has a State of its own; the
// renderers of a ContextGroup share one, drawing one after another: every frame sets all the GL
// state and uniforms it draws with and redraws every pixel of the scratch targets it reads.
struct ContextGroup::State {
  State(GlBackend backend, int mesa_copy) : context(backend, mesa_copy), floor(make_floor_mesh()) {
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glFrontFace(GL_CW);  // the flipped projection mirrors the winding
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  }

  // The GL objects below are deleted by their owners, after this, and then the context (declared
  // first, so it goes last; destroying it while current here unbinds it from this thread).
  ~State() { context.make_current(); }
  State(const State&) = delete;
  State& operator=(const State&) = delete;

  // The frame being drawn, by size and samples.
  ColorTarget& target(const Camera& camera) {
    const TargetKey key{camera.width, camera.height, camera.msaa_samples};
    auto found = targets.find(key);
    if (found != targets.end()) return found->second;
    return targets
        .emplace(key, ColorTarget(camera.width, camera.height, camera.msaa_samples, true, "colour"))
        .first->second;
  }

  // The image of `store` drawn from `key` when there is one; else one to draw it into (with
  // another key: a new one, or the least recently used when kBackgroundsPerSize exist). `what`
  // names it in errors.
  Background& cached_image(std::map<TargetKey, std::vector<Background>>& store,
                           const Camera& camera, const std::vector<float>& key, const char* what) {
    std::vector<Background>& kept =
        store[TargetKey{camera.width, camera.height, camera.msaa_samples}];
    Background* chosen = nullptr;
    for (Background& candidate : kept) {
      if (candidate.key == key) {
        chosen = &candidate;
        break;
      }
      if (chosen == nullptr || candidate.last_used < chosen->last_used) chosen = &candidate;
    }
    if (chosen == nullptr || (chosen->key != key && kept.size() < kBackgroundsPerSize)) {
      kept.push_back(
          {ColorTarget(camera.width, camera.height, camera.msaa_samples, false, what), {}, 0});
      chosen = &kept.back();
    }
    chosen->last_used = ++frames;
    return *chosen;
  }

  SegmentationTarget& segmentation_target(const Camera& camera) {
    const auto key = std::make_pair(camera.width, camera.height);
    auto found = segmentation_targets.find(key);
    if (found != segmentation_targets.end()) return found->second;
    return segmentation_targets.emplace(key, SegmentationTarget(camera.width, camera.height))
        .first->second;
  }

  void draw_instances(const Scene& scene) {
    const LitProgram& lit = programs.lit;
    glUseProgram(lit.program.get());
    bool culling = false;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Instance& instance = scene.instances[i];
      if (cullable(instance, *drawn[i]->keep_alive) != culling) {
        culling = !culling;
        if (culling) {
          glEnable(GL_CULL_FACE);
        } else {
          glDisable(GL_CULL_FACE);
        }
      }
      const Eigen::Matrix4f model = model_matrix(instance);
      const Eigen::Matrix3f normal_matrix = model.block<3, 3>(0, 0).inverse().transpose();
      glUniformMatrix4fv(lit.model, 1, GL_FALSE, model.data());
      glUniformMatrix3fv(lit.normal_matrix, 1, GL_FALSE, normal_matrix.data());
      glUniform1f(lit.specular, instance.material.specular);
      glUniform1f(lit.shininess, instance.material.shininess);
      const bool textured = !instance.material.texture_path.empty();
      glUniform1i(lit.use_texture, textured ? 1 : 0);
      glUniform1i(lit.mirrored, instance.scale.prod() < 0.0F ? 1 : 0);
      if (textured) {
        textures.bind(instance.material.texture_path);
      } else {
        textures.bind_white();
      }
      glUniform4fv(lit.base_color, 1, instance.material.base_color.data());
      glUniform3fv(lit.color_offset, 1, instance.material.color_offset.data());
      MeshArena::draw(*drawn[i]);
    }
    glDisable(GL_CULL_FACE);
  }

  // Draws `mesh` from `vertex_array` as floor. `depth_offset` pushes it back (polygon offset
  // factor and units) so that shapes resting on the floor never fight it for depth.
  void draw_floor(const Scene& scene, const Eigen::Vector3f& eye,
                  const Eigen::Matrix4f& view_projection, const Eigen::Matrix4f& light_matrix,
                  bool use_shadows, const GpuMesh& mesh, GLuint vertex_array, float depth_offset) {
    const FloorProgram& program = programs.floor;
    Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
    model(2, 3) = scene.floor.height_m;
    const Eigen::Vector3f to_light = -scene.light.direction.normalized();
    const Eigen::Vector3f direct = scene.light.color * std::max(0.0F, to_light.z());
    glUseProgram(program.program.get());
    glBindVertexArray(vertex_array);
    glUniformMatrix4fv(program.model, 1, GL_FALSE, model.data());
    glUniformMatrix4fv(program.view_projection, 1, GL_FALSE, view_projection.data());
    glUniformMatrix4fv(program.light_matrix, 1, GL_FALSE, light_matrix.data());
    glUniform1f(program.tile, scene.floor.tile_m);
    glUniform3fv(program.color_a, 1, scene.floor.color_a.data());
    glUniform3fv(program.color_b, 1, scene.floor.color_b.data());
    glUniform3fv(program.ambient, 1, scene.light.ambient.data());
    glUniform3fv(program.direct, 1, direct.data());
    glUniform1i(program.use_shadows, use_shadows ? 1 : 0);
    glUniform1i(program.shadow_map, 1);
    glUniform1i(program.use_image, scene.floor.image != nullptr ? 1 : 0);
    glUniform1i(program.image, 0);
    if (scene.floor.image != nullptr) textures.bind_image(scene.floor.image, 0);
    glUniform1f(program.opacity, scene.floor.opacity);
    glUniform3fv(program.camera_position, 1, eye.data());
    glUniform1f(program.height, scene.floor.height_m);
    set_sky(program.sky, scene.sky);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(depth_offset, depth_offset);
    MeshArena::draw(mesh);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindVertexArray(arena.vertex_array());
  }

  // Sets the shared sky colour's uniforms of the program in use, binding the sky's image if any.
  void set_sky(const SkyUniforms& uniforms, const Sky& sky) {
    glUniform3fv(uniforms.horizon, 1, sky.horizon.data());
    glUniform3fv(uniforms.zenith, 1, sky.zenith.data());
    glUniform1i(uniforms.use_image, sky.image != nullptr ? 1 : 0);
    glUniform1i(uniforms.image, kSkyImageUnit);
    glUniform1f(uniforms.span, sky.image_span_deg * kRadiansPerDegree);
    if (sky.image != nullptr) textures.bind_image(sky.image, kSkyImageUnit);
  }

  // The sky over the whole of the target bound, from the camera's orientation alone (a camera
  // that moves without turning sees the same sky), writing no depth.
  void draw_sky(const Scene& scene, const Eigen::Matrix4f& turn_projection) {
    const SkyProgram& sky = programs.sky;
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glUseProgram(sky.program.get());
    const Eigen::Matrix4f inverse = turn_projection.inverse();
    glUniformMatrix4fv(sky.inverse_view_projection, 1, GL_FALSE, inverse.data());
    set_sky(sky.sky, scene.sky);
    glDrawArrays(GL_TRIANGLES, 0, 3);  // positions come from gl_VertexID; the arena is bound
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
  }

  void render(const Scene& scene, const Camera& camera, const RenderTargets& out) {
    camera.validate();
    check_sizes(camera, out);
    check_background(scene);
    // Bound for this call only: the next call may come from another thread (see Context).
    const Context::Scope current(context);
    if (camera.msaa_samples > max_samples) {
      throw std::invalid_argument("Renderer: msaa_samples " + std::to_string(camera.msaa_samples) +
                                  " is more than this OpenGL offers: at most " +
                                  std::to_string(max_samples) + " (" + context.description() + ")");
    }
    drawn.resize(scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      if (scene.instances[i].mesh == nullptr) {
        throw std::invalid_argument("Renderer: instance " + std::to_string(i) + " has no mesh");
      }
      drawn[i] = &arena.add(select_detail(scene.instances[i], camera));
    }
    const GpuMesh& floor_mesh = arena.add(floor);
    arena.sync();
    textures.forget_binding();  // the shadow map, when (re)made below, is bound on unit 0
    const Eigen::Matrix4f view_projection = camera.projection_matrix() * camera.view_matrix();
    bounds.resize(scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) bounds[i] = drawn[i]->bounds;

    // Every pass depth-tests (without it GL writes no depth, and a shadow map would stay empty).
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    Eigen::Matrix4f light_matrix = Eigen::Matrix4f::Zero();
    bool use_shadows = false;
    if (scene.shadows) {
      if (const std::optional<Eigen::Matrix4f> fit = fit_light_projection(scene, bounds)) {
        light_matrix = *fit;
        use_shadows = true;
        shadow_pass.draw(scene, drawn, light_matrix, shadow_map_size(camera), programs.depth);
        glBindVertexArray(arena.vertex_array());
      }
    }

    const LitProgram& lit = programs.lit;
    glUseProgram(lit.program.get());
    const Eigen::Vector3f to_light = -scene.light.direction.normalized();
    const Eigen::Vector3f eye = camera.X_world_camera.translation();
    glUniformMatrix4fv(lit.view_projection, 1, GL_FALSE, view_projection.data());
    glUniformMatrix4fv(lit.light_matrix, 1, GL_FALSE, light_matrix.data());
    glUniform3fv(lit.to_light, 1, to_light.data());
    glUniform3fv(lit.light_color, 1, scene.light.color.data());
    glUniform3fv(lit.ambient, 1, scene.light.ambient.data());
    glUniform3fv(lit.camera_position, 1, eye.data());
    glUniform1i(lit.use_shadows, use_shadows ? 1 : 0);
    glUniform1i(lit.albedo, 0);
    glUniform1i(lit.shadow_map, 1);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, use_shadows ? shadow_pass.shadow_map() : 0);
    glActiveTexture(GL_TEXTURE0);

    // The sky and the unshadowed floor depend only on the camera and the scene's settings: they
    // are drawn once into a background image and copied in each frame. Shadows can only fall
    // inside the casters' footprints on the floor, so with shadows on, only those rectangles of
    // floor are drawn again (same shader, now with the shadow lookup). Every frame, the first
    // included, takes this path, so a scene always gives the same bytes.
    // The sky depends on the camera's orientation alone: a camera that follows a body without
    // turning (a tracking camera) redraws the floor every frame but copies its sky.
    const ColorTarget& frame = target(camera);
    background_key(scene, camera, view_projection, frame_key);
    Background& cached = cached_image(backgrounds, camera, frame_key, "background");
    if (frame_key != cached.key) {
      Eigen::Matrix4f turn = camera.view_matrix();
      turn.block<3, 1>(0, 3).setZero();
      const Eigen::Matrix4f turn_projection = camera.projection_matrix() * turn;
      sky_key(scene, camera, turn_projection, sky_frame_key);
      Background& sky = cached_image(skies, camera, sky_frame_key, "sky");
      if (sky_frame_key != sky.key) {
        glBindFramebuffer(GL_FRAMEBUFFER, sky.target.framebuffer());
        glViewport(0, 0, camera.width, camera.height);
        draw_sky(scene, turn_projection);
        sky.key = sky_frame_key;
      }
      glBindFramebuffer(GL_READ_FRAMEBUFFER, sky.target.framebuffer());
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, cached.target.framebuffer());
      glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                        GL_COLOR_BUFFER_BIT, GL_NEAREST);
      glBindFramebuffer(GL_FRAMEBUFFER, cached.target.framebuffer());
      glViewport(0, 0, camera.width, camera.height);
      glClear(GL_DEPTH_BUFFER_BIT);
      if (scene.floor.enabled) {
        draw_floor(scene, eye, view_projection, light_matrix, false, floor_mesh,
                   arena.vertex_array(), kFloorDepthOffset);
      }
      cached.key = frame_key;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, cached.target.framebuffer());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, frame.framebuffer());
    glBlitFramebuffer(0, 0, camera.width, camera.height, 0, 0, camera.width, camera.height,
                      GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, frame.framebuffer());
    glViewport(0, 0, camera.width, camera.height);
    if (use_shadows && scene.floor.enabled) {
      shadow_footprints(scene, bounds, footprint_rectangles);
      if (!footprint_rectangles.empty()) {
        // Footprints overlap (a tall arm casts long ones). Drawn a little nearer than the cached
        // floor (and still behind the instances), the first footprint over a pixel passes the
        // depth test and the ones after it tie and fail: each floor pixel is shaded once.
        const GpuMesh& footprints = shadow_floor.upload(footprint_rectangles);
        draw_floor(scene, eye, view_projection, light_matrix, true, footprints,
                   shadow_floor.vertex_array(), kFootprintDepthOffset);
      }
    }
    draw_instances(scene);

    frame.resolve();
    glBindFramebuffer(GL_FRAMEBUFFER, frame.read_framebuffer());
    if (out.rgb != nullptr) read_rgb(camera.width, camera.height, readback, out.rgb);
    if (out.depth != nullptr) {
      read_depth(camera.width, camera.height, camera.near_m, camera.far_m, out.depth);
      if (scene.floor.enabled) {
        exact_floor_depth(camera, view_projection, scene.floor.height_m, out.depth);
      }
    }
    if (out.segmentation != nullptr) {
      render_segmentation(scene, camera, view_projection, floor_mesh, out.segmentation);
    }
  }

  void render_segmentation(const Scene& scene, const Camera& camera,
                           const Eigen::Matrix4f& view_projection, const GpuMesh& floor_mesh,
                           std::int32_t* out) {
    const SegmentationProgram& program = programs.segmentation;
    glBindFramebuffer(GL_FRAMEBUFFER, segmentation_target(camera).framebuffer());
    glViewport(0, 0, camera.width, camera.height);
    const GLint sky_id[4] = {0, 0, 0, 0};
    glClearBufferiv(GL_COLOR, 0, sky_id);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glUseProgram(program.program.get());
    if (scene.floor.enabled) {
      Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
      model(2, 3) = scene.floor.height_m;
      const Eigen::Matrix4f m = view_projection * model;
      glUniformMatrix4fv(program.model_view_projection, 1, GL_FALSE, m.data());
      glUniform1i(program.segmentation_id, -1);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.0F, 1.0F);
      MeshArena::draw(floor_mesh);
      glDisable(GL_POLYGON_OFFSET_FILL);
    }
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
      const Eigen::Matrix4f m = view_projection * model_matrix(scene.instances[i]);
      glUniformMatrix4fv(program.model_view_projection, 1, GL_FALSE, m.data());
      glUniform1i(program.segmentation_id, scene.instances[i].segmentation_id);
      MeshArena::draw(*drawn[i]);
    }
    read_segmentation(camera.width, camera.height, out);
  }

  Context context;  // first: destroyed after every GL object below
  // Shared by the renderers of a ContextGroup: every uniform a frame draws with is set during
  // that frame, never left from an earlier one (tests/render/shared_context_test.cc checks).
  ShaderPrograms programs;
  MeshArena arena;
  TextureCache textures;
  ShadowPass shadow_pass;
  ShadowFootprints shadow_floor;
  std::shared_ptr<const MeshData> floor;
  std::map<TargetKey, ColorTarget> targets;
  // Several per size (the renderers of a ContextGroup may look from different cameras), the
  // least recently used redrawn when none matches.
  std::map<TargetKey, std::vector<Background>> backgrounds;
  // The skies the backgrounds were drawn over, kept as the backgrounds are.
  std::map<TargetKey, std::vector<Background>> skies;
  std::uint64_t frames = 0;
  std::map<std::pair<int, int>, SegmentationTarget> segmentation_targets;
  GLint max_samples = 0;
  // Per-frame scratch, kept so that a frame allocates nothing once the renderer is warm.
  std::vector<const GpuMesh*> drawn;        // the arena mesh each instance is drawn with
  std::vector<Eigen::AlignedBox3f> bounds;  // each drawn mesh's bounds, in mesh coordinates
  std::vector<Eigen::AlignedBox2f> footprint_rectangles;
  std::vector<float> frame_key;        // of this frame's background
  std::vector<float> sky_frame_key;    // of this frame's sky
  std::vector<std::uint8_t> readback;  // RGBA, packed into RGB
};

std::shared_ptr<ContextGroup::State> ContextGroup::state() {
  if (state_ == nullptr) {
    state_ = std::make_shared<State>(backend_, mesa_copy_);
  } else {
    state_->context.make_current();
  }
  return state_;
}

struct Renderer::Impl {
  std::shared_ptr<ContextGroup::State> state;
};

Renderer::Renderer(GlBackend backend, int mesa_copy)
    : impl_(
          std::make_unique<Impl>(Impl{std::make_shared<ContextGroup::State>(backend, mesa_copy)})) {
  impl_->state->context.release();  // current since created; see render()
}

Renderer::Renderer(ContextGroup& group) : impl_(std::make_unique<Impl>(Impl{group.state()})) {
  impl_->state->context.release();  // current since state(); see render()
}

Renderer::~Renderer() {
  // The last renderer of a state deletes its GL objects and context (see State); otherwise
  // nothing of this renderer's is left to delete but what the state keeps.
}

void Renderer::render(const Scene& scene, const Camera& camera, const RenderTargets& targets) {
  impl_->state->render(scene, camera, targets);
}

std::string Renderer::description() { return impl_->state->context.description(); }

int Renderer::max_samples() const { return impl_->state->max_samples; }

}  // namespace pixelgym::render
