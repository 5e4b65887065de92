#pragma once
#include <string>

namespace segue {

// The assets/ folder: $SEGUE_ASSETS if set, else the source tree's assets/.
std::string assets_dir();
// Full path of a file under assets/; throws segue::Error when it does not exist.
std::string asset_path(const std::string& relative);
// A path as a recipe gives it (e.g. assets/policies/walker/walker_forward.pt): as is when
// it exists from the working directory or is absolute, else from the source tree.
std::string repo_path(const std::string& path);

}  // namespace segue
