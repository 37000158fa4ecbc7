#include "pixelgym/engine/robot_model.h"

#include <console_bridge/console.h>
#include <dlfcn.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "pixelgym/engine/regular_file.h"
#include "pixelgym/engine/xml_depth.h"

namespace pixelgym::engine {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw UrdfError("URDF " + path + ": " + problem);
}

// Collects urdfdom's console_bridge messages while it parses, so that its reasons reach the
// exception. console_bridge has one process-wide handler, so parses are serialized.
class CapturedLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*file*/,
           int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN)
      messages += (messages.empty() ? "" : "; ") + text;
  }
  std::string messages;
};

std::mutex& urdfdom_mutex() {
  static std::mutex mutex;
  return mutex;
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  X.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  return X;
}

// What the XML pass learns before urdfdom sees the file.
struct XmlFacts {
  std::string xml;  // with <capsule> rewritten as <cylinder>
  // (link, "visual"/"collision", index within that link) of each element that was a capsule.
  std::set<std::tuple<std::string, std::string, int>> capsules;
  // Joint name -> <dynamics stiffness>, which urdfdom does not read.
  std::map<std::string, double> stiffness;
};

std::string read_file(const std::string& path) {
  try {
    return read_regular_file(path, "a URDF file", kMaxUrdfBytes);
  } catch (const FileProblem& problem) {
    fail(path, problem.what());
  }
}

// Refuses `xml` (the file's text, or the text urdfdom is given) when TinyXML would nest elements
// deeper than kMaxElementDepth in it: its recursion overflowed the stack on a file 50,000 deep.
void check_element_depth(const std::string& xml, const std::string& path) {
  if (tinyxml_element_depth(xml, kMaxElementDepth) > kMaxElementDepth) {
    fail(path, "elements nested more than " + std::to_string(kMaxElementDepth) +
                   " deep; a URDF nests at most " + std::to_string(kMaxElementDepth) +
                   " (a robot's file needs about 6)");
  }
}

// `xml` with the zero bytes TinyXML must find after it (see kTinyXmlPadding).
std::string padded(const std::string& xml) { return xml + std::string(kTinyXmlPadding, '\0'); }

// The numbers in attribute `attribute` of `element`, when it has one: `count` of them, each
// finite and (when `positive`) > 0, or the file is refused naming `where`. urdfdom reads them
// leniently: a box size of "nan 1 1" made it drop the whole visual without an error.
void check_numbers(const TiXmlElement* element, const char* attribute, std::size_t count,
                   bool positive, const std::string& path, const std::string& where) {
  if (element == nullptr) return;
  const char* text = element->Attribute(attribute);
  if (text == nullptr) return;
  std::vector<double> values;
  const char* at = text;
  for (;;) {
    while (*at != '\0' && std::isspace(static_cast<unsigned char>(*at)) != 0) ++at;
    if (*at == '\0') break;
    char* end = nullptr;
    const double value = std::strtod(at, &end);
    const bool number =
        end != at && (*end == '\0' || std::isspace(static_cast<unsigned char>(*end)) != 0);
    if (!number || !std::isfinite(value) || (positive && !(value > 0))) {
      values.clear();
      break;
    }
    values.push_back(value);
    at = end;
  }
  if (values.size() != count) {
    fail(path, where + " <" + element->Value() + " " + attribute + "=\"" + text + "\">: expected " +
                   (count == 1 ? std::string("a finite number")
                               : std::to_string(count) + " finite numbers") +
                   (positive ? " > 0" : ""));
  }
}

// The numbers of attribute `attribute` of `element` (already checked to be finite), each within
// [-max_abs, max_abs], or the file is refused naming `where`, the value and the range. A finite but
// huge value (a limit of 1e300) passed the finite check and failed later, deep in the physics or
// the renderer, without naming the file.
void check_magnitudes(const TiXmlElement* element, const char* attribute, double max_abs,
                      const char* units, const std::string& path, const std::string& where) {
  if (element == nullptr || element->Attribute(attribute) == nullptr) return;
  const char* text = element->Attribute(attribute);
  for (const char* at = text; *at != '\0';) {
    while (std::isspace(static_cast<unsigned char>(*at)) != 0) ++at;
    char* end = nullptr;
    const double value = std::strtod(at, &end);
    if (end == at) break;
    if (std::fabs(value) > max_abs) {
      std::ostringstream message;
      message << where << " <" << element->Value() << " " << attribute << "=\"" << text
              << "\">: " << std::string(at, static_cast<std::size_t>(end - at)) << " is outside [-"
              << max_abs << ", " << max_abs << "] " << units;
      fail(path, message.str());
    }
    at = end;
  }
}

