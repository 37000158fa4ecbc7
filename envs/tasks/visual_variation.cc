#include "pixelgym/envs/tasks/visual_variation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

namespace pixelgym {
namespace {

constexpr float kPi = 3.14159265358979F;
constexpr float kDegree = kPi / 180.0F;
// Images larger than this on their longer side are shrunk when read (a background 84 pixels wide
// shows a fraction of one): uploads and memory stay small whatever the user's folder holds.
constexpr int kMaxImageSide = 512;
// Images read and kept per env, the oldest dropped first.
constexpr std::size_t kKeptImages = 8;

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

double read_level(const Params& params, const std::string& key, bool may_follow,
                  const std::string& env) {
  const double value = params.at(key).as_float();
  if (may_follow && value == -1.0) return -1.0;
  if (!(value >= 0.0 && value <= 1.0)) {
    throw std::invalid_argument(env + ": " + key + " must be in [0, 1]" +
                                (may_follow ? " (or -1 to follow variation)" : "") + ", got " +
                                Param(value).to_string());
  }
  return value;
}

Eigen::Vector3f shifted(const Eigen::Vector3f& color, float level, Rng& rng) {
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) {
    out[c] = std::clamp(color[c] + static_cast<float>(rng.uniform(-level, level)), 0.0F, 1.0F);
  }
  return out;
}

Eigen::Vector3f random_shift(float level, Rng& rng) {
  return Eigen::Vector3f(static_cast<float>(rng.uniform(-level, level)),
                         static_cast<float>(rng.uniform(-level, level)),
                         static_cast<float>(rng.uniform(-level, level)));
}

// A periodic grid of `cells` x `cells` random values, interpolated smoothly at (u, v) in [0, 1).
float value_noise(const std::vector<float>& grid, int cells, float u, float v) {
  const float x = u * static_cast<float>(cells);
  const float y = v * static_cast<float>(cells);
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const float fx = x - static_cast<float>(x0);
  const float fy = y - static_cast<float>(y0);
  const float sx = fx * fx * (3.0F - 2.0F * fx);
  const float sy = fy * fy * (3.0F - 2.0F * fy);
  const auto at = [&](int i, int j) {
    return grid[static_cast<std::size_t>(((j % cells + cells) % cells) * cells +
                                         (i % cells + cells) % cells)];
  };
  const float top = at(x0, y0) + sx * (at(x0 + 1, y0) - at(x0, y0));
  const float bottom = at(x0, y0 + 1) + sx * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
  return top + sy * (bottom - top);
}

}  // namespace

TextureSource TextureSource::parse(const std::string& text, const std::string& default_name,
                                   const std::string& key, const std::string& context) {
  TextureSource source;
  if (text == default_name) return source;
  if (text == "noise") {
    source.kind = Kind::kNoise;
    return source;
  }
  namespace fs = std::filesystem;
  const std::string expected =
      " (expected \"" + default_name + "\", \"noise\" or a folder of .png or .jpg images)";
  std::error_code error;
  if (!fs::exists(text, error)) {
    throw std::invalid_argument(context + ": " + key + ": no folder \"" + text + "\"" + expected);
  }
  if (!fs::is_directory(text, error)) {
    throw std::invalid_argument(context + ": " + key + ": \"" + text + "\" is not a folder" +
                                expected);
  }
  source.kind = Kind::kFolder;
  source.folder = text;
  const auto is_image = [](const fs::directory_entry& entry, std::error_code& code) {
    const std::string extension = lower(entry.path().extension().string());
    return (extension == ".png" || extension == ".jpg" || extension == ".jpeg") &&
           entry.is_regular_file(code);
  };
  // The images directly in `folder`, sorted by name.
  const auto images_in = [&](const fs::path& folder) {
    std::vector<std::string> files;
    for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
      if (is_image(*it, error)) files.push_back(it->path().string());
    }
    if (error) {
      throw std::invalid_argument(context + ": " + key + ": cannot list the folder \"" +
                                  folder.string() + "\": " + error.message());
    }
    std::sort(files.begin(), files.end());
    return files;
  };
  // Each image directly in the folder is a background of its own, each subfolder with images one
  // video; both sorted together by name.
  std::vector<std::pair<std::string, std::vector<std::string>>> named;
  for (const std::string& file : images_in(text)) named.push_back({file, {file}});
  std::vector<fs::path> subfolders;
  for (fs::directory_iterator it(text, error), end; !error && it != end; it.increment(error)) {
    if (it->is_directory(error)) subfolders.push_back(it->path());
  }
  if (error) {
    throw std::invalid_argument(context + ": " + key + ": cannot list the folder \"" + text +
                                "\": " + error.message());
  }
  for (const fs::path& subfolder : subfolders) {
    std::vector<std::string> frames = images_in(subfolder);
    if (!frames.empty()) named.push_back({subfolder.string(), std::move(frames)});
  }
  if (named.empty()) {
    throw std::invalid_argument(
        context + ": " + key + ": the folder \"" + text +
        "\" holds no .png, .jpg or .jpeg image, directly or in a subfolder");
  }
  std::sort(named.begin(), named.end());
  for (auto& [name, frames] : named) source.clips.push_back(std::move(frames));
  return source;
}

