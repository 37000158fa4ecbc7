#include "pixelgym/engine/world.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <thread>

namespace pixelgym::engine {
namespace {

using ::testing::HasSubstr;

// A small deterministic command source (tests must not depend on envs/).
class Commands {
 public:
  explicit Commands(std::uint64_t seed) : state_(seed * 2654435761ULL + 1) {}
  double next(double scale) {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return scale * (static_cast<double>(state_ >> 11) * 0x1.0p-53 * 2.0 - 1.0);
  }

 private:
  std::uint64_t state_;
};

// The arm on a table beside a cube: enough contact and articulation to expose any
// nondeterminism.
struct Scene {
  explicit Scene(ModelCache& cache) {
    arm = world.add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
    RobotOptions table_options;
    table_options.X_world_base.translation() = Eigen::Vector3d(0.6, 0, 0);
    world.add_robot(cache.load_urdf(asset_path("objects/table.urdf")), table_options);
    RobotOptions cube_options;
    cube_options.fixed_base = false;
    cube_options.X_world_base.translation() = Eigen::Vector3d(0.45, 0.05, 0.8);
    cube = world.add_robot(cache.load_urdf(asset_path("objects/cube.urdf")), cube_options);
  }

  void drive(Commands& commands, int steps) {
    Eigen::VectorXd torques(7);
    for (int s = 0; s < steps; ++s) {
      for (int d = 0; d < 7; ++d) torques[d] = commands.next(40.0);
      world.set_joint_commands(arm, torques);
      world.step();
    }
  }

  // Every double of the state, for bitwise comparison.
  std::vector<double> state() const {
    std::vector<double> values;
    for (RobotId robot : {arm, cube}) {
      const Eigen::VectorXd q = world.joint_positions(robot);
      const Eigen::VectorXd qd = world.joint_velocities(robot);
      values.insert(values.end(), q.data(), q.data() + q.size());
      values.insert(values.end(), qd.data(), qd.data() + qd.size());
      const Eigen::Isometry3d base = world.base_pose(robot);
      values.insert(values.end(), base.data(), base.data() + 16);
    }
    const Eigen::Isometry3d tip =
        world.link_pose(arm, world.robot_model(arm).link_index("end_effector"));
    values.insert(values.end(), tip.data(), tip.data() + 16);
    return values;
  }

