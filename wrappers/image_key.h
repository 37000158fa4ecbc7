// The part the image wrappers share: finding the image they transform (a bare image Box, or one
// key of a spaces::Dict), validating it, building the output space, and the per-step helpers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"

namespace pixelgym::wrappers {

/// Where an image wrapper's image is in an observation, and its layout.
///
/// The observation space is either a bare uint8 Box (the image itself) or a spaces::Dict with the
/// image under `key`. For a bare Box the key must be the default "pixels" or empty: any other key
/// names an entry a Box does not have, and is refused rather than ignored.
struct ImageKey {
  /// The key as given ("pixels" by default); empty when the space is a bare Box.
  std::string key;
  /// True when the observation space is a spaces::Dict.
  bool in_dict = false;
  /// Position of `key` among the Dict's entries (0 for a bare Box).
  std::size_t index = 0;
  /// (H, W, C) or, where the wrapper allows it, (H, W).
  Shape shape;

  /// H and W.
  std::int64_t height() const { return shape[0]; }
  std::int64_t width() const { return shape[1]; }
  /// C, or 0 for an (H, W) image.
  std::int64_t channels() const { return shape.size() == 3 ? shape[2] : 0; }
};

/// What an image wrapper accepts.
struct ImageRequirement {
  /// The accepted channel counts C of an (H, W, C) image; 0 stands for an (H, W) image.
  std::vector<std::int64_t> channels = {1, 3};
  /// When true, any rank-3 uint8 Box is accepted whatever its last extent (e.g. a channel-first
  /// (C, H, W) image); `channels` then only says whether 0, an (H, W) image, is accepted too.
  bool any_rank3 = false;
};

/// Finds the image `key` in `space` for `wrapper` (its class name, used in messages).
///
/// An image is a uint8 Box of shape (H, W, C) with C in `requirement.channels` (or (H, W) when 0
/// is listed) and H, W >= 1. Throws std::invalid_argument naming the wrapper and the key, what
/// was expected and what was found, and listing the keys of `space` that are such images: when
/// `key` is absent from a Dict, when its entry is not such an image, when a bare Box is not such
/// an image, when the key given for a bare Box is neither "pixels" nor empty, and when the space
/// is neither a Box nor a Dict.
ImageKey find_image(const Space& space, const std::string& key, const std::string& wrapper,
                    const ImageRequirement& requirement = {});

/// The observation space with the image replaced by `image_space`: `image_space` itself for a
/// bare Box, else the Dict with that one entry replaced (spaces::Dict::replaced).
SpacePtr replace_image(const Space& space, const ImageKey& image, SpacePtr image_space);

/// A uint8 Box with bounds [0, 255] and the given shape: the output space of an image wrapper.
SpacePtr uint8_image_space(Shape shape);

/// The image array of an observation laid out as the space `image` was found in.
const Array& image_of(const Value& observation, const ImageKey& image);
Array& image_of(Value& observation, const ImageKey& image);

/// Copies every entry of `in` but the image into the matching arrays of `out` (Array::copy_from,
/// no allocation); nothing for a bare Box. `in` and `out` are Dicts with the same keys in the
/// same order, laid out as the input and the output observation spaces.
void copy_other_entries(const Value& in, Value& out, const ImageKey& image);

/// Copies each array of `from` into the array at the same place in `to` (same structure;
/// Array::copy_from throws std::invalid_argument on a dtype or shape mismatch).
void copy_value(const Value& from, Value& to);

}  // namespace pixelgym::wrappers
