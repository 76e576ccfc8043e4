#pragma once

#include <stdexcept>
#include <string>

namespace pspslam {

// Every user-facing failure (bad file, bad flag, bad config) is reported as an Error whose
// message is complete on its own: it names the file/line/field and what was expected.
// The CLI prints what() and exits non-zero; nothing else catches it.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace pspslam