std::size_t TextureSource::count() const {
  switch (kind) {
    case Kind::kDefault:
      return 0;
    case Kind::kNoise:
      return noise_textures().size();
    case Kind::kFolder:
      return clips.size();
  }
  return 0;
}

bool VariationConfig::active() const {
  return colors > 0.0 || textures > 0.0 || light > 0.0 || camera > 0.0 || fov > 0.0 ||
         floor.kind != TextureSource::Kind::kDefault || sky.kind != TextureSource::Kind::kDefault ||
         floor_opacity < 1.0F;
}

std::vector<ParamSpec> VariationConfig::params() {
  return {
      {"variation", 0.0,
       "visual variation at reset, 0 (none) to 1, for every factor below left at -1 (the "
       "Distracting Control Suite's intensity: 0.1, 0.2, 0.3 for easy, medium, hard)"},
      {"vary_colors", -1.0, "bodies' colours: each channel shifted by up to this (-1: variation)"},
      {"vary_textures", -1.0,
       "floor and sky colours shifted by up to this, floor tiles scaled by up to 2^this (-1: "
       "variation)"},
      {"vary_light", -1.0,
       "light turned by up to 180*this degrees, tilted by 30*this, intensities scaled by 1 +- "
       "this/2 (-1: variation)"},
      {"vary_camera", -1.0,
       "camera turned about what it looks at by up to 90*this degrees in azimuth, elevation and "
       "roll, distance scaled within [1 - this/2, 1 + 1.5*this] (-1: variation)"},
      {"vary_fov", -1.0, "field of view scaled by 1 +- 0.3*this (-1: variation)"},
      {"floor_texture", std::string("checker"),
       "the floor: \"checker\", \"noise\" (procedural images) or a folder of .png/.jpg images (one "
       "picked per episode)"},
      {"sky_texture", std::string("gradient"),
       "the background: \"gradient\", \"noise\" (procedural images) or a folder of .png/.jpg "
       "images, or of subfolders each holding one video's frames (one image picked per "
       "episode)"},
      {"sky_backgrounds", 0,
       "how many of sky_texture's backgrounds (its images and videos, or the noise images) "
       "episodes pick from, the first by name; 0: all (the Distracting Control Suite: 4 at easy, "
       "8 at medium, all at hard)"},
      {"floor_opacity", 1.0, "how much of the background the floor hides, 0 to 1"}};
}

