// The documentation and the shipped recipes against the code: docs/recipes.md is exactly
// what `segue keys` prints from the loaders, and every recipe under experiments/ (the lab
// aside) loads and passes every check (`--check`), each stage of a curriculum included.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/run_dir.h"
#include "tests/cli_run.h"

namespace segue {

TEST(Docs, RecipeReferenceIsTheLoadersOutput) {
  CliRun keys = run_cli("keys");
  ASSERT_EQ(keys.code, 0) << keys.output;
  EXPECT_EQ(keys.output, read_file(std::string(SEGUE_SOURCE_DIR) + "/docs/recipes.md"))
      << "docs/recipes.md is stale: regenerate it with `build/segue keys > docs/recipes.md`";
  for (const char* key : {"`ppo.lr`", "`env.throw_force`", "`switch.attempts`", "`lead_in.share`"})
    EXPECT_NE(keys.output.find(key), std::string::npos) << key;
  // Every number a recipe may hold declares the values it accepts (where it is read).
  std::istringstream rows(keys.output);
  int numbers = 0;
  for (std::string row; std::getline(rows, row);) {
    std::vector<std::string> cells;
    std::istringstream in(row);
    for (std::string cell; std::getline(in, cell, '|');) cells.push_back(cell);
    if (cells.size() != 5 || cells[1].find('`') == std::string::npos) continue;  // not a key's row
    if (cells[2].find("number") == std::string::npos && cells[2].find("integer") == std::string::npos) continue;
    ++numbers;
    EXPECT_NE(cells[3], " ") << "no range declared for" << cells[1];
  }
  EXPECT_GT(numbers, 200);
}

TEST(Docs, EveryShippedRecipeLoadsAndValidates) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(SEGUE_SOURCE_DIR) / "experiments";
  int checked = 0;
  for (const char* folder : {"primitives", "single", ""}) {
    for (const auto& entry : fs::directory_iterator(root / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      const std::string command = std::string(folder).empty() ? "run " : "train ";
      CliRun r = run_cli(command + entry.path().string() + " --check");
      EXPECT_EQ(r.code, 0) << entry.path() << ": " << r.output;
      EXPECT_NE(r.output.find(": ok"), std::string::npos) << r.output;
      ++checked;
    }
  }
  EXPECT_GE(checked, 15);
}

}  // namespace segue
