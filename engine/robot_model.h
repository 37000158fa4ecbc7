// RobotModel: a URDF robot parsed once (urdfdom) with its meshes (assimp), immutable and shared.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/engine/mesh.h"

namespace pixelgym::engine {

/// A URDF or mesh file that cannot be used; the message names the file and the problem.
class UrdfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which shape a Geometry is: a primitive, or a triangle mesh read from a file.
enum class GeometryType { kBox, kSphere, kCylinder, kCapsule, kMesh };

/// "box", "sphere", "cylinder", "capsule", "mesh".
const char* geometry_type_name(GeometryType type);

/// A primitive or a mesh, in metres. Cylinders and capsules lie along their local z axis.
struct Geometry {
  /// Which of the fields below apply.
  GeometryType type = GeometryType::kBox;
  /// Box: full side lengths.
  Eigen::Vector3d box_size_m{1.0, 1.0, 1.0};
  /// Sphere, cylinder, capsule.
  double radius_m = 0.0;
  /// Cylinder and capsule: length of the cylindrical part (a capsule adds a hemisphere each end).
  double length_m = 0.0;
  /// Mesh: shared vertex data in the file's units.
  std::shared_ptr<const Mesh> mesh;
  /// Mesh: the URDF's per-axis scale from the file's units to metres.
  Eigen::Vector3d mesh_scale{1.0, 1.0, 1.0};
};

/// Surface appearance from the URDF's <material>.
struct Material {
  /// The URDF's material name; may be empty.
  std::string name;
  /// Colour, RGBA in [0, 1]; grey when `has_rgba` is false.
  Eigen::Vector4d rgba{0.75, 0.75, 0.75, 1.0};
  /// False when the URDF gave no colour (mesh parts then keep their own). A black colour counts
  /// as none: urdfdom leaves an unset colour black and the two cannot be told apart.
  bool has_rgba = false;
  /// Absolute path of the texture image, or empty.
  std::string texture_path;
};

/// One <visual> of a link: what the renderer draws.
struct VisualElement {
  /// The geometry's pose in the link's URDF frame (the element's <origin>).
  Eigen::Isometry3d X_link_geometry = Eigen::Isometry3d::Identity();
  Geometry geometry;
  Material material;
};

/// One <collision> of a link: what Bullet collides.
struct CollisionElement {
  /// The geometry's pose in the link's URDF frame (the element's <origin>).
  Eigen::Isometry3d X_link_geometry = Eigen::Isometry3d::Identity();
  Geometry geometry;
};

/// Mass properties; the inertia is about the centre of mass, in the frame X_link_inertial.
/// A link without <inertial> keeps the zeros.
struct Inertial {
  double mass_kg = 0.0;
  /// The centre of mass frame in the link's URDF frame (the <inertial>'s <origin>).
  Eigen::Isometry3d X_link_inertial = Eigen::Isometry3d::Identity();
  /// The symmetric inertia tensor about the centre of mass, in kg m^2.
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();
};

/// One <link> of a URDF.
struct LinkModel {
  /// The URDF's link name.
  std::string name;
  Inertial inertial;
  /// Its <visual> elements, in file order (may be empty).
  std::vector<VisualElement> visuals;
  /// Its <collision> elements, in file order (may be empty: the link then collides with nothing).
  std::vector<CollisionElement> collisions;
  /// Index of the joint whose child this link is; -1 for the root.
  int parent_joint = -1;
};

/// How a joint moves: revolute turns about its axis within limits, continuous turns without
/// limits, prismatic slides along its axis within limits, fixed does not move.
enum class JointType { kRevolute, kContinuous, kPrismatic, kFixed };

/// "revolute", "continuous", "prismatic", "fixed".
const char* joint_type_name(JointType type);

/// One <joint> of a URDF.
struct JointModel {
  /// The URDF's joint name.
  std::string name;
  JointType type = JointType::kFixed;
  /// Indices into RobotModel::links() of the link it hangs from and of the link it moves.
  int parent_link = 0;
  int child_link = 0;
  /// The joint frame in the parent link's frame; the child link's frame is the joint frame moved
  /// by the joint position.
  Eigen::Isometry3d X_parent_joint = Eigen::Isometry3d::Identity();
  /// Unit axis in the joint frame.
  Eigen::Vector3d axis{1.0, 0.0, 0.0};
  /// Whether `lower` and `upper` hold position limits; false for continuous and fixed joints.
  bool has_limits = false;
  /// Position limits (rad or m), lower <= upper; 0 when `has_limits` is false.
  double lower = 0.0;
  double upper = 0.0;
  /// Largest torque (N m) or force (N) the joint's actuator gives; 0 when the URDF sets none.
  double effort_limit = 0.0;
  /// Largest speed (rad/s or m/s) from the URDF's <limit>; 0 when it sets none. The World does
  /// not enforce it; tasks may scale their actions by it.
  double velocity_limit = 0.0;
  /// Viscous damping (N m s / rad or N s / m) from <dynamics>; 0 when the URDF sets none.
  double damping = 0.0;
  /// Dry friction (N m or N) from <dynamics>; 0 when the URDF sets none.
  double friction = 0.0;
  /// A spring towards position 0 (N m / rad or N / m) from <dynamics stiffness="...">, an
  /// attribute pixelgym adds to URDF (for models such as dm_control's, whose joints have springs;
  /// other URDF readers ignore it); 0 when the URDF sets none.
  double stiffness = 0.0;

