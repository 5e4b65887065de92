// The documentation and the shipped recipes against the code: docs/recipes.md is exactly
// what `segue keys` prints from the loaders, docs/usage.md names every command's flags as
// its --help does, and every recipe under experiments/ loads and passes every check
// (`--check`), each stage of a curriculum included.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
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

// The repository stands alone: no tracked file points outside it, neither to a folder beside
// the checkout nor to a path on one machine; the reference facts the code relies on are in
// docs/reference/. Skipped: binaries, and this file, which spells the patterns.
TEST(Docs, NoFileRefersOutsideTheRepository) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(SEGUE_SOURCE_DIR);
  // Built from pieces so that the patterns do not spell themselves here.
  const std::string dot_dot = "..";
  const std::vector<std::string> patterns = {dot_dot + "/shared", "/" + std::string("work/"),
                                             "/" + std::string("tmp/"), "/" + std::string("home/"),
                                             "/" + std::string("root/")};
  // The tracked files, or, outside a git checkout, every file below the source tree.
  std::vector<std::string> files;
  const std::string cmd = "git -C '" + root.string() + "' ls-files -z 2>/dev/null";
  if (FILE* p = popen(cmd.c_str(), "r")) {
    std::string listing;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) listing.append(buf.data(), n);
    if (pclose(p) == 0)
      for (size_t begin = 0, end; (end = listing.find('\0', begin)) != std::string::npos; begin = end + 1)
        files.push_back(listing.substr(begin, end - begin));
  }
  if (files.empty()) {
    const auto options = fs::directory_options::skip_permission_denied;
    for (auto it = fs::recursive_directory_iterator(root, options); it != fs::recursive_directory_iterator(); ++it) {
      const std::string name = it->path().filename().string();
      const bool skipped = name == ".git" || (it.depth() == 0 && (name.rfind("build", 0) == 0 || name == "runs"));
      if (it->is_directory() && skipped) {
        it.disable_recursion_pending();
        continue;
      }
      if (it->is_regular_file()) files.push_back(fs::relative(it->path(), root).generic_string());
    }
  }
  int checked = 0;
  for (const std::string& file : files) {
    if (file == "tests/test_docs.cpp") continue;
    const std::string ext = fs::path(file).extension().string();
    if (ext == ".pt" || ext == ".png" || ext == ".mp4") continue;
    if (!fs::is_regular_file(root / file)) continue;  // deleted in the working tree
    const std::string text = read_file((root / file).string());
    if (text.substr(0, 8192).find('\0') != std::string::npos) continue;  // binary
    ++checked;
    std::istringstream lines(text);
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
      ++number;
      for (const std::string& pattern : patterns)
        if (line.find(pattern) != std::string::npos)
          ADD_FAILURE() << file << ":" << number << ": refers outside the repository (" << pattern
                        << "); point into docs/reference/ or the repository instead: " << line;
    }
  }
  EXPECT_GT(checked, 100) << "the file listing found too few files below " << root;
}

// The README's import order, checked: environments/ and algorithms/ include only core/
// (and themselves), hrl/ does not include tools/, core/ includes no other folder.
TEST(Docs, IncludesRunOneWay) {
  namespace fs = std::filesystem;
  const fs::path root(SEGUE_SOURCE_DIR);
  const std::map<std::string, std::set<std::string>> allowed{{"core", {"core"}},
                                                             {"environments", {"core", "environments"}},
                                                             {"algorithms", {"core", "algorithms"}},
                                                             {"hrl", {"core", "environments", "algorithms", "hrl"}}};
  int includes = 0;
  for (const auto& [folder, may] : allowed)
    for (const auto& entry : fs::directory_iterator(root / folder)) {
      std::istringstream lines(read_file(entry.path().string()));
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("#include \"", 0) != 0) continue;
        const std::string target = line.substr(10, line.find('/', 10) - 10);
        ++includes;
        EXPECT_TRUE(may.count(target)) << folder << "/" << entry.path().filename().string() << " includes " << line;
      }
    }
  EXPECT_GT(includes, 100);
}

// Each command's section of docs/usage.md ("### segue CMD") names exactly the flags its
// --help lists, so neither can drift from the other.
TEST(Docs, UsageNamesEveryCommandsFlagsAsItsHelpDoes) {
  const std::string usage = read_file(std::string(SEGUE_SOURCE_DIR) + "/docs/usage.md");
  const std::regex flag("--([a-z][a-z0-9-]*)");
  auto flags_in = [&](const std::string& text) {
    std::set<std::string> out;
    for (std::sregex_iterator it(text.begin(), text.end(), flag), end; it != end; ++it) out.insert((*it)[1]);
    out.erase("help");
    return out;
  };
  for (const std::string cmd : {"train", "run", "eval", "report", "diagnose", "export", "render", "plot", "keys", "bench"}) {
    SCOPED_TRACE(cmd);
    const CliRun help = run_cli(cmd + " --help");
    ASSERT_EQ(help.code, 0) << help.output;
    std::set<std::string> listed;  // the "flags:" lines of --help: "  --name VALUE  text"
    std::istringstream lines(help.output);
    for (std::string line; std::getline(lines, line);) {
      std::smatch m;
      if (std::regex_search(line, m, std::regex("^  --([a-z][a-z0-9-]*)"))) listed.insert(m[1]);
    }
    listed.erase("help");
    const size_t at = usage.find("### segue " + cmd + "\n");
    ASSERT_NE(at, std::string::npos) << "docs/usage.md has no section '### segue " << cmd << "'";
    size_t end = usage.find("\n#", at + 1);
    const std::string section = usage.substr(at, end == std::string::npos ? std::string::npos : end - at);
    EXPECT_EQ(flags_in(section), listed) << "docs/usage.md's '### segue " << cmd << "' against its --help";
  }
}

}  // namespace segue