// Bounds no real robot approaches, well inside what the physics and the renderer handle. An origin
// 10 km from its parent link; a joint limit of 10,000 rad (1,600 turns) or 10 km; an actuator of
// 1e9 N m or N; a speed of 1e6 rad/s or m/s; damping and friction of 1e9.
constexpr double kMaxOffsetM = 1e4;
constexpr double kMaxAngleRad = 1e4;
constexpr double kMaxJointPosition = 1e4;
constexpr double kMaxEffort = 1e9;
constexpr double kMaxSpeed = 1e6;
constexpr double kMaxDamping = 1e9;

// An origin's xyz and rpy: three finite numbers each, within the bounds above.
void check_origin(const TiXmlElement* parent, const std::string& path, const std::string& where) {
  if (parent == nullptr) return;
  const TiXmlElement* origin = parent->FirstChildElement("origin");
  check_numbers(origin, "xyz", 3, false, path, where);
  check_numbers(origin, "rpy", 3, false, path, where);
  check_magnitudes(origin, "xyz", kMaxOffsetM, "m", path, where);
  check_magnitudes(origin, "rpy", kMaxAngleRad, "rad", path, where);
}

// The numbers of a link's inertial, visuals and collisions: finite, sizes > 0, mass >= 0.
void check_link_numbers(const TiXmlElement* link, const std::string& name,
                        const std::string& path) {
  const std::string where = "link \"" + name + "\"";
  if (const TiXmlElement* inertial = link->FirstChildElement("inertial")) {
    check_origin(inertial, path, where + " inertial");
    const TiXmlElement* mass = inertial->FirstChildElement("mass");
    check_numbers(mass, "value", 1, false, path, where + " inertial");
    if (mass != nullptr && mass->Attribute("value") != nullptr &&
        std::strtod(mass->Attribute("value"), nullptr) < 0) {
      fail(path, where + " has mass " + mass->Attribute("value") +
                     " kg; a mass must be >= 0 (and > 0 for a link that moves)");
    }
    const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
    for (const char* moment : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
      check_numbers(inertia, moment, 1, false, path, where + " inertial");
    }
  }
  for (const char* kind : {"visual", "collision"}) {
    int index = 0;
    for (const TiXmlElement* element = link->FirstChildElement(kind); element != nullptr;
         element = element->NextSiblingElement(kind), ++index) {
      const std::string element_where = where + " " + kind + " " + std::to_string(index);
      check_origin(element, path, element_where);
      const TiXmlElement* geometry = element->FirstChildElement("geometry");
      if (geometry == nullptr) continue;
      check_numbers(geometry->FirstChildElement("box"), "size", 3, true, path, element_where);
      check_numbers(geometry->FirstChildElement("sphere"), "radius", 1, true, path, element_where);
      for (const char* round : {"cylinder", "capsule"}) {
        check_numbers(geometry->FirstChildElement(round), "radius", 1, true, path, element_where);
        check_numbers(geometry->FirstChildElement(round), "length", 1, true, path, element_where);
      }
      check_numbers(geometry->FirstChildElement("mesh"), "scale", 3, false, path, element_where);
    }
  }
}

// A joint's origin, axis, limits and dynamics: finite numbers.
void check_joint_numbers(const TiXmlElement* joint, const std::string& name,
                         const std::string& path) {
  const std::string where = "joint \"" + name + "\"";
  check_origin(joint, path, where);
  check_numbers(joint->FirstChildElement("axis"), "xyz", 3, false, path, where);
  const TiXmlElement* limit = joint->FirstChildElement("limit");
  for (const char* bound : {"lower", "upper", "effort", "velocity"}) {
    check_numbers(limit, bound, 1, false, path, where);
  }
  check_magnitudes(limit, "lower", kMaxJointPosition, "rad or m", path, where);
  check_magnitudes(limit, "upper", kMaxJointPosition, "rad or m", path, where);
  check_magnitudes(limit, "effort", kMaxEffort, "N m or N", path, where);
  check_magnitudes(limit, "velocity", kMaxSpeed, "rad/s or m/s", path, where);
  const TiXmlElement* dynamics = joint->FirstChildElement("dynamics");
  for (const char* coefficient : {"damping", "friction", "stiffness"}) {
    check_numbers(dynamics, coefficient, 1, false, path, where);
    check_magnitudes(dynamics, coefficient, kMaxDamping, "N m s/rad, N s/m, N m or N", path, where);
  }
}

