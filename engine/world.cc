#include "pixelgym/engine/world.h"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace pixelgym::engine {
namespace {

constexpr double kHullMargin = 0.001;    // m; Bullet's 0.04 default inflates small parts
constexpr double kUnboundedForce = 1e9;  // N or N m, for motors without a limit
// Bullet's collision configuration preallocates pools of contact manifolds and collision
// algorithms, 4096 of each by default: about 8 MB per world in double precision, written whole
// on every build (so on every World::reset), where a task's few bodies use a dozen entries. A
// pair past the pool is allocated from the heap instead (Bullet's dispatcher falls back to
// btAlignedAlloc), so the size changes memory, not results.
constexpr int kCollisionPoolSize = 128;

btVector3 to_bt(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d from_bt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btTransform to_bt(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), to_bt(X.translation()));
}

Eigen::Isometry3d from_bt(const btTransform& X) {
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  const btQuaternion q = X.getRotation();
  result.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).toRotationMatrix();
  result.translation() = from_bt(X.getOrigin());
  return result;
}

// Gives a link's collider its material; a stiffness of 0 clears Bullet's flag for soft contacts,
// so that a link made soft and then rigid again is rigid.
void apply_contact_material(btMultiBodyLinkCollider& collider, const ContactMaterial& material) {
  collider.setFriction(material.friction);
  if (material.stiffness_n_m > 0.0) {
    collider.setContactStiffnessAndDamping(material.stiffness_n_m, material.damping_n_s_m);
  } else {
    collider.setCollisionFlags(collider.getCollisionFlags() &
                               ~btCollisionObject::CF_HAS_CONTACT_STIFFNESS_DAMPING);
  }
}

// Throws std::out_of_range naming `caller` for a link index outside the model's links().
void check_link_index(const RobotModel& model, int link, const char* caller) {
  if (link < 0 || static_cast<std::size_t>(link) >= model.links().size()) {
    throw std::out_of_range(std::string("World::") + caller + ": robot \"" + model.name() +
                            "\" has " + std::to_string(model.links().size()) + " links, got link " +
                            std::to_string(link));
  }
}

btQuaternion to_bt_rotation(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return btQuaternion(q.x(), q.y(), q.z(), q.w());
}

// The centre-of-mass frame of a link, with axes along the principal axes of its inertia, in the
// link's URDF frame, and the principal moments. Bullet's multibody links live in this frame.
struct PrincipalFrame {
  Eigen::Isometry3d X_link_com = Eigen::Isometry3d::Identity();
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
};

PrincipalFrame principal_frame(const Inertial& inertial) {
  PrincipalFrame frame;
  frame.X_link_com = inertial.X_link_inertial;
  if (inertial.inertia_kg_m2.isZero()) return frame;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertial.inertia_kg_m2);
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  frame.X_link_com.linear() = inertial.X_link_inertial.linear() * axes;
  frame.moments = solver.eigenvalues();
  return frame;
}

// Owns a collision shape and whatever it refers to (children of a compound, mesh data).
struct ShapeHolder {
  std::unique_ptr<btCollisionShape> shape;
  std::vector<std::unique_ptr<btCollisionShape>> children;
  std::unique_ptr<btTriangleMesh> triangles;
};

std::unique_ptr<btCollisionShape> primitive_shape(const Geometry& geometry) {
  switch (geometry.type) {
    case GeometryType::kBox:
      return std::make_unique<btBoxShape>(to_bt(geometry.box_size_m * 0.5));
    case GeometryType::kSphere:
      return std::make_unique<btSphereShape>(geometry.radius_m);
    case GeometryType::kCylinder:
      return std::make_unique<btCylinderShapeZ>(
          btVector3(geometry.radius_m, geometry.radius_m, geometry.length_m * 0.5));
    case GeometryType::kCapsule:
      return std::make_unique<btCapsuleShapeZ>(geometry.radius_m, geometry.length_m);
    case GeometryType::kMesh: {
      // Moving meshes collide as their convex hull, reduced to its hull vertices.
      auto hull = std::make_unique<btConvexHullShape>();
      const Mesh& mesh = *geometry.mesh;
      for (const Eigen::Vector3f& p : mesh.positions) {
        hull->addPoint(to_bt(p.cast<double>().cwiseProduct(geometry.mesh_scale)), false);
      }
      hull->recalcLocalAabb();
      hull->optimizeConvexHull();
      hull->setMargin(kHullMargin);
      return hull;
    }
  }
  throw std::invalid_argument("unknown geometry type");
}

}  // namespace

void WorldConfig::validate() const {
  if (!(timestep_s > 0) || !std::isfinite(timestep_s)) {
    throw std::invalid_argument("WorldConfig: timestep_s must be positive and finite, got " +
                                std::to_string(timestep_s));
  }
  if (!gravity_m_s2.allFinite()) throw std::invalid_argument("WorldConfig: gravity is not finite");
  if (solver_iterations < 1) {
    throw std::invalid_argument("WorldConfig: solver_iterations must be >= 1, got " +
                                std::to_string(solver_iterations));
  }
}

struct World::Impl {
  struct Dof {
    int joint = 0;        // index into the model's joints
    int bullet_link = 0;  // index of the Bullet link it moves
    ControlMode mode = ControlMode::kTorque;
    double command = 0.0;
    double max_force = 0.0;
    double position_gain = 0.3;
    double velocity_gain = 1.0;
  };

  struct Robot {
    std::shared_ptr<const RobotModel> model;
    RobotOptions options;
    std::vector<PrincipalFrame> frames;  // per model link
    std::vector<ShapeHolder> shapes;     // per model link; shape null when none
    std::vector<Dof> dofs;
    // Rebuilt by build():
    std::unique_ptr<btMultiBody> body;
    std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
    std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints;
    std::vector<btMultiBodyJointMotor*> motors;           // per dof, owned by `constraints`
    std::vector<btMultiBodyJointMotor*> friction_motors;  // per dof or null
    int first_segmentation_id = 0;                        // of link 0; link l has this + l
    std::vector<ContactMaterial> link_materials;          // per model link, from add_robot
  };