  World world;
  RobotId arm;
  RobotId cube;
};

bool bit_identical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(WorldTest, TwoWorldsFedTheSameCommandsStayBitIdenticalFor10000Steps) {
  ModelCache cache;
  Scene a(cache);
  Scene b(cache);
  Commands ca(7);
  Commands cb(7);
  for (int chunk = 0; chunk < 100; ++chunk) {
    a.drive(ca, 100);
    b.drive(cb, 100);
    ASSERT_TRUE(bit_identical(a.state(), b.state())) << "diverged by step " << (chunk + 1) * 100;
  }
  EXPECT_EQ(a.world.step_count(), 10000);
}

TEST(WorldTest, AResetWorldMatchesAFreshOneBitForBit) {
  ModelCache cache;
  Scene used(cache);
  Commands history(1);
  used.drive(history, 700);  // contacts, warm-started solver, moved cube
  used.world.reset();
  EXPECT_EQ(used.world.step_count(), 0);

  Scene fresh(cache);
  ASSERT_TRUE(bit_identical(used.state(), fresh.state()));
  Commands c1(2);
  Commands c2(2);
  for (int chunk = 0; chunk < 10; ++chunk) {
    used.drive(c1, 100);
    fresh.drive(c2, 100);
    ASSERT_TRUE(bit_identical(used.state(), fresh.state()))
        << "diverged by step " << (chunk + 1) * 100;
  }
}

TEST(WorldTest, WorldsInTwoThreadsMatchOneThread) {
  ModelCache cache;
  const auto run = [&cache](std::vector<double>& out) {
    Scene scene(cache);
    Commands commands(3);
    scene.drive(commands, 1000);
    out = scene.state();
  };
  std::vector<double> sequential;
  run(sequential);
  std::vector<double> first;
  std::vector<double> second;
  std::thread t1(run, std::ref(first));
  std::thread t2(run, std::ref(second));
  t1.join();
  t2.join();
  EXPECT_TRUE(bit_identical(first, sequential));
  EXPECT_TRUE(bit_identical(second, sequential));
}

TEST(WorldTest, SixteenWorldsShareOneParsedModelAndReadMeshesOnce) {
  ModelCache cache;
  std::vector<std::unique_ptr<World>> worlds;
  for (int i = 0; i < 16; ++i) {
    worlds.push_back(std::make_unique<World>());
    worlds.back()->add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
  }
  EXPECT_EQ(cache.urdfs_parsed(), 1);
  EXPECT_EQ(cache.meshes().files_read(), 16);  // each distinct mesh file once, not 16 times
  worlds[3]->step(10);
  EXPECT_EQ(worlds[4]->step_count(), 0);
}

TEST(WorldTest, LinkPosesFollowTheJoints) {
  ModelCache cache;
  World world;
  const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  const int pole = world.robot_model(cartpole).link_index("pole");
  Eigen::VectorXd q(2);
  q << 0.5, M_PI / 2;  // cart 0.5 m along x, pole tipped 90 degrees about y (towards +x)
  world.set_joint_state(cartpole, q, Eigen::VectorXd::Zero(2));
  const Eigen::Isometry3d X_world_pole = world.link_pose(cartpole, pole);
  EXPECT_TRUE(X_world_pole.translation().isApprox(Eigen::Vector3d(0.5, 0, 1.1), 1e-9));
  const Eigen::Vector3d tip = X_world_pole * Eigen::Vector3d(0, 0, 1.0);
  EXPECT_TRUE(tip.isApprox(Eigen::Vector3d(1.5, 0, 1.1), 1e-9)) << tip.transpose();
  EXPECT_TRUE(world.joint_positions(cartpole).isApprox(q));
}

TEST(WorldTest, LinkVelocityMatchesJointRates) {
  ModelCache cache;
  World world;
  const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  Eigen::VectorXd qd(2);
  qd << 0.3, 2.0;
  world.set_joint_state(cartpole, Eigen::VectorXd::Zero(2), qd);
  // The pole frame sits on the cart's pivot: it moves with the cart only.
  const Eigen::Vector3d v =
      world.link_linear_velocity(cartpole, world.robot_model(cartpole).link_index("pole"));
  EXPECT_TRUE(v.isApprox(Eigen::Vector3d(0.3, 0, 0), 1e-9)) << v.transpose();
}

TEST(WorldTest, LinkVelocityAwayFromTheJointsMatchesTheAnalyticValue) {
  // The reacher's fingertip frame is 0.12 m beyond the wrist, which is 0.12 m beyond the
  // shoulder; both hinges turn about z. Its velocity depends on both rates:
  //   v = 0.12 q1' (-sin q1, cos q1) + 0.12 (q1' + q2') (-sin(q1 + q2), cos(q1 + q2)).
  ModelCache cache;
  World world;
  const auto model = cache.load_urdf(asset_path("reacher/reacher.urdf"));
  const RobotId reacher = world.add_robot(model);
  const Eigen::Vector2d q(0.4, -0.7);
  const Eigen::Vector2d qd(1.5, -2.0);
  world.set_joint_state(reacher, q, qd);
  const double a = q[0];
  const double b = q[0] + q[1];
  const Eigen::Vector3d elbow = 0.12 * qd[0] * Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
  const Eigen::Vector3d tip =
      elbow + 0.12 * (qd[0] + qd[1]) * Eigen::Vector3d(-std::sin(b), std::cos(b), 0);
  const Eigen::Vector3d v_tip = world.link_linear_velocity(reacher, model->link_index("fingertip"));
  EXPECT_TRUE(v_tip.isApprox(tip, 1e-9)) << v_tip.transpose() << " vs " << tip.transpose();
  const Eigen::Vector3d v_hand = world.link_linear_velocity(reacher, model->link_index("hand"));
  EXPECT_TRUE(v_hand.isApprox(elbow, 1e-9)) << v_hand.transpose() << " vs " << elbow.transpose();
  // And after a step, against a finite difference of the fingertip's position.
  const Eigen::Vector3d before =
      world.link_pose(reacher, model->link_index("fingertip")).translation();
  world.step();
  const Eigen::Vector3d after =
      world.link_pose(reacher, model->link_index("fingertip")).translation();
  const Eigen::Vector3d v_now = world.link_linear_velocity(reacher, model->link_index("fingertip"));
  EXPECT_LT((v_now - (after - before) / world.config().timestep_s).norm(), 0.02 * v_now.norm());
}

TEST(WorldTest, VelocityControlReachesItsTarget) {
  ModelCache cache;
  WorldConfig config;
  config.gravity_m_s2.setZero();
  World world(config);
  const RobotId arm = world.add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
  world.set_control_mode(arm, ControlMode::kVelocity);
  Eigen::VectorXd target = Eigen::VectorXd::Zero(7);
  target[0] = 0.5;
  world.set_joint_commands(arm, target);
  world.step(240);
  EXPECT_NEAR(world.joint_velocities(arm)[0], 0.5, 1e-3);
}

TEST(WorldTest, JointLimitsHold) {
  // The cart's rail is a prismatic joint limited to [-2, 2] m: pushed hard either way, the cart
  // comes to rest at that end (not before it, not beyond it).
  ModelCache cache;
  for (const double force : {10.0, -10.0}) {
    World world;
    const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
    world.set_joint_commands(cartpole, Eigen::Vector2d(force, 0.0));
    world.step(2400);
    EXPECT_NEAR(world.joint_position(cartpole, 0), force > 0 ? 2.0 : -2.0, 0.02)
        << "pushed with " << force << " N";
  }
}

std::shared_ptr<const RobotModel> slider(ModelCache& cache) {
  return cache.load_urdf(std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/slider.urdf");
}

TEST(WorldTest, PrismaticLimitsHoldOnBothSides) {
  // tests/data/urdf_good/slider.urdf: a 2 kg carriage on a rail limited to [-0.5, 0.3] m.
  ModelCache cache;
  for (const double force : {50.0, -50.0}) {
    World world;
    const RobotId robot = world.add_robot(slider(cache));
    world.set_joint_commands(robot, Eigen::Matrix<double, 1, 1>(force));
    world.step(480);
    EXPECT_NEAR(world.joint_position(robot, 0), force > 0 ? 0.3 : -0.5, 0.01)
        << "pushed with " << force << " N";
    EXPECT_NEAR(world.joint_velocity(robot, 0), 0.0, 0.01) << "not resting on the limit";
  }
}

TEST(WorldTest, PrismaticJointsFollowVelocityAndPositionCommands) {
  ModelCache cache;
  World world;
  const RobotId robot = world.add_robot(slider(cache));
  world.set_control_mode(robot, ControlMode::kVelocity);
  world.set_joint_commands(robot, Eigen::Matrix<double, 1, 1>(-0.2));
  world.step(240);
  EXPECT_NEAR(world.joint_velocity(robot, 0), -0.2, 1e-3);
  EXPECT_NEAR(world.joint_position(robot, 0), -0.2, 0.01);  // about 1 s at -0.2 m/s
  world.set_control_mode(robot, ControlMode::kPosition);
  world.set_joint_commands(robot, Eigen::Matrix<double, 1, 1>(0.15));
  world.step(720);
  EXPECT_NEAR(world.joint_position(robot, 0), 0.15, 1e-3);
}

TEST(WorldTest, LimitsAndMotorsWorkOnRobotsWithoutCollisionShapes) {
  // The reacher has no collision geometry; Bullet solves joint limits and motors per collision
  // island, which such a robot would not have without the world's help.
  ModelCache cache;
  World world;
  const RobotId reacher = world.add_robot(cache.load_urdf(asset_path("reacher/reacher.urdf")));
  // Push the wrist into its 2.8 rad limit. Without an island for its links the limit is ignored
  // and the wrist spins on (18.9 rad after 2 s). Bullet's limits are soft (error reduction per
  // step), so a light link under full torque rests slightly inside the limit.
  world.set_joint_commands(reacher, (Eigen::VectorXd(2) << 0.0, 0.05).finished());
  world.step(480);
  EXPECT_GT(world.joint_positions(reacher)[1], 2.7);
  EXPECT_LT(world.joint_positions(reacher)[1], 3.0) << "the wrist limit did not hold";
  EXPECT_NEAR(world.joint_velocities(reacher)[1], 0.0, 0.05)
      << "the wrist is not resting on its limit";
  world.set_control_mode(reacher, 0, ControlMode::kVelocity);
  world.set_joint_commands(reacher, (Eigen::VectorXd(2) << 1.0, 0.0).finished());
  world.step(240);
  EXPECT_NEAR(world.joint_velocities(reacher)[0], 1.0, 1e-3);
}

TEST(WorldTest, FloatingBaseCanBeMovedAndSettles) {
  ModelCache cache;
  World world;
  RobotOptions options;
  options.fixed_base = false;
  const RobotId cube = world.add_robot(cache.load_urdf(asset_path("objects/cube.urdf")), options);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.3, -0.2, 0.5);
  world.set_base_pose(cube, pose);
  EXPECT_TRUE(world.base_pose(cube).translation().isApprox(pose.translation(), 1e-12));
  world.step(480);
  EXPECT_TRUE(
      world.base_pose(cube).translation().isApprox(Eigen::Vector3d(0.3, -0.2, 0.025), 2e-3));
  const RobotId fixed = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  EXPECT_THROW(world.set_base_pose(fixed, pose), std::invalid_argument);
}

TEST(WorldTest, VisualShapesListEveryVisualWithItsPose) {
  ModelCache cache;
  World world;
  world.add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
  BodyOptions marker;
  marker.name = "marker";
  marker.geometry.type = GeometryType::kSphere;
  marker.geometry.radius_m = 0.03;
  marker.mass_kg = 0;
  marker.collides = false;
  marker.X_world_body.translation() = Eigen::Vector3d(0.5, 0.2, 0.3);
  world.add_body(marker);
  ASSERT_EQ(world.visual_shapes().size(), 10U);  // pedestal, 7 links, hand, marker
  EXPECT_EQ(world.visual_shapes().front().owner, "arm/base");
  EXPECT_EQ(world.visual_shapes().back().owner, "marker");
  std::vector<Eigen::Isometry3d> poses;
  world.visual_poses(poses);
  ASSERT_EQ(poses.size(), 10U);
  EXPECT_TRUE(poses.back().translation().isApprox(Eigen::Vector3d(0.5, 0.2, 0.3)));
  EXPECT_NEAR(poses[1].translation().z(), 0.16, 1e-9);  // link1 starts on the pedestal
  world.step(100);
  std::vector<Eigen::Isometry3d> later;
  world.visual_poses(later);
  EXPECT_TRUE(later.back().isApprox(poses.back())) << "a static marker does not move";
}

TEST(WorldTest, SegmentationIdsAreOnePerOwnerInTheOrderAdded) {
  ModelCache cache;
  World world;
  const auto reacher_model = cache.load_urdf(asset_path("reacher/reacher.urdf"));
  const RobotId reacher = world.add_robot(reacher_model);
  BodyOptions target;
  target.name = "target";
  target.geometry.type = GeometryType::kSphere;
  target.geometry.radius_m = 0.05;
  target.mass_kg = 0;
  target.collides = false;
  const BodyId target_id = world.add_body(target);
  const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  const int reacher_links = static_cast<int>(reacher_model->links().size());
  // Link l of the first robot has id 1 + l, the body the next id, the next robot's links after.
  for (int l = 0; l < reacher_links; ++l) EXPECT_EQ(world.segmentation_id(reacher, l), 1 + l);
  EXPECT_EQ(world.segmentation_id(target_id), 1 + reacher_links);
  EXPECT_EQ(world.segmentation_id(cartpole, 0), 2 + reacher_links);
  // Every visual shape carries its owner's id; shapes of different owners never share one.
  std::map<std::string, int> id_of_owner;
  std::map<int, std::string> owner_of_id;
  for (const VisualShape& shape : world.visual_shapes()) {
    id_of_owner.emplace(shape.owner, shape.segmentation_id);
    EXPECT_EQ(id_of_owner.at(shape.owner), shape.segmentation_id) << shape.owner;
    owner_of_id.emplace(shape.segmentation_id, shape.owner);
    EXPECT_EQ(owner_of_id.at(shape.segmentation_id), shape.owner) << shape.segmentation_id;
  }
  EXPECT_EQ(id_of_owner.at("reacher/fingertip"),
            world.segmentation_id(reacher, reacher_model->link_index("fingertip")));
  EXPECT_EQ(id_of_owner.at("target"), world.segmentation_id(target_id));
  // A reset keeps them.
  const std::vector<VisualShape> before = world.visual_shapes();
  world.step(10);
  world.reset();
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_EQ(world.visual_shapes()[i].segmentation_id, before[i].segmentation_id);
}

TEST(WorldTest, MarkerHasNoCollision) {
  ModelCache cache;
  World world;
  BodyOptions marker;
  marker.name = "marker";
  marker.geometry.type = GeometryType::kSphere;
  marker.geometry.radius_m = 0.5;
  marker.mass_kg = 0;
  marker.collides = false;
  world.add_body(marker);  // overlaps the ground
  BodyOptions ball;
  ball.name = "ball";
  ball.geometry.type = GeometryType::kSphere;
  ball.geometry.radius_m = 0.1;
  ball.X_world_body.translation() = Eigen::Vector3d(0, 0, 0.3);  // inside the marker
  const BodyId b = world.add_body(ball);
  world.step(240);
  EXPECT_NEAR(world.body_pose(b).translation().z(), 0.1, 2e-3) << "fell through the marker";
  for (const Contact& contact : world.contacts()) {
    EXPECT_NE(contact.a, "marker");
    EXPECT_NE(contact.b, "marker");
  }
}

TEST(WorldTest, DetectContactsSeesOverlapsWithoutAStep) {
  ModelCache cache;
  World world;
  BodyOptions ball;
  ball.name = "ball";
  ball.geometry.type = GeometryType::kSphere;
  ball.geometry.radius_m = 0.1;
  ball.X_world_body.translation() = Eigen::Vector3d(0, 0, 0.5);
  const BodyId b = world.add_body(ball);
  // The finger's two chains, one robot: the tip reaches into the spinner when both point at each
  // other, and does not when the finger hangs down.
  RobotOptions self;
  self.self_collision = true;
  const RobotId finger = world.add_robot(cache.load_urdf(asset_path("finger/finger.urdf")), self);
  const RobotModel& model = world.robot_model(finger);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  q[model.dof_index("proximal")] = -M_PI / 2;
  world.set_joint_state(finger, q, Eigen::VectorXd::Zero(3));
  EXPECT_TRUE(world.detect_contacts().empty());

  Eigen::Isometry3d low = Eigen::Isometry3d::Identity();
  low.translation() = Eigen::Vector3d(0, 0, 0.05);  // 5 cm into the ground
  world.set_body_pose(b, low);
  q[model.dof_index("proximal")] = 0.0;
  q[model.dof_index("hinge")] = M_PI / 2;
  world.set_joint_state(finger, q, Eigen::VectorXd::Zero(3));
  std::map<std::string, int> pairs;
  for (const Contact& contact : world.detect_contacts()) {
    pairs[std::min(contact.a, contact.b) + " " + std::max(contact.a, contact.b)]++;
    EXPECT_EQ(contact.normal_force_n, 0.0);
  }
  EXPECT_EQ(pairs.count("ball ground"), 1U);
  EXPECT_EQ(pairs.count("finger/distal finger/spinner"), 1U);
  EXPECT_EQ(pairs.size(), 2U);
  EXPECT_EQ(world.step_count(), 0);  // nothing moved
  EXPECT_EQ(world.body_pose(b).translation().z(), 0.05);
}

TEST(WorldTest, LinkContactsListWhatTouchesOneLinkWithItsForce) {
  ModelCache cache;
  WorldConfig config;
  config.gravity_m_s2 = Eigen::Vector3d::Zero();
  config.timestep_s = 0.001;
  World world(config);
  RobotOptions self;
  self.self_collision = true;
  const RobotId finger = world.add_robot(cache.load_urdf(asset_path("finger/finger.urdf")), self);
  const RobotModel& model = world.robot_model(finger);
  // The finger points at the spinner, which is turned flat so that it cannot slip past, and
  // the proximal joint pushes the fingertip into its left end.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  q[model.dof_index("proximal")] = 0.3;
  q[model.dof_index("hinge")] = M_PI / 2;
  world.set_joint_state(finger, q, Eigen::VectorXd::Zero(3));
  Eigen::VectorXd torque = Eigen::VectorXd::Zero(3);
  torque[model.dof_index("proximal")] = -5.0;
  std::vector<LinkContact> touching;
  double force = 0.0;
  for (int t = 0; t < 300 && force == 0.0; ++t) {
    world.set_joint_commands(finger, torque);
    world.step();
    world.link_contacts(finger, model.link_index("distal"), touching);
    for (const LinkContact& contact : touching) force += contact.normal_force_n;
  }
  EXPECT_GT(force, 0.0) << "the fingertip never pressed on the spinner";
  std::vector<LinkContact> proximal(4);
  world.link_contacts(finger, model.link_index("proximal"), proximal);
  EXPECT_TRUE(proximal.empty());  // cleared: the proximal link touches nothing
  EXPECT_THAT([&] { world.link_contacts(finger, 7, proximal); },
              ::testing::ThrowsMessage<std::out_of_range>(HasSubstr("has 4 links, got link 7")));
}

// Adds a free 5 cm cube resting on the ground at (0, y).
RobotId add_resting_cube(World& world, ModelCache& cache, double y) {
  RobotOptions free;
  free.fixed_base = false;
  free.X_world_base.translation() = Eigen::Vector3d(0, y, 0.025);
  return world.add_robot(cache.load_urdf(asset_path("objects/cube.urdf")), free);
}

// On ground tilted by gravity's x component (tan 0.5) a cube slides where its friction is under
// 0.5 (Bullet multiplies it by the ground's 1) and holds where it is over: the default 0.8 holds,
// 0.3 slides at (0.5 - 0.3) g, and the setting outlives the rebuilds of add_robot and reset.
TEST(WorldTest, AContactMaterialsFrictionChangesHowALinkSlides) {
  ModelCache cache;
  WorldConfig config;
  config.gravity_m_s2 = Eigen::Vector3d(0.5 * 9.81, 0, -9.81);
  World world(config);
  const RobotId held = add_resting_cube(world, cache, 0.0);
  const RobotId sliding = add_resting_cube(world, cache, 0.5);
  ContactMaterial slippery;
  slippery.friction = 0.3;
  world.set_link_contact_material(sliding, 0, slippery);
  EXPECT_EQ(world.link_contact_material(held, 0).friction, 0.8);
  EXPECT_EQ(world.link_contact_material(sliding, 0).friction, 0.3);
  add_resting_cube(world, cache, 1.0);  // a rebuild
  for (int pass = 0; pass < 2; ++pass) {
    const double held_x = world.base_pose(held).translation().x();
    const double sliding_x = world.base_pose(sliding).translation().x();
    world.step(240);  // one second
    EXPECT_NEAR(world.base_pose(held).translation().x(), held_x, 1e-3) << "pass " << pass;
    // x = a t^2 / 2 with a = (0.5 - 0.3) g, from rest.
    EXPECT_NEAR(world.base_pose(sliding).translation().x() - sliding_x, 0.2 * 9.81 / 2, 0.1)
        << "pass " << pass;
    world.reset();
  }
}

// A cube of 0.1 kg resting on the ground sinks m g / 4 k into it where each of its contact points
// is a spring of stiffness k (its face touches the plane at four corners), and not at all where
// they are rigid; made rigid again, it rises back. The setting outlives a rebuild.
TEST(WorldTest, AContactMaterialsStiffnessMakesALinksContactsSoft) {
  ModelCache cache;
  World world;  // gravity on
  const RobotId rigid = add_resting_cube(world, cache, 0.0);
  const RobotId soft = add_resting_cube(world, cache, 0.5);
  ContactMaterial spring;
  spring.stiffness_n_m = 100.0;
  spring.damping_n_s_m = 2.0;
  world.set_link_contact_material(soft, 0, spring);
  add_resting_cube(world, cache, 1.0);           // a rebuild
  world.step(480);                               // two seconds, to settle
  const double sink = 0.1 * 9.81 / (4 * 100.0);  // 2.5 mm
  EXPECT_NEAR(world.base_pose(rigid).translation().z(), 0.025, 2e-4);
  EXPECT_NEAR(world.base_pose(soft).translation().z(), 0.025 - sink, 2e-4);
  world.set_link_contact_material(soft, 0, ContactMaterial{});
  world.step(480);
  EXPECT_NEAR(world.base_pose(soft).translation().z(), 0.025, 2e-4);
  EXPECT_EQ(world.link_contact_material(soft, 0).stiffness_n_m, 0.0);
}

TEST(WorldTest, AContactMaterialOutOfRangeIsRefusedNamingIt) {
  ModelCache cache;
  World world;
  const RobotId cube = add_resting_cube(world, cache, 0.0);
  EXPECT_THAT([&] { world.set_link_contact_material(cube, 1, ContactMaterial{}); },
              ::testing::ThrowsMessage<std::out_of_range>(HasSubstr("has 1 links, got link 1")));
  EXPECT_THAT([&] { world.link_contact_material(cube, -1); },
              ::testing::ThrowsMessage<std::out_of_range>(HasSubstr("has 1 links, got link -1")));
  const auto refused = [&](double friction, double stiffness, double damping,
                           const std::string& got) {
    ContactMaterial material;
    material.friction = friction;
    material.stiffness_n_m = stiffness;
    material.damping_n_s_m = damping;
    EXPECT_THAT([&] { world.set_link_contact_material(cube, 0, material); },
                ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr(got)))
        << got;
  };
  refused(-0.1, 0, 0, "got friction -0.1, stiffness_n_m 0, damping_n_s_m 0");
  refused(0.8, std::nan(""), 0, "stiffness_n_m nan");
  refused(0.8, 100, -1, "damping_n_s_m -1");
  refused(0.8, 0, 1, "a damping of 0 with a stiffness of 0");
  EXPECT_EQ(world.link_contact_material(cube, 0).friction, 0.8);  // unchanged by the refusals
}

TEST(WorldTest, AStringIsSlackUpToItsLengthAndPullsPastIt) {
  ModelCache cache;
  World world;  // gravity on
  const RobotId cup_and_ball =
      world.add_robot(cache.load_urdf(asset_path("ball_in_cup/ball_in_cup.urdf")), RobotOptions{});
  const RobotModel& model = world.robot_model(cup_and_ball);
  StringOptions options;
  options.robot_a = cup_and_ball;
  options.link_a = model.link_index("ball");
  options.robot_b = cup_and_ball;
  options.link_b = model.link_index("cup");
  options.point_b = Eigen::Vector3d(0, 0, -0.108);
  options.max_length_m = 0.3;
  options.stiffness_n_m = 500.0;
  options.damping_n_s_m = 2.0;
  const int string = world.add_string(options);
  // The ball starts 0.1 m below the cup's bottom: slack, so it falls freely for 0.1 s.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(4);
  q[model.dof_index("ball_z")] = 0.6 - 0.108 - 0.1 - 0.2;
  world.set_joint_state(cup_and_ball, q, Eigen::VectorXd::Zero(4));
  EXPECT_NEAR(world.string_length(string), 0.1, 1e-9);
  const int steps = static_cast<int>(std::lround(0.1 / world.config().timestep_s));
  world.step(steps);
  EXPECT_NEAR(world.joint_velocity(cup_and_ball, model.dof_index("ball_z")),
              -9.81 * steps * world.config().timestep_s, 1e-6);
  // Held up by the string, it comes to hang 0.3 m under the cup's bottom, plus the stretch of
  // its weight (0.0654 kg x 9.81 / 500 N/m = 1.3 mm).
  world.step(2400);
  EXPECT_NEAR(world.string_length(string), 0.3 + 0.0654 * 9.81 / 500.0, 2e-4);
  EXPECT_NEAR(world.joint_velocity(cup_and_ball, model.dof_index("ball_z")), 0.0, 1e-3);

  StringOptions bad = options;
  bad.max_length_m = 0.0;
  EXPECT_THAT([&] { world.add_string(bad); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("got max_length_m 0")));
  bad = options;
  bad.damping_n_s_m = -1.0;
  EXPECT_THAT([&] { world.add_string(bad); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("damping_n_s_m -1")));
  bad = options;
  bad.link_b = 9;
  EXPECT_THAT([&] { world.add_string(bad); },
              ::testing::ThrowsMessage<std::out_of_range>(HasSubstr("has 5 links, got link 9")));
  EXPECT_THAT([&] { world.string_length(1); },
              ::testing::ThrowsMessage<std::out_of_range>(HasSubstr("no string 1 (there are 1)")));
}

TEST(WorldTest, StaticMeshBodiesCollideAsTriangles) {
  // A ball dropped into the pedestal's open top ring lands on its cap, 0.16 m up: the triangles,
  // not a bounding box, hold it.
  ModelCache cache;
  World world;
  BodyOptions pedestal;
  pedestal.name = "pedestal";
  pedestal.geometry.type = GeometryType::kMesh;
  pedestal.geometry.mesh = cache.meshes().get(asset_path("arm/meshes/pedestal.dae"));
  pedestal.mass_kg = 0;
  world.add_body(pedestal);
  BodyOptions ball;
  ball.name = "ball";
  ball.geometry.type = GeometryType::kSphere;
  ball.geometry.radius_m = 0.03;
  ball.X_world_body.translation() = Eigen::Vector3d(0.02, 0.01, 0.5);
  const BodyId b = world.add_body(ball);
  world.step(480);
  EXPECT_NEAR(world.body_pose(b).translation().z(), 0.16 + 0.03, 3e-3);
  BodyOptions scaled = pedestal;
  scaled.name = "scaled";
  scaled.mass_kg = 1.0;  // a moving mesh: its convex hull, scaled
  scaled.geometry.mesh_scale = Eigen::Vector3d(0.5, 0.5, 0.5);
  scaled.X_world_body.translation() = Eigen::Vector3d(2, 0, 0.3);
  const BodyId s = world.add_body(scaled);
  world.step(480);
  EXPECT_NEAR(world.body_pose(s).translation().z(), 0.0, 3e-3)
      << "the 0.08 m hull rests on the ground";
}

TEST(WorldTest, NonFiniteStateRaisesNamingTheRobot) {
  ModelCache cache;
  World world;
  const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  world.set_joint_commands(cartpole, (Eigen::VectorXd(2) << 0.0, 1e308).finished());
  try {
    world.step(10);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("robot \"cartpole\" has a non-finite state"));
  }
}

