// Bullet checked against analytic answers.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "pixelgym/engine/world.h"

namespace pixelgym::engine {
namespace {

constexpr double kG = 9.81;

// The pendulum asset: pivot inertia and centre-of-mass distance from its own model.
struct PendulumProperties {
  double mass;
  double com_distance;
  double pivot_inertia;
};

PendulumProperties pendulum_properties(const RobotModel& model) {
  const Inertial& inertial = model.links()[1].inertial;
  const double d = inertial.X_link_inertial.translation().norm();
  const double I_com = (inertial.X_link_inertial.linear() * inertial.inertia_kg_m2 *
                        inertial.X_link_inertial.linear().transpose())(1, 1);
  return {inertial.mass_kg, d, I_com + inertial.mass_kg * d * d};
}

TEST(WorldPhysicsTest, PendulumSmallAnglePeriodWithinOnePercent) {
  ModelCache cache;
  const auto model = cache.load_urdf(asset_path("pendulum/pendulum.urdf"));
  const PendulumProperties p = pendulum_properties(*model);
  const double expected = 2 * M_PI * std::sqrt(p.pivot_inertia / (p.mass * kG * p.com_distance));

  World world;
  const RobotId robot = world.add_robot(model);
  world.set_joint_state(robot, Eigen::VectorXd::Constant(1, 0.05), Eigen::VectorXd::Zero(1));
  // Times of upward zero crossings, linearly interpolated between steps.
  std::vector<double> crossings;
  double previous = 0.05;
  while (world.time_s() < 10.0) {
    world.step();
    const double q = world.joint_positions(robot)[0];
    if (previous < 0 && q >= 0) {
      const double fraction = -previous / (q - previous);
      crossings.push_back(world.time_s() - (1 - fraction) * world.config().timestep_s);
    }
    previous = q;
  }
  ASSERT_GE(crossings.size(), 5U);
  const double measured =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(measured / expected, 1.0, 0.01)
      << "measured " << measured << " s, expected " << expected << " s";
  std::cout << "pendulum period: measured " << measured << " s, analytic " << expected
            << " s, ratio " << measured / expected << "\n";
}

TEST(WorldPhysicsTest, UndampedPendulumEnergyDriftBelowOnePercentOverTenSeconds) {
  ModelCache cache;
  const auto model = cache.load_urdf(asset_path("pendulum/pendulum.urdf"));
  const PendulumProperties p = pendulum_properties(*model);
  World world;
  const RobotId robot = world.add_robot(model);
  world.set_joint_state(robot, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Zero(1));
  // Energy above the lowest point of the centre of mass.
  const auto energy = [&] {
    const double q = world.joint_positions(robot)[0];
    const double w = world.joint_velocities(robot)[0];
    return 0.5 * p.pivot_inertia * w * w + p.mass * kG * p.com_distance * (1 - std::cos(q));
  };
  const double initial = energy();
  double worst = 0.0;
  while (world.time_s() < 10.0) {
    world.step();
    worst = std::max(worst, std::abs(energy() - initial) / initial);
  }
  EXPECT_LT(worst, 0.01) << "largest relative energy change over 10 s: " << worst;
  std::cout << "pendulum energy: largest relative change over 10 s " << worst << "\n";
}

TEST(WorldPhysicsTest, FreeFallMatchesHalfGTSquared) {
  // Bullet integrates semi-implicitly: after time t its fall exceeds g t^2 / 2 by g t dt / 2.
  // At dt = 0.1 ms that is 0.49 mm after 1 s; at the default 1/240 s it is 20 mm.
  for (const double dt : {1.0 / 10000, 1.0 / 240}) {
    WorldConfig config;
    config.timestep_s = dt;
    config.ground_plane = false;
    World world(config);
    BodyOptions ball;
    ball.name = "ball";
    ball.geometry.type = GeometryType::kSphere;
    ball.geometry.radius_m = 0.1;
    ball.X_world_body.translation() = Eigen::Vector3d(0, 0, 100);
    const BodyId body = world.add_body(ball);
    const int steps = static_cast<int>(std::lround(1.0 / dt));
    world.step(steps);
    const double fallen = 100.0 - world.body_pose(body).translation().z();
    const double analytic = 0.5 * kG * 1.0;
    std::cout << "free fall at dt = " << dt << " s: " << fallen << " m vs " << analytic << " m\n";
    if (dt < 1e-3) {
      EXPECT_NEAR(fallen, analytic, 1e-3);
    } else {
      EXPECT_NEAR(fallen - analytic, 0.5 * kG * dt, 1e-6);  // exactly the integrator's lead
    }
  }
}

TEST(WorldPhysicsTest, PositionControlledArmJointsSettleWithinOneHundredthRadian) {
  ModelCache cache;
  World world;
  const RobotId arm = world.add_robot(cache.load_urdf(asset_path("arm/arm.urdf")));
  ASSERT_EQ(world.num_dofs(arm), 7);
  world.set_control_mode(arm, ControlMode::kPosition);
  Eigen::VectorXd target(7);
  target << 0.4, 0.6, -0.3, -1.2, 0.5, 0.8, -0.7;
  world.set_joint_commands(arm, target);
  world.step(static_cast<int>(3.0 / world.config().timestep_s));
  const Eigen::VectorXd error = world.joint_positions(arm) - target;
  EXPECT_LT(error.cwiseAbs().maxCoeff(), 0.01) << "errors: " << error.transpose();
  std::cout << "arm PD: largest joint error after 3 s " << error.cwiseAbs().maxCoeff() << " rad\n";
  EXPECT_LT(world.joint_velocities(arm).cwiseAbs().maxCoeff(), 0.01);
}

TEST(WorldPhysicsTest, CubeRestsOnTheGroundWithItsWeightInContacts) {
  ModelCache cache;
  World world;
  RobotOptions options;
  options.fixed_base = false;
  options.X_world_base.translation() = Eigen::Vector3d(0, 0, 0.2);
  const RobotId cube = world.add_robot(cache.load_urdf(asset_path("objects/cube.urdf")), options);
  world.step(480);
  EXPECT_NEAR(world.base_pose(cube).translation().z(), 0.025, 2e-3);
  double normal_force = 0.0;
  for (const Contact& contact : world.contacts()) {
    if ((contact.a == "cube/cube" && contact.b == "ground") ||
        (contact.b == "cube/cube" && contact.a == "ground")) {
      normal_force += contact.normal_force_n;
    }
  }
  EXPECT_NEAR(normal_force, 0.1 * kG, 0.05);
}

TEST(WorldPhysicsTest, TorqueOnAFreeJointGivesTheExpectedAcceleration) {
  ModelCache cache;
  WorldConfig config;
  config.gravity_m_s2.setZero();
  World world(config);
  const auto model = cache.load_urdf(asset_path("pendulum/pendulum.urdf"));
  const RobotId robot = world.add_robot(model);
  const double torque = 1.5;  // within the 2 N m effort limit
  world.set_joint_commands(robot, Eigen::VectorXd::Constant(1, torque));
  world.step(240);
  const double expected_velocity = torque / pendulum_properties(*model).pivot_inertia * 1.0;
  EXPECT_NEAR(world.joint_velocities(robot)[0] / expected_velocity, 1.0, 1e-3);
}

std::shared_ptr<const RobotModel> good_urdf(ModelCache& cache, const std::string& name) {
  return cache.load_urdf(std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/" + name);
}

TEST(WorldPhysicsTest, ForceOnAPrismaticJointGivesTheExpectedMotion) {
  // tests/data/urdf_good/slider.urdf: 2 kg on a horizontal rail, so F = 4 N gives a = 2 m/s^2:
  // after 0.25 s, v = 0.5 m/s and x = 0.0625 m (well inside the [-0.5, 0.3] m limits).
  ModelCache cache;
  for (const double force : {4.0, -4.0}) {
    World world;
    const RobotId robot = world.add_robot(good_urdf(cache, "slider.urdf"));
    world.set_joint_commands(robot, Eigen::Matrix<double, 1, 1>(force));
    world.step(60);
    const double a = force / 2.0;
    EXPECT_NEAR(world.joint_velocity(robot, 0), a * 0.25, 1e-3 * std::abs(a * 0.25));
    // Bullet integrates semi-implicitly (velocity first), so after n steps of dt the position is
    // a dt^2 n (n + 1) / 2 = a t (t + dt) / 2: half a step ahead of a t^2 / 2.
    const double dt = world.config().timestep_s;
    const double x = 0.5 * a * 0.25 * (0.25 + dt);
    EXPECT_NEAR(world.joint_position(robot, 0), x, 1e-3 * std::abs(x));
  }
}

TEST(WorldPhysicsTest, JointDampingDecaysVelocityExponentially) {
  ModelCache cache;
  World world;
  const RobotId wheel = world.add_robot(good_urdf(cache, "damped_wheel.urdf"));
  world.set_joint_state(wheel, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, 2.0));
  world.step(120);  // 0.5 s = one time constant I / c
  EXPECT_NEAR(world.joint_velocities(wheel)[0] / (2.0 * std::exp(-1.0)), 1.0, 0.01);
}

TEST(WorldPhysicsTest, JointStiffnessIsASpringTowardsZero) {
  // tests/data/urdf_good/spring_slider.urdf: 2 kg on a spring of 8 pi^2 N/m, a period of 1 s.
  ModelCache cache;
  const auto model = good_urdf(cache, "spring_slider.urdf");
  EXPECT_DOUBLE_EQ(model->joints()[0].stiffness, 8 * M_PI * M_PI);
  World world;
  const RobotId slider = world.add_robot(model);
  world.set_joint_state(slider, Eigen::VectorXd::Constant(1, 0.1), Eigen::VectorXd::Zero(1));
  world.step(120);  // half a period: at the other end
  EXPECT_NEAR(world.joint_position(slider, 0), -0.1, 0.002);
  world.step(60);  // three quarters: through 0 at the top speed, 2 pi A / T
  EXPECT_NEAR(world.joint_position(slider, 0), 0.0, 0.002);
  EXPECT_NEAR(world.joint_velocity(slider, 0), 2 * M_PI * 0.1, 0.01);
  world.step(60);
  EXPECT_NEAR(world.joint_position(slider, 0), 0.1, 0.002);
}

TEST(WorldPhysicsTest, CenterOfMassAndItsVelocityWeighEveryLink) {
  ModelCache cache;
  World world;
  // The pendulum: hinge about y at (0, 0, 1.2), 1.1 kg with its centre of mass d below the
  // hinge; its mount has no mass. Turned by q and spinning at w, the centre of mass is at
  // (-d sin q, 0, 1.2 - d cos q) and moves at w d (-cos q, 0, sin q).
  const auto model = cache.load_urdf(asset_path("pendulum/pendulum.urdf"));
  const double d = pendulum_properties(*model).com_distance;
  const RobotId pendulum = world.add_robot(model);
  // The slider: 2 kg 0.5 m above x, moving at its joint velocity. (Both are added first: adding a
  // robot rebuilds the world.)
  const RobotId slider = world.add_robot(good_urdf(cache, "slider.urdf"));
  const double q = 0.3;
  const double w = 2.0;
  world.set_joint_state(pendulum, Eigen::VectorXd::Constant(1, q), Eigen::VectorXd::Constant(1, w));
  const Eigen::Vector3d com = world.center_of_mass(pendulum);
  const Eigen::Vector3d velocity = world.center_of_mass_velocity(pendulum);
  EXPECT_NEAR((com - Eigen::Vector3d(-d * std::sin(q), 0, 1.2 - d * std::cos(q))).norm(), 0, 1e-9)
      << com.transpose();
  EXPECT_NEAR((velocity - w * d * Eigen::Vector3d(-std::cos(q), 0, std::sin(q))).norm(), 0, 1e-9)
      << velocity.transpose();
  world.set_joint_state(slider, Eigen::VectorXd::Constant(1, 0.2),
                        Eigen::VectorXd::Constant(1, -0.7));
  EXPECT_NEAR((world.center_of_mass(slider) - Eigen::Vector3d(0.2, 0, 0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR((world.center_of_mass_velocity(slider) - Eigen::Vector3d(-0.7, 0, 0)).norm(), 0,
              1e-12);
  EXPECT_NEAR((world.center_of_mass_velocity(pendulum) - velocity).norm(), 0, 1e-12);
}

TEST(WorldPhysicsTest, JointFrictionStopsTheJointAndHoldsIt) {
  ModelCache cache;
  World world;
  const RobotId wheel = world.add_robot(good_urdf(cache, "rubbing_wheel.urdf"));
  world.set_joint_state(wheel, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, 1.0));
  world.step(24);  // 0.1 s: friction 0.05 N m on I = 0.01 decelerates at 5 rad/s^2
  EXPECT_NEAR(world.joint_velocities(wheel)[0], 0.5, 0.02);
  world.step(48);  // stopped at 0.2 s
  EXPECT_NEAR(world.joint_velocities(wheel)[0], 0.0, 1e-6);
  // A torque below the friction does not move it; above, it does.
  world.set_joint_commands(wheel, Eigen::VectorXd::Constant(1, 0.04));
  world.step(240);
  EXPECT_NEAR(world.joint_velocities(wheel)[0], 0.0, 1e-6);
  world.set_joint_commands(wheel, Eigen::VectorXd::Constant(1, 0.06));
  world.step(240);
  EXPECT_NEAR(world.joint_velocities(wheel)[0], 0.01 / 0.01 * 1.0,
              0.02);  // (0.06 - 0.05) / I * 1 s
}

}  // namespace
}  // namespace pixelgym::engine