  struct Body {
    BodyOptions options;
    ShapeHolder shape;
    std::unique_ptr<btRigidBody> rigid;  // rebuilt by build()
    int segmentation_id = 0;
  };

  // What a visual shape is attached to.
  struct VisualRef {
    int robot = -1;  // or -1 for a body
    int index = 0;   // model link or body
    Eigen::Isometry3d X_owner_geometry = Eigen::Isometry3d::Identity();
  };

  explicit Impl(const WorldConfig& world_config) : config(world_config) {
    ground_shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
    island_anchor_shape = std::make_unique<btSphereShape>(1e-3);
    build();
  }

  ~Impl() { teardown(); }

  void teardown() {
    // The dynamics world refers to everything else, so it goes first.
    dynamics.reset();
    for (Robot& robot : robots) {
      robot.constraints.clear();
      robot.motors.clear();
      robot.friction_motors.clear();
      robot.colliders.clear();
      robot.body.reset();
    }
    for (Body& body : bodies) body.rigid.reset();
    ground.reset();
    solver.reset();
    broadphase.reset();
    dispatcher.reset();
    collision_config.reset();
    names.clear();
  }

  void build() {
    btDefaultCollisionConstructionInfo pools;
    pools.m_defaultMaxPersistentManifoldPoolSize = kCollisionPoolSize;
    pools.m_defaultMaxCollisionAlgorithmPoolSize = kCollisionPoolSize;
    collision_config = std::make_unique<btDefaultCollisionConfiguration>(pools);
    dispatcher = std::make_unique<btCollisionDispatcher>(collision_config.get());
    broadphase = std::make_unique<btDbvtBroadphase>();
    solver = std::make_unique<btMultiBodyConstraintSolver>();
    dynamics = std::make_unique<btMultiBodyDynamicsWorld>(dispatcher.get(), broadphase.get(),
                                                          solver.get(), collision_config.get());
    dynamics->setGravity(to_bt(config.gravity_m_s2));
    dynamics->getSolverInfo().m_numIterations = config.solver_iterations;
    if (config.ground_plane) {
      ground = std::make_unique<btCollisionObject>();
      ground->setCollisionShape(ground_shape.get());
      ground->setFriction(config.ground_friction);
      dynamics->addCollisionObject(ground.get(), btBroadphaseProxy::StaticFilter,
                                   btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
      names[ground.get()] = "ground";
    }
    for (std::size_t i = 0; i < robots.size(); ++i) build_robot(robots[i]);
    for (Body& body : bodies) build_body(body);
  }

  void rebuild() {
    teardown();
    build();
  }

  void build_robot(Robot& robot) {
    const RobotModel& model = *robot.model;
    const auto& links = model.links();
    const auto& joints = model.joints();
    const int num_links = static_cast<int>(links.size()) - 1;
    const PrincipalFrame& root = robot.frames[0];
    robot.body = std::make_unique<btMultiBody>(num_links, links[0].inertial.mass_kg,
                                               to_bt(root.moments), robot.options.fixed_base,
                                               /*canSleep=*/false);
    btMultiBody& body = *robot.body;
    body.setBaseWorldTransform(to_bt(robot.options.X_world_base * root.X_link_com));
    for (int j = 0; j < num_links; ++j) {
      const JointModel& joint = joints[static_cast<std::size_t>(j)];
      const PrincipalFrame& parent = robot.frames[static_cast<std::size_t>(joint.parent_link)];
      const PrincipalFrame& child = robot.frames[static_cast<std::size_t>(joint.child_link)];
      const LinkModel& link = links[static_cast<std::size_t>(joint.child_link)];
      // The joint frame in the parent's and in the child's centre-of-mass frames (the child's
      // URDF frame is the joint frame at zero position).
      const Eigen::Isometry3d X_parentcom_joint =
          parent.X_link_com.inverse() * joint.X_parent_joint;
      const Eigen::Isometry3d X_childcom_joint = child.X_link_com.inverse();
      const btQuaternion rot_parent_to_this =
          to_bt_rotation(X_childcom_joint.linear() * X_parentcom_joint.linear().transpose());
      const btVector3 parent_com_to_pivot = to_bt(X_parentcom_joint.translation());
      const btVector3 pivot_to_com = to_bt(-X_childcom_joint.translation());
      const btVector3 axis = to_bt(X_childcom_joint.linear() * joint.axis);
      const int parent_index = joint.parent_link - 1;
      const double mass = link.inertial.mass_kg;
      const btVector3 moments = to_bt(child.moments);
      switch (joint.type) {
        case JointType::kRevolute:
        case JointType::kContinuous:
          body.setupRevolute(j, mass, moments, parent_index, rot_parent_to_this, axis,
                             parent_com_to_pivot, pivot_to_com, true);
          break;
        case JointType::kPrismatic:
          body.setupPrismatic(j, mass, moments, parent_index, rot_parent_to_this, axis,
                              parent_com_to_pivot, pivot_to_com, true);
          break;
        case JointType::kFixed:
          body.setupFixed(j, mass, moments, parent_index, rot_parent_to_this, parent_com_to_pivot,
                          pivot_to_com, true);
          break;
      }
    }
    body.finalizeMultiDof();
    body.setLinearDamping(0.0);
    body.setAngularDamping(0.0);
    body.setUseGyroTerm(true);
    body.setHasSelfCollision(robot.options.self_collision);
    dynamics->addMultiBody(&body);

    const int group = robot.options.fixed_base ? btBroadphaseProxy::StaticFilter
                                               : btBroadphaseProxy::DefaultFilter;
    for (std::size_t l = 0; l < links.size(); ++l) {
      btCollisionShape* shape = robot.shapes[l].shape.get();
      const int bullet_link = static_cast<int>(l) - 1;
      auto collider = std::make_unique<btMultiBodyLinkCollider>(&body, bullet_link);
      if (shape != nullptr) {
        collider->setCollisionShape(shape);
        apply_contact_material(*collider, robot.link_materials[l]);
        const bool is_static_base = l == 0 && robot.options.fixed_base;
        const int link_group = l == 0 ? group : btBroadphaseProxy::DefaultFilter;
        const int mask = is_static_base
                             ? btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter
                             : btBroadphaseProxy::AllFilter;
        dynamics->addCollisionObject(collider.get(), link_group, mask);
      } else {
        // Bullet solves joint limits and motors per simulation island, found through the
        // colliders of the links they act on; a link without one has no island, and its limits,
        // motors and friction would silently do nothing. A tiny collider that collides with
        // nothing (group and mask 0) gives it one. (Turning island splitting off instead hits a
        // Bullet 3.24 bug that passes no multibody constraint to the solver.)
        collider->setCollisionShape(island_anchor_shape.get());
        dynamics->addCollisionObject(collider.get(), 0, 0);
      }
      if (l == 0) {
        body.setBaseCollider(collider.get());
      } else {
        body.getLink(bullet_link).m_collider = collider.get();
      }
      names[collider.get()] = model.name() + "/" + links[l].name;
      robot.colliders.push_back(std::move(collider));
    }

    robot.motors.assign(robot.dofs.size(), nullptr);
    robot.friction_motors.assign(robot.dofs.size(), nullptr);
    for (std::size_t d = 0; d < robot.dofs.size(); ++d) {
      const Dof& dof = robot.dofs[d];
      const JointModel& joint = joints[static_cast<std::size_t>(dof.joint)];
      if (joint.has_limits) {
        auto limit = std::make_unique<btMultiBodyJointLimitConstraint>(&body, dof.bullet_link,
                                                                       joint.lower, joint.upper);
        dynamics->addMultiBodyConstraint(limit.get());
        robot.constraints.push_back(std::move(limit));
      }
      auto motor = std::make_unique<btMultiBodyJointMotor>(&body, dof.bullet_link, 0.0, 0.0);
      dynamics->addMultiBodyConstraint(motor.get());
      robot.motors[d] = motor.get();
      robot.constraints.push_back(std::move(motor));
      if (joint.friction > 0) {
        auto friction = std::make_unique<btMultiBodyJointMotor>(&body, dof.bullet_link, 0.0,
                                                                joint.friction * config.timestep_s);
        dynamics->addMultiBodyConstraint(friction.get());
        robot.friction_motors[d] = friction.get();
        robot.constraints.push_back(std::move(friction));
      }
    }
    update_kinematics(robot);
  }

  void build_body(Body& body) {
    const BodyOptions& options = body.options;
    btVector3 inertia(0, 0, 0);
    if (options.mass_kg > 0) body.shape.shape->calculateLocalInertia(options.mass_kg, inertia);
    btRigidBody::btRigidBodyConstructionInfo info(options.mass_kg, nullptr, body.shape.shape.get(),
                                                  inertia);
    info.m_startWorldTransform = to_bt(options.X_world_body);
    info.m_friction = options.friction;
    body.rigid = std::make_unique<btRigidBody>(info);
    body.rigid->setActivationState(DISABLE_DEACTIVATION);
    if (options.collides) {
      dynamics->addRigidBody(body.rigid.get());
    } else {
      body.rigid->setCollisionFlags(body.rigid->getCollisionFlags() |
                                    btCollisionObject::CF_NO_CONTACT_RESPONSE);
      dynamics->addRigidBody(body.rigid.get(), 0, 0);
    }
    names[body.rigid.get()] = options.name;
  }

  // A string's two ends in world coordinates.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> string_ends(const StringOptions& string) const {
    const Robot& a = robots[static_cast<std::size_t>(string.robot_a.index)];
    const Robot& b = robots[static_cast<std::size_t>(string.robot_b.index)];
    return {link_pose(a, string.link_a) * string.point_a,
            link_pose(b, string.link_b) * string.point_b};
  }

