// Params: typed key/value settings — `make` kwargs, `--set key=value`, reset options.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace pixelgym {

/// The types a setting can have.
enum class ParamType { kBool, kInt, kFloat, kString };

/// "bool", "int", "float" or "string".
const char* param_type_name(ParamType type);

/// One setting's value: a bool, a 64-bit int, a double or a string. Constructible from literals
/// (`{"width", 64}`, `{"camera", "side"}`) without ambiguity.
class Param {
 public:
  Param(bool value) : value_(value) {}                      // NOLINT
  Param(int value) : value_(std::int64_t{value}) {}         // NOLINT
  Param(long value) : value_(std::int64_t{value}) {}        // NOLINT
  Param(long long value) : value_(std::int64_t{value}) {}   // NOLINT
  Param(double value) : value_(value) {}                    // NOLINT
  Param(const char* value) : value_(std::string(value)) {}  // NOLINT
  Param(std::string value) : value_(std::move(value)) {}    // NOLINT

  /// Which of the four types it holds (every integer type is kInt, stored as int64).
  ParamType type() const { return static_cast<ParamType>(value_.index()); }
  /// Each accessor throws std::invalid_argument when the type differs; `as_float` also accepts
  /// an int (as Python would).
  bool as_bool() const;
  std::int64_t as_int() const;
  double as_float() const;
  const std::string& as_string() const;
  /// "true", "64", "0.5", "\"side\"" (floats with 6 significant digits).
  std::string to_string() const;

  /// Same type and same value: the int 1 and the float 1.0 differ.
  friend bool operator==(const Param& a, const Param& b) { return a.value_ == b.value_; }

 private:
  std::variant<bool, std::int64_t, double, std::string> value_;  // order matches ParamType
};

/// Settings by name.
using Params = std::map<std::string, Param>;

/// One declared setting: its name, default (which fixes its type) and a short description.
struct ParamSpec {
  std::string name;
  Param default_value;
  /// One line for `pixelgym info` and the like.
  std::string doc;
  /// The setting's type: its default's.
  ParamType type() const { return default_value.type(); }
};

/// Parses command-line text as `type`: bools accept true/false/1/0/yes/no/on/off (any case), ints
/// decimal within int64, floats anything strtod reads fully, strings as they are. Throws
/// std::invalid_argument naming the text and type.
Param parse_param(ParamType type, const std::string& text);

/// `given` checked against `specs`, with defaults filled in. Throws std::invalid_argument,
/// prefixed with `context`, for an unknown key (listing every valid key with its type and
/// default) or a value of the wrong type (an int where a float is declared is converted).
Params resolve_params(const std::vector<ParamSpec>& specs, const Params& given,
                      const std::string& context);

/// "render_width (int, default 256)" for each spec, comma-separated; "none" for no specs.
std::string describe_params(const std::vector<ParamSpec>& specs);

}  // namespace pixelgym
