// pixelgym inspect
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "examples/pixelgym/cli.h"
#include "pixelgym/engine/robot_model.h"
#include "pixelgym/engine/world.h"

namespace pixelgym::cli {
namespace {

// "1 triangle", "2 triangles".
std::string count(std::size_t n, const std::string& singular, const std::string& plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

std::string describe(const engine::Geometry& geometry) {
  std::ostringstream out;
  out << engine::geometry_type_name(geometry.type);
  if (geometry.type == engine::GeometryType::kMesh) {
    out << " " << std::filesystem::path(geometry.mesh->path).filename().string() << " ("
        << count(geometry.mesh->triangle_count(), "triangle", "triangles") << ")";
  }
  return out.str();
}

template <typename Elements>
std::string describe_all(const Elements& elements) {
  if (elements.empty()) return "none";
  std::string text;
  for (const auto& element : elements)
    text += (text.empty() ? "" : ", ") + describe(element.geometry);
  return text;
}

int run_inspect(const std::string& path, bool floating_base) {
  const auto model = engine::default_model_cache().load_urdf(path);
  // Build it as an env would, and take one step, so that a robot that cannot simulate is refused.
  engine::World world;
  engine::RobotOptions options;
  options.fixed_base = !floating_base;
  const engine::RobotId robot = world.add_robot(model, options);
  world.step();

  std::cout << std::fixed << std::setprecision(3);
  std::cout << "robot \"" << model->name() << "\" from " << model->path() << "\n";
  std::cout << "links (" << model->links().size() << "), total mass " << model->total_mass_kg()
            << " kg:\n";
  for (const engine::LinkModel& link : model->links()) {
    std::cout << "  " << std::left << std::setw(16) << link.name << std::right << std::setw(8)
              << link.inertial.mass_kg << " kg   visual: " << describe_all(link.visuals)
              << "   collision: " << describe_all(link.collisions) << "\n";
  }
  std::cout << "joints (" << model->joints().size() << ", " << model->movable_joints().size()
            << " movable):\n";
  for (const engine::JointModel& joint : model->joints()) {
    const auto& links = model->links();
    std::cout << "  " << std::left << std::setw(20) << joint.name << " " << std::setw(11)
              << engine::joint_type_name(joint.type)
              << links[static_cast<std::size_t>(joint.parent_link)].name << " -> "
              << links[static_cast<std::size_t>(joint.child_link)].name;
    if (joint.movable()) {
      const char* unit = joint.type == engine::JointType::kPrismatic ? " m" : " rad";
      std::cout << "   axis (" << joint.axis.x() << ", " << joint.axis.y() << ", " << joint.axis.z()
                << ")";
      if (joint.has_limits) {
        std::cout << "   limits [" << joint.lower << ", " << joint.upper << "]" << unit;
      } else {
        std::cout << "   no limits";
      }
      std::cout << "   effort " << joint.effort_limit << "   damping " << joint.damping;
      if (joint.stiffness != 0.0) std::cout << "   stiffness " << joint.stiffness;
    }
    std::cout << "\n";
  }
  std::set<std::string> files;
  std::size_t triangles = 0;
  std::ostringstream mesh_lines;
  for (const engine::LinkModel& link : model->links()) {
    const auto add = [&](const engine::Geometry& geometry) {
      if (geometry.type != engine::GeometryType::kMesh || !files.insert(geometry.mesh->path).second)
        return;
      triangles += geometry.mesh->triangle_count();
      mesh_lines << "  " << geometry.mesh->path << "   "
                 << count(geometry.mesh->triangle_count(), "triangle", "triangles") << "\n";
    };
    for (const auto& visual : link.visuals) add(visual.geometry);
    for (const auto& collision : link.collisions) add(collision.geometry);
  }
  std::cout << "mesh files (" << files.size() << ", " << count(triangles, "triangle", "triangles")
            << "):\n"
            << mesh_lines.str();
  // A floating base adds its six degrees of freedom (three translations, three rotations) to
  // those of the joints.
  const auto joint_dofs = static_cast<std::size_t>(world.num_dofs(robot));
  const std::size_t base_dofs = floating_base ? 6 : 0;
  std::cout << "simulates: "
            << count(joint_dofs + base_dofs, "degree of freedom", "degrees of freedom") << " ("
            << count(joint_dofs, "joint", "joints");
  if (floating_base) std::cout << " + 6 of the floating base";
  std::cout << "), " << (floating_base ? "floating" : "fixed") << " base\n";
  return 0;
}

}  // namespace

std::vector<Command> add_engine_commands(CLI::App& app) {
  struct Options {
    std::string path;
    bool floating_base = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* inspect = app.add_subcommand(
      "inspect",
      "Load a URDF as an env would and print its links, joints (type, axis, limits), masses and "
      "mesh files with triangle counts; exit 1 with the reason when it cannot be used");
  inspect->add_option("urdf", options->path, "URDF file")->required();
  inspect->add_flag("--floating-base", options->floating_base,
                    "Add the robot with a floating base (default: fixed to the world)");
  return {{inspect, [options] { return run_inspect(options->path, options->floating_base); }}};
}

}  // namespace pixelgym::cli
