// The documentation and the shipped recipes against the code: docs/recipes.md is exactly
// what `segue keys` prints from the loaders, and every recipe under experiments/ (the lab
// aside) loads and passes every check (`--check`), each stage of a curriculum included.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>

#include "core/run_dir.h"

namespace segue {
namespace {

struct Output {
  int code;
  std::string text;
};

Output run(const std::string& args) {
  std::string cmd = std::string(SEGUE_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

}  // namespace

TEST(Docs, RecipeReferenceIsTheLoadersOutput) {
  Output keys = run("keys");
  ASSERT_EQ(keys.code, 0) << keys.text;
  EXPECT_EQ(keys.text, read_file(std::string(SEGUE_SOURCE_DIR) + "/docs/recipes.md"))
      << "docs/recipes.md is stale: regenerate it with `build/segue keys > docs/recipes.md`";
  for (const char* key : {"`ppo.lr`", "`env.throw_force`", "`switch.attempts`", "`lead_in.share`"})
    EXPECT_NE(keys.text.find(key), std::string::npos) << key;
}

TEST(Docs, EveryShippedRecipeLoadsAndValidates) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(SEGUE_SOURCE_DIR) / "experiments";
  int checked = 0;
  for (const char* folder : {"primitives", "single", ""}) {
    for (const auto& entry : fs::directory_iterator(root / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      const std::string command = std::string(folder).empty() ? "run " : "train ";
      Output r = run(command + entry.path().string() + " --check");
      EXPECT_EQ(r.code, 0) << entry.path() << ": " << r.text;
      EXPECT_NE(r.text.find(": ok"), std::string::npos) << r.text;
      ++checked;
    }
  }
  EXPECT_GE(checked, 15);
}

}  // namespace segue
