#pragma once
// One error type for everything a user can get wrong: a recipe, a file, a policy.
// The message is the whole story on one line ("FILE: key 'a.b': why"), so the CLI
// prints it and exits non-zero instead of crashing.
#include <stdexcept>
#include <string>

namespace segue {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace segue