  // Adds `force` (world) at `point` (world) of model link `link` to its Bullet link, as a force
  // at the centre of mass and the torque about it.
  void add_force_at(Robot& robot, int link, const Eigen::Vector3d& point,
                    const Eigen::Vector3d& force) {
    const Eigen::Vector3d torque = (point - com_position(robot, link)).cross(force);
    if (link == 0) {
      robot.body->addBaseForce(to_bt(force));
      robot.body->addBaseTorque(to_bt(torque));
    } else {
      robot.body->addLinkForce(link - 1, to_bt(force));
      robot.body->addLinkTorque(link - 1, to_bt(torque));
    }
  }

  // Each taut string's pull, for the coming physics step.
  void apply_strings() {
    for (const StringOptions& string : strings) {
      const auto [end_a, end_b] = string_ends(string);
      const Eigen::Vector3d span = end_b - end_a;
      const double length = span.norm();
      if (length <= string.max_length_m) continue;
      const Eigen::Vector3d along = span / length;
      Robot& a = robots[static_cast<std::size_t>(string.robot_a.index)];
      Robot& b = robots[static_cast<std::size_t>(string.robot_b.index)];
      const double lengthening =
          (point_velocity(b, string.link_b, end_b) - point_velocity(a, string.link_a, end_a))
              .dot(along);
      const double pull = std::max(0.0, string.stiffness_n_m * (length - string.max_length_m) +
                                            string.damping_n_s_m * lengthening);
      add_force_at(a, string.link_a, end_a, pull * along);
      add_force_at(b, string.link_b, end_b, -pull * along);
    }
  }