VariationConfig VariationConfig::from_params(const Params& params, const std::string& env) {
  VariationConfig config;
  const double level = read_level(params, "variation", false, env);
  const auto factor = [&](const std::string& key) {
    const double value = read_level(params, key, true, env);
    return value < 0.0 ? level : value;
  };
  config.colors = factor("vary_colors");
  config.textures = factor("vary_textures");
  config.light = factor("vary_light");
  config.camera = factor("vary_camera");
  config.fov = factor("vary_fov");
  config.floor =
      TextureSource::parse(params.at("floor_texture").as_string(), "checker", "floor_texture", env);
  config.sky =
      TextureSource::parse(params.at("sky_texture").as_string(), "gradient", "sky_texture", env);
  config.floor_opacity = static_cast<float>(read_level(params, "floor_opacity", false, env));
  const std::int64_t backgrounds = params.at("sky_backgrounds").as_int();
  const std::size_t available = config.sky.count();
  if (backgrounds < 0 || (backgrounds > 0 && static_cast<std::size_t>(backgrounds) > available)) {
    const std::string source = params.at("sky_texture").as_string();
    throw std::invalid_argument(
        env + ": sky_backgrounds must be in [0, " + std::to_string(available) + "] (0: all of " +
        (available == 0 ? "them; sky_texture \"" + source +
                              "\" has none: give \"noise\" or a folder for it to count)"
                        : "sky_texture \"" + source + "\"'s " + std::to_string(available) + ")") +
        ", got " + std::to_string(backgrounds));
  }
  config.sky_backgrounds = static_cast<std::size_t>(backgrounds);
  for (const ParamSpec& spec : VariationConfig::params()) {
    config.settings.emplace(spec.name, params.at(spec.name));
  }
  return config;
}

const std::vector<std::shared_ptr<const render::TextureImage>>& noise_textures() {
  static const std::vector<std::shared_ptr<const render::TextureImage>> images = [] {
    constexpr int kImages = 16;
    constexpr int kSide = 128;
    std::vector<std::shared_ptr<const render::TextureImage>> made;
    for (int k = 0; k < kImages; ++k) {
      Rng rng(0x5eed0000U + static_cast<std::uint64_t>(k));
      // Four octaves of value noise, and a palette of three colours the noise runs through.
      std::vector<std::vector<float>> grids;
      const int cells[4] = {4, 8, 16, 32};
      const float weights[4] = {0.4F, 0.3F, 0.2F, 0.1F};
      for (const int n : cells) {
        std::vector<float> grid(static_cast<std::size_t>(n * n));
        for (float& value : grid) value = static_cast<float>(rng.uniform());
        grids.push_back(std::move(grid));
      }
      Eigen::Vector3f palette[3];
      for (Eigen::Vector3f& color : palette) {
        color =
            Eigen::Vector3f(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()),
                            static_cast<float>(rng.uniform()));
      }
      render::Image image;
      image.width = kSide;
      image.height = kSide;
      image.channels = 3;
      image.pixels.resize(static_cast<std::size_t>(kSide * kSide * 3));
      for (int y = 0; y < kSide; ++y) {
        for (int x = 0; x < kSide; ++x) {
          const float u = static_cast<float>(x) / kSide;
          const float v = static_cast<float>(y) / kSide;
          float n = 0.0F;
          for (int octave = 0; octave < 4; ++octave) {
            n += weights[octave] * value_noise(grids[octave], cells[octave], u, v);
          }
          // Stretched about the middle, so that all three colours show in every image.
          const float t = std::clamp(1.0F + 4.0F * (n - 0.5F), 0.0F, 2.0F);
          const Eigen::Vector3f color = t < 1.0F
                                            ? palette[0] + t * (palette[1] - palette[0])
                                            : palette[1] + (t - 1.0F) * (palette[2] - palette[1]);
          for (int c = 0; c < 3; ++c) {
            image.pixels[static_cast<std::size_t>((y * kSide + x) * 3 + c)] =
                static_cast<std::uint8_t>(std::lround(std::clamp(color[c], 0.0F, 1.0F) * 255.0F));
          }
        }
      }
      made.push_back(render::TextureImage::make(std::move(image)));
    }
    return made;
  }();
  return images;
}

VisualVariation::VisualVariation(VariationConfig config, const render::Scene& base)
    : config_(std::move(config)),
      base_light_(base.light),
      base_floor_(base.floor),
      base_sky_(base.sky) {}

