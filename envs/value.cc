#include "pixelgym/envs/value.h"

#include <algorithm>
#include <stdexcept>

namespace pixelgym {

ValueDict::ValueDict(std::initializer_list<std::pair<std::string, Value>> entries) {
  for (const auto& [key, value] : entries) insert(key, value);
}

std::ptrdiff_t ValueDict::find(const std::string& key) const {
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    if (keys_[i] == key) return static_cast<std::ptrdiff_t>(i);
  }
  return -1;
}

void ValueDict::insert(const std::string& key, Value value) {
  const std::ptrdiff_t i = find(key);
  if (i >= 0) {
    values_[static_cast<std::size_t>(i)] = std::move(value);
    return;
  }
  keys_.push_back(key);
  values_.push_back(std::move(value));
}

void ValueDict::erase(const std::string& key) {
  at(key);  // throws for a missing key
  const auto i = find(key);
  keys_.erase(keys_.begin() + i);
  values_.erase(values_.begin() + i);
}

void ValueDict::clear() {
  keys_.clear();
  values_.clear();
}

bool ValueDict::contains(const std::string& key) const { return find(key) >= 0; }

const Value& ValueDict::at(const std::string& key) const {
  const std::ptrdiff_t i = find(key);
  if (i < 0) {
    std::string present;
    for (const auto& k : keys_) present += (present.empty() ? "\"" : ", \"") + k + "\"";
    throw std::out_of_range("ValueDict: no key \"" + key +
                            "\" (keys: " + (present.empty() ? "none" : present) + ")");
  }
  return values_[static_cast<std::size_t>(i)];
}

Value& ValueDict::at(const std::string& key) {
  return const_cast<Value&>(static_cast<const ValueDict&>(*this).at(key));
}

ValueTuple::ValueTuple(std::initializer_list<Value> items) : items_(items) {}
ValueTuple::ValueTuple(std::vector<Value> items) : items_(std::move(items)) {}

const Value& ValueTuple::at(std::size_t i) const {
  if (i >= items_.size()) {
    throw std::out_of_range("ValueTuple: index " + std::to_string(i) + " out of range for size " +
                            std::to_string(items_.size()));
  }
  return items_[i];
}

Value::Value() : data_(Array()) {}
Value::Value(Array array) : data_(std::move(array)) {}
Value::Value(ValueDict dict) : data_(std::move(dict)) {}
Value::Value(ValueTuple tuple) : data_(std::move(tuple)) {}

const char* Value::kind() const {
  if (is_array()) return "array";
  return is_dict() ? "Dict" : "Tuple";
}

const Array& Value::array() const {
  if (!is_array())
    throw std::invalid_argument(std::string("Value: expected an array, got a ") + kind());
  return std::get<Array>(data_);
}
Array& Value::array() { return const_cast<Array&>(static_cast<const Value&>(*this).array()); }

const ValueDict& Value::dict() const {
  if (!is_dict())
    throw std::invalid_argument(std::string("Value: expected a Dict, got a ") + kind());
  return std::get<ValueDict>(data_);
}
ValueDict& Value::dict() { return const_cast<ValueDict&>(static_cast<const Value&>(*this).dict()); }

const ValueTuple& Value::tuple() const {
  if (!is_tuple())
    throw std::invalid_argument(std::string("Value: expected a Tuple, got a ") + kind());
  return std::get<ValueTuple>(data_);
}

Value Value::clone() const {
  if (is_array()) return array().clone();
  if (is_dict()) {
    ValueDict copy;
    const ValueDict& source = dict();
    for (std::size_t i = 0; i < source.size(); ++i) {
      copy.insert(source.keys()[i], source.values()[i].clone());
    }
    return copy;
  }
  std::vector<Value> items;
  for (const Value& item : tuple().items()) items.push_back(item.clone());
  return ValueTuple(std::move(items));
}

bool Value::equals(const Value& other) const {
  if (data_.index() != other.data_.index()) return false;
  if (is_array()) return array().equals(other.array());
  if (is_dict()) {
    return dict().keys() == other.dict().keys() &&
           std::equal(dict().values().begin(), dict().values().end(), other.dict().values().begin(),
                      [](const Value& a, const Value& b) { return a.equals(b); });
  }
  const auto& mine = tuple().items();
  const auto& theirs = other.tuple().items();
  return mine.size() == theirs.size() &&
         std::equal(mine.begin(), mine.end(), theirs.begin(),
                    [](const Value& a, const Value& b) { return a.equals(b); });
}

std::vector<Array> Value::leaves() const {
  if (is_array()) return {array()};
  std::vector<Array> result;
  const std::vector<Value>& children = is_dict() ? dict().values() : tuple().items();
  for (const Value& child : children) {
    for (Array& leaf : child.leaves()) result.push_back(std::move(leaf));
  }
  return result;
}

bool Value::shares_memory(const Value& other) const {
  const std::vector<Array> mine = leaves();
  const std::vector<Array> theirs = other.leaves();
  for (const Array& a : mine) {
    for (const Array& b : theirs) {
      if (a.shares_memory(b)) return true;
    }
  }
  return false;
}

std::string Value::to_string() const {
  if (is_array()) return array().to_string();
  std::string text;
  if (is_dict()) {
    text = "Dict{";
    for (std::size_t i = 0; i < dict().size(); ++i) {
      if (i > 0) text += ", ";
      text += "\"" + dict().keys()[i] + "\": " + dict().values()[i].to_string();
    }
    return text + "}";
  }
  text = "Tuple(";
  for (std::size_t i = 0; i < tuple().size(); ++i) {
    if (i > 0) text += ", ";
    text += tuple().items()[i].to_string();
  }
  return text + ")";
}

}  // namespace pixelgym