  // The points of the dispatcher's manifolds: those with a normal impulse in the last step or
  // overlapping, or (touching_only) just those overlapping or touching.
  std::vector<Contact> manifold_contacts(double timestep_s, bool touching_only) const {
    std::vector<Contact> result;
    for (int m = 0; m < dispatcher->getNumManifolds(); ++m) {
      const btPersistentManifold& manifold = *dispatcher->getManifoldByIndexInternal(m);
      for (int p = 0; p < manifold.getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold.getContactPoint(p);
        if (point.getDistance() > 0 && (touching_only || point.getAppliedImpulse() <= 0)) continue;
        Contact contact;
        contact.a = names.at(manifold.getBody0());
        contact.b = names.at(manifold.getBody1());
        contact.position_world_m = from_bt(point.getPositionWorldOnB());
        contact.normal_world = from_bt(point.m_normalWorldOnB);
        contact.normal_force_n = touching_only ? 0.0 : point.getAppliedImpulse() / timestep_s;
        result.push_back(contact);
      }
    }
    return result;
  }

  void update_kinematics(Robot& robot) {
    robot.body->forwardKinematics(scratch_rotations, scratch_origins);
    robot.body->updateCollisionObjectWorldTransforms(scratch_rotations, scratch_origins);
  }

  void apply_controls(Robot& robot) {
    btMultiBody& body = *robot.body;
    const auto& joints = robot.model->joints();
    for (std::size_t d = 0; d < robot.dofs.size(); ++d) {
      const Dof& dof = robot.dofs[d];
      const JointModel& joint = joints[static_cast<std::size_t>(dof.joint)];
      const double velocity = body.getJointVel(dof.bullet_link);
      double torque = -joint.damping * velocity;
      if (joint.stiffness != 0.0) torque -= joint.stiffness * body.getJointPos(dof.bullet_link);
      btMultiBodyJointMotor& motor = *robot.motors[d];
      if (dof.mode == ControlMode::kTorque) {
        double command = dof.command;
        if (joint.effort_limit > 0)
          command = std::clamp(command, -joint.effort_limit, joint.effort_limit);
        torque += command;
        motor.setMaxAppliedImpulse(0.0);
      } else {
        const double max_force = dof.max_force > 0        ? dof.max_force
                                 : joint.effort_limit > 0 ? joint.effort_limit
                                                          : kUnboundedForce;
        motor.setMaxAppliedImpulse(max_force * config.timestep_s);
        if (dof.mode == ControlMode::kVelocity) {
          motor.setPositionTarget(0.0, 0.0);
          motor.setVelocityTarget(dof.command, dof.velocity_gain);
        } else {
          motor.setPositionTarget(dof.command, dof.position_gain);
          motor.setVelocityTarget(0.0, dof.velocity_gain);
        }
      }
      if (torque != 0.0) body.addJointTorque(dof.bullet_link, torque);
    }
  }

  void check_finite(std::int64_t step) const {
    for (const Robot& robot : robots) {
      const btMultiBody& body = *robot.body;
      const bool base_finite = body.getBaseWorldTransform().getOrigin().length2() < BT_INFINITY &&
                               std::isfinite(body.getBaseVel().length2()) &&
                               std::isfinite(body.getBaseOmega().length2());
      if (!base_finite) throw_non_finite(robot, "its base", step);
      for (const Dof& dof : robot.dofs) {
        if (!std::isfinite(body.getJointPos(dof.bullet_link)) ||
            !std::isfinite(body.getJointVel(dof.bullet_link))) {
          throw_non_finite(
              robot,
              "joint \"" + robot.model->joints()[static_cast<std::size_t>(dof.joint)].name + "\"",
              step);
        }
      }
    }
    for (const Body& body : bodies) {
      const btVector3 origin = body.rigid->getWorldTransform().getOrigin();
      if (!std::isfinite(origin.length2()) ||
          !std::isfinite(body.rigid->getLinearVelocity().length2()) ||
          !std::isfinite(body.rigid->getAngularVelocity().length2())) {
        throw NonFiniteState("World: body \"" + body.options.name +
                             "\" has a non-finite state after step " + std::to_string(step));
      }
    }
  }

  [[noreturn]] static void throw_non_finite(const Robot& robot, const std::string& where,
                                            std::int64_t step) {
    throw NonFiniteState("World: robot \"" + robot.model->name() + "\" has a non-finite state (" +
                         where + ") after step " + std::to_string(step));
  }

  // World position of link `link`'s centre of mass (the Bullet link frame's origin).
  Eigen::Vector3d com_position(const Robot& robot, int link) const {
    return from_bt(link == 0 ? robot.body->getBaseWorldTransform().getOrigin()
                             : robot.body->getLink(link - 1).m_cachedWorldTransform.getOrigin());
  }

  // World velocity of the point of link `link` that is at `point` (world coordinates) now.
  Eigen::Vector3d point_velocity(const Robot& robot, int link, const Eigen::Vector3d& point) const {
    const btMultiBody& body = *robot.body;
    if (link == 0) {
      const Eigen::Vector3d com = from_bt(body.getBaseWorldTransform().getOrigin());
      return from_bt(body.getBaseVel()) + from_bt(body.getBaseOmega()).cross(point - com);
    }
    // v = J u along each world axis, with J the contact Jacobian of the point.
    const int n = body.getNumDofs() + 6;
    scratch_jacobian.resize(n);
    const btScalar* u = body.getVelocityVector();
    Eigen::Vector3d velocity;
    for (int axis = 0; axis < 3; ++axis) {
      btVector3 direction(0, 0, 0);
      direction[axis] = 1;
      body.fillContactJacobianMultiDof(link - 1, to_bt(point), direction, &scratch_jacobian[0],
                                       scratch_r, scratch_v, scratch_m);
      double v = 0;
      for (int k = 0; k < n; ++k) v += scratch_jacobian[k] * u[k];
      velocity[axis] = v;
    }
    return velocity;
  }

  Eigen::Isometry3d link_pose(const Robot& robot, int link) const {
    const btTransform X_world_com = link == 0
                                        ? robot.body->getBaseWorldTransform()
                                        : robot.body->getLink(link - 1).m_cachedWorldTransform;
    return from_bt(X_world_com) * robot.frames[static_cast<std::size_t>(link)].X_link_com.inverse();
  }