// Checks the structure that urdfdom reports poorly (or not at all) and rewrites capsules.
XmlFacts inspect_xml(const std::string& path) {
  const std::string text = read_file(path);
  check_element_depth(text, path);
  TiXmlDocument document;
  document.Parse(padded(text).c_str());
  if (document.Error()) {
    fail(path, "malformed XML at line " + std::to_string(document.ErrorRow()) + ", column " +
                   std::to_string(document.ErrorCol()) + ": " + document.ErrorDesc());
  }
  TiXmlElement* robot = document.RootElement();
  if (robot == nullptr || std::string(robot->Value()) != "robot") {
    fail(path, "the root element must be <robot>");
  }

  XmlFacts facts;
  std::vector<std::string> links;
  for (TiXmlElement* link = robot->FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    if (name == nullptr || *name == '\0') fail(path, "a <link> has no name");
    if (std::find(links.begin(), links.end(), name) != links.end()) {
      fail(path, "two links are named \"" + std::string(name) + "\"");
    }
    links.emplace_back(name);
    check_link_numbers(link, name, path);
    for (const char* kind : {"visual", "collision"}) {
      int index = 0;
      for (TiXmlElement* element = link->FirstChildElement(kind); element != nullptr;
           element = element->NextSiblingElement(kind), ++index) {
        TiXmlElement* geometry = element->FirstChildElement("geometry");
        TiXmlElement* capsule =
            geometry != nullptr ? geometry->FirstChildElement("capsule") : nullptr;
        if (capsule != nullptr) {
          capsule->SetValue("cylinder");
          facts.capsules.emplace(name, kind, index);
        }
      }
    }
  }
  if (links.empty()) fail(path, "has no links (a robot needs at least one <link>)");
  if (links.size() > kMaxLinks) {
    fail(path, "has " + std::to_string(links.size()) +
                   " links; pixelgym simulates robots of at most " + std::to_string(kMaxLinks) +
                   " (Bullet keeps, for each joint limit and contact, a Jacobian over all of the "
                   "robot's degrees of freedom: memory grows with the square of the link count)");
  }

  std::map<std::string, std::string> parent_joint_of;  // child link -> joint
  std::map<std::string, std::vector<std::string>> children_of;
  for (TiXmlElement* joint = robot->FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const std::string name = joint->Attribute("name") != nullptr ? joint->Attribute("name") : "";
    const std::string type = joint->Attribute("type") != nullptr ? joint->Attribute("type") : "";
    if (name.empty()) fail(path, "a <joint> has no name");
    check_joint_numbers(joint, name, path);
    if (TiXmlElement* dynamics = joint->FirstChildElement("dynamics")) {
      double stiffness = 0.0;
      if (dynamics->QueryDoubleAttribute("stiffness", &stiffness) == TIXML_SUCCESS) {
        // urdfdom refuses a <dynamics> with neither damping nor friction.
        dynamics->RemoveAttribute("stiffness");
        if (dynamics->Attribute("damping") == nullptr &&
            dynamics->Attribute("friction") == nullptr) {
          dynamics->SetAttribute("damping", "0");
        }
        if (stiffness < 0) {
          fail(path, "joint \"" + name + "\" has a negative stiffness (" +
                         std::to_string(stiffness) + " N m/rad or N/m; a spring needs >= 0)");
        }
        facts.stiffness[name] = stiffness;
      }
    }
    if (type == "planar" || type == "floating") {
      fail(path, "joint \"" + name + "\" has type " + type +
                     ", which pixelgym does not support inside a robot (supported: revolute, "
                     "continuous, prismatic, fixed; a floating base is chosen when the robot is "
                     "added to a world)");
    }
    const TiXmlElement* parent = joint->FirstChildElement("parent");
    const TiXmlElement* child = joint->FirstChildElement("child");
    const char* parent_name = parent != nullptr ? parent->Attribute("link") : nullptr;
    const char* child_name = child != nullptr ? child->Attribute("link") : nullptr;
    if (parent_name == nullptr || child_name == nullptr) {
      fail(path, "joint \"" + name + "\" needs <parent link=...> and <child link=...>");
    }
    for (const char* link : {parent_name, child_name}) {
      if (std::find(links.begin(), links.end(), link) == links.end()) {
        fail(path, "joint \"" + name + "\" names link \"" + link + "\", which does not exist");
      }
    }
    if (std::string(parent_name) == child_name) {
      fail(path, "joint \"" + name + "\" connects link \"" + child_name + "\" to itself");
    }
    if (parent_joint_of.count(child_name) != 0) {
      fail(path, "link \"" + std::string(child_name) + "\" is the child of two joints (\"" +
                     parent_joint_of[child_name] + "\" and \"" + name + "\"): joints form a cycle");
    }
    parent_joint_of[child_name] = name;
    children_of[parent_name].emplace_back(child_name);
  }

  std::vector<std::string> roots;
  for (const std::string& link : links) {
    if (parent_joint_of.count(link) == 0) roots.push_back(link);
  }
  if (roots.empty()) fail(path, "every link has a parent: the joints form a cycle");
  if (roots.size() > 1) {
    fail(path, "has " + std::to_string(roots.size()) + " root links (\"" + roots[0] + "\" and \"" +
                   roots[1] + "\"); a robot is one tree");
  }
  std::set<std::string> reached;
  std::vector<std::string> stack = {roots[0]};
  while (!stack.empty()) {
    const std::string link = stack.back();
    stack.pop_back();
    if (!reached.insert(link).second) continue;
    for (const std::string& child : children_of[link]) stack.push_back(child);
  }
  if (reached.size() != links.size()) {
    for (const std::string& link : links) {
      if (reached.count(link) == 0) {
        fail(path, "link \"" + link + "\" cannot be reached from the root \"" + roots[0] +
                       "\": its joints form a cycle");
      }
    }
  }
  TiXmlPrinter printer;
  document.Accept(&printer);
  facts.xml = printer.CStr();
  return facts;
}

