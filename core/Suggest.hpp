#pragma once
/// \file
/// \brief "Did you mean ...?" suggestions for misspelt keys, patch names and choices.
#include <string>
#include <vector>

namespace mfsi {

/// Edit distance (case-sensitive): insertions, deletions, substitutions, adjacent transpositions.
int editDistance(const std::string& a, const std::string& b);

/// The closest candidate when it is close enough to be a plausible typo, else "".
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

/// " (did you mean 'x'?)" or "" — ready to append to a message.
std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates);

/// "a, b, c" for messages.
std::string joinList(const std::vector<std::string>& items);

}  // namespace mfsi