  /// True for every type but kFixed: the joint is one of the robot's degrees of freedom.
  bool movable() const { return type != JointType::kFixed; }
};

/// A robot as its URDF describes it. Links are in tree order: links()[0] is the root and every
/// parent comes before its children; joints()[i] has child link i + 1.
class RobotModel {
 public:
  /// Takes links and joints already in that order (as parse_urdf builds them) and checks nothing;
  /// movable_joints() is computed from `joints`.
  RobotModel(std::string name, std::string path, std::vector<LinkModel> links,
             std::vector<JointModel> joints);

  /// The URDF's robot name.
  const std::string& name() const { return name_; }
  /// The URDF file it came from.
  const std::string& path() const { return path_; }
  /// Every link, root first (see the class comment).
  const std::vector<LinkModel>& links() const { return links_; }
  /// Every joint, fixed ones included; joints()[i] moves links()[i + 1].
  const std::vector<JointModel>& joints() const { return joints_; }
  /// Indices into joints() of the non-fixed joints, in tree order (the robot's degrees of freedom).
  const std::vector<int>& movable_joints() const { return movable_joints_; }
  /// The index into links() of the link named `name`. Throws std::out_of_range naming the robot
  /// and the name.
  int link_index(const std::string& name) const;
  /// The index into joints() of the joint named `name`. Throws std::out_of_range as link_index.
  int joint_index(const std::string& name) const;
  /// The index into movable_joints() (the degree of freedom, as World numbers them) of the joint
  /// named `name`. Throws std::out_of_range naming the robot and the name when there is no such
  /// joint or it is fixed.
  int dof_index(const std::string& name) const;
  /// The sum of every link's mass, in kg.
  double total_mass_kg() const;

