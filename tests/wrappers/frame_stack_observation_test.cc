#include "pixelgym/wrappers/frame_stack_observation.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/checker.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/time_limit.h"
#include "tests/wrappers/image_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::expect_invalid;
using testing::image_box;
using testing::ImageEnv;
using testing::pixels_and_state;

SpacePtr gray_box(std::int64_t height, std::int64_t width) {
  return std::make_shared<spaces::Box>(0.0, 255.0, Shape{height, width}, DType::kUInt8);
}

// A FrameStackObservation over an ImageEnv, with the ImageEnv reachable to script its frames.
struct Stack {
  ImageEnv* inner = nullptr;
  std::unique_ptr<FrameStackObservation> env;
};

Stack make_stack(SpacePtr space, std::int64_t k,
                 FrameStackPadding padding = FrameStackPadding::kReset,
                 FrameStackLayout layout = FrameStackLayout::kNewAxis, int episode_length = 10) {
  auto inner = std::make_unique<ImageEnv>(std::move(space), episode_length);
  Stack stack;
  stack.inner = inner.get();
  stack.env =
      std::make_unique<FrameStackObservation>(std::move(inner), k, padding, "pixels", layout);
  return stack;
}

// An observation of `space` whose uint8 arrays hold `v` everywhere and float arrays v / 1000.
Value filled(const Space& space, std::uint8_t v) {
  Value value = space.zeros();
  std::vector<Array> leaves = value.leaves();
  for (Array& array : leaves) {
    for (std::int64_t i = 0; i < array.size(); ++i) {
      if (array.dtype() == DType::kUInt8) {
        array.data<std::uint8_t>()[i] = v;
      } else {
        array.data<float>()[i] = static_cast<float>(v) / 1000.0F;
      }
    }
  }
  return value;
}

const Array& pixels(const Value& obs) {
  return obs.is_dict() ? obs.dict().at("pixels").array() : obs.array();
}

// The value of every element of frame j of a kNewAxis stack (they must all be equal).
int frame_value(const Array& stacked, std::int64_t j) {
  const Array frame = stacked.index(j);
  const auto* data = frame.data<std::uint8_t>();
  for (std::int64_t i = 1; i < frame.size(); ++i) {
    if (data[i] != data[0]) return -1;
  }
  return data[0];
}

std::vector<int> frame_values(const Value& obs) {
  const Array& stacked = pixels(obs);
  std::vector<int> values;
  for (std::int64_t j = 0; j < stacked.shape()[0]; ++j) values.push_back(frame_value(stacked, j));
  return values;
}

std::string failures(const CheckReport& report) {
  std::string text;
  for (const CheckResult& failure : report.failures()) {
    text += failure.name + ": " + failure.reason + "\n";
  }
  return text;
}

TEST(FrameStackObservationTest, OutputSpacePerLayout) {
  struct Case {
    SpacePtr image;
    FrameStackLayout layout;
    Shape expected;
  };
  const std::vector<Case> cases = {
      {image_box(84, 80, 3), FrameStackLayout::kNewAxis, {4, 84, 80, 3}},
      {image_box(84, 80, 3), FrameStackLayout::kChannelsLast, {84, 80, 12}},
      {image_box(3, 84, 80), FrameStackLayout::kChannelsFirst, {12, 84, 80}},
      {image_box(3, 84, 80), FrameStackLayout::kNewAxis, {4, 3, 84, 80}},
      {image_box(84, 80, 1), FrameStackLayout::kChannelsLast, {84, 80, 4}},
      {gray_box(84, 80), FrameStackLayout::kNewAxis, {4, 84, 80}},
      {gray_box(84, 80), FrameStackLayout::kChannelsLast, {84, 80, 4}},
  };
  for (const Case& c : cases) {
    FrameStackObservation env(std::make_unique<ImageEnv>(c.image), 4, FrameStackPadding::kReset,
                              "pixels", c.layout);
    const spaces::Box expected(0.0, 255.0, c.expected, DType::kUInt8);
    EXPECT_TRUE(env.observation_space().equals(expected))
        << to_string(c.layout) << ": " << env.observation_space().to_string();
    EXPECT_TRUE(env.observation_space().contains(env.reset(0).obs));
  }
}

