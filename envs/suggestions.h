// "Did you mean": the names a mistyped one is closest to (env ids, kwargs, wrappers, subcommands,
// algorithms, config members all use these, so every suggestion follows one rule).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace pixelgym {

/// Up to `count` of `candidates` within a typo's edit distance of `name` (Levenshtein, case
/// ignored: at most a third of the name's length, and at least 2), closest first; ties keep the
/// candidates' order. Empty when none is that close.
std::vector<std::string> closest_names(const std::string& name,
                                       const std::vector<std::string>& candidates,
                                       std::size_t count = 3);

/// "did you mean width?", "did you mean a or b?", "did you mean a, b or c?" for the
/// closest_names of `name`; "" when none is close.
std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates);

/// `names` joined by ", " ("a, b, c"), "" for none.
std::string join_names(const std::vector<std::string>& names);

}  // namespace pixelgym
