// The shared torch layer (examples/trainer/torch_common/): the input layout an off-policy learner
// reads and the spaces it refuses (a Discrete action space, an image without its frame stack),
// DrQ's random shift on uint8 stacks (the same images as random_shift gives on float images,
// never a pixel from outside the padded window), the conv encoders' grids, checkpoint blobs and
// the parameter digest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/random_shift.h"
#include "examples/trainer/torch_common/torch_state.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/examples/trainer/torch_common/learner_test_support.h"

namespace pixelgym::trainer {
namespace {

using testing::pixel_space;

TEST(InputLayoutTest, ReadsStacksAndRefusesWhatItCannotLearnFrom) {
  const spaces::Box action(-2.0, 2.0, Shape{2});
  const InputLayout input = input_layout(pixel_space({3, 32, 32}), action, 3, "drqv2", "Env-v0");
  EXPECT_TRUE(input.has_image);
  EXPECT_EQ(input.image_key, "pixels");
  EXPECT_EQ(input.channels, 1);
  EXPECT_EQ(input.height, 32);
  EXPECT_EQ(input.vector_keys, (std::vector<std::string>{"joint_pos"}));
  EXPECT_EQ(input.action_size, 2);
  EXPECT_EQ(input_layout(pixel_space({3, 32, 32, 3}), action, 3, "drqv2", "Env-v0").channels, 3);

  const auto refused = [](auto call, std::vector<std::string> words) {
    try {
      call();
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& error) {
      for (const std::string& word : words) {
        EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
      }
    }
  };
  refused(
      [&] {
        input_layout(pixel_space({3, 32, 32}), spaces::Discrete(3), 3, "drqv2", "Pole-v0");
      },
      {"drqv2 on Pole-v0", "Discrete(3)"});
  refused(
      [&] {
        input_layout(pixel_space({32, 32, 3}), action, 3, "drqv2", "Pole-v0");
      },
      {"Pole-v0", "\"pixels\"", "frame_stack=3"});
  refused(
      [&] {
        input_layout(pixel_space({3, 32, 32}), spaces::Box(-INFINITY, INFINITY, Shape{1}), 3,
                     "drqv2", "P-v0");
      },
      {"bounded"});
}

// Whether `shifted` is `images` (B, frames, H, W, C as `shape` gives them) shifted by `shifts`
// as random_shift shifts their float (B, frames C, H, W) form.
bool equals_float_random_shift(std::vector<std::uint8_t> images, std::vector<std::uint8_t> shifted,
                               const std::vector<std::int64_t>& shifts,
                               const std::vector<std::int64_t>& shape, std::int64_t pad) {
  const std::int64_t batch = shape[0];
  const auto as_chw = [&](std::vector<std::uint8_t>& bytes) {
    return torch::from_blob(bytes.data(), shape, torch::kUInt8)
        .permute({0, 1, 4, 2, 3})
        .reshape({batch, shape[1] * shape[4], shape[2], shape[3]})
        .to(torch::kFloat32);
  };
  const torch::Tensor expected =
      random_shift(as_chw(images), torch::tensor(shifts, torch::kInt64).view({batch, 2}), pad);
  return torch::equal(as_chw(shifted), expected);
}

TEST(RandomShiftTest, ShiftFramesMatchesRandomShiftAndStaysInsideThePaddedWindow) {
  const std::int64_t batch = 6, frames = 2, h = 12, w = 10, c = 3, pad = 4;
  std::mt19937 rng(7);
  std::vector<std::uint8_t> images(static_cast<std::size_t>(batch * frames * h * w * c));
  for (auto& v : images) v = static_cast<std::uint8_t>(rng());
  std::vector<std::int64_t> shifts = {0, 0, 8, 8, 4, 4, 0, 8, 8, 0, 3, 5};
  std::vector<std::uint8_t> shifted(images.size());
  shift_frames(images.data(), shifted.data(), batch, frames, h, w, c, pad, shifts.data());
  EXPECT_TRUE(equals_float_random_shift(images, shifted, shifts, {batch, frames, h, w, c}, pad));
  // Offset (pad, pad) is the identity.
  const std::size_t stack_bytes = static_cast<std::size_t>(frames * h * w * c);
  EXPECT_TRUE(std::equal(images.begin() + 2 * stack_bytes, images.begin() + 3 * stack_bytes,
                         shifted.begin() + 2 * stack_bytes));
  // Every output pixel of a stack comes from within `pad` rows and columns of its own place.
  for (std::int64_t b = 0; b < batch; ++b) {
    for (std::int64_t y = 0; y < h; ++y) {
      for (std::int64_t x = 0; x < w; ++x) {
        const std::int64_t sy = std::clamp<std::int64_t>(y + shifts[2 * b] - pad, 0, h - 1);
        const std::int64_t sx = std::clamp<std::int64_t>(x + shifts[2 * b + 1] - pad, 0, w - 1);
        EXPECT_LE(std::abs(sy - y), pad);
        EXPECT_LE(std::abs(sx - x), pad);
        const std::size_t at = static_cast<std::size_t>((((b * frames) * h + y) * w + x) * c);
        const std::size_t from = static_cast<std::size_t>((((b * frames) * h + sy) * w + sx) * c);
        EXPECT_EQ(shifted[at], images[from]);
      }
    }
  }
}

// A pad wider and taller than the image (shift_pad 65 at 64x64 once wrote out of bounds: the
// copy's length went negative): shifts past an edge repeat the edge pixel, as replicate padding
// by that much and cropping does, and as random_shift computes it.
TEST(RandomShiftTest, APadLargerThanTheImageRepeatsTheEdges) {
  const std::int64_t batch = 7, frames = 2, h = 6, w = 5, c = 1, pad = 13;
  std::mt19937 rng(11);
  std::vector<std::uint8_t> images(static_cast<std::size_t>(batch * frames * h * w * c));
  for (auto& v : images) v = static_cast<std::uint8_t>(rng());
  // Offsets 0 and 2 pad shift the whole image past an edge; pad - w and pad + w just so.
  std::vector<std::int64_t> shifts = {0,       0,       2 * pad, 2 * pad, 0,       2 * pad, pad - w,
                                      pad + w, pad + w, pad - w, pad - 1, pad + 4, pad,     pad};
  std::vector<std::uint8_t> shifted(images.size(), 0);
  shift_frames(images.data(), shifted.data(), batch, frames, h, w, c, pad, shifts.data());
  EXPECT_TRUE(equals_float_random_shift(images, shifted, shifts, {batch, frames, h, w, c}, pad));
  // Offset (0, 0) reads from 13 rows above and columns left of the image: every pixel of the
  // first frame is the source's top-left one.
  const std::size_t frame = static_cast<std::size_t>(h * w * c);
  for (std::size_t i = 0; i < frame; ++i) EXPECT_EQ(shifted[i], images[0]) << i;
}

// Each architecture's four convolutions leave the documented grid at 64x64: 25x25 cells
// (drqv2), 5x5 (mrq), 11x11 (fine), 32 channels each; an image too small is refused by name.
TEST(ConvEncoderTest, EachArchitectureLeavesItsDocumentedGrid) {
  const std::vector<std::pair<EncoderArchitecture, std::int64_t>> grids = {
      {EncoderArchitecture::kDrqV2, 25},
      {EncoderArchitecture::kMrq, 5},
      {EncoderArchitecture::kFine, 11}};
  for (const auto& [architecture, cells] : grids) {
    ConvEncoder encoder = make_conv_encoder(architecture, 9, 64, 64, "test");
    EXPECT_EQ(encoder.features, 32 * cells * cells) << to_string(architecture);
    const torch::Tensor out = encoder.layers->forward(torch::zeros({2, 9, 64, 64}));
    EXPECT_EQ(out.sizes(), (std::vector<std::int64_t>{2, encoder.features}));
    EXPECT_EQ(parse_encoder_architecture(to_string(architecture)), architecture);
  }
  try {
    make_conv_encoder(EncoderArchitecture::kMrq, 3, 16, 16, "drqv2");
    ADD_FAILURE() << "a 16x16 image accepted by the mrq encoder";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("drqv2: images of 16x16 are too small for the mrq"),
              std::string::npos)
        << error.what();
  }
  EXPECT_THROW(parse_encoder_architecture("nature"), std::invalid_argument);
}

// A module's state saved to a blob loads back into another of the same shape, bit for bit (the
// digests agree), a missing blob is named with the checkpoint's path, and a changed parameter
// changes the digest.
TEST(TorchStateTest, BlobsRoundTripAndTheDigestSeesEveryParameter) {
  torch::manual_seed(1);
  torch::nn::Linear saved(3, 2);
  torch::nn::Linear loaded(3, 2);
  EXPECT_NE(parameter_digest(*saved), parameter_digest(*loaded));
  LoadedCheckpoint checkpoint;
  checkpoint.path = "ckpt-000001.pgck";
  checkpoint.blobs["model"] = save_blob(saved);
  load_blob(checkpoint, "model", loaded);
  EXPECT_EQ(parameter_digest(*saved), parameter_digest(*loaded));
  {
    torch::NoGradGuard no_grad;
    loaded->bias[1].add_(1e-6);
  }
  EXPECT_NE(parameter_digest(*saved), parameter_digest(*loaded));
  try {
    load_blob(checkpoint, "optimizer", loaded);
    ADD_FAILURE() << "a missing blob loaded";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()),
              "ckpt-000001.pgck: the checkpoint has no \"optimizer\" entry");
  }
  at::Generator generator = at::detail::createCPUGenerator(5);
  checkpoint.blobs["rng"] = generator_blob(generator);
  const torch::Tensor first = torch::rand({4}, generator);
  load_generator(checkpoint, "rng", generator);
  EXPECT_TRUE(torch::equal(torch::rand({4}, generator), first));
}

}  // namespace
}  // namespace pixelgym::trainer