 private:
  std::string name_;
  std::string path_;
  std::vector<LinkModel> links_;
  std::vector<JointModel> joints_;
  std::vector<int> movable_joints_;
};

/// pixelgym's own assets folder: installed (`cmake --install`, the Debian package), the
/// share/pixelgym/assets of the prefix the engine library was installed to, found from the
/// library's own location; in the build tree, the source tree's assets/.
std::string assets_folder();

/// Folders searched for `package://` URIs and for assets named by relative paths: the entries of
/// the PIXELGYM_ASSET_PATH environment variable (colon-separated), then assets_folder().
std::vector<std::string> asset_search_path();

/// The absolute path of `uri` as used inside the URDF at `urdf_path`: `file://` and absolute
/// paths as they are; a relative path, or `package://NAME/REST` (as NAME/REST, then REST), is
/// looked for in the URDF's folder, then each of its parent folders up to the root, then each
/// folder of asset_search_path() (PIXELGYM_ASSET_PATH's, then pixelgym's assets/); the first
/// file found wins. Throws UrdfError naming the URI, what was looked for and where, when nothing
/// is found.
std::string resolve_uri(const std::string& uri, const std::string& urdf_path);

/// The most links a robot may have: Bullet keeps, for each joint limit and contact of a robot, a
/// Jacobian over all its degrees of freedom, so memory grows with the square of the link count
/// (a chain of 3,000 links took 722 MB, one of 10,000 5.7 GB).
inline constexpr std::size_t kMaxLinks = 512;
/// The deepest nesting of XML elements a URDF may have (a robot's file needs about 6); deeper
/// files are refused before parsing, whose recursion would overflow the stack. The depth counted is
/// TinyXML's (see tinyxml_element_depth in engine/xml_depth.h), in the file and in the XML urdfdom
/// is then given.
inline constexpr std::size_t kMaxElementDepth = 100;
/// The largest URDF file read, in bytes: 32 MiB. A robot of kMaxLinks links, each with an inertial,
/// a few visuals and collisions and a joint, takes about 2 KB a link, 1 MB in all; files generated
/// with long comments or many digits stay well under 10 MB. Larger files (a 3 GB file, /dev/zero
/// through a link) are refused before they are read instead of filling memory.
inline constexpr std::size_t kMaxUrdfBytes = 32 * 1024 * 1024;

/// Parses a URDF and imports its meshes through `meshes`. Throws UrdfError naming the file and
/// the problem: a path that is not a regular file (a FIFO, a device, a folder, its symbolic links
/// followed) or a file larger than kMaxUrdfBytes, unreadable or malformed XML, elements nested
/// deeper than kMaxElementDepth, no
/// links, more than kMaxLinks links, a number that is not finite (an origin, an axis, a limit, a
/// mass or inertia) or beyond the bounds no robot approaches (origin xyz ±1e4 m, rpy ±1e4 rad,
/// joint limits ±1e4 rad or m, effort ±1e9, velocity ±1e6, damping and friction ±1e9) or a size
/// that is not > 0 (box, sphere, cylinder, capsule), a negative mass, two roots, a joint cycle, an
/// unknown parent or child, an unsupported joint type (planar, floating), lower limit > upper
/// limit, a zero axis, a moving link with non-positive mass or a non-positive-definite inertia, and
/// any mesh that is missing, unreadable, of an unsupported format or without triangles.
std::shared_ptr<const RobotModel> parse_urdf(const std::string& path, MeshCache& meshes);

/// Parses each URDF once and shares the result (and its meshes) with every caller. Thread-safe.
class ModelCache {
 public:
  /// The model of the URDF at `path` (absolute, normalized), parsed on first use. Throws
  /// UrdfError as parse_urdf; a file that failed is not remembered. Parses under the cache's
  /// lock: concurrent first uses take turns.
  std::shared_ptr<const RobotModel> load_urdf(const std::string& path);
  /// The mesh cache this cache's URDFs read their meshes through.
  MeshCache& meshes() { return meshes_; }
  /// How many URDF files this cache has parsed.
  int urdfs_parsed() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const RobotModel>> models_;
  MeshCache meshes_;
  int urdfs_parsed_ = 0;
};

/// The process-wide cache envs load their robots through; it lives until the process ends.
ModelCache& default_model_cache();

/// `relative` in the first folder of asset_search_path() that has it (PIXELGYM_ASSET_PATH's,
/// then pixelgym's assets/), lexically normalized. Throws UrdfError naming `relative` when no
/// folder has it.
std::string asset_path(const std::string& relative);

}  // namespace pixelgym::engine