TEST(FrameStackObservationTest, DictOutputSpaceReplacesOnlyTheImage) {
  const SpacePtr inner = pixels_and_state(48, 64, 3);
  FrameStackObservation env(std::make_unique<ImageEnv>(inner), 3);
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  const auto& inner_dict = dynamic_cast<const spaces::Dict&>(*inner);
  ASSERT_EQ(dict.entries().size(), 4U);
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {3, 48, 64, 3}, DType::kUInt8)));
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(dict.at(key).equals(inner_dict.at(key))) << key;
  }
  EXPECT_EQ(dict.index("pixels"), inner_dict.index("pixels"));
  EXPECT_EQ(env.name(), "FrameStackObservation<ImageEnv>");
}

TEST(FrameStackObservationTest, OrderIsOldestFirst) {
  Stack s = make_stack(image_box(6, 5, 3), 4);
  const Space& space = s.inner->observation_space();
  s.inner->next = filled(space, 10);
  EXPECT_EQ(frame_values(s.env->reset(0).obs), (std::vector<int>{10, 10, 10, 10}));
  std::vector<Value> held;
  for (std::uint8_t v = 11; v <= 16; ++v) {
    s.inner->next = filled(space, v);
    held.push_back(s.env->step(s.env->action_space().zeros()).obs);
  }
  EXPECT_EQ(frame_values(held[0]), (std::vector<int>{10, 10, 10, 11}));
  EXPECT_EQ(frame_values(held[2]), (std::vector<int>{10, 11, 12, 13}));
  EXPECT_EQ(frame_values(held[5]), (std::vector<int>{13, 14, 15, 16}));
}

TEST(FrameStackObservationTest, PaddingAfterResetAndAfterASecondResetMidStream) {
  for (const FrameStackPadding padding : {FrameStackPadding::kReset, FrameStackPadding::kZero}) {
    SCOPED_TRACE(to_string(padding));
    const bool zero = padding == FrameStackPadding::kZero;
    Stack s = make_stack(image_box(4, 4, 3), 3, padding);
    const Space& space = s.inner->observation_space();
    const Value action = s.env->action_space().zeros();
    s.inner->next = filled(space, 50);
    const int p1 = zero ? 0 : 50;
    EXPECT_EQ(frame_values(s.env->reset(0).obs), (std::vector<int>{p1, p1, 50}));
    s.inner->next = filled(space, 51);
    const Value first = s.env->step(action).obs;
    EXPECT_EQ(frame_values(first), (std::vector<int>{p1, 50, 51}));
    s.inner->next = filled(space, 52);
    s.env->step(action);
    s.inner->next = filled(space, 53);
    EXPECT_EQ(frame_values(s.env->step(action).obs), (std::vector<int>{51, 52, 53}));
    // A second reset mid-episode pads again with its own frame; nothing of the last one leaks.
    s.inner->next = filled(space, 90);
    const int p2 = zero ? 0 : 90;
    EXPECT_EQ(frame_values(s.env->reset().obs), (std::vector<int>{p2, p2, 90}));
    s.inner->next = filled(space, 91);
    EXPECT_EQ(frame_values(s.env->step(action).obs), (std::vector<int>{p2, 90, 91}));
    EXPECT_EQ(frame_values(first), (std::vector<int>{p1, 50, 51}));  // unchanged
  }
}

TEST(FrameStackObservationTest, OtherKeysPassThroughTheLatestStep) {
  Stack s = make_stack(pixels_and_state(8, 6, 3), 4);
  const Value reset = s.env->reset(0).obs;
  for (int t = 0; t < 5; ++t) {
    const Value latest = filled(s.inner->observation_space(), static_cast<std::uint8_t>(100 + t));
    s.inner->next = latest;
    const Value obs = s.env->step(s.env->action_space().zeros()).obs;
    for (const char* key : {"state", "depth", "velocity"}) {
      EXPECT_TRUE(obs.dict().at(key).equals(latest.dict().at(key))) << key;
    }
    EXPECT_EQ(frame_value(pixels(obs), 3), 100 + t);
    EXPECT_EQ(obs.dict().keys(), reset.dict().keys());
  }
}

