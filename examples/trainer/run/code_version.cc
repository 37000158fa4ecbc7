#include "pixelgym/trainer/code_version.h"

namespace pixelgym::trainer {

nlohmann::json code_version_json(const CodeVersion& version) {
  nlohmann::json json = nlohmann::json::object();
  json["commit"] = version.commit.empty() ? nlohmann::json() : nlohmann::json(version.commit);
  json["dirty"] = version.dirty ? nlohmann::json(*version.dirty) : nlohmann::json();
  json["recorded"] = "at build time";
  if (!version.note.empty()) json["note"] = version.note;
  return json;
}

}  // namespace pixelgym::trainer