TEST(WorldTest, BadArgumentsAreRejected) {
  WorldConfig config;
  config.timestep_s = 0;
  EXPECT_THROW(World{config}, std::invalid_argument);
  ModelCache cache;
  World world;
  EXPECT_THROW(world.add_robot(nullptr), std::invalid_argument);
  const RobotId cartpole = world.add_robot(cache.load_urdf(asset_path("cartpole/cartpole.urdf")));
  EXPECT_THROW(world.set_joint_commands(cartpole, Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_THROW(world.set_joint_commands(cartpole, Eigen::VectorXd::Constant(2, NAN)),
               std::invalid_argument);
  EXPECT_THROW(world.set_joint_state(cartpole, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(2)),
               std::invalid_argument);
  EXPECT_THROW(world.link_pose(cartpole, 9), std::out_of_range);
  EXPECT_THROW(world.joint_positions(RobotId{5}), std::out_of_range);
  EXPECT_THROW(world.joint_positions(RobotId{}), std::out_of_range);
  EXPECT_THROW(world.body_pose(BodyId{0}), std::out_of_range);
  EXPECT_THROW(world.joint_position(cartpole, 2), std::out_of_range);
  EXPECT_THROW(world.joint_velocity(cartpole, -1), std::out_of_range);
  EXPECT_THROW(world.control_mode(cartpole, 2), std::out_of_range);
  EXPECT_THROW(world.segmentation_id(cartpole, 3), std::out_of_range);
  Eigen::VectorXd three(3);
  EXPECT_THROW(world.joint_positions(cartpole, three), std::invalid_argument);
  EXPECT_THROW(world.joint_velocities(cartpole, three), std::invalid_argument);
  try {
    world.set_joint_commands(cartpole, Eigen::Vector3d::Zero());
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("World::set_joint_commands: robot \"cartpole\" has 2 "
                                        "degrees of freedom, got 3 commands"));
  }
  try {
    world.link_pose(RobotId{7}, 0);
    FAIL() << "no error";
  } catch (const std::out_of_range& error) {
    EXPECT_THAT(error.what(), HasSubstr("World::link_pose: no robot 7 (there are 1)"));
  }
  RobotOptions floating;
  floating.fixed_base = false;
  EXPECT_THROW(world.add_robot(cache.load_urdf(asset_path("objects/table.urdf")), floating),
               std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::engine