std::shared_ptr<const render::TextureImage> VisualVariation::load(const std::string& path) {
  const auto found = loaded_.find(path);
  if (found != loaded_.end()) return found->second;
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw std::runtime_error("visual variation: cannot read the image \"" + path +
                             "\" (expected a readable PNG or JPEG file)");
  }
  const int side = std::max(bgr.cols, bgr.rows);
  if (side > kMaxImageSide) {
    const double scale = static_cast<double>(kMaxImageSide) / side;
    cv::Mat small;
    cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
    bgr = small;
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  render::Image image;
  image.width = rgb.cols;
  image.height = rgb.rows;
  image.channels = 3;
  image.pixels.resize(static_cast<std::size_t>(rgb.cols) * static_cast<std::size_t>(rgb.rows) * 3);
  for (int row = 0; row < rgb.rows; ++row) {
    std::copy_n(rgb.ptr<std::uint8_t>(row), static_cast<std::size_t>(rgb.cols) * 3,
                image.pixels.data() + static_cast<std::size_t>(row) * rgb.cols * 3);
  }
  auto texture = render::TextureImage::make(std::move(image));
  if (load_order_.size() >= kKeptImages) {
    loaded_.erase(load_order_.front());
    load_order_.erase(load_order_.begin());
  }
  loaded_.emplace(path, texture);
  load_order_.push_back(path);
  return texture;
}

std::unique_ptr<VisualVariation> VisualVariation::with_config(VariationConfig config) const {
  auto out = std::make_unique<VisualVariation>(*this);
  out->config_ = std::move(config);
  return out;
}

VariationSample VisualVariation::base(std::size_t instance_count) const {
  VariationSample out;
  out.color_offsets.assign(instance_count, Eigen::Vector3f::Zero());
  out.floor = base_floor_;
  out.sky = base_sky_;
  out.light = base_light_;
  return out;
}

std::shared_ptr<const render::TextureImage> VisualVariation::pick(const TextureSource& source,
                                                                  std::size_t limit, Rng& rng) {
  const std::size_t count = limit > 0 ? std::min(limit, source.count()) : source.count();
  if (count == 0) return nullptr;
  const auto index = static_cast<std::size_t>(rng.integer(0, static_cast<std::int64_t>(count) - 1));
  if (source.kind == TextureSource::Kind::kNoise) return noise_textures()[index];
  // A video shows one of its frames (a background of one image draws nothing more).
  const std::vector<std::string>& frames = source.clips[index];
  const std::size_t frame =
      frames.size() == 1
          ? 0
          : static_cast<std::size_t>(rng.integer(0, static_cast<std::int64_t>(frames.size()) - 1));
  return load(frames[frame]);
}

VariationSample VisualVariation::sample(std::size_t instance_count, Rng& rng) {
  VariationSample out;
  // Every draw is made whatever the levels (a level of 0 scales it to nothing), so that one
  // factor's setting never changes what another draws for the same seed.
  const auto colors = static_cast<float>(config_.colors);
  out.color_offsets.resize(instance_count);
  for (Eigen::Vector3f& offset : out.color_offsets) offset = random_shift(colors, rng);

  const auto textures = static_cast<float>(config_.textures);
  out.floor = base_floor_;
  out.sky = base_sky_;
  out.floor.color_a = shifted(base_floor_.color_a, textures, rng);
  out.floor.color_b = shifted(base_floor_.color_b, textures, rng);
  out.floor.tile_m =
      base_floor_.tile_m * std::exp2(static_cast<float>(rng.uniform(-textures, textures)));
  const Eigen::Vector3f tint = shifted(Eigen::Vector3f::Ones(), textures, rng);
  out.sky.horizon = shifted(base_sky_.horizon, textures, rng);
  out.sky.zenith = shifted(base_sky_.zenith, textures, rng);
  out.floor.image = pick(config_.floor, 0, rng);
  if (out.floor.image != nullptr) out.floor.color_a = tint;
  out.sky.image = pick(config_.sky, config_.sky_backgrounds, rng);
  out.floor.opacity = config_.floor_opacity;

  const auto light = static_cast<float>(config_.light);
  out.light = base_light_;
  const Eigen::Vector3f direction = base_light_.direction.normalized();
  const float azimuth = std::atan2(direction.y(), direction.x()) +
                        static_cast<float>(rng.uniform(-light, light)) * kPi;
  const float below =
      std::clamp(std::asin(std::clamp(-direction.z(), -1.0F, 1.0F)) +
                     static_cast<float>(rng.uniform(-light, light)) * 30.0F * kDegree,
                 15.0F * kDegree, 89.0F * kDegree);
  out.light.direction = Eigen::Vector3f(std::cos(below) * std::cos(azimuth),
                                        std::cos(below) * std::sin(azimuth), -std::sin(below));
  out.light.color =
      (base_light_.color * (1.0F + 0.5F * static_cast<float>(rng.uniform(-light, light))))
          .cwiseMin(1.0F);
  out.light.ambient =
      (base_light_.ambient * (1.0F + 0.5F * static_cast<float>(rng.uniform(-light, light))))
          .cwiseMin(1.0F);
  if (light == 0.0F) out.light = base_light_;  // exactly (the angles above round)

  const auto camera = static_cast<float>(config_.camera);
  const float quarter_turn = 0.5F * kPi;
  out.camera_azimuth = static_cast<float>(rng.uniform(-camera, camera)) * quarter_turn;
  out.camera_elevation = static_cast<float>(rng.uniform(-camera, camera)) * quarter_turn;
  out.camera_roll = static_cast<float>(rng.uniform(-camera, camera)) * quarter_turn;
  out.camera_zoom = static_cast<float>(rng.uniform(1.0 - 0.5 * camera, 1.0 + 1.5 * camera));
  const auto fov = static_cast<float>(config_.fov);
  out.fov_scale = 1.0F + 0.3F * static_cast<float>(rng.uniform(-fov, fov));
  return out;
}

