// The text form of wrapper stacks (`--wrap resize=64x64`): parsing, applying, and its errors.
#include "pixelgym/wrappers/wrapper_spec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/time_limit.h"
#include "pixelgym/wrappers/resize_observation.h"
#include "tests/wrappers/image_env.h"

namespace pixelgym::wrappers {
namespace {

using Arguments = std::vector<std::pair<std::string, std::string>>;

std::unique_ptr<Env> image_env() {
  auto pixels = std::make_shared<spaces::Box>(0.0, 255.0, Shape{48, 40, 3}, DType::kUInt8);
  auto state = std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2}, DType::kFloat32);
  return std::make_unique<testing::ImageEnv>(
      std::make_shared<spaces::Dict>(spaces::Dict::Entries{{"pixels", pixels}, {"state", state}}));
}

Shape pixels_shape(const Env& env) {
  return dynamic_cast<const spaces::Dict&>(env.observation_space()).at("pixels").shape().value();
}

// The message of the std::invalid_argument that `body` throws ("" when it throws none).
template <typename Body>
std::string error_of(Body body) {
  try {
    body();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(WrapperSpecTest, ParsesNameAlone) {
  const WrapperSpec spec = parse_wrapper_spec("grayscale");
  EXPECT_EQ(spec.name, "grayscale");
  EXPECT_TRUE(spec.arguments.empty());
}

TEST(WrapperSpecTest, BareValuesFillParametersInOrder) {
  EXPECT_EQ(parse_wrapper_spec("resize=64x32,state").arguments,
            (Arguments{{"size", "64x32"}, {"key", "state"}}));
}

TEST(WrapperSpecTest, NamedAndBareValuesMix) {
  EXPECT_EQ(parse_wrapper_spec("resize=key=img,size=8").arguments,
            (Arguments{{"key", "img"}, {"size", "8"}}));
  EXPECT_EQ(parse_wrapper_spec("grayscale=keep_dim,key=img").arguments,
            (Arguments{{"keep_dim", "true"}, {"key", "img"}}));
  EXPECT_EQ(parse_wrapper_spec("grayscale=false,img").arguments,
            (Arguments{{"keep_dim", "false"}, {"key", "img"}}));
}

TEST(WrapperSpecTest, AppliesInOrderFirstInnermost) {
  const auto env = apply_wrappers(image_env(), {"resize=24x20", "grayscale=keep_dim"});
  EXPECT_EQ(env->name(), "GrayscaleObservation<ResizeObservation<ImageEnv>>");
  EXPECT_EQ(pixels_shape(*env), (Shape{24, 20, 1}));
}

TEST(WrapperSpecTest, SquareSizeFromOneNumber) {
  const auto env = apply_wrappers(image_env(), {"resize=16"});
  EXPECT_EQ(pixels_shape(*env), (Shape{16, 16, 3}));
}

TEST(WrapperSpecTest, ChannelFirstAndTimeLimit) {
  auto env = apply_wrappers(image_env(), {"channel_first=pixels", "time_limit=3"});
  EXPECT_EQ(pixels_shape(*env), (Shape{3, 48, 40}));
  ASSERT_NE(dynamic_cast<TimeLimit*>(env.get()), nullptr);
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*env).max_episode_steps(), 3);
}

TEST(WrapperSpecTest, SpecValuesReachTheWrapperAndItSteps) {
  auto env = apply_wrappers(image_env(), {"resize=12x10", "time_limit=2"});
  env->reset(7);
  env->step(env->action_space().sample());
  const StepResult result = env->step(env->action_space().sample());
  EXPECT_TRUE(result.truncated);
  EXPECT_EQ(result.obs.dict().at("pixels").array().shape(), (Shape{12, 10, 3}));
}