TEST(FrameStackObservationTest, LayoutsHoldTheSameFrames) {
  // A patterned (A, B, C) frame per step: element (y, x, c) = v + 3 y + 5 x + c.
  const auto frame = [](const Space& space, std::uint8_t v) {
    Value value = space.zeros();
    Array& image = value.array();
    const Shape& shape = image.shape();
    auto* data = image.data<std::uint8_t>();
    for (std::int64_t y = 0; y < shape[0]; ++y) {
      for (std::int64_t x = 0; x < shape[1]; ++x) {
        for (std::int64_t c = 0; c < shape[2]; ++c) {
          data[(y * shape[1] + x) * shape[2] + c] =
              static_cast<std::uint8_t>(v + 3 * y + 5 * x + c);
        }
      }
    }
    return value;
  };
  // (4, 5, 7): a rank-3 image channels_first accepts (a channels-last one is refused).
  Stack axis = make_stack(image_box(4, 5, 7), 3, FrameStackPadding::kZero);
  Stack first =
      make_stack(image_box(4, 5, 7), 3, FrameStackPadding::kZero, FrameStackLayout::kChannelsFirst);
  Stack last =
      make_stack(image_box(4, 5, 7), 3, FrameStackPadding::kZero, FrameStackLayout::kChannelsLast);
  Value a;
  Value f;
  Value l;
  for (std::uint8_t v = 0; v < 5; ++v) {
    for (Stack* s : {&axis, &first, &last})
      s->inner->next = frame(s->inner->observation_space(), v);
    if (v == 0) {
      a = axis.env->reset(0).obs;
      f = first.env->reset(0).obs;
      l = last.env->reset(0).obs;
    } else {
      a = axis.env->step(axis.env->action_space().zeros()).obs;
      f = first.env->step(first.env->action_space().zeros()).obs;
      l = last.env->step(last.env->action_space().zeros()).obs;
    }
    // channels_first is the same bytes as new_axis.
    EXPECT_TRUE(f.array().equals(a.array().reshape({12, 5, 7})));
    // channels_last: out[y][x][j C + c] = frame_j[y][x][c].
    const auto* stacked = a.array().data<std::uint8_t>();
    const auto* interleaved = l.array().data<std::uint8_t>();
    bool same = true;
    for (std::int64_t j = 0; j < 3; ++j) {
      for (std::int64_t p = 0; p < 20; ++p) {
        for (std::int64_t c = 0; c < 7; ++c) {
          same = same && interleaved[p * 21 + j * 7 + c] == stacked[(j * 20 + p) * 7 + c];
        }
      }
    }
    EXPECT_TRUE(same) << "step " << static_cast<int>(v);
  }
}

