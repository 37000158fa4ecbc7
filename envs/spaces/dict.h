// spaces::Dict: an ordered mapping of named subspaces, as gymnasium.spaces.Dict.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/space.h"

namespace pixelgym::spaces {

/// Elements are pixelgym::ValueDict values with exactly these keys, each value in its subspace.
/// Keys keep the order given (pixel tasks list "pixels" first, then state arrays).
class Dict final : public Space {
 public:
  /// (key, subspace) pairs, in order.
  using Entries = std::vector<std::pair<std::string, SpacePtr>>;

  /// Throws std::invalid_argument for an empty or duplicate key or a null subspace.
  explicit Dict(Entries entries);

  using Space::sample;
  Value sample(Rng& rng) const override;
  std::string mismatch(const Value& value) const override;
  Value zeros() const override;
  std::string layout_mismatch(const Value& value) const override;
  std::optional<Shape> shape() const override { return std::nullopt; }
  std::optional<DType> dtype() const override { return std::nullopt; }
  std::string to_string() const override;
  bool equals(const Space& other) const override;

  /// The entries in the order given.
  const Entries& entries() const { return entries_; }
  /// Whether `key` is one of the keys.
  bool has(const std::string& key) const;
  /// Throws std::out_of_range naming the key and the keys present.
  const Space& at(const std::string& key) const;
  /// The position of `key` in entries(). Throws std::out_of_range like `at`.
  std::size_t index(const std::string& key) const;

  /// Copies with one entry changed (spaces are immutable), for wrappers that change one key:
  /// `replaced` swaps the subspace of `key` in place (std::out_of_range when absent);
  /// `inserted` adds `key` at `position` (the end by default; std::invalid_argument when present,
  /// std::out_of_range past the end); `removed` drops `key` (std::out_of_range when absent).
  std::shared_ptr<const Dict> replaced(const std::string& key, SpacePtr space) const;
  std::shared_ptr<const Dict> inserted(const std::string& key, SpacePtr space,
                                       std::optional<std::size_t> position = std::nullopt) const;
  std::shared_ptr<const Dict> removed(const std::string& key) const;

 private:
  Entries entries_;
};

}  // namespace pixelgym::spaces
