// The shared off-policy settings (examples/trainer/torch_common/off_policy_settings.h) over every
// off-policy algorithm's config, DrQ's and DrQ-v2's: each member, changed alone, survives the JSON
// round trip (none is written but not read), and every recipe shipped in the algorithm's
// configs/ folder (the docs' `--config NAME`) parses and validates.
#include <gtest/gtest.h>

#include <filesystem>

#include "examples/trainer/drq/drq.h"
#include "examples/trainer/drqv2/drqv2.h"
#include "tests/examples/trainer/torch_common/learner_test_support.h"

namespace pixelgym::trainer {
namespace {

struct DrqRecipes {
  using Config = drq::DrqConfig;
  static constexpr const char* kFolder = "examples/trainer/drq/configs";
};
struct DrqV2Recipes {
  using Config = drqv2::DrqV2Config;
  static constexpr const char* kFolder = "examples/trainer/drqv2/configs";
};

template <typename Algorithm>
class OffPolicyConfigTest : public ::testing::Test {};
using OffPolicyAlgorithms = ::testing::Types<DrqRecipes, DrqV2Recipes>;
TYPED_TEST_SUITE(OffPolicyConfigTest, OffPolicyAlgorithms);

TYPED_TEST(OffPolicyConfigTest, EveryMemberSurvivesTheJsonRoundTrip) {
  testing::expect_every_member_round_trips<typename TypeParam::Config>();
}

TYPED_TEST(OffPolicyConfigTest, EveryShippedRecipeParses) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_SOURCE_DIR) / TypeParam::kFolder;
  EXPECT_GE(testing::expect_every_config_parses<typename TypeParam::Config>(folder), 2) << folder;
}

}  // namespace
}  // namespace pixelgym::trainer