void VisualVariation::apply(const VariationSample& sample, render::Scene& scene) {
  const std::size_t count = std::min(sample.color_offsets.size(), scene.instances.size());
  for (std::size_t i = 0; i < count; ++i) {
    scene.instances[i].material.color_offset = sample.color_offsets[i];
  }
  const bool enabled = scene.floor.enabled;
  const float height = scene.floor.height_m;
  scene.floor = sample.floor;
  scene.floor.enabled = enabled;
  scene.floor.height_m = height;
  scene.sky = sample.sky;
  scene.light = sample.light;
}

render::Camera VisualVariation::apply(const VariationSample& sample, const render::Camera& camera,
                                      float pivot_distance_m) {
  render::Camera out = camera;
  out.fov_y_deg = std::clamp(camera.fov_y_deg * sample.fov_scale, 1.0F, 170.0F);
  if (sample.camera_azimuth == 0.0F && sample.camera_elevation == 0.0F &&
      sample.camera_roll == 0.0F && sample.camera_zoom == 1.0F) {
    return out;
  }
  Eigen::Isometry3f pose = camera.X_world_camera;
  const Eigen::Vector3f forward = -pose.linear().col(2);
  const Eigen::Vector3f pivot = pose.translation() + pivot_distance_m * forward;
  const auto about = [&pivot](const Eigen::AngleAxisf& turn) {
    return Eigen::Translation3f(pivot) * turn * Eigen::Translation3f(-pivot);
  };
  pose = about(Eigen::AngleAxisf(sample.camera_azimuth, Eigen::Vector3f::UnitZ())) * pose;
  // Elevation: turning about the camera's right axis by -a raises it by a. It stays within 90
  // degrees above the pivot and never goes below the horizon unless it started there.
  const Eigen::Vector3f offset = (pose.translation() - pivot).normalized();
  const float elevation = std::asin(std::clamp(offset.z(), -1.0F, 1.0F));
  const float lowest = std::min(elevation, 0.0F);
  const float target = std::clamp(elevation + sample.camera_elevation, lowest, 0.5F * kPi);
  pose = about(Eigen::AngleAxisf(-(target - elevation), pose.linear().col(0))) * pose;
  pose = pose * Eigen::AngleAxisf(sample.camera_roll, Eigen::Vector3f::UnitZ());
  pose.translation() = pivot + sample.camera_zoom * (pose.translation() - pivot);
  out.X_world_camera = pose;
  // Moved away, the scene must stay inside the far plane.
  out.far_m = std::max(camera.far_m, camera.far_m * sample.camera_zoom);
  return out;
}

}  // namespace pixelgym