TEST(WrapperSpecTest, EveryHelpUsageIsItselfAValidSpec) {
  // Placeholders filled in, longest first ("<max>" is a prefix of "<max_episode_steps>").
  const std::vector<std::pair<std::string, std::string>> values = {
      {"<max_episode_steps>", "5"}, {"<stack_size>", "2"},  {"<min>", "-1"},    {"<max>", "1"},
      {"<keys>", "pixels"},         {"<dtype>", "float32"}, {"<key>", "state"}, {"HxW", "8x8"}};
  for (const WrapperSpecHelp& help : wrapper_spec_help()) {
    std::string plain;
    for (char c : help.usage) {
      if (c != '[' && c != ']') plain += c;
    }
    for (const auto& [placeholder, value] : values) {
      for (std::size_t at = plain.find(placeholder); at != std::string::npos;
           at = plain.find(placeholder)) {
        plain.replace(at, placeholder.size(), value);
      }
    }
    // Each applies to the image env or (rendering wrappers) to a real one.
    std::string errors;
    bool applied = false;
    for (int candidate = 0; candidate < 2 && !applied; ++candidate) {
      try {
        apply_wrapper(
            candidate == 0 ? image_env() : make("CartPoleSwingup-v0", {{"obs_mode", "state"}}),
            parse_wrapper_spec(plain));
        applied = true;
      } catch (const std::invalid_argument& error) {
        errors += std::string(error.what()) + "\n";
      }
    }
    EXPECT_TRUE(applied) << help.usage << " as " << plain << ":\n" << errors;
    EXPECT_FALSE(help.summary.empty());
  }
}

