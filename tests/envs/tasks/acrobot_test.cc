#include "envs/tasks/acrobot.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <iostream>

#include "envs/pixel_env.h"
#include "envs/registry.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

using testing::state;

constexpr double kPi = 3.14159265358979;

// The acrobot asset as an analytic model: two 1 kg, 1 m links with centres at 0.5 m and 1/12 kg m^2
// about them; angles from hanging straight down, the elbow relative to the upper arm.
struct AcrobotModel {
  static constexpr double m = 1.0, l = 1.0, lc = 0.5, I = 1.0 / 12.0, g = 9.81;
  static constexpr double kTopEnergy = (m * lc + m * l) * g + m * lc * g;

  // Accelerations (shoulder, elbow) for state s = (q1, q2, w1, w2) and elbow torque tau.
  static Eigen::Vector2d accel(const Eigen::Vector4d& s, double tau) {
    const double q1 = s[0], q2 = s[1], w1 = s[2], w2 = s[3];
    const double d1 = m * lc * lc + m * (l * l + lc * lc + 2 * l * lc * std::cos(q2)) + 2 * I;
    const double d2 = m * (lc * lc + l * lc * std::cos(q2)) + I;
    const double phi2 = m * lc * g * std::sin(q1 + q2);
    const double phi1 = -m * l * lc * w2 * w2 * std::sin(q2) -
                        2 * m * l * lc * w2 * w1 * std::sin(q2) +
                        (m * lc + m * l) * g * std::sin(q1) + phi2;
    const double a2 = (tau + d2 / d1 * phi1 - m * l * lc * w1 * w1 * std::sin(q2) - phi2) /
                      (m * lc * lc + I - d2 * d2 / d1);
    return {-(d2 * a2 + phi1) / d1, a2};
  }

  // Kinetic plus potential energy (0 potential at the shoulder's height).
  static double energy(const Eigen::Vector4d& s) {
    const double q1 = s[0], q2 = s[1], w1 = s[2], w2 = s[3];
    const double d1 = m * lc * lc + m * (l * l + lc * lc + 2 * l * lc * std::cos(q2)) + 2 * I;
    const double d2 = m * (lc * lc + l * lc * std::cos(q2)) + I;
    const double kinetic = 0.5 * (d1 * w1 * w1 + 2 * d2 * w1 * w2 + (m * lc * lc + I) * w2 * w2);
    return kinetic - (m * lc + m * l) * g * std::cos(q1) - m * lc * g * std::cos(q1 + q2);
  }
};

double wrap(double a) { return std::remainder(a, 2 * kPi); }

// Energy-based swing-up: the elbow pumps energy in (its power is tau * w2) while the arm is below
// the upright energy and keeps the arm straight so that it coasts up; near upright an LQR on the
// linearized model takes over. Under the task's 2 N m limit the LQR catches the arm only briefly
// (its gains ask for more than 2 N m a few hundredths of a radian off upright), so this shows the
// reward rising far above a random policy's, not a solved task.
class SwingUp {
 public:
  SwingUp() {
    const Eigen::Vector4d top(kPi, 0, 0, 0);
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    a(0, 2) = a(1, 3) = 1.0;
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector4d moved = top;
      moved[k] += 1e-6;
      a.block<2, 1>(2, k) =
          (AcrobotModel::accel(moved, 0.0) - AcrobotModel::accel(top, 0.0)) / 1e-6;
    }
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    b.tail<2>() = (AcrobotModel::accel(top, 1e-6) - AcrobotModel::accel(top, 0.0)) / 1e-6;
    const double dt = 0.01;
    const Eigen::Matrix4d ad = Eigen::Matrix4d::Identity() + dt * a;
    const Eigen::Vector4d bd = dt * b;
    const Eigen::Matrix4d q = Eigen::Vector4d(10, 10, 1, 1).asDiagonal();
    const double r = 0.1;
    Eigen::Matrix4d p = q;
    for (int i = 0; i < 20000; ++i) {
      k_ = (bd.transpose() * p * ad) / (r + (bd.transpose() * p * bd)(0, 0));
      p = q + ad.transpose() * p * (ad - bd * k_);
    }
  }

  Value operator()(const Value& obs) const {
    const Eigen::Vector4d s(state(obs, "joint_pos", 0), state(obs, "joint_pos", 1),
                            state(obs, "joint_vel", 0), state(obs, "joint_vel", 1));
    const Eigen::Vector4d deviation(wrap(s[0] - kPi), wrap(s[1]), s[2], s[3]);
    double tau;
    if (std::abs(deviation[0]) < kLqrAngle && std::abs(deviation[1]) < 2 * kLqrAngle) {
      tau = -(k_ * deviation)(0, 0);
    } else {
      tau = 20.0 * (AcrobotModel::kTopEnergy - AcrobotModel::energy(s)) * s[3] - 4.0 * wrap(s[1]) -
            1.0 * s[3];
    }
    return Array::from_vector<float>(
        {1}, {static_cast<float>(std::clamp(tau / AcrobotTask::kMaxTorqueNm, -1.0, 1.0))});
  }

 private:
  static constexpr double kLqrAngle = 0.3;  // rad from upright where the LQR takes over
  Eigen::RowVector4d k_;
};

