#include "pixelgym/envs/params.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "pixelgym/envs/suggestions.h"

namespace pixelgym {
namespace {

// "an int", "a float": the type's name with its article, for messages.
std::string with_article(ParamType type) {
  return (type == ParamType::kInt ? "an " : "a ") + std::string(param_type_name(type));
}

std::invalid_argument wrong_type(ParamType wanted, const Param& got) {
  return std::invalid_argument(std::string("expected ") + with_article(wanted) + ", got " +
                               param_type_name(got.type()) + " " + got.to_string());
}

}  // namespace

const char* param_type_name(ParamType type) {
  switch (type) {
    case ParamType::kBool:
      return "bool";
    case ParamType::kInt:
      return "int";
    case ParamType::kFloat:
      return "float";
    case ParamType::kString:
      return "string";
  }
  return "unknown";
}

bool Param::as_bool() const {
  if (type() != ParamType::kBool) throw wrong_type(ParamType::kBool, *this);
  return std::get<bool>(value_);
}

std::int64_t Param::as_int() const {
  if (type() != ParamType::kInt) throw wrong_type(ParamType::kInt, *this);
  return std::get<std::int64_t>(value_);
}

double Param::as_float() const {
  if (type() == ParamType::kInt) return static_cast<double>(std::get<std::int64_t>(value_));
  if (type() != ParamType::kFloat) throw wrong_type(ParamType::kFloat, *this);
  return std::get<double>(value_);
}

const std::string& Param::as_string() const {
  if (type() != ParamType::kString) throw wrong_type(ParamType::kString, *this);
  return std::get<std::string>(value_);
}

std::string Param::to_string() const {
  switch (type()) {
    case ParamType::kBool:
      return std::get<bool>(value_) ? "true" : "false";
    case ParamType::kInt:
      return std::to_string(std::get<std::int64_t>(value_));
    case ParamType::kFloat: {
      std::ostringstream out;
      out << std::get<double>(value_);
      return out.str();
    }
    case ParamType::kString:
      return "\"" + std::get<std::string>(value_) + "\"";
  }
  return "";
}

Param parse_param(ParamType type, const std::string& text) {
  const auto fail = [&] {
    return std::invalid_argument("cannot read \"" + text + "\" as " + with_article(type));
  };
  switch (type) {
    case ParamType::kBool: {
      std::string lower = text;
      std::transform(lower.begin(), lower.end(), lower.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (lower == "true" || lower == "1" || lower == "yes" || lower == "on") return true;
      if (lower == "false" || lower == "0" || lower == "no" || lower == "off") return false;
      throw fail();
    }
    case ParamType::kInt: {
      if (text.empty()) throw fail();
      char* end = nullptr;
      errno = 0;
      const long long value = std::strtoll(text.c_str(), &end, 10);
      if (errno != 0 || *end != '\0') throw fail();
      return value;
    }
    case ParamType::kFloat: {
      if (text.empty()) throw fail();
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(text.c_str(), &end);
      if (errno != 0 || *end != '\0') throw fail();
      return value;
    }
    case ParamType::kString:
      return text;
  }
  throw fail();
}

std::string describe_params(const std::vector<ParamSpec>& specs) {
  std::string text;
  for (const ParamSpec& spec : specs) {
    if (!text.empty()) text += ", ";
    text += spec.name + " (" + param_type_name(spec.type()) + ", default " +
            spec.default_value.to_string() + ")";
  }
  return text.empty() ? "none" : text;
}

Params resolve_params(const std::vector<ParamSpec>& specs, const Params& given,
                      const std::string& context) {
  Params resolved;
  for (const ParamSpec& spec : specs) resolved.emplace(spec.name, spec.default_value);
  for (const auto& [key, value] : given) {
    const std::string& name = key;  // (a structured binding cannot be captured before C++20)
    const auto spec = std::find_if(specs.begin(), specs.end(),
                                   [&](const ParamSpec& s) { return s.name == name; });
    if (spec == specs.end()) {
      std::vector<std::string> names;
      for (const ParamSpec& s : specs) names.push_back(s.name);
      const std::string suggestion = did_you_mean(key, names);
      throw std::invalid_argument(context + ": unknown kwarg \"" + key + "\"; " +
                                  (suggestion.empty() ? "" : suggestion + " ") +
                                  "valid kwargs: " + describe_params(specs));
    }
    if (value.type() == spec->type()) {
      resolved.at(key) = value;
    } else if (spec->type() == ParamType::kFloat && value.type() == ParamType::kInt) {
      resolved.at(key) = value.as_float();
    } else {
      throw std::invalid_argument(context + ": kwarg \"" + key + "\" must be " +
                                  with_article(spec->type()) + ", got " +
                                  param_type_name(value.type()) + " " + value.to_string());
    }
  }
  return resolved;
}

}  // namespace pixelgym
