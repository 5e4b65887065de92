#pragma once
#include <string>

namespace segue {

// The assets/ folder: $SEGUE_ASSETS if set, else the source tree's assets/.
std::string assets_dir();
// Full path of a file under assets/; throws segue::Error when it does not exist.
std::string asset_path(const std::string& relative);

}  // namespace segue