TEST(WrapperSpecTest, EveryWrapperOfTheIssueHasAForm) {
  std::vector<std::string> names;
  for (const WrapperSpecHelp& help : wrapper_spec_help()) names.push_back(help.name);
  for (const char* name :
       {"resize", "grayscale", "channel_first", "frame_stack", "clip_action", "rescale_action",
        "normalize_observation", "normalize_reward", "record_episode_statistics",
        "add_render_observation", "filter_observation", "dtype_observation", "time_limit"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
}

TEST(WrapperSpecTest, FrameStackFromText) {
  const auto env = apply_wrappers(
      image_env(), {"resize=16x12", "grayscale", "frame_stack=3,padding=zero,layout=new_axis"});
  EXPECT_EQ(pixels_shape(*env), (Shape{3, 16, 12}));
  const auto channels_last = apply_wrappers(image_env(), {"frame_stack=2,layout=channels_last"});
  EXPECT_EQ(pixels_shape(*channels_last), (Shape{48, 40, 6}));
  const std::string message =
      error_of([] { apply_wrappers(image_env(), {"frame_stack=3,padding=repeat"}); });
  EXPECT_EQ(message,
            "wrapper spec \"frame_stack=3,padding=repeat\": frame_stack's padding: expected reset "
            "| zero, got \"repeat\"");
}

TEST(WrapperSpecTest, ActionRewardAndInfoWrappersFromText) {
  // The time limit inside the statistics, so that they see the episode end it makes.
  auto env = apply_wrappers(image_env(), {"time_limit=3", "rescale_action=0,10", "clip_action",
                                          "normalize_reward=0.9", "record_episode_statistics=5"});
  EXPECT_EQ(env->action_space().to_string(), "Box(-inf, inf, (1,), float32)");
  env->reset(1);
  StepResult result;
  for (int t = 0; t < 3; ++t) result = env->step(env->action_space().sample());
  EXPECT_TRUE(result.truncated);
  EXPECT_TRUE(result.info.contains("episode"));
}

TEST(WrapperSpecTest, ObservationDictWrappersFromText) {
  const auto filtered = apply_wrappers(image_env(), {"filter_observation=state+pixels"});
  const auto& dict = dynamic_cast<const spaces::Dict&>(filtered->observation_space());
  ASSERT_EQ(dict.entries().size(), 2u);
  EXPECT_EQ(dict.entries()[0].first, "state");
  const auto cast = apply_wrappers(image_env(), {"dtype_observation=float32,key=pixels"});
  EXPECT_EQ(dynamic_cast<const spaces::Dict&>(cast->observation_space()).at("pixels").dtype(),
            DType::kFloat32);
  const auto normalized = apply_wrappers(image_env(), {"normalize_observation=state,1e-6"});
  EXPECT_EQ(normalized->name(), "NormalizeObservation<ImageEnv>");
  EXPECT_NE(error_of([] { apply_wrappers(image_env(), {"dtype_observation=float16"}); })
                .find("dtype_observation's dtype: expected bool | uint8 | int32 | int64 | "
                      "float32 | float64, got \"float16\""),
            std::string::npos);
  EXPECT_NE(error_of([] {
              apply_wrappers(image_env(), {"filter_observation=state++pixels"});
            }).find("filter_observation's keys: expected observation keys joined by '+'"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              apply_wrappers(image_env(), {"rescale_action=0,nan"});
            }).find("rescale_action's max: expected a finite number, got \"nan\""),
            std::string::npos);
}

TEST(WrapperSpecTest, UnknownWrapperListsTheKnownOnes) {
  const std::string message = error_of([] { parse_wrapper_spec("resise=64"); });
  EXPECT_NE(message.find("\"resise=64\""), std::string::npos) << message;
  EXPECT_NE(message.find("unknown wrapper \"resise\""), std::string::npos) << message;
  EXPECT_NE(message.find("resize, grayscale"), std::string::npos) << message;
}

// A typo of a wrapper or of one of its parameters is answered with the name it is a typo of.
TEST(WrapperSpecTest, UnknownNamesSuggestTheClosest) {
  const std::string wrapper = error_of([] { parse_wrapper_spec("grayscal"); });
  EXPECT_NE(wrapper.find("unknown wrapper \"grayscal\"; did you mean grayscale? the wrappers are: "
                         "resize, grayscale"),
            std::string::npos)
      << wrapper;
  const std::string blur = error_of([] { parse_wrapper_spec("blur=3"); });
  EXPECT_EQ(blur.find("did you mean"), std::string::npos) << blur;
  const std::string parameter = error_of([] { parse_wrapper_spec("grayscale=keep_dims=true"); });
  EXPECT_NE(parameter.find("unknown parameter \"keep_dims\"; did you mean keep_dim? grayscale's "
                           "parameters are: keep_dim, key"),
            std::string::npos)
      << parameter;
}

// The docs write "grey" and "channels first": those words name the wrappers too.
TEST(WrapperSpecTest, TheDocsWordsAreAliasesOfTheWrappers) {
  for (const char* alias : {"greyscale", "grey", "gray"}) {
    EXPECT_EQ(parse_wrapper_spec(alias).name, "grayscale") << alias;
  }
  EXPECT_EQ(parse_wrapper_spec("greyscale=keep_dim").arguments, (Arguments{{"keep_dim", "true"}}));
  EXPECT_EQ(parse_wrapper_spec("channels_first").name, "channel_first");
  const std::unique_ptr<Env> grey = apply_wrappers(image_env(), {"greyscale=keep_dim"});
  EXPECT_EQ(pixels_shape(*grey), (Shape{48, 40, 1}));
  for (const WrapperSpecHelp& help : wrapper_spec_help()) {
    if (help.name == "grayscale") {
      EXPECT_EQ(help.aliases, (std::vector<std::string>{"greyscale", "grey", "gray"}));
    }
    for (const std::string& alias : help.aliases) {
      EXPECT_EQ(parse_wrapper_spec(alias).name, help.name) << alias;
    }
  }
}

// "resize=64,48" reads 48 as the key; the message names the size's form, not a missing key.
TEST(WrapperSpecTest, TwoNumbersForASizeNameTheSizesForm) {
  for (const char* text : {"resize=64,48", "resize=size=64,48"}) {
    const std::string message = error_of([&] { parse_wrapper_spec(text); });
    EXPECT_NE(message.find("resize's size: expected HEIGHTxWIDTH (e.g. 64x64) or N for NxN, as "
                           "resize=64x48 for 64 high and 48 wide; got \"64,48\""),
              std::string::npos)
        << message;
  }
  EXPECT_EQ(parse_wrapper_spec("resize=64,img").arguments,
            (Arguments{{"size", "64"}, {"key", "img"}}));
}

TEST(WrapperSpecTest, SyntaxErrorsNameWhatIsWrong) {
  EXPECT_NE(error_of([] { parse_wrapper_spec("=64"); }).find("got no name"), std::string::npos);
  EXPECT_NE(error_of([] { parse_wrapper_spec("resize=64x64,,key=a"); }).find("an empty one"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              parse_wrapper_spec("resize=64x64,colour=rgb");
            }).find("unknown parameter \"colour\"; resize's parameters are: size, key"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_wrapper_spec("resize=8,key=a,b"); }).find("too many values"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_wrapper_spec("resize=8,size=9"); }).find("\"size\" given twice"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse_wrapper_spec("channel_first=a,b"); }).find("too many values"),
            std::string::npos);
}