TEST(FrameStackObservationTest, Errors) {
  const auto make = [](SpacePtr space, std::int64_t k, const std::string& key,
                       FrameStackLayout layout) {
    return [space, k, key, layout] {
      FrameStackObservation env(std::make_unique<ImageEnv>(space), k, FrameStackPadding::kReset,
                                key, layout);
    };
  };
  const FrameStackLayout axis = FrameStackLayout::kNewAxis;
  expect_invalid(make(image_box(8, 8, 3), 0, "pixels", axis),
                 {"FrameStackObservation", "stack_size must be between 1 and 256", "got 0"});
  expect_invalid(make(image_box(8, 8, 3), -2, "pixels", axis), {"got -2"});
  expect_invalid(make(image_box(8, 8, 3), 257, "pixels", axis), {"between 1 and 256, got 257"});
  expect_invalid(make(pixels_and_state(8, 8, 3), 4, "camera", axis),
                 {"FrameStackObservation", "key \"camera\" is not in the observation space",
                  "image keys: \"pixels\", \"depth\""});
  expect_invalid(make(pixels_and_state(8, 8, 3), 4, "state", axis),
                 {"FrameStackObservation",
                  "key \"state\" must be a uint8 (H, W), (H, W, C) or "
                  "(C, H, W) Box, got",
                  "image keys: \"pixels\", \"depth\""});
  expect_invalid(make(std::make_shared<spaces::Box>(0.0, 1.0, Shape{8, 8, 3}), 4, "pixels", axis),
                 {"FrameStackObservation", "float32", "image keys: none"});
  expect_invalid(make(image_box(8, 8, 3), 4, "depth", axis),
                 {"FrameStackObservation", "key \"depth\" given", "bare Box"});
  expect_invalid(make(image_box(84, 80, 3), 4, "pixels", FrameStackLayout::kChannelsFirst),
                 {"FrameStackObservation", "channels_first", "uint8 (84, 80, 3)",
                  "apply ChannelFirstObservation", "giving (12, 84, 80)",
                  "channels_last (giving (84, 80, 12))"});
  expect_invalid(make(gray_box(8, 8), 4, "pixels", FrameStackLayout::kChannelsFirst),
                 {"FrameStackObservation", "channels_first", "rank 3", "uint8 (8, 8)",
                  "use layout new_axis (giving (4, 8, 8))"});
  expect_invalid(
      [] {
        FrameStackObservation env(std::make_unique<ImageEnv>(image_box(8, 8, 3)), 4,
                                  static_cast<FrameStackPadding>(7));
      },
      {"FrameStackObservation", "padding must be reset or zero, got 7"});
}

TEST(FrameStackObservationTest, ReturnedObservationsNeverChange) {
  for (const FrameStackLayout layout :
       {FrameStackLayout::kNewAxis, FrameStackLayout::kChannelsFirst,
        FrameStackLayout::kChannelsLast}) {
    SCOPED_TRACE(to_string(layout));
    // Episodes of 10 steps: resets mid-stream, and several tapes of 64 slots filled.
    Stack s = make_stack(pixels_and_state(6, 4, 5), 4, FrameStackPadding::kReset, layout);
    std::vector<Value> held;
    std::vector<Value> copies;
    const auto keep = [&](const Value& obs) {
      held.push_back(obs);
      copies.push_back(obs.clone());
    };
    keep(s.env->reset(7).obs);
    Rng rng(7);
    for (int t = 0; t < 300; ++t) {
      const StepResult step = s.env->step(s.env->action_space().sample(rng));
      if (t % 6 == 0) keep(step.obs);
      if (step.terminated || step.truncated) {
        const Value reset = s.env->reset().obs;
        if (t % 4 == 0) keep(reset);
      }
    }
    ASSERT_GE(held.size(), 50U);
    for (std::size_t i = 0; i < held.size(); ++i) {
      EXPECT_TRUE(held[i].equals(copies[i])) << "observation " << i << " changed";
    }
    if (layout != FrameStackLayout::kChannelsLast) {
      EXPECT_GT(s.env->tapes_allocated(), 2);  // held views kept tapes from being rewound
    } else {
      EXPECT_EQ(s.env->tapes_allocated(), 1);  // copies: nobody else holds the tape
    }
  }
}

TEST(FrameStackObservationTest, ConsecutiveObservationsShareFrames) {
  Stack s = make_stack(image_box(6, 4, 3), 4);
  const Value a = s.env->reset(0).obs;
  const Value b = s.env->step(s.env->action_space().zeros()).obs;
  const Value c = s.env->step(s.env->action_space().zeros()).obs;
  EXPECT_TRUE(a.shares_memory(b));
  const std::size_t frame = 6 * 4 * 3;
  EXPECT_EQ(static_cast<const std::byte*>(c.array().raw_data()) -
                static_cast<const std::byte*>(b.array().raw_data()),
            static_cast<std::ptrdiff_t>(frame));
}

