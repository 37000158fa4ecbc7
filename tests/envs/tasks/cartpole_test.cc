#include "pixelgym/envs/tasks/cartpole.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "tests/envs/tasks/scripted.h"

namespace pixelgym {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The cart-pole asset's parameters: cart 1 kg, pole 0.1 kg with its centre 0.5 m from the hinge
// and 0.00833 kg m^2 about it.
constexpr double kCartMass = 1.0;
constexpr double kPoleMass = 0.1;
constexpr double kPoleCentre = 0.5;
constexpr double kPoleInertia =
    0.008333 + kPoleMass * kPoleCentre * kPoleCentre;  // about the hinge
constexpr double kG = 9.81;

// LQR gains for the upright cart-pole, from its linearization about theta = 0, discretized at
// the control step, by iterating the discrete Riccati equation.
Eigen::RowVector4d lqr_gains(double dt) {
  Eigen::Matrix2d mass;
  mass << kCartMass + kPoleMass, kPoleMass * kPoleCentre, kPoleMass * kPoleCentre, kPoleInertia;
  const Eigen::Matrix2d inverse = mass.inverse();
  // state (x, theta, x_dot, theta_dot); input: force in N.
  Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
  a(0, 2) = a(1, 3) = 1.0;
  a.block<2, 1>(2, 1) = inverse * Eigen::Vector2d(0.0, kPoleMass * kG * kPoleCentre);
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  b.tail<2>() = inverse * Eigen::Vector2d(1.0, 0.0);
  const Eigen::Matrix4d ad = Eigen::Matrix4d::Identity() + dt * a;
  const Eigen::Vector4d bd = dt * b;
  const Eigen::Matrix4d q = Eigen::Vector4d(1.0, 10.0, 0.5, 0.5).asDiagonal();
  const double r = 0.05;
  Eigen::Matrix4d p = q;
  Eigen::RowVector4d k = Eigen::RowVector4d::Zero();
  for (int i = 0; i < 5000; ++i) {
    k = (bd.transpose() * p * ad) / (r + (bd.transpose() * p * bd)(0, 0));
    p = q + ad.transpose() * p * (ad - bd * k);
  }
  return k;
}

// Energy pumping far from upright, LQR near it. Returns the command in [-1, 1].
double swing_up_and_balance(const Eigen::Vector4d& s, const Eigen::RowVector4d& k) {
  const double theta = s[1];
  double force;
  if (std::abs(theta) < 0.35) {
    force = -(k * s)(0, 0);
  } else {
    // Pole energy relative to resting upright; drive it to 0 by moving the cart with the
    // pole's swing, and keep the cart near the middle.
    const double energy =
        0.5 * kPoleInertia * s[3] * s[3] + kPoleMass * kG * kPoleCentre * (std::cos(theta) - 1.0);
    const double pump = (s[3] * std::cos(theta) >= 0 ? 1.0 : -1.0) * energy;
    force = 150.0 * pump - 2.0 * s[0] - 2.0 * s[2];
  }
  return std::clamp(force / CartPoleTask::kMaxForceN, -1.0, 1.0);
}

double run_episode(Env& env, std::uint64_t seed, bool scripted) {
  const Eigen::RowVector4d k = lqr_gains(0.01);
  Value obs = env.reset(seed).obs;
  Rng rng(seed);
  double total = 0.0;
  for (;;) {
    Value action;
    if (scripted) {
      const Array& pos = obs.dict().at("joint_pos").array();
      const Array& vel = obs.dict().at("joint_vel").array();
      const Eigen::Vector4d s(pos.data<float>()[0], pos.data<float>()[1], vel.data<float>()[0],
                              vel.data<float>()[1]);
      action = Array::from_vector<float>({1}, {static_cast<float>(swing_up_and_balance(s, k))});
    } else {
      action = env.action_space().sample(rng);
    }
    const StepResult step = env.step(action);
    total += step.reward;
    obs = step.obs;
    if (step.terminated || step.truncated) return total;
  }
}

TEST(CartPoleTest, EnergyPumpingAndLqrSwingUpAndHold) {
  std::unique_ptr<Env> env = make("CartPoleSwingup-v0", {{"obs_mode", "state"}});
  const double scripted = run_episode(*env, 0, true);
  const double random = run_episode(*env, 0, false);
  std::cout << "CartPoleSwingup-v0 return over 1000 steps: scripted " << scripted << ", random "
            << random << "\n";
  EXPECT_GE(scripted, 700.0);
  EXPECT_LT(random, 200.0);
}

TEST(CartPoleTest, LqrHoldsTheBalanceTask) {
  std::unique_ptr<Env> env = make("CartPoleBalance-v0", {{"obs_mode", "state"}});
  const double scripted = run_episode(*env, 1, true);
  const double random = run_episode(*env, 1, false);
  std::cout << "CartPoleBalance-v0 return over 1000 steps: scripted " << scripted << ", random "
            << random << "\n";
  EXPECT_GE(scripted, 900.0);
  EXPECT_LT(random, scripted - 200.0);
}

TEST(CartPoleTest, EpisodeIsOneThousandControlStepsWhateverTheActionRepeat) {
  for (const int repeat : {1, 4}) {
    std::unique_ptr<Env> env =
        make("CartPoleBalance-v0", {{"obs_mode", "state"}, {"action_repeat", repeat}});
    env->reset(0);
    int steps = 0;
    StepResult step;
    do {
      step = env->step(Array::from_vector<float>({1}, {0.0F}));
      ++steps;
    } while (!step.truncated && !step.terminated);
    EXPECT_EQ(steps, 1000 / repeat);
    EXPECT_TRUE(step.truncated);
    EXPECT_LE(step.reward, static_cast<double>(repeat));
  }
}

TEST(CartPoleTest, SwingUpStartsHangingAndBalanceStartsUpright) {
  for (const char* id : {"CartPoleSwingup-v0", "CartPoleSwingupDiscrete-v0", "CartPoleBalance-v0",
                         "CartPoleBalanceDiscrete-v0"}) {
    const bool swing_up = std::string(id).find("Swingup") != std::string::npos;
    std::unique_ptr<Env> env = make(id, {{"obs_mode", "state"}});
    for (std::uint64_t seed = 0; seed < 20; ++seed) {
      const Value obs = env->reset(seed).obs;
      const double cart = testing::state(obs, "joint_pos", 0);
      const double angle = testing::state(obs, "joint_pos", 1);  // 0 upright, in [-pi, pi)
      EXPECT_LE(std::abs(cart), 0.25) << id << " seed " << seed;
      if (swing_up) {
        EXPECT_GE(std::abs(angle), 3.14159265 - 0.1) << id << " seed " << seed;
      } else {
        EXPECT_LE(std::abs(angle), 0.05) << id << " seed " << seed;
      }
    }
  }
}

TEST(CartPoleTest, RewardIsHighUprightAndLowHanging) {
  std::unique_ptr<Env> balance = make("CartPoleBalance-v0", {{"obs_mode", "state"}});
  balance->reset(2);
  EXPECT_GT(balance->step(Array::from_vector<float>({1}, {0.0F})).reward, 0.9);
  std::unique_ptr<Env> swing = make("CartPoleSwingup-v0", {{"obs_mode", "state"}});
  swing->reset(2);
  EXPECT_LT(swing->step(Array::from_vector<float>({1}, {0.0F})).reward, 0.05);
}

TEST(CartPoleTest, DiscreteActionsPushLeftNothingRight) {
  std::unique_ptr<Env> env = make("CartPoleBalanceDiscrete-v0", {{"obs_mode", "state"}});
  for (std::int64_t a = 0; a < 3; ++a) {
    Value obs = env->reset(3).obs;
    const float x0 = obs.dict().at("joint_pos").array().data<float>()[0];
    for (int t = 0; t < 20; ++t) obs = env->step(Array::scalar<std::int64_t>(a)).obs;
    const float dx = obs.dict().at("joint_pos").array().data<float>()[0] - x0;
    const float expected_sign = static_cast<float>(a - 1);
    if (a == 1) {
      EXPECT_NEAR(dx, 0.0F, 0.05F);
    } else {
      EXPECT_GT(dx * expected_sign, 0.05F) << "action " << a;
    }
  }
}

// Pixels of the cart and the pole (orange and yellow: red well above blue; the sky, floor and rail
// are blue or grey) in a 64 x 64 observation after reset(seed=0).
int cart_and_pole_pixels(const std::string& camera) {
  auto env = make("CartPoleBalance-v0",
                  {{"width", 64}, {"height", 64}, {"obs_mode", "pixels"}, {"camera", camera}});
  const Array frame = env->reset(0).obs.dict().at("pixels").array();
  const std::uint8_t* p = frame.data<std::uint8_t>();
  int count = 0;
  for (std::int64_t i = 0; i < frame.size(); i += 3) {
    if (p[i] > 120 && p[i] > p[i + 2] + 60) ++count;
  }
  return count;
}

// The close camera is for learning from small images: the cart and pole cover about 1.7^2 times
// the pixels they cover under the fixed camera.
TEST(CartPoleTest, CloseCameraShowsTheCartAndPoleLarger) {
  const int fixed = cart_and_pole_pixels("fixed");
  const int close = cart_and_pole_pixels("close");
  EXPECT_GT(fixed, 10);
  EXPECT_GE(close, 2 * fixed) << "fixed " << fixed << ", close " << close;
}

// The rows of a 64 x 64 observation above the cart (rows 0-33 under the fixed camera) in which
// the pole shows: a pixel that differs from its row's median (the sky is one colour along a
// row) by more than 12 levels summed over R, G and B.
struct PoleRows {
  int first = -1;
  int last = -1;
  int missing = 0;  // rows between first and last without the pole
};

// The median colour of row y of a 64-pixel-wide RGB frame: the sky's, above the cart.
std::array<int, 3> row_median(const std::uint8_t* p, int y) {
  std::array<std::vector<int>, 3> channels;
  for (int x = 0; x < 64; ++x) {
    for (int c = 0; c < 3; ++c) channels[c].push_back(p[(y * 64 + x) * 3 + c]);
  }
  std::array<int, 3> median{};
  for (int c = 0; c < 3; ++c) {
    std::nth_element(channels[c].begin(), channels[c].begin() + 32, channels[c].end());
    median[c] = channels[c][32];
  }
  return median;
}

PoleRows pole_rows(const Array& frame) {
  const std::uint8_t* p = frame.data<std::uint8_t>();
  PoleRows rows;
  int shown = 0;
  for (int y = 0; y < 34; ++y) {
    const std::array<int, 3> median = row_median(p, y);
    bool pole = false;
    for (int x = 0; x < 64 && !pole; ++x) {
      int difference = 0;
      for (int c = 0; c < 3; ++c) difference += std::abs(p[(y * 64 + x) * 3 + c] - median[c]);
      pole = difference > 12;
    }
    if (!pole) continue;
    if (rows.first < 0) rows.first = y;
    rows.last = y;
    ++shown;
  }
  if (rows.first >= 0) rows.missing = rows.last - rows.first + 1 - shown;
  return rows;
}

// At 64 x 64 the pole is thinner than a pixel. Without anti-aliasing it covers a pixel only
// where it crosses the pixel's centre: in some frames it breaks into pieces or loses its top,
// depending on where the cart stands. With msaa=4 it is one unbroken line from the cart to its
// tip in every frame.
TEST(CartPoleTest, AntiAliasedObservationsShowTheWholePole) {
  int aliased_frames_broken = 0;
  for (const int msaa : {0, 4}) {
    for (std::uint64_t seed = 0; seed < 4; ++seed) {
      auto env = make(
          "CartPoleBalance-v0",
          {{"width", 64}, {"height", 64}, {"obs_mode", "pixels"}, {"msaa", std::int64_t{msaa}}});
      env->reset(seed);
      Rng rng(seed);
      for (int step = 0; step < 8; ++step) {
        const Value& obs = env->step(env->action_space().sample(rng)).obs;
        const PoleRows rows = pole_rows(obs.dict().at("pixels").array());
        if (msaa == 0) {
          aliased_frames_broken += rows.missing > 0 || rows.first > 19 ? 1 : 0;
          continue;
        }
        EXPECT_LE(rows.first, 19) << "seed " << seed << ", step " << step << ": top row";
        EXPECT_GE(rows.last, 32) << "seed " << seed << ", step " << step << ": bottom row";
        EXPECT_EQ(rows.missing, 0)
            << "seed " << seed << ", step " << step << ": rows " << rows.first << "-" << rows.last;
      }
    }
  }
  EXPECT_GT(aliased_frames_broken, 0) << "the aliased pole was never broken: a weaker test";
}

// -v1 draws the cart-pole of -v0 (same physics: the same states, rewards and flags for the same
// seed and actions) with a thicker, darker pole.
TEST(CartPoleTest, V1IsV0sPhysics) {
  for (const char* name : {"CartPoleBalance", "CartPoleSwingup", "CartPoleBalanceDiscrete",
                           "CartPoleSwingupDiscrete"}) {
    auto v0 = make(std::string(name) + "-v0", {{"obs_mode", "state"}});
    auto v1 = make(std::string(name) + "-v1", {{"obs_mode", "state"}});
    EXPECT_TRUE(v0->reset(3).obs.equals(v1->reset(3).obs)) << name;
    Rng rng(3);
    for (int step = 0; step < 300; ++step) {
      const Value action = v0->action_space().sample(rng);
      const StepResult a = v0->step(action);
      const StepResult b = v1->step(action);
      ASSERT_TRUE(a.obs.equals(b.obs)) << name << ", step " << step;
      ASSERT_EQ(a.reward, b.reward) << name << ", step " << step;
      ASSERT_EQ(a.terminated, b.terminated);
      ASSERT_EQ(a.truncated, b.truncated);
    }
  }
}

// How the pole shows in a 64 x 64 anti-aliased frame after reset(seed) (rows 0-33, above the
// cart): its pixels (those that differ from their row's median, the sky, by more than 12 levels
// summed over R, G and B), and their summed difference from the median in grey level
// (0.299 R + 0.587 G + 0.114 B), which grows with the pole's width and its contrast to the sky.
struct PoleLook {
  int pixels = 0;
  double grey_contrast = 0.0;
};

PoleLook pole_look(const std::string& id, std::uint64_t seed) {
  auto env = make(id, {{"width", 64}, {"height", 64}, {"obs_mode", "pixels"}, {"msaa", 4}});
  const Array frame = env->reset(seed).obs.dict().at("pixels").array();
  const std::uint8_t* p = frame.data<std::uint8_t>();
  const auto grey = [](const auto& rgb) {
    return 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2];
  };
  PoleLook look;
  for (int y = 0; y < 34; ++y) {
    const std::array<int, 3> median = row_median(p, y);
    for (int x = 0; x < 64; ++x) {
      const std::uint8_t* pixel = p + (y * 64 + x) * 3;
      int difference = 0;
      for (int c = 0; c < 3; ++c) difference += std::abs(pixel[c] - median[c]);
      if (difference <= 12) continue;
      ++look.pixels;
      look.grey_contrast += std::abs(grey(pixel) - grey(median));
    }
  }
  return look;
}

// v0's pale yellow pole is a little brighter than the sky (and under a pixel wide); v1's dark red
// one is twice as wide and far darker, so that it stands out in grey frames as well.
TEST(CartPoleTest, V1DrawsAThickerPoleThatStandsOutInGrey) {
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    const PoleLook v0 = pole_look("CartPoleBalance-v0", seed);
    const PoleLook v1 = pole_look("CartPoleBalance-v1", seed);
    const std::string figures = "seed " + std::to_string(seed) + ": pixels v0 " +
                                std::to_string(v0.pixels) + ", v1 " + std::to_string(v1.pixels) +
                                "; grey contrast v0 " + std::to_string(v0.grey_contrast) + ", v1 " +
                                std::to_string(v1.grey_contrast);
    EXPECT_GT(v0.pixels, 10) << figures;
    EXPECT_GE(v1.pixels, v0.pixels) << figures;
    EXPECT_GT(v1.grey_contrast, 2.8 * v0.grey_contrast) << figures;
  }
}

}  // namespace
}  // namespace pixelgym
