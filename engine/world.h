// World: one Bullet multibody dynamics world and everything in it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/engine/robot_model.h"

namespace pixelgym::engine {

/// Settings of a World. SI units, z up.
struct WorldConfig {
  /// One physics step, in seconds (PyBullet's default, 1/240 s).
  double timestep_s = 1.0 / 240.0;
  /// Gravity in world coordinates, m/s^2.
  Eigen::Vector3d gravity_m_s2{0.0, 0.0, -9.81};
  /// Constraint solver iterations per step.
  int solver_iterations = 50;
  /// An infinite static plane z = 0.
  bool ground_plane = true;
  /// The ground plane's friction coefficient (Bullet combines it with the other side's).
  double ground_friction = 1.0;

  /// Throws std::invalid_argument for a non-positive or non-finite timestep, non-finite gravity
  /// or fewer than one solver iteration.
  void validate() const;
};

/// How a joint is driven.
enum class ControlMode {
  /// The commanded torque (force for prismatic joints), clipped to the URDF effort limit.
  kTorque,
  /// A motor drives the joint velocity to its target with at most `max_force`.
  kVelocity,
  /// A PD motor drives the joint position to its target with at most `max_force`.
  kPosition,
};

/// How `add_robot` places a robot.
struct RobotOptions {
  /// Where the root link's frame goes.
  Eigen::Isometry3d X_world_base = Eigen::Isometry3d::Identity();
  /// A fixed base is welded to the world; a floating base moves freely (its root link then needs
  /// positive mass and inertia).
  bool fixed_base = true;
  /// Whether links of this robot collide with each other (parent-child pairs never do).
  bool self_collision = false;
};

/// A free rigid body: a cube to push, a table, a target marker.
struct BodyOptions {
  /// Names the body in contacts and visual shapes (not checked for uniqueness).
  std::string name;
  /// Its shape, for collisions and drawing alike.
  Geometry geometry;
  /// How it is drawn.
  Material material;
  /// 0 makes the body static.
  double mass_kg = 1.0;
  /// Where the body's frame starts; reset() puts it back here.
  Eigen::Isometry3d X_world_body = Eigen::Isometry3d::Identity();
  /// False for markers: drawn, never touched.
  bool collides = true;
  /// Its friction coefficient (Bullet combines it with the other side's).
  double friction = 0.8;
};

/// One contact point between two named things ("cartpole/pole", "cube", "ground").
struct Contact {
  /// The two things touching: "robot/link" (the URDF's robot and link names), a body's name, or
  /// "ground".
  std::string a;
  std::string b;
  /// The contact point on b's surface, in world coordinates, m.
  Eigen::Vector3d position_world_m = Eigen::Vector3d::Zero();
  /// Unit normal from b towards a, in world coordinates.
  Eigen::Vector3d normal_world = Eigen::Vector3d::Zero();
  /// The normal impulse of the last step divided by the timestep, N.
  double normal_force_n = 0.0;
};

/// Where one contact touches a robot's link, and how hard: what World::link_contacts lists.
struct LinkContact {
  /// Midway between the two bodies' surface points, in world coordinates, m: MuJoCo's contact
  /// position, which stays between the surfaces where soft contacts let them overlap.
  Eigen::Vector3d position_world_m = Eigen::Vector3d::Zero();
  /// The normal impulse of the last step divided by the timestep, N.
  double normal_force_n = 0.0;
};

/// Thrown by World::step when the simulation went non-finite (a robot's base or joint, or a
/// body), naming what and the simulation step.
class NonFiniteState : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown by World::set_joint_commands for a command that is not finite (a std::invalid_argument,
/// as any bad value given to the World).
class NonFiniteCommand : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Names a robot of one World: what `World::add_robot` returned. Only meaningful for that world.
struct RobotId {
  /// The robot's position in the order of add_robot calls, from 0; -1 (the default) names none.
  int index = -1;
};
inline bool operator==(RobotId a, RobotId b) { return a.index == b.index; }
inline bool operator!=(RobotId a, RobotId b) { return a.index != b.index; }

/// Names a free body of one World: what `World::add_body` returned. Only meaningful for that world.
struct BodyId {
  /// The body's position in the order of add_body calls, from 0; -1 (the default) names none.
  int index = -1;
};
inline bool operator==(BodyId a, BodyId b) { return a.index == b.index; }
inline bool operator!=(BodyId a, BodyId b) { return a.index != b.index; }

/// How the contacts of one link of a robot behave (World::set_link_contact_material).
struct ContactMaterial {
  /// The friction coefficient. Bullet multiplies the two sides' coefficients, so against a link
  /// at 0.8 a link at 1.25 makes the contact's friction 1 (MuJoCo takes the larger side's).
  double friction = 0.8;
  /// 0: rigid contacts. Otherwise each contact point of the link pushes back as a spring of this
  /// stiffness and a damper of damping_n_s_m on the penetration (Bullet's contact stiffness and
  /// damping; against another soft link the stiffnesses act in series and the dampings add), as
  /// the soft contacts of a MuJoCo model do. Per point: a box resting on a face touches at four
  /// corners, so it sinks m g / (4 k).
  double stiffness_n_m = 0.0;
  /// N s/m; 0 unless stiffness_n_m is set.
  double damping_n_s_m = 0.0;
};

/// A massless string between a point of one robot link and a point of another (dm_control's
/// spatial tendon with only a length limit, as ball-in-cup's). Slack while the points are at
/// most `max_length_m` apart; past that it pulls them together along the line between them with a
/// spring and a damper (pull only, never push), every physics step.
struct StringOptions {
  RobotId robot_a;
  /// An index into robot_a's model links(), and the point in that link's frame, m.
  int link_a = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  RobotId robot_b;
  int link_b = 0;
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  /// The length at which it goes taut, m (> 0).
  double max_length_m = 1.0;
  /// Its pull per metre past max_length_m, N/m (> 0), and per m/s of lengthening, N s/m (>= 0).
  double stiffness_n_m = 1000.0;
  double damping_n_s_m = 0.0;
};

/// Something the renderer draws. Its pose comes from `visual_poses()`, in the same order.
struct VisualShape {
  /// The shape; `visual_poses()` gives its world pose.
  Geometry geometry;
  Material material;
  /// "robot/link" or the body name.
  std::string owner;
  /// The id of the owner (a robot link or a body) in segmentation images: see World.
  int segmentation_id = 0;
};

/// Owns one btMultiBodyDynamicsWorld and every Bullet object in it; nothing is shared with other
/// worlds except immutable models and meshes, so worlds in different threads are independent. A
/// World is used by one thread at a time (its const queries included: some keep scratch space).
/// Robots and bodies are named by the RobotId / BodyId that `add_robot` / `add_body` returned;
/// an id out of range (a default one, or one from a world with more robots or bodies) throws
/// std::out_of_range.
///
/// Segmentation ids: every owner of visual shapes, i.e. every link of every robot (with or
/// without visuals) and every body, has its own id, handed out 1, 2, 3, ... in the order things
/// are added: `add_robot` gives link l of RobotModel::links() the robot's first id + l, `add_body`
/// gives the body the next id. 0 is never used (renderers keep it for the background). Ids do not
/// change for the life of the world (reset() keeps them).
///
/// Allocation: step(), set_joint_commands() and the per-step queries (the out-parameter
/// joint_positions / joint_velocities, joint_position, joint_velocity, link_pose,
/// link_linear_velocity, base_pose, body_pose, body_linear_velocity) allocate no heap memory
/// once the world has stepped once; error messages are built only when they are thrown.
///
/// Determinism: the same additions and commands give bit-identical states. `reset()` rebuilds
/// every Bullet object (solver caches and contact manifolds included), so a reset world matches a
/// newly built one bit for bit. A step that leaves any state non-finite throws NonFiniteState (a
/// std::runtime_error) naming the robot or body.
class World {
 public:
  /// Throws std::invalid_argument for an invalid config.
  explicit World(WorldConfig config = {});
  /// Destroys every Bullet object it owns; the models and meshes stay with whoever shares them.
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Adds a robot built from `model`. Throws std::invalid_argument for a null model or a
  /// floating base whose root link has no positive mass and inertia.
  RobotId add_robot(std::shared_ptr<const RobotModel> model, RobotOptions options = {});
  /// Adds a free body. A static mesh body collides as its triangles, a moving one as its convex
  /// hull. Throws std::invalid_argument for a negative mass or a mesh geometry without a mesh.
  BodyId add_body(BodyOptions options);
  /// Adds a string (StringOptions) and returns its index, from 0 in the order added. Throws
  /// std::out_of_range for a robot or link that does not exist, std::invalid_argument for a
  /// length or stiffness that is not positive and finite or a negative damping.
  int add_string(const StringOptions& options);
  /// String `string`'s length now (the distance between its points), m.
  double string_length(int string) const;
  /// Gives link `link` (an index into the model's links()) of `robot` the contact material
  /// `material`; every link starts with ContactMaterial's defaults (friction 0.8, rigid). Kept
  /// across the world's rebuilds. Throws std::out_of_range for a robot or link that does not
  /// exist, std::invalid_argument for a value that is negative or not finite, or a damping
  /// without a stiffness.
  void set_link_contact_material(RobotId robot, int link, const ContactMaterial& material);
  /// Link `link`'s contact material. Throws std::out_of_range as set_link_contact_material.
  const ContactMaterial& link_contact_material(RobotId robot, int link) const;

  /// Advances `steps` physics steps of config().timestep_s with the current controls. Throws
  /// std::invalid_argument for steps < 0, and NonFiniteState after the step that left a state
  /// non-finite (the world stays in that state until reset()).
  void step(int steps = 1);
  /// Returns to the state right after the robots and bodies were added: every Bullet object is
  /// rebuilt, controls are cleared (every degree of freedom back to kTorque with command 0), time
  /// restarts at 0.
  void reset();

  /// The config it was built with.
  const WorldConfig& config() const { return config_; }
  /// Simulated time since the last reset (or construction): step_count() * timestep_s, seconds.
  double time_s() const;
  /// Physics steps taken since the last reset (or construction).
  std::int64_t step_count() const { return step_count_; }

  // --- robots -------------------------------------------------------------------------------
  /// Robots added so far.
  int num_robots() const;
  /// The model `robot` was built from.
  const RobotModel& robot_model(RobotId robot) const;
  /// Degrees of freedom: the robot's movable joints in RobotModel::movable_joints() order.
  int num_dofs(RobotId robot) const;
  /// Writes the joint positions (rad or m) into `out`, which must have num_dofs(robot) entries
  /// (else std::invalid_argument). Allocates nothing.
  void joint_positions(RobotId robot, Eigen::Ref<Eigen::VectorXd> out) const;
  /// Writes the joint velocities (rad/s or m/s) into `out`, as joint_positions.
  void joint_velocities(RobotId robot, Eigen::Ref<Eigen::VectorXd> out) const;
  /// The position of degree of freedom `dof`; std::out_of_range for a dof the robot lacks.
  double joint_position(RobotId robot, int dof) const;
  /// The velocity of degree of freedom `dof`; std::out_of_range for a dof the robot lacks.
  double joint_velocity(RobotId robot, int dof) const;
  /// Convenience form of joint_positions that returns a new vector (it allocates).
  Eigen::VectorXd joint_positions(RobotId robot) const;
  /// Convenience form of joint_velocities that returns a new vector (it allocates).
  Eigen::VectorXd joint_velocities(RobotId robot) const;
  /// Sets positions and velocities of every degree of freedom. Throws std::invalid_argument on a
  /// size mismatch or a non-finite value.
  void set_joint_state(RobotId robot, const Eigen::Ref<const Eigen::VectorXd>& positions,
                       const Eigen::Ref<const Eigen::VectorXd>& velocities);

  /// Switches degree of freedom `dof` to `mode`. For kVelocity and kPosition, `max_force` bounds
  /// the motor (0: the URDF effort limit, or unbounded when it has none); `position_gain` and
  /// `velocity_gain` are Bullet's motor gains (as PyBullet's positionGain / velocityGain). The
  /// dof's command goes back to 0. Throws std::out_of_range for a dof the robot lacks and
  /// std::invalid_argument for a negative (or NaN) max_force or gain.
  void set_control_mode(RobotId robot, int dof, ControlMode mode, double max_force = 0.0,
                        double position_gain = 0.3, double velocity_gain = 1.0);
  /// Sets every degree of freedom to `mode` with the same settings.
  void set_control_mode(RobotId robot, ControlMode mode, double max_force = 0.0,
                        double position_gain = 0.3, double velocity_gain = 1.0);
  /// The mode of degree of freedom `dof` (kTorque until set); std::out_of_range for a dof the
  /// robot lacks.
  ControlMode control_mode(RobotId robot, int dof) const;
  /// The command of each degree of freedom: a torque (kTorque), a velocity (kVelocity) or a
  /// position (kPosition), per its mode. Held until changed. Throws std::invalid_argument on a size
  /// mismatch or a non-finite value. Allocates nothing (fixed-size vectors bind without a copy).
  void set_joint_commands(RobotId robot, const Eigen::Ref<const Eigen::VectorXd>& commands);

  /// World pose of the URDF frame of link `link` (an index into RobotModel::links()).
  /// std::out_of_range for a link the robot lacks, as for every `link` argument below.
  Eigen::Isometry3d link_pose(RobotId robot, int link) const;
  /// World linear velocity of the origin of link `link`'s URDF frame, in m/s.
  Eigen::Vector3d link_linear_velocity(RobotId robot, int link) const;
  /// World position of the robot's centre of mass (every link's mass, the root's included; for a
  /// fixed base of zero mass, the links that move), m. Allocates nothing.
  Eigen::Vector3d center_of_mass(RobotId robot) const;
  /// World velocity of the robot's centre of mass, m/s (dm_control's subtreelinvel of the root):
  /// the mass-weighted mean of the links' centre-of-mass velocities. Allocates nothing once warm.
  Eigen::Vector3d center_of_mass_velocity(RobotId robot) const;
  /// World pose of the root link's URDF frame: link_pose(robot, 0).
  Eigen::Isometry3d base_pose(RobotId robot) const;
  /// Moves a floating-base robot's root link frame to `X_world_base` and stops its base. Throws
  /// std::invalid_argument for a fixed-base robot or a non-finite pose.
  void set_base_pose(RobotId robot, const Eigen::Isometry3d& X_world_base);
  /// The segmentation id of link `link` of `robot` (see the class comment).
  int segmentation_id(RobotId robot, int link) const;

  // --- free bodies --------------------------------------------------------------------------
  /// Bodies added so far.
  int num_bodies() const;
  /// The options `body` was added with.
  const BodyOptions& body_options(BodyId body) const;
  /// World pose of the body's frame.
  Eigen::Isometry3d body_pose(BodyId body) const;
  /// World linear velocity of the origin of the body's frame, in m/s.
  Eigen::Vector3d body_linear_velocity(BodyId body) const;
  /// Moves a body and stops it. Throws std::invalid_argument for a non-finite pose.
  void set_body_pose(BodyId body, const Eigen::Isometry3d& X_world_body);
  /// The segmentation id of `body` (see the class comment).
  int segmentation_id(BodyId body) const;

  // --- contacts and visuals -----------------------------------------------------------------
  /// Contact points of the last step (with positive normal force or penetration). Allocates the
  /// returned vector.
  std::vector<Contact> contacts() const;
  /// The contacts of the last step that touch link `link` (an index into the model's links())
  /// of `robot`, those contacts() lists, written into `out` (cleared first): no allocation once
  /// `out` has room, for sensors read at every step.
  void link_contacts(RobotId robot, int link, std::vector<LinkContact>& out) const;
  /// Runs collision detection on the current state, without stepping, and returns the points
  /// where two things touch or overlap (normal_force_n 0): for an episode start that must be
  /// free of contacts, as dm_control's finger and ball-in-cup ask after setting joints.
  std::vector<Contact> detect_contacts();
  /// Every visual element of every robot and body, in a fixed order.
  const std::vector<VisualShape>& visual_shapes() const { return visual_shapes_; }
  /// Writes the current world pose of each visual shape, in visual_shapes() order, into `poses`
  /// (resized to visual_shapes().size(); no allocation once it has that size).
  void visual_poses(std::vector<Eigen::Isometry3d>& poses) const;

 private:
  struct Impl;

  // Throw std::out_of_range naming `caller` for an id this world did not hand out.
  void check_robot(RobotId robot, const char* caller) const;
  void check_body(BodyId body, const char* caller) const;

  WorldConfig config_;
  std::unique_ptr<Impl> impl_;
  std::vector<VisualShape> visual_shapes_;
  std::int64_t step_count_ = 0;
  int next_segmentation_id_ = 1;
};

}  // namespace pixelgym::engine