TEST(FrameStackObservationTest, StepIntoACallerBufferGivesWhatStepGives) {
  for (const FrameStackLayout layout :
       {FrameStackLayout::kNewAxis, FrameStackLayout::kChannelsFirst,
        FrameStackLayout::kChannelsLast}) {
    SCOPED_TRACE(to_string(layout));
    for (const FrameStackPadding padding : {FrameStackPadding::kReset, FrameStackPadding::kZero}) {
      Stack returned = make_stack(pixels_and_state(6, 4, 5), 3, padding, layout);
      Stack into = make_stack(pixels_and_state(6, 4, 5), 3, padding, layout);
      ResetResult reset;
      reset.obs = into.env->observation_space().zeros();
      StepResult step;
      step.obs = into.env->observation_space().zeros();
      const void* memory = pixels(step.obs).raw_data();
      into.env->reset_into(reset, 5);
      EXPECT_TRUE(reset.obs.equals(returned.env->reset(5).obs));
      for (int t = 0; t < 200; ++t) {
        const Value action = into.env->action_space().zeros();
        const StepResult expected = returned.env->step(action);
        into.env->step_into(action, step);
        ASSERT_TRUE(step.obs.equals(expected.obs)) << "step " << t;
        EXPECT_EQ(pixels(step.obs).raw_data(), memory);
        if (step.terminated) {
          into.env->reset_into(reset);
          ASSERT_TRUE(reset.obs.equals(returned.env->reset().obs));
        }
      }
      // A caller that keeps nothing of the tape gets it rewound: one tape in all.
      EXPECT_EQ(into.env->tapes_allocated(), 1);
    }
  }
}

TEST(FrameStackObservationTest, Deterministic) {
  const auto run = [] {
    Stack s = make_stack(pixels_and_state(6, 4, 3), 4, FrameStackPadding::kZero);
    std::vector<Value> trajectory{s.env->reset(11).obs};
    Rng rng(3);
    for (int t = 0; t < 100; ++t) {
      const StepResult step = s.env->step(s.env->action_space().sample(rng));
      trajectory.push_back(step.obs);
      if (step.terminated) trajectory.push_back(s.env->reset().obs);
    }
    return trajectory;
  };
  const std::vector<Value> a = run();
  const std::vector<Value> b = run();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].equals(b[i])) << i;
}

TEST(FrameStackObservationTest, RefusesAnObservationItReturnedAsABuffer) {
  Stack s = make_stack(pixels_and_state(6, 4, 3), 4);
  const Value action = s.env->action_space().zeros();
  ResetResult reset = s.env->reset(0);
  StepResult step = s.env->step(action);
  const Value before = step.obs.clone();
  expect_invalid([&] { s.env->step_into(action, step); },
                 {"FrameStackObservation<ImageEnv>: step_into() buffer", "key \"pixels\"",
                  "views stacked frames that other observations share",
                  "would change those observations", "observation_space().zeros()"});
  EXPECT_TRUE(step.obs.equals(before));
  // As for any error in step_into, the episode must be reset; the refusal came before the
  // inner env moved.
  EXPECT_THROW(s.env->step(action), ResetNeeded);
  expect_invalid([&] { s.env->reset_into(reset); }, {"reset_into() buffer"});
  EXPECT_NO_THROW(s.env->reset());
  EXPECT_NO_THROW(s.env->step(action));
  // Another frame stack's observation is refused too.
  Stack other = make_stack(pixels_and_state(6, 4, 3), 4);
  StepResult foreign;
  foreign.obs = other.env->reset(0).obs;
  expect_invalid([&] { s.env->step_into(action, foreign); }, {"views stacked frames"});
}

TEST(FrameStackObservationTest, TheBufferHookWritesOnlyTheNewFrame) {
  Stack s = make_stack(image_box(6, 4, 3), 4);
  const Value action = s.env->action_space().zeros();
  s.env->reset(0);
  StepResult step;
  step.obs = s.env->observation_buffer(BufferFor::kStep);
  const void* window = step.obs.array().raw_data();
  s.env->step_into(action, step);
  EXPECT_EQ(step.obs.array().raw_data(), window);  // filled in place, no copy
  Stack twin = make_stack(image_box(6, 4, 3), 4);
  twin.env->reset(0);
  EXPECT_TRUE(step.obs.equals(twin.env->step(action).obs));
  // A hook asked for a reset, then a step instead: the stack is still right.
  const Value unused = s.env->observation_buffer(BufferFor::kReset);
  EXPECT_TRUE(s.env->step(action).obs.equals(twin.env->step(action).obs));
  // Used twice, the hook's window is no longer where the next observation goes.
  expect_invalid([&] { s.env->step_into(action, step); }, {"views stacked frames"});
}

