#include "pixelgym/envs/suggestions.h"

#include <algorithm>
#include <cctype>
#include <utility>

namespace pixelgym {
namespace {

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::vector<std::string> closest_names(const std::string& name,
                                       const std::vector<std::string>& candidates,
                                       std::size_t count) {
  // Close enough to be a typo: an edit distance of at most a third of the name (and at least 2).
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
  const std::string wanted = lowercase(name);
  std::vector<std::pair<std::size_t, std::size_t>> ranked;  // (distance, index in candidates)
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const std::size_t distance = edit_distance(wanted, lowercase(candidates[i]));
    if (distance <= limit) ranked.emplace_back(distance, i);
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::string> closest;
  for (std::size_t i = 0; i < ranked.size() && i < count; ++i) {
    closest.push_back(candidates[ranked[i].second]);
  }
  return closest;
}

std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates) {
  const std::vector<std::string> closest = closest_names(name, candidates);
  if (closest.empty()) return "";
  std::string text = "did you mean ";
  for (std::size_t i = 0; i < closest.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == closest.size() ? " or " : ", ") + closest[i];
  }
  return text + "?";
}

std::string join_names(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace pixelgym
