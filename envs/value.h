// Value: what an observation, an action or an info entry is — an Array, a Dict or a Tuple.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "pixelgym/envs/array.h"

namespace pixelgym {

class Value;

/// An ordered map from string keys to Values (insertion order is kept, as in Gymnasium's Dict).
class ValueDict {
 public:
  ValueDict() = default;
  /// The entries inserted in order (a repeated key keeps its first position and its last value).
  ValueDict(std::initializer_list<std::pair<std::string, Value>> entries);

  /// Adds `key`, or replaces its value when present (keeping its position).
  void insert(const std::string& key, Value value);
  /// Removes `key`. Throws std::out_of_range naming the key and the keys present.
  void erase(const std::string& key);
  /// Removes every entry (keeping the memory for the next ones).
  void clear();
  /// Whether `key` is present.
  bool contains(const std::string& key) const;
  /// The value of `key`. Throws std::out_of_range naming the key and the keys present.
  const Value& at(const std::string& key) const;
  Value& at(const std::string& key);
  /// Number of entries.
  std::size_t size() const { return keys_.size(); }
  bool empty() const { return keys_.empty(); }
  /// The keys in insertion order.
  const std::vector<std::string>& keys() const { return keys_; }
  /// The values, in the order of keys(): values()[i] belongs to keys()[i].
  const std::vector<Value>& values() const { return values_; }
  /// The same, writable (replace values in place; adding or removing entries here would break
  /// the pairing with keys()).
  std::vector<Value>& values() { return values_; }

 private:
  std::ptrdiff_t find(const std::string& key) const;

  std::vector<std::string> keys_;
  std::vector<Value> values_;
};

/// A fixed-length sequence of Values.
class ValueTuple {
 public:
  ValueTuple() = default;
  /// The items in order.
  ValueTuple(std::initializer_list<Value> items);
  explicit ValueTuple(std::vector<Value> items);

  /// Number of items.
  std::size_t size() const { return items_.size(); }
  /// Item `i`. Throws std::out_of_range unless i < size().
  const Value& at(std::size_t i) const;
  /// Every item, in order.
  const std::vector<Value>& items() const { return items_; }

 private:
  std::vector<Value> items_;
};

/// One of Array, ValueDict or ValueTuple. Copies are shallow for the arrays inside (they share
/// memory).
class Value {
 public:
  /// An empty Array (float32, shape (0,)).
  Value();
  /// Holds `array` (sharing its memory), `dict` or `tuple`; implicit, so that each converts.
  Value(Array array);       // NOLINT(google-explicit-constructor): arrays are values
  Value(ValueDict dict);    // NOLINT(google-explicit-constructor)
  Value(ValueTuple tuple);  // NOLINT(google-explicit-constructor)

  /// Which alternative it holds.
  bool is_array() const { return std::holds_alternative<Array>(data_); }
  bool is_dict() const { return std::holds_alternative<ValueDict>(data_); }
  bool is_tuple() const { return std::holds_alternative<ValueTuple>(data_); }

  /// The held alternative; each throws std::invalid_argument naming what is held instead.
  const Array& array() const;
  Array& array();
  const ValueDict& dict() const;
  ValueDict& dict();
  const ValueTuple& tuple() const;

  /// Exchanges contents with `other` without copying or allocating.
  void swap(Value& other) noexcept { data_.swap(other.data_); }

  /// "array", "Dict" or "Tuple".
  const char* kind() const;
  /// A deep copy: no array in the result shares memory with this one.
  Value clone() const;
  /// Same structure, keys, dtypes, shapes and bytes.
  bool equals(const Value& other) const;
  /// True when any array in this value shares memory with any array in `other`.
  bool shares_memory(const Value& other) const;
  /// Every array in this value, depth first in key / item order.
  std::vector<Array> leaves() const;
  /// A readable description for messages: Array::to_string, or Dict{"key": ..., ...}.
  std::string to_string() const;

 private:
  std::variant<Array, ValueDict, ValueTuple> data_;
};

}  // namespace pixelgym