Geometry convert_geometry(const urdf::Geometry& source, bool is_capsule, const std::string& path,
                          const std::string& where, MeshCache& meshes) {
  Geometry geometry;
  switch (source.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(source);
      geometry.type = GeometryType::kBox;
      geometry.box_size_m = {box.dim.x, box.dim.y, box.dim.z};
      break;
    }
    case urdf::Geometry::SPHERE:
      geometry.type = GeometryType::kSphere;
      geometry.radius_m = static_cast<const urdf::Sphere&>(source).radius;
      break;
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(source);
      geometry.type = is_capsule ? GeometryType::kCapsule : GeometryType::kCylinder;
      geometry.radius_m = cylinder.radius;
      geometry.length_m = cylinder.length;
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(source);
      geometry.type = GeometryType::kMesh;
      geometry.mesh_scale = {mesh.scale.x, mesh.scale.y, mesh.scale.z};
      try {
        geometry.mesh = meshes.get(resolve_uri(mesh.filename, path));
      } catch (const std::runtime_error& error) {
        fail(path, where + ": " + error.what());
      }
      break;
    }
  }
  const bool positive =
      geometry.type == GeometryType::kBox    ? (geometry.box_size_m.array() > 0).all()
      : geometry.type == GeometryType::kMesh ? (geometry.mesh_scale.array() != 0).all()
                                             : geometry.radius_m > 0 && geometry.length_m >= 0;
  if (!positive)
    fail(path, where + ": " + geometry_type_name(geometry.type) + " has a zero or negative size");
  return geometry;
}

}  // namespace

const char* geometry_type_name(GeometryType type) {
  switch (type) {
    case GeometryType::kBox:
      return "box";
    case GeometryType::kSphere:
      return "sphere";
    case GeometryType::kCylinder:
      return "cylinder";
    case GeometryType::kCapsule:
      return "capsule";
    case GeometryType::kMesh:
      return "mesh";
  }
  return "unknown";
}

const char* joint_type_name(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kContinuous:
      return "continuous";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kFixed:
      return "fixed";
  }
  return "unknown";
}

