#include "core/assets.h"

#include <cstdlib>
#include <filesystem>

#include "core/error.h"

namespace segue {

std::string assets_dir() {
  if (const char* env = std::getenv("SEGUE_ASSETS"); env && *env) return env;
  return std::string(SEGUE_SOURCE_DIR) + "/assets";
}

std::string asset_path(const std::string& relative) {
  std::string path = assets_dir() + "/" + relative;
  if (!std::filesystem::exists(path))
    throw Error(path + ": missing asset (set SEGUE_ASSETS to the assets/ folder)");
  return path;
}

}  // namespace segue