  WorldConfig config;
  std::unique_ptr<btCollisionShape> ground_shape;
  std::unique_ptr<btCollisionShape> island_anchor_shape;  // see build_robot
  std::vector<Robot> robots;
  std::vector<Body> bodies;
  std::vector<VisualRef> visual_refs;
  std::vector<StringOptions> strings;

  std::unique_ptr<btDefaultCollisionConfiguration> collision_config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btBroadphaseInterface> broadphase;
  std::unique_ptr<btMultiBodyConstraintSolver> solver;
  std::unique_ptr<btCollisionObject> ground;
  std::unique_ptr<btMultiBodyDynamicsWorld> dynamics;
  std::unordered_map<const btCollisionObject*, std::string> names;
  btAlignedObjectArray<btQuaternion> scratch_rotations;
  btAlignedObjectArray<btVector3> scratch_origins;
  // Scratch of link_linear_velocity, kept so that the query allocates nothing once warm (this
  // is why a World's const queries are not safe to call from two threads at once).
  mutable btAlignedObjectArray<btScalar> scratch_jacobian;
  mutable btAlignedObjectArray<btScalar> scratch_r;
  mutable btAlignedObjectArray<btVector3> scratch_v;
  mutable btAlignedObjectArray<btMatrix3x3> scratch_m;
};

World::World(WorldConfig config) : config_((config.validate(), config)) {
  impl_ = std::make_unique<Impl>(config_);
}

World::~World() = default;

RobotId World::add_robot(std::shared_ptr<const RobotModel> model, RobotOptions options) {
  if (model == nullptr) throw std::invalid_argument("World::add_robot: model is null");
  const auto& links = model->links();
  if (!options.fixed_base) {
    const Inertial& root = links[0].inertial;
    if (!(root.mass_kg > 0) || !(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(root.inertia_kg_m2)
                                     .eigenvalues()
                                     .minCoeff() > 0)) {
      throw std::invalid_argument("World::add_robot: robot \"" + model->name() + "\" root link \"" +
                                  links[0].name +
                                  "\" needs positive mass and inertia for a floating base");
    }
  }
  Impl::Robot robot;
  robot.model = model;
  robot.options = options;
  robot.first_segmentation_id = next_segmentation_id_;
  const int robot_index = static_cast<int>(impl_->robots.size());
  for (std::size_t l = 0; l < links.size(); ++l) {
    const LinkModel& link = links[l];
    robot.frames.push_back(principal_frame(link.inertial));
    ShapeHolder holder;
    if (!link.collisions.empty()) {
      auto compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/false);
      const Eigen::Isometry3d X_com_link = robot.frames.back().X_link_com.inverse();
      for (const CollisionElement& element : link.collisions) {
        std::unique_ptr<btCollisionShape> child = primitive_shape(element.geometry);
        compound->addChildShape(to_bt(X_com_link * element.X_link_geometry), child.get());
        holder.children.push_back(std::move(child));
      }
      holder.shape = std::move(compound);
    }
    robot.shapes.push_back(std::move(holder));
    const int segmentation_id = robot.first_segmentation_id + static_cast<int>(l);
    for (const VisualElement& visual : link.visuals) {
      visual_shapes_.push_back(
          {visual.geometry, visual.material, model->name() + "/" + link.name, segmentation_id});
      impl_->visual_refs.push_back({robot_index, static_cast<int>(l), visual.X_link_geometry});
    }
  }
  robot.link_materials.assign(links.size(), ContactMaterial{});
  for (int joint : model->movable_joints()) {
    Impl::Dof dof;
    dof.joint = joint;
    dof.bullet_link = model->joints()[static_cast<std::size_t>(joint)].child_link - 1;
    robot.dofs.push_back(dof);
  }
  impl_->robots.push_back(std::move(robot));
  next_segmentation_id_ += static_cast<int>(links.size());
  impl_->rebuild();
  return RobotId{robot_index};
}

BodyId World::add_body(BodyOptions options) {
  if (!(options.mass_kg >= 0)) {
    throw std::invalid_argument("World::add_body: body \"" + options.name + "\" has negative mass");
  }
  if (options.geometry.type == GeometryType::kMesh && options.geometry.mesh == nullptr) {
    throw std::invalid_argument("World::add_body: body \"" + options.name + "\" has a null mesh");
  }
  Impl::Body body;
  body.options = options;
  if (options.geometry.type == GeometryType::kMesh && options.mass_kg == 0) {
    // Static meshes collide as their triangles.
    const Mesh& mesh = *options.geometry.mesh;
    body.shape.triangles = std::make_unique<btTriangleMesh>();
    for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
      btVector3 corners[3];
      for (int k = 0; k < 3; ++k) {
        corners[k] = to_bt(mesh.positions[mesh.indices[i + static_cast<std::size_t>(k)]]
                               .cast<double>()
                               .cwiseProduct(options.geometry.mesh_scale));
      }
      body.shape.triangles->addTriangle(corners[0], corners[1], corners[2]);
    }
    body.shape.shape = std::make_unique<btBvhTriangleMeshShape>(body.shape.triangles.get(), true);
  } else {
    body.shape.shape = primitive_shape(options.geometry);
  }
  body.segmentation_id = next_segmentation_id_++;
  const int body_index = static_cast<int>(impl_->bodies.size());
  visual_shapes_.push_back(
      {options.geometry, options.material, options.name, body.segmentation_id});
  impl_->visual_refs.push_back({-1, body_index, Eigen::Isometry3d::Identity()});
  impl_->bodies.push_back(std::move(body));
  impl_->rebuild();
  return BodyId{body_index};
}

void World::step(int steps) {
  if (steps < 0)
    throw std::invalid_argument("World::step: steps must be >= 0, got " + std::to_string(steps));
  for (int s = 0; s < steps; ++s) {
    for (Impl::Robot& robot : impl_->robots) impl_->apply_controls(robot);
    impl_->apply_strings();
    impl_->dynamics->stepSimulation(config_.timestep_s, 0, config_.timestep_s);
    ++step_count_;
    for (Impl::Robot& robot : impl_->robots) impl_->update_kinematics(robot);
    impl_->check_finite(step_count_);
  }
}