TEST(WrapperSpecTest, MissingRequiredArgumentShowsTheForm) {
  const std::string message = error_of([] { parse_wrapper_spec("resize"); });
  EXPECT_NE(message.find("resize needs its size (HEIGHTxWIDTH"), std::string::npos) << message;
  EXPECT_NE(message.find("resize=HxW[,key=pixels]"), std::string::npos) << message;
}

TEST(WrapperSpecTest, BadValuesNameWrapperArgumentAndExpectation) {
  const auto apply = [](const std::string& text) {
    return error_of([&] { apply_wrapper(image_env(), parse_wrapper_spec(text)); });
  };
  EXPECT_EQ(apply("resize=64y64"),
            "wrapper spec \"resize=64y64\": resize's size: expected HEIGHTxWIDTH (e.g. 64x64) or "
            "N for NxN, got \"64y64\"");
  EXPECT_NE(apply("resize=64x").find("got \"64x\""), std::string::npos);
  EXPECT_NE(apply("resize=x64").find("got \"x64\""), std::string::npos);
  EXPECT_NE(apply("grayscale=maybe")
                .find("grayscale's keep_dim: expected true or false, got "
                      "\"maybe\""),
            std::string::npos);
  EXPECT_NE(apply("time_limit=ten").find("time_limit's max_episode_steps: expected a whole number"),
            std::string::npos);
  EXPECT_NE(apply("resize=8,key=").find("resize's key: expected a non-empty word"),
            std::string::npos);
}

TEST(WrapperSpecTest, WrapperConstructorErrorsArePrefixedWithTheSpec) {
  const auto apply = [](const std::string& text) {
    return error_of([&] { apply_wrapper(image_env(), parse_wrapper_spec(text)); });
  };
  const std::string zero = apply("resize=0x64");
  EXPECT_EQ(zero.rfind("wrapper spec \"resize=0x64\": ResizeObservation", 0), 0u) << zero;
  const std::string key = apply("grayscale=key=state");
  EXPECT_NE(key.find("wrapper spec \"grayscale=key=state\""), std::string::npos) << key;
  EXPECT_NE(key.find("pixels"), std::string::npos) << key;  // lists the image keys
  EXPECT_NE(apply("time_limit=0").find("wrapper spec \"time_limit=0\""), std::string::npos);
}

TEST(WrapperSpecTest, ArgumentsNeedAnEqualsSignAfterTheName) {
  EXPECT_EQ(error_of([] { parse_wrapper_spec("grayscale,key=state"); }),
            "wrapper spec \"grayscale,key=state\": expected NAME=ARGS with '=' after the name "
            "(e.g. grayscale=key=state), got a ',' in the name \"grayscale,key\"");
}

TEST(WrapperSpecTest, DescribeWrappedGivesTheSpacesOfTheWrappedEnv) {
  EnvDescription description = describe("CartPoleSwingup-v0", {{"obs_mode", "pixels+state"}});
  const std::optional<std::int64_t> limit = description.max_episode_steps;
  ASSERT_TRUE(limit.has_value());
  const EnvDescription wrapped =
      describe_wrapped(description, {"resize=32x24", "grayscale", "time_limit=7"});
  const auto& dict = dynamic_cast<const spaces::Dict&>(*wrapped.observation_space);
  EXPECT_EQ(dict.at("pixels").shape().value(), (Shape{32, 24}));
  EXPECT_TRUE(
      dict.at("joint_pos")
          .equals(
              dynamic_cast<const spaces::Dict&>(*description.observation_space).at("joint_pos")));
  EXPECT_EQ(wrapped.max_episode_steps, 7);
  EXPECT_EQ(describe_wrapped(description, {"time_limit=100000"}).max_episode_steps, limit);

  // The same spaces as the wrappers over the env itself.
  const auto env = apply_wrappers(make("CartPoleSwingup-v0", {{"obs_mode", "pixels+state"}}),
                                  {"resize=32x24", "grayscale"});
  EXPECT_TRUE(env->observation_space().equals(*wrapped.observation_space));
  EXPECT_TRUE(env->action_space().equals(*wrapped.action_space));
}

TEST(WrapperSpecTest, DescribeWrappedReportsBadSpecs) {
  const EnvDescription description = describe("CartPoleSwingup-v0", {{"obs_mode", "state"}});
  const std::string message = error_of([&] { describe_wrapped(description, {"grayscale"}); });
  EXPECT_NE(message.find("wrapper spec \"grayscale\": GrayscaleObservation"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace pixelgym::wrappers