RobotModel::RobotModel(std::string name, std::string path, std::vector<LinkModel> links,
                       std::vector<JointModel> joints)
    : name_(std::move(name)),
      path_(std::move(path)),
      links_(std::move(links)),
      joints_(std::move(joints)) {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].movable()) movable_joints_.push_back(static_cast<int>(i));
  }
}

int RobotModel::link_index(const std::string& name) const {
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].name == name) return static_cast<int>(i);
  }
  throw std::out_of_range("robot \"" + name_ + "\" has no link \"" + name + "\"");
}

int RobotModel::joint_index(const std::string& name) const {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].name == name) return static_cast<int>(i);
  }
  throw std::out_of_range("robot \"" + name_ + "\" has no joint \"" + name + "\"");
}

int RobotModel::dof_index(const std::string& name) const {
  const int joint = joint_index(name);
  for (std::size_t d = 0; d < movable_joints_.size(); ++d) {
    if (movable_joints_[d] == joint) return static_cast<int>(d);
  }
  throw std::out_of_range("robot \"" + name_ + "\": joint \"" + name +
                          "\" is fixed, not a degree of freedom");
}

double RobotModel::total_mass_kg() const {
  double total = 0.0;
  for (const LinkModel& link : links_) total += link.inertial.mass_kg;
  return total;
}

std::string assets_folder() {
  // Installed, the assets sit at PIXELGYM_LIB_TO_ASSETS from the folder of the library holding
  // this code (share/pixelgym/assets beside lib/); in the build tree, that folder does not exist
  // and the source tree's assets/ serve.
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(&assets_folder), &info) != 0 && info.dli_fname != nullptr) {
    std::error_code error;
    const fs::path library = fs::canonical(info.dli_fname, error);
    if (!error) {
      const fs::path installed =
          (library.parent_path() / PIXELGYM_LIB_TO_ASSETS).lexically_normal();
      if (fs::is_directory(installed, error)) return installed.string();
    }
  }
  return PIXELGYM_ASSETS_DIR;
}

std::vector<std::string> asset_search_path() {
  std::vector<std::string> folders;
  if (const char* variable = std::getenv("PIXELGYM_ASSET_PATH")) {
    std::stringstream entries(variable);
    std::string entry;
    while (std::getline(entries, entry, ':')) {
      if (!entry.empty()) folders.push_back(entry);
    }
  }
  folders.push_back(assets_folder());
  return folders;
}

std::string asset_path(const std::string& relative) {
  for (const std::string& folder : asset_search_path()) {
    const fs::path candidate = fs::path(folder) / relative;
    if (fs::exists(candidate)) return candidate.lexically_normal().string();
  }
  throw UrdfError("asset \"" + relative + "\" not found in PIXELGYM_ASSET_PATH or " +
                  assets_folder());
}

std::string resolve_uri(const std::string& uri, const std::string& urdf_path) {
  const fs::path urdf_folder = fs::absolute(urdf_path).parent_path();
  const std::string kFile = "file://";
  const std::string kPackage = "package://";
  if (uri.rfind(kFile, 0) == 0)
    return fs::path(uri.substr(kFile.size())).lexically_normal().string();
  // What to look for under each folder: the path itself, or for package://NAME/REST, NAME/REST
  // and then REST.
  std::vector<fs::path> wanted;
  if (uri.rfind(kPackage, 0) == 0) {
    const std::string rest = uri.substr(kPackage.size());
    const std::size_t slash = rest.find('/');
    wanted.emplace_back(rest);
    if (slash != std::string::npos) wanted.emplace_back(rest.substr(slash + 1));
  } else {
    const fs::path file(uri);
    if (file.is_absolute()) return file.lexically_normal().string();
    wanted.push_back(file);
  }
  // The URDF's folder and every parent up to the root, then the asset search path.
  std::vector<fs::path> roots;
  for (fs::path folder = urdf_folder;; folder = folder.parent_path()) {
    roots.push_back(folder);
    if (folder == folder.parent_path() || folder.empty()) break;
  }
  const std::vector<std::string> asset_folders = asset_search_path();
  roots.insert(roots.end(), asset_folders.begin(), asset_folders.end());
  for (const fs::path& root : roots) {
    for (const fs::path& relative : wanted) {
      const fs::path candidate = root / relative;
      if (fs::is_regular_file(candidate)) return candidate.lexically_normal().string();
    }
  }
  std::string looked_for = "\"" + wanted[0].string() + "\"";
  if (wanted.size() > 1) looked_for += " or \"" + wanted[1].string() + "\"";
  std::string searched;
  for (const std::string& folder : asset_folders)
    searched += (searched.empty() ? "" : ", ") + folder;
  throw UrdfError("cannot resolve \"" + uri + "\": no file " + looked_for + " in " +
                  urdf_folder.string() + " (the URDF's folder), its parent folders, or the asset " +
                  "search path (" + searched + "; PIXELGYM_ASSET_PATH adds folders before " +
                  "pixelgym's assets)");
}