TEST(AcrobotTest, AnalyticModelMatchesTheSimulation) {
  std::unique_ptr<Env> env = make("AcrobotSwingup-v0", {{"obs_mode", "state"}});
  env->reset(0);
  auto& world = const_cast<engine::World&>(static_cast<PixelEnv&>(env->unwrapped()).world());
  for (const auto& c : std::vector<std::array<double, 5>>{{0.5, 0, 0, 0, 0},
                                                          {0.5, 0.7, 0, 0, 0},
                                                          {0, 0, 0, 0, 1.0},
                                                          {2.0, -1.0, 1.0, -0.5, 0.5}}) {
    world.set_joint_state(0, (Eigen::VectorXd(2) << c[0], c[1]).finished(),
                          (Eigen::VectorXd(2) << c[2], c[3]).finished());
    const Eigen::Vector2d model =
        AcrobotModel::accel(Eigen::Vector4d(c[0], c[1], c[2], c[3]), 2.0 * c[4]);
    const StepResult r = env->step(Array::from_vector<float>({1}, {static_cast<float>(c[4])}));
    EXPECT_NEAR((state(r.obs, "joint_vel", 0) - c[2]) / 0.01, model[0],
                0.02 * std::abs(model[0]) + 0.05);
    EXPECT_NEAR((state(r.obs, "joint_vel", 1) - c[3]) / 0.01, model[1],
                0.02 * std::abs(model[1]) + 0.05);
  }
}

TEST(AcrobotTest, EnergySwingUpRaisesTheRewardFarAboveRandom) {
  std::unique_ptr<Env> env = make("AcrobotSwingup-v0", {{"obs_mode", "state"}});
  const SwingUp controller;
  double scripted = 0.0;
  double random = 0.0;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    scripted +=
        testing::episode_return(*env, seed, [&](const Value& obs) { return controller(obs); }) /
        3.0;
    random += testing::episode_return(*env, seed, testing::random_policy(*env, seed)) / 3.0;
  }
  std::cout << "AcrobotSwingup-v0 mean return over 3 episodes: energy swing-up " << scripted
            << ", random " << random << "\n";
  EXPECT_GT(scripted, 10.0 * random);
}

TEST(AcrobotTest, RewardIsOneWithTheTipAtTheTop) {
  std::unique_ptr<Env> env = make("AcrobotSwingup-v0", {{"obs_mode", "state"}});
  env->reset(0);
  auto& pixel_env = static_cast<PixelEnv&>(env->unwrapped());
  const auto& task = static_cast<const AcrobotTask&>(pixel_env.task());
  const_cast<engine::World&>(pixel_env.world())
      .set_joint_state(0, (Eigen::VectorXd(2) << kPi, 0.0).finished(), Eigen::VectorXd::Zero(2));
  EXPECT_NEAR((task.tip(pixel_env.world()) - AcrobotTask::kTop).norm(), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(task.reward(pixel_env.world()), 1.0);
}

}  // namespace
}  // namespace pixelgym