void World::reset() {
  for (Impl::Robot& robot : impl_->robots) {
    for (Impl::Dof& dof : robot.dofs) dof = Impl::Dof{dof.joint, dof.bullet_link};
  }
  impl_->rebuild();
  step_count_ = 0;
}

double World::time_s() const { return static_cast<double>(step_count_) * config_.timestep_s; }

void World::check_robot(RobotId robot, const char* caller) const {
  if (robot.index < 0 || robot.index >= num_robots()) {
    throw std::out_of_range(std::string("World::") + caller + ": no robot " +
                            std::to_string(robot.index) + " (there are " +
                            std::to_string(num_robots()) + ")");
  }
}

void World::check_body(BodyId body, const char* caller) const {
  if (body.index < 0 || body.index >= num_bodies()) {
    throw std::out_of_range(std::string("World::") + caller + ": no body " +
                            std::to_string(body.index) + " (there are " +
                            std::to_string(num_bodies()) + ")");
  }
}

namespace {

// The size check of the vector-valued joint queries and commands; builds its message only when
// it throws.
void check_dof_count(const char* caller, const std::string& robot_name, std::size_t dofs,
                     Eigen::Index given, const char* what) {
  if (given != static_cast<Eigen::Index>(dofs)) {
    throw std::invalid_argument(std::string("World::") + caller + ": robot \"" + robot_name +
                                "\" has " + std::to_string(dofs) + " degrees of freedom, got " +
                                std::to_string(given) + " " + what);
  }
}

}  // namespace

int World::num_robots() const { return static_cast<int>(impl_->robots.size()); }

const RobotModel& World::robot_model(RobotId robot) const {
  check_robot(robot, "robot_model");
  return *impl_->robots[static_cast<std::size_t>(robot.index)].model;
}

int World::num_dofs(RobotId robot) const {
  check_robot(robot, "num_dofs");
  return static_cast<int>(impl_->robots[static_cast<std::size_t>(robot.index)].dofs.size());
}

void World::joint_positions(RobotId robot, Eigen::Ref<Eigen::VectorXd> out) const {
  check_robot(robot, "joint_positions");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof_count("joint_positions", r.model->name(), r.dofs.size(), out.size(), "outputs");
  for (std::size_t d = 0; d < r.dofs.size(); ++d) {
    out[static_cast<Eigen::Index>(d)] = r.body->getJointPos(r.dofs[d].bullet_link);
  }
}

void World::joint_velocities(RobotId robot, Eigen::Ref<Eigen::VectorXd> out) const {
  check_robot(robot, "joint_velocities");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof_count("joint_velocities", r.model->name(), r.dofs.size(), out.size(), "outputs");
  for (std::size_t d = 0; d < r.dofs.size(); ++d) {
    out[static_cast<Eigen::Index>(d)] = r.body->getJointVel(r.dofs[d].bullet_link);
  }
}

namespace {

void check_dof(const char* caller, const std::string& robot_name, std::size_t dofs, int dof) {
  if (dof < 0 || dof >= static_cast<int>(dofs)) {
    throw std::out_of_range(std::string("World::") + caller + ": robot \"" + robot_name +
                            "\" has no dof " + std::to_string(dof) + " (it has " +
                            std::to_string(dofs) + ")");
  }
}

}  // namespace

double World::joint_position(RobotId robot, int dof) const {
  check_robot(robot, "joint_position");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof("joint_position", r.model->name(), r.dofs.size(), dof);
  return r.body->getJointPos(r.dofs[static_cast<std::size_t>(dof)].bullet_link);
}

double World::joint_velocity(RobotId robot, int dof) const {
  check_robot(robot, "joint_velocity");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof("joint_velocity", r.model->name(), r.dofs.size(), dof);
  return r.body->getJointVel(r.dofs[static_cast<std::size_t>(dof)].bullet_link);
}

Eigen::VectorXd World::joint_positions(RobotId robot) const {
  Eigen::VectorXd q(num_dofs(robot));
  joint_positions(robot, q);
  return q;
}

Eigen::VectorXd World::joint_velocities(RobotId robot) const {
  Eigen::VectorXd qd(num_dofs(robot));
  joint_velocities(robot, qd);
  return qd;
}

void World::set_joint_state(RobotId robot, const Eigen::Ref<const Eigen::VectorXd>& positions,
                            const Eigen::Ref<const Eigen::VectorXd>& velocities) {
  check_robot(robot, "set_joint_state");
  Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof_count("set_joint_state", r.model->name(), r.dofs.size(), positions.size(), "positions");
  check_dof_count("set_joint_state", r.model->name(), r.dofs.size(), velocities.size(),
                  "velocities");
  if (!positions.allFinite() || !velocities.allFinite()) {
    throw std::invalid_argument("World::set_joint_state: non-finite value for robot \"" +
                                r.model->name() + "\"");
  }
  for (std::size_t d = 0; d < r.dofs.size(); ++d) {
    const auto i = static_cast<Eigen::Index>(d);
    r.body->setJointPos(r.dofs[d].bullet_link, positions[i]);
    r.body->setJointVel(r.dofs[d].bullet_link, velocities[i]);
  }
  impl_->update_kinematics(r);
}

void World::set_control_mode(RobotId robot, int dof, ControlMode mode, double max_force,
                             double position_gain, double velocity_gain) {
  check_robot(robot, "set_control_mode");
  Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof("set_control_mode", r.model->name(), r.dofs.size(), dof);
  if (!(max_force >= 0) || !(position_gain >= 0) || !(velocity_gain >= 0)) {
    std::ostringstream message;
    message << "World::set_control_mode: max_force and gains must be >= 0, got max_force "
            << max_force << ", position_gain " << position_gain << ", velocity_gain "
            << velocity_gain;
    throw std::invalid_argument(message.str());
  }
  Impl::Dof& d = r.dofs[static_cast<std::size_t>(dof)];
  d.mode = mode;
  d.command = 0.0;
  d.max_force = max_force;
  d.position_gain = position_gain;
  d.velocity_gain = velocity_gain;
}