TEST(FrameStackObservationTest, HookCallsAtEveryTapePositionKeepTheStack) {
  // Ask for buffers the caller then does not use, at every position of two tapes.
  Stack s =
      make_stack(image_box(3, 2, 1), 2, FrameStackPadding::kZero, FrameStackLayout::kNewAxis, 1000);
  Stack twin =
      make_stack(image_box(3, 2, 1), 2, FrameStackPadding::kZero, FrameStackLayout::kNewAxis, 1000);
  const Value action = s.env->action_space().zeros();
  ASSERT_TRUE(s.env->reset(1).obs.equals(twin.env->reset(1).obs));
  std::vector<Value> unused;
  for (int t = 0; t < 80; ++t) {
    unused.push_back(s.env->observation_buffer(t % 3 == 0 ? BufferFor::kReset : BufferFor::kStep));
    ASSERT_TRUE(s.env->step(action).obs.equals(twin.env->step(action).obs)) << t;
  }
}

// An ObservationWrapper that copies its input: above a frame stack it must not hand out tape
// views (it writes into its buffer), and the stack copies into its own buffer.
class Identity final : public ObservationWrapper {
 public:
  using ObservationWrapper::ObservationWrapper;

 protected:
  void observation(const Value& in, Value& out) override { copy_value(in, out); }
};

TEST(FrameStackObservationTest, WrappersAboveKeepOrStopTheSharing) {
  auto stack = std::make_unique<FrameStackObservation>(
      std::make_unique<ImageEnv>(image_box(6, 4, 3), 100), 4);
  TimeLimit limited(std::move(stack), 50);
  const Value a = limited.reset(0).obs;
  const Value b = limited.step(limited.action_space().zeros()).obs;
  EXPECT_TRUE(a.shares_memory(b));  // TimeLimit forwards the buffer hook

  Identity identity(std::make_unique<FrameStackObservation>(
      std::make_unique<ImageEnv>(image_box(6, 4, 3), 100), 4));
  Value c = identity.reset(0).obs;
  for (int t = 0; t < 90; ++t) {
    const Value d = identity.step(identity.action_space().zeros()).obs;
    EXPECT_FALSE(c.shares_memory(d));
    c = d;
  }
  // The stack copied into the Identity's own buffer: nobody held its tape, rewound in place.
  EXPECT_EQ(dynamic_cast<FrameStackObservation&>(identity.env()).tapes_allocated(), 1);
}

TEST(FrameStackObservationTest, CheckEnvPassesOnCartPoleSwingup) {
  for (const FrameStackLayout layout :
       {FrameStackLayout::kNewAxis, FrameStackLayout::kChannelsLast}) {
    for (const char* mode : {"pixels", "pixels+state"}) {
      FrameStackObservation env(make("CartPoleSwingup-v0", {{"obs_mode", mode}}), 3,
                                FrameStackPadding::kZero, "pixels", layout);
      const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
      EXPECT_EQ(dict.at("pixels").shape().value(),
                layout == FrameStackLayout::kNewAxis ? (Shape{3, 84, 84, 3}) : (Shape{84, 84, 9}));
      const CheckReport report = check_env(env, CheckOptions{0, 30});
      EXPECT_TRUE(report.passed()) << env.name() << " " << mode << "\n" << failures(report);
    }
  }
  // With the registry's TimeLimit above the stack too.
  TimeLimit limited(std::make_unique<FrameStackObservation>(
                        make("CartPoleSwingup-v0", {{"obs_mode", "pixels"}}), 4),
                    20);
  const CheckReport report = check_env(limited, CheckOptions{1, 30});
  EXPECT_TRUE(report.passed()) << limited.name() << "\n" << failures(report);
}

}  // namespace
}  // namespace pixelgym::wrappers
