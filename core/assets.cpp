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

std::string repo_path(const std::string& path) {
  if (std::filesystem::exists(path) || std::filesystem::path(path).is_absolute()) return path;
  std::string in_tree = std::string(SEGUE_SOURCE_DIR) + "/" + path;
  return std::filesystem::exists(in_tree) ? in_tree : path;
}

}  // namespace segue