void World::set_control_mode(RobotId robot, ControlMode mode, double max_force,
                             double position_gain, double velocity_gain) {
  for (int d = 0; d < num_dofs(robot); ++d) {
    set_control_mode(robot, d, mode, max_force, position_gain, velocity_gain);
  }
}

ControlMode World::control_mode(RobotId robot, int dof) const {
  check_robot(robot, "control_mode");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof("control_mode", r.model->name(), r.dofs.size(), dof);
  return r.dofs[static_cast<std::size_t>(dof)].mode;
}

void World::set_joint_commands(RobotId robot, const Eigen::Ref<const Eigen::VectorXd>& commands) {
  check_robot(robot, "set_joint_commands");
  Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_dof_count("set_joint_commands", r.model->name(), r.dofs.size(), commands.size(),
                  "commands");
  if (!commands.allFinite()) {
    throw NonFiniteCommand("World::set_joint_commands: non-finite command for robot \"" +
                           r.model->name() + "\"");
  }
  for (std::size_t d = 0; d < r.dofs.size(); ++d)
    r.dofs[d].command = commands[static_cast<Eigen::Index>(d)];
}

namespace {

void check_link(const char* caller, const RobotModel& model, int link) {
  if (link < 0 || link >= static_cast<int>(model.links().size())) {
    throw std::out_of_range(std::string("World::") + caller + ": robot \"" + model.name() +
                            "\" has no link " + std::to_string(link) + " (it has " +
                            std::to_string(model.links().size()) + ")");
  }
}

}  // namespace

Eigen::Isometry3d World::link_pose(RobotId robot, int link) const {
  check_robot(robot, "link_pose");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_link("link_pose", *r.model, link);
  return impl_->link_pose(r, link);
}

Eigen::Vector3d World::link_linear_velocity(RobotId robot, int link) const {
  check_robot(robot, "link_linear_velocity");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_link("link_linear_velocity", *r.model, link);
  return impl_->point_velocity(r, link, impl_->link_pose(r, link).translation());
}

Eigen::Vector3d World::center_of_mass(RobotId robot) const {
  check_robot(robot, "center_of_mass");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (int link = 0; link <= r.body->getNumLinks(); ++link) {
    const double m = link == 0 ? r.body->getBaseMass() : r.body->getLinkMass(link - 1);
    sum += m * impl_->com_position(r, link);
    mass += m;
  }
  return mass > 0 ? Eigen::Vector3d(sum / mass) : impl_->link_pose(r, 0).translation();
}

Eigen::Vector3d World::center_of_mass_velocity(RobotId robot) const {
  check_robot(robot, "center_of_mass_velocity");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (int link = 0; link <= r.body->getNumLinks(); ++link) {
    const double m = link == 0 ? r.body->getBaseMass() : r.body->getLinkMass(link - 1);
    if (m > 0) sum += m * impl_->point_velocity(r, link, impl_->com_position(r, link));
    mass += m;
  }
  return mass > 0 ? Eigen::Vector3d(sum / mass) : Eigen::Vector3d::Zero();
}

Eigen::Isometry3d World::base_pose(RobotId robot) const {
  check_robot(robot, "base_pose");
  return impl_->link_pose(impl_->robots[static_cast<std::size_t>(robot.index)], 0);
}

void World::set_base_pose(RobotId robot, const Eigen::Isometry3d& X_world_base) {
  check_robot(robot, "set_base_pose");
  Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  if (r.options.fixed_base) {
    throw std::invalid_argument("World::set_base_pose: robot \"" + r.model->name() +
                                "\" has a fixed base");
  }
  if (!X_world_base.matrix().allFinite()) {
    throw std::invalid_argument("World::set_base_pose: non-finite pose for robot \"" +
                                r.model->name() + "\"");
  }
  r.body->setBaseWorldTransform(to_bt(X_world_base * r.frames[0].X_link_com));
  r.body->setBaseVel(btVector3(0, 0, 0));
  r.body->setBaseOmega(btVector3(0, 0, 0));
  impl_->update_kinematics(r);
}

int World::segmentation_id(RobotId robot, int link) const {
  check_robot(robot, "segmentation_id");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  check_link("segmentation_id", *r.model, link);
  return r.first_segmentation_id + link;
}

int World::num_bodies() const { return static_cast<int>(impl_->bodies.size()); }

const BodyOptions& World::body_options(BodyId body) const {
  check_body(body, "body_options");
  return impl_->bodies[static_cast<std::size_t>(body.index)].options;
}

Eigen::Isometry3d World::body_pose(BodyId body) const {
  check_body(body, "body_pose");
  return from_bt(impl_->bodies[static_cast<std::size_t>(body.index)].rigid->getWorldTransform());
}

Eigen::Vector3d World::body_linear_velocity(BodyId body) const {
  check_body(body, "body_linear_velocity");
  return from_bt(impl_->bodies[static_cast<std::size_t>(body.index)].rigid->getLinearVelocity());
}

void World::set_body_pose(BodyId body, const Eigen::Isometry3d& X_world_body) {
  check_body(body, "set_body_pose");
  Impl::Body& b = impl_->bodies[static_cast<std::size_t>(body.index)];
  if (!X_world_body.matrix().allFinite()) {
    throw std::invalid_argument("World::set_body_pose: non-finite pose for body \"" +
                                b.options.name + "\"");
  }
  btRigidBody& rigid = *b.rigid;
  rigid.setWorldTransform(to_bt(X_world_body));
  rigid.setLinearVelocity(btVector3(0, 0, 0));
  rigid.setAngularVelocity(btVector3(0, 0, 0));
  rigid.clearForces();
}

int World::segmentation_id(BodyId body) const {
  check_body(body, "segmentation_id");
  return impl_->bodies[static_cast<std::size_t>(body.index)].segmentation_id;
}