std::shared_ptr<const RobotModel> parse_urdf(const std::string& path, MeshCache& meshes) {
  const XmlFacts facts = inspect_xml(path);
  // urdfdom parses the XML as TinyXML prints it back, which need not nest as the file did: a
  // declaration's values are printed without escaping, so '&lt;a&gt;' in one becomes '<a>'.
  check_element_depth(facts.xml, path);

  urdf::ModelInterfaceSharedPtr urdf;
  std::string urdfdom_messages;
  {
    std::lock_guard<std::mutex> lock(urdfdom_mutex());
    CapturedLog log;
    console_bridge::OutputHandler* previous = console_bridge::getOutputHandler();
    console_bridge::useOutputHandler(&log);
    urdf = urdf::parseURDF(padded(facts.xml));
    console_bridge::useOutputHandler(previous);
    urdfdom_messages = log.messages;
  }
  if (urdf == nullptr)
    fail(path, urdfdom_messages.empty() ? "urdfdom could not parse it" : urdfdom_messages);

  // Tree order: depth first from the root, children in the order urdfdom lists them.
  std::vector<urdf::LinkConstSharedPtr> order;
  std::vector<urdf::LinkConstSharedPtr> stack = {urdf->getRoot()};
  while (!stack.empty()) {
    urdf::LinkConstSharedPtr link = stack.back();
    stack.pop_back();
    order.push_back(link);
    for (auto child = link->child_links.rbegin(); child != link->child_links.rend(); ++child) {
      stack.push_back(*child);
    }
  }

  std::vector<LinkModel> links;
  std::vector<JointModel> joints;
  std::map<std::string, int> index_of;
  for (const urdf::LinkConstSharedPtr& source : order) {
    LinkModel link;
    link.name = source->name;
    index_of[link.name] = static_cast<int>(links.size());
    if (source->inertial) {
      const urdf::Inertial& inertial = *source->inertial;
      link.inertial.mass_kg = inertial.mass;
      link.inertial.X_link_inertial = to_isometry(inertial.origin);
      link.inertial.inertia_kg_m2 << inertial.ixx, inertial.ixy, inertial.ixz, inertial.ixy,
          inertial.iyy, inertial.iyz, inertial.ixz, inertial.iyz, inertial.izz;
    }
    for (std::size_t i = 0; i < source->visual_array.size(); ++i) {
      const urdf::Visual& visual = *source->visual_array[i];
      const std::string where = "link \"" + link.name + "\" visual " + std::to_string(i);
      if (!visual.geometry) fail(path, where + " has no geometry");
      VisualElement element;
      element.X_link_geometry = to_isometry(visual.origin);
      element.geometry = convert_geometry(
          *visual.geometry, facts.capsules.count({link.name, "visual", static_cast<int>(i)}) != 0,
          path, where, meshes);
      element.material.name = visual.material_name;
      if (visual.material) {
        const urdf::Color& color = visual.material->color;
        element.material.rgba = {color.r, color.g, color.b, color.a};
        // urdfdom leaves an unset colour black; black is read as "no colour given".
        element.material.has_rgba = color.r != 0 || color.g != 0 || color.b != 0;
        if (!element.material.has_rgba) element.material.rgba = {0.75, 0.75, 0.75, 1.0};
        if (!visual.material->texture_filename.empty()) {
          try {
            element.material.texture_path = resolve_uri(visual.material->texture_filename, path);
          } catch (const UrdfError& error) {
            fail(path, where + " texture: " + error.what());
          }
        }
      }
      link.visuals.push_back(std::move(element));
    }
    for (std::size_t i = 0; i < source->collision_array.size(); ++i) {
      const urdf::Collision& collision = *source->collision_array[i];
      const std::string where = "link \"" + link.name + "\" collision " + std::to_string(i);
      if (!collision.geometry) fail(path, where + " has no geometry");
      CollisionElement element;
      element.X_link_geometry = to_isometry(collision.origin);
      element.geometry =
          convert_geometry(*collision.geometry,
                           facts.capsules.count({link.name, "collision", static_cast<int>(i)}) != 0,
                           path, where, meshes);
      link.collisions.push_back(std::move(element));
    }
    links.push_back(std::move(link));
  }

  for (std::size_t i = 1; i < order.size(); ++i) {
    const urdf::Joint& source = *order[i]->parent_joint;
    JointModel joint;
    joint.name = source.name;
    joint.parent_link = index_of.at(source.parent_link_name);
    joint.child_link = index_of.at(source.child_link_name);
    joint.X_parent_joint = to_isometry(source.parent_to_joint_origin_transform);
    const std::string where = "joint \"" + joint.name + "\"";
    switch (source.type) {
      case urdf::Joint::REVOLUTE:
        joint.type = JointType::kRevolute;
        break;
      case urdf::Joint::CONTINUOUS:
        joint.type = JointType::kContinuous;
        break;
      case urdf::Joint::PRISMATIC:
        joint.type = JointType::kPrismatic;
        break;
      case urdf::Joint::FIXED:
        joint.type = JointType::kFixed;
        break;
      default:
        fail(path, where + " has an unsupported type");
    }
    if (joint.movable()) {
      const Eigen::Vector3d axis(source.axis.x, source.axis.y, source.axis.z);
      if (axis.norm() < 1e-9) fail(path, where + " has a zero axis");
      joint.axis = axis.normalized();
    }
    if (source.limits) {
      joint.effort_limit = source.limits->effort;
      joint.velocity_limit = source.limits->velocity;
      if (joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic) {
        joint.has_limits = true;
        joint.lower = source.limits->lower;
        joint.upper = source.limits->upper;
        if (joint.lower > joint.upper) {
          std::ostringstream message;
          message << where << " has lower limit " << joint.lower << " > upper limit "
                  << joint.upper;
          fail(path, message.str());
        }
      }
    }
    if (source.dynamics) {
      joint.damping = source.dynamics->damping;
      joint.friction = source.dynamics->friction;
    }
    if (const auto spring = facts.stiffness.find(source.name); spring != facts.stiffness.end()) {
      joint.stiffness = spring->second;
    }
    links[static_cast<std::size_t>(joint.child_link)].parent_joint =
        static_cast<int>(joints.size());
    joints.push_back(joint);
  }

  // A link that moves needs positive mass and a positive-definite inertia. (The root's mass is
  // checked when it is added with a floating base.)
  for (const JointModel& joint : joints) {
    if (!joint.movable()) continue;
    const LinkModel& link = links[static_cast<std::size_t>(joint.child_link)];
    const std::string where = "link \"" + link.name + "\" (moved by joint \"" + joint.name + "\")";
    if (!(link.inertial.mass_kg > 0)) {
      std::ostringstream message;
      message << where << " has mass " << link.inertial.mass_kg
              << " kg; moving links need mass > 0";
      fail(path, message.str());
    }
    const Eigen::Vector3d eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(link.inertial.inertia_kg_m2).eigenvalues();
    if (!(eigenvalues.minCoeff() > 0)) {
      std::ostringstream message;
      message << where << " has an inertia that is not positive definite (eigenvalues "
              << eigenvalues.transpose() << ")";
      fail(path, message.str());
    }
  }
  return std::make_shared<const RobotModel>(urdf->getName(),
                                            fs::absolute(path).lexically_normal().string(),
                                            std::move(links), std::move(joints));
}

std::shared_ptr<const RobotModel> ModelCache::load_urdf(const std::string& path) {
  const std::string key = fs::absolute(path).lexically_normal().string();
  std::lock_guard<std::mutex> lock(mutex_);
  auto found = models_.find(key);
  if (found != models_.end()) return found->second;
  std::shared_ptr<const RobotModel> model = parse_urdf(key, meshes_);
  ++urdfs_parsed_;
  models_.emplace(key, model);
  return model;
}

int ModelCache::urdfs_parsed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return urdfs_parsed_;
}

ModelCache& default_model_cache() {
  static ModelCache cache;
  return cache;
}

}  // namespace pixelgym::engine
