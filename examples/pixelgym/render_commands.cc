// pixelgym view
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>

#include "examples/pixelgym/cli.h"
#include "pixelgym/engine/robot_model.h"
#include "pixelgym/engine/world.h"
#include "pixelgym/envs/tasks/world_scene.h"
#include "pixelgym/render/context.h"
#include "pixelgym/render/renderer.h"

namespace pixelgym::cli {
namespace {

struct ViewOptions {
  std::string path;
  std::string out;
  int width = 512;
  int height = 512;
  std::string camera = "iso";
  int msaa = 4;
  bool shadows = true;
};

int run_view(const ViewOptions& options) {
  const auto model = engine::default_model_cache().load_urdf(options.path);
  // At its zero pose, lifted so that its lowest visual point rests on the floor.
  engine::RobotOptions placement;
  float lift = 0.0F;
  for (int attempt = 0; attempt < 2; ++attempt) {
    engine::WorldConfig config;
    config.ground_plane = false;
    engine::World world(config);
    placement.X_world_base.translation().z() = lift;
    world.add_robot(model, placement);
    WorldScene view(world);
    const Eigen::AlignedBox3f bounds = view.bounds();
    if (bounds.isEmpty()) {
      throw std::runtime_error("view: robot \"" + model->name() + "\" in " + options.path +
                               " has nothing to draw");
    }
    if (attempt == 0 && bounds.min().z() < 0.0F) {
      lift = -bounds.min().z();
      continue;
    }
    static const std::map<std::string, std::pair<float, float>> kViews = {{"iso", {-50.0F, 25.0F}},
                                                                          {"front", {-90.0F, 8.0F}},
                                                                          {"side", {0.0F, 8.0F}},
                                                                          {"top", {-90.0F, 89.0F}}};
    const auto [azimuth, elevation] = kViews.at(options.camera);
    render::Camera camera = frame_box(bounds, azimuth, elevation, options.width, options.height);
    camera.msaa_samples = options.msaa;
    view.scene().shadows = options.shadows;
    render::Renderer renderer;
    Array frame(DType::kUInt8, {options.height, options.width, 3});
    std::vector<std::int32_t> ids(static_cast<std::size_t>(options.width) *
                                  static_cast<std::size_t>(options.height));
    renderer.render(
        view.scene(), camera,
        {options.width, options.height, frame.data<std::uint8_t>(), nullptr, ids.data()});
    // How much of the frame the robot fills: a robot that cannot be seen is an error, not a PNG of
    // an empty floor.
    const auto covered =
        std::count_if(ids.begin(), ids.end(), [](std::int32_t id) { return id > 0; });
    const double coverage = static_cast<double>(covered) / static_cast<double>(ids.size());
    if (covered == 0) {
      throw std::runtime_error("view: robot \"" + model->name() + "\" covers no pixel of the " +
                               std::to_string(options.width) + "x" +
                               std::to_string(options.height) + " frame from camera " +
                               options.camera);
    }
    write_frame_png(options.out, frame);
    std::cout << "wrote " << options.out << " (" << options.width << "x" << options.height
              << ", robot \"" << model->name() << "\", " << view.scene().instances.size()
              << (view.scene().instances.size() == 1 ? " visual shape" : " visual shapes")
              << ", camera " << options.camera << ", robot covers " << std::fixed
              << std::setprecision(1) << 100.0 * coverage << "% of the frame)\n";
    return 0;
  }
  return 0;
}

// The sample counts this machine's OpenGL offers for --msaa: 0 (off) and the powers of two up to
// GL_MAX_SAMPLES. A context is created to ask, once, and only when --msaa is given or help shown.
class MsaaChoices {
 public:
  const std::vector<int>& values() {
    if (values_.empty()) {
      render::Context context;
      description_ = context.description();
      values_ = {0};
      for (int samples = 2; samples <= context.max_samples(); samples *= 2) {
        values_.push_back(samples);
      }
    }
    return values_;
  }
  const std::string& description() {
    values();
    return description_;
  }
  std::string list() {
    std::string text;
    for (int samples : values()) text += (text.empty() ? "" : ", ") + std::to_string(samples);
    return text;
  }

 private:
  std::vector<int> values_;
  std::string description_;
};

// Accepts what MsaaChoices offers; help lists it (CLI11 keeps a validator's description as a
// function, called when help is printed).
class MsaaValidator : public CLI::Validator {
 public:
  MsaaValidator() {
    auto choices = std::make_shared<MsaaChoices>();
    desc_function_ = [choices] {
      try {
        return "{" + choices->list() + "}";
      } catch (const std::exception&) {  // no OpenGL: help still prints
        return std::string("{0, 2, 4, ...}");
      }
    };
    func_ = [choices](std::string& text) -> std::string {
      const std::vector<int>& values = choices->values();
      const auto listed = std::find_if(values.begin(), values.end(), [&](int samples) {
        return std::to_string(samples) == text;
      });
      if (listed != values.end()) return "";
      return "this OpenGL (" + choices->description() + ") offers " + choices->list() +
             " samples, got \"" + text + "\"";
    };
  }
};

}  // namespace

std::vector<Command> add_render_commands(CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* view = app.add_subcommand("view",
                                      "Render a URDF at its zero pose on the floor, framed "
                                      "automatically, to a PNG (no display needed)");
  view->add_option("urdf", options->path, "URDF file")->required();
  view->add_option("--out", options->out, "PNG file to write (folders are created; PNG only)")
      ->required()
      ->check(png_path());
  view->add_option("--width", options->width, "Image width in pixels")
      ->capture_default_str()
      ->check(integer_in(1, 8192));
  view->add_option("--height", options->height, "Image height in pixels")
      ->capture_default_str()
      ->check(integer_in(1, 8192));
  view->add_option("--camera", options->camera, "Viewpoint")
      ->capture_default_str()
      ->check(CLI::IsMember({"iso", "front", "side", "top"}));
  view->add_option("--msaa", options->msaa,
                   "Multisample anti-aliasing samples per pixel: 0 (off) or a power of two up to "
                   "what this machine's OpenGL offers")
      ->capture_default_str()
      ->check(MsaaValidator());
  view->add_flag("!--no-shadows", options->shadows, "Draw without shadows");
  return {{view, [options] { return run_view(*options); }}};
}

}  // namespace pixelgym::cli