int World::add_string(const StringOptions& options) {
  const auto check_end = [&](RobotId robot, int link, const Eigen::Vector3d& point) {
    check_robot(robot, "add_string");
    check_link_index(*impl_->robots[static_cast<std::size_t>(robot.index)].model, link,
                     "add_string");
    const RobotModel& model = *impl_->robots[static_cast<std::size_t>(robot.index)].model;
    if (!point.allFinite()) {
      throw std::invalid_argument("World::add_string: a non-finite point on robot \"" +
                                  model.name() + "\"");
    }
  };
  check_end(options.robot_a, options.link_a, options.point_a);
  check_end(options.robot_b, options.link_b, options.point_b);
  const auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  if (!positive(options.max_length_m) || !positive(options.stiffness_n_m) ||
      !(options.damping_n_s_m >= 0 && std::isfinite(options.damping_n_s_m))) {
    std::ostringstream message;
    message << "World::add_string: max_length_m and stiffness_n_m must be > 0 and "
               "damping_n_s_m >= 0, all finite; got max_length_m "
            << options.max_length_m << ", stiffness_n_m " << options.stiffness_n_m
            << ", damping_n_s_m " << options.damping_n_s_m;
    throw std::invalid_argument(message.str());
  }
  impl_->strings.push_back(options);
  return static_cast<int>(impl_->strings.size()) - 1;
}

void World::set_link_contact_material(RobotId robot, int link, const ContactMaterial& material) {
  check_robot(robot, "set_link_contact_material");
  check_link_index(*impl_->robots[static_cast<std::size_t>(robot.index)].model, link,
                   "set_link_contact_material");
  Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  const auto finite_at_least = [](double value, double least) {
    return std::isfinite(value) && value >= least;
  };
  if (!finite_at_least(material.friction, 0.0) || !finite_at_least(material.stiffness_n_m, 0.0) ||
      !finite_at_least(material.damping_n_s_m, 0.0) ||
      (material.stiffness_n_m == 0.0 && material.damping_n_s_m != 0.0)) {
    std::ostringstream message;
    message << "World::set_link_contact_material: expected a friction, stiffness_n_m and "
               "damping_n_s_m that are finite and >= 0, and a damping of 0 with a stiffness of 0 "
               "(rigid); got friction "
            << material.friction << ", stiffness_n_m " << material.stiffness_n_m
            << ", damping_n_s_m " << material.damping_n_s_m;
    throw std::invalid_argument(message.str());
  }
  r.link_materials[static_cast<std::size_t>(link)] = material;
  btMultiBodyLinkCollider& collider = *r.colliders[static_cast<std::size_t>(link)];
  if (collider.getCollisionShape() != impl_->island_anchor_shape.get()) {
    apply_contact_material(collider, material);
  }
}

const ContactMaterial& World::link_contact_material(RobotId robot, int link) const {
  check_robot(robot, "link_contact_material");
  check_link_index(*impl_->robots[static_cast<std::size_t>(robot.index)].model, link,
                   "link_contact_material");
  return impl_->robots[static_cast<std::size_t>(robot.index)]
      .link_materials[static_cast<std::size_t>(link)];
}

double World::string_length(int string) const {
  if (string < 0 || static_cast<std::size_t>(string) >= impl_->strings.size()) {
    throw std::out_of_range("World::string_length: no string " + std::to_string(string) +
                            " (there are " + std::to_string(impl_->strings.size()) + ")");
  }
  const auto [end_a, end_b] = impl_->string_ends(impl_->strings[static_cast<std::size_t>(string)]);
  return (end_b - end_a).norm();
}

std::vector<Contact> World::contacts() const {
  return impl_->manifold_contacts(config_.timestep_s, /*touching_only=*/false);
}

void World::link_contacts(RobotId robot, int link, std::vector<LinkContact>& out) const {
  check_robot(robot, "link_contacts");
  check_link_index(*impl_->robots[static_cast<std::size_t>(robot.index)].model, link,
                   "link_contacts");
  const Impl::Robot& r = impl_->robots[static_cast<std::size_t>(robot.index)];
  const auto is_link = [&](const btCollisionObject* object) {
    const btMultiBodyLinkCollider* collider = btMultiBodyLinkCollider::upcast(object);
    return collider != nullptr && collider->m_multiBody == r.body.get() &&
           collider->m_link == link - 1;  // Bullet numbers the links after the base from 0
  };
  out.clear();
  btCollisionDispatcher& dispatcher = *impl_->dispatcher;
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold& manifold = *dispatcher.getManifoldByIndexInternal(m);
    if (!is_link(manifold.getBody0()) && !is_link(manifold.getBody1())) continue;
    for (int p = 0; p < manifold.getNumContacts(); ++p) {
      const btManifoldPoint& point = manifold.getContactPoint(p);
      if (point.getDistance() > 0 && point.getAppliedImpulse() <= 0) continue;
      out.push_back({from_bt((point.getPositionWorldOnA() + point.getPositionWorldOnB()) * 0.5),
                     point.getAppliedImpulse() / config_.timestep_s});
    }
  }
}

std::vector<Contact> World::detect_contacts() {
  impl_->dynamics->performDiscreteCollisionDetection();
  return impl_->manifold_contacts(config_.timestep_s, /*touching_only=*/true);
}

void World::visual_poses(std::vector<Eigen::Isometry3d>& poses) const {
  poses.resize(impl_->visual_refs.size());
  for (std::size_t i = 0; i < impl_->visual_refs.size(); ++i) {
    const Impl::VisualRef& ref = impl_->visual_refs[i];
    const Eigen::Isometry3d X_world_owner =
        ref.robot >= 0
            ? impl_->link_pose(impl_->robots[static_cast<std::size_t>(ref.robot)], ref.index)
            : from_bt(
                  impl_->bodies[static_cast<std::size_t>(ref.index)].rigid->getWorldTransform());
    poses[i] = X_world_owner * ref.X_owner_geometry;
  }
}

}  // namespace pixelgym::engine
