// VisualVariation: seeded changes to how a pixel task looks (colours, floor and sky, light,
// camera), drawn at reset from a generator of their own, so that the physics never sees them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/params.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/render/camera.h"
#include "pixelgym/render/scene.h"

namespace pixelgym {

/// Where the floor's or the sky's look comes from: the task's own (the checker, the gradient),
/// the built-in procedural images (value noise in random colours), or the PNG and JPEG images of
/// a folder the user names.
struct TextureSource {
  enum class Kind { kDefault, kNoise, kFolder };
  Kind kind = Kind::kDefault;
  /// The folder, for kFolder.
  std::string folder;
  /// The folder's backgrounds, sorted by name: each image directly in it is one of a single frame,
  /// and each subfolder holding images is one video, its frames sorted by name (the layout of
  /// DAVIS's JPEGImages/480p). Read when an episode first shows them.
  std::vector<std::vector<std::string>> clips;

  /// `text` read as `key`'s value: `default_name` ("checker" or "gradient"), "noise", or a folder
  /// holding at least one .png, .jpg or .jpeg file, directly or in its subfolders. Throws
  /// std::invalid_argument naming `context`, `key` and the text for a folder that does not exist,
  /// is not a folder, or holds no image.
  static TextureSource parse(const std::string& text, const std::string& default_name,
                             const std::string& key, const std::string& context);
  /// How many backgrounds an episode picks from: the folder's clips, the noise images, or 0 for
  /// the task's own look.
  std::size_t count() const;
};

/// The settings of visual variation: a level per factor in [0, 1] (0: the task as it is drawn),
/// as the Distracting Control Suite grades its intensities, and where textures come from.
struct VariationConfig {
  /// Each body's colour: every channel shifted by uniform(-L, L), clamped to [0, 1] (the
  /// Distracting Control Suite's colour distraction, max_delta = L).
  double colors = 0.0;
  /// The floor's and sky's colours shifted as the bodies' are (an image floor is tinted), and the
  /// floor's tile size scaled by 2^uniform(-L, L).
  double textures = 0.0;
  /// The light turned by up to 180 L degrees about the vertical and tilted by up to 30 L degrees,
  /// its direct and ambient intensities each scaled by 1 + uniform(-L/2, L/2).
  double light = 0.0;
  /// The camera turned about the point it looks at by up to 90 L degrees in azimuth and in
  /// elevation (never below the horizon unless it started there), rolled by up to 90 L degrees,
  /// and moved along its view to between 1 - L/2 and 1 + 3L/2 times its distance (the Distracting
  /// Control Suite's camera distraction at scale L, static).
  double camera = 0.0;
  /// The field of view scaled by 1 + uniform(-0.3 L, 0.3 L).
  double fov = 0.0;
  /// The floor's and sky's looks (images are picked at random each episode when there are
  /// several).
  TextureSource floor;
  TextureSource sky;
  /// The floor's opacity (render::Floor::opacity): below 1 the sky shows through it.
  float floor_opacity = 1.0F;
  /// How many of the sky's backgrounds episodes pick from, the first by name (0: all of them).
  /// The Distracting Control Suite uses 4 videos at easy, 8 at medium and all at hard.
  std::size_t sky_backgrounds = 0;
  /// The kwargs it was read from, each of params() with its value (for reset options that change
  /// some of them).
  Params settings;

  /// Whether anything differs from the task as it is drawn.
  bool active() const;

  /// The `make` kwargs: variation (the level of every factor), vary_colors, vary_textures,
  /// vary_light, vary_camera, vary_fov (each -1 to follow variation), floor_texture, sky_texture,
  /// sky_backgrounds, floor_opacity.
  static std::vector<ParamSpec> params();
  /// Reads resolved kwargs. Throws std::invalid_argument naming `env`, the key and the value for a
  /// level outside [0, 1] (vary_* may also be -1), an opacity outside [0, 1], a texture source
  /// TextureSource::parse refuses, or sky_backgrounds below 0 or above the sky's count.
  static VariationConfig from_params(const Params& params, const std::string& env);
};

/// One episode's draw of every factor: what to change in the scene and the camera.
struct VariationSample {
  /// Per scene instance, added to its colour.
  std::vector<Eigen::Vector3f> color_offsets;
  render::Floor floor;
  render::Sky sky;
  render::Light light;
  /// Radians, and factors on the distance and the field of view.
  float camera_azimuth = 0.0F;
  float camera_elevation = 0.0F;
  float camera_roll = 0.0F;
  float camera_zoom = 1.0F;
  float fov_scale = 1.0F;
};

/// Draws and applies visual variation for one env. Images are read when an episode first shows
/// them (and a few kept): an image that cannot be read fails that reset with its file named, and
/// the scene keeps its previous look; nothing is drawn from a half-read image.
class VisualVariation {
 public:
  /// `base` is the scene as the task draws it (its light, floor and sky are the centre of the
  /// variation).
  VisualVariation(VariationConfig config, const render::Scene& base);

  const VariationConfig& config() const { return config_; }
  /// The same base look (and images read so far) under another config.
  std::unique_ptr<VisualVariation> with_config(VariationConfig config) const;
  /// The task's own look: no colour offsets, and the base floor, sky and light.
  VariationSample base(std::size_t instance_count) const;

  /// A new episode's look, drawn from `rng` for `instance_count` instances. Throws
  /// std::runtime_error naming the file when an image it picks cannot be read.
  VariationSample sample(std::size_t instance_count, Rng& rng);
  /// Writes `sample` into `scene` (colour offsets, floor, sky, light); poses stay.
  static void apply(const VariationSample& sample, render::Scene& scene);
  /// `camera` moved as `sample` says about the point `pivot_distance_m` ahead of it.
  static render::Camera apply(const VariationSample& sample, const render::Camera& camera,
                              float pivot_distance_m);

 private:
  /// One of the first `limit` (0: all) of `source`'s backgrounds, and for a video one of its
  /// frames; null for the task's own look.
  std::shared_ptr<const render::TextureImage> pick(const TextureSource& source, std::size_t limit,
                                                   Rng& rng);
  std::shared_ptr<const render::TextureImage> load(const std::string& path);

  VariationConfig config_;
  render::Light base_light_;
  render::Floor base_floor_;
  render::Sky base_sky_;
  std::map<std::string, std::shared_ptr<const render::TextureImage>> loaded_;  // by path
  std::vector<std::string> load_order_;
};

/// The built-in procedural images (smooth value noise in random colours, 128 x 128), made once
/// per process, the same on every machine.
const std::vector<std::shared_ptr<const render::TextureImage>>& noise_textures();

}  // namespace pixelgym
