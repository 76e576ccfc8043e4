#pragma once

#include <optional>
#include <string>
#include <vector>

namespace pspslam {

// Levenshtein distance (insertions, deletions, substitutions), for "did you mean" hints.
size_t edit_distance(const std::string& a, const std::string& b);

// The candidate closest to `typed`, if it is close enough to be a likely typo: at most 2 edits
// and fewer edits than half the longer name (so "x" does not suggest "fx").
std::optional<std::string> nearest(const std::string& typed,
                                   const std::vector<std::string>& candidates);

}  // namespace pspslam
