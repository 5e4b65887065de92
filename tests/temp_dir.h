#pragma once
// A scratch folder for a test, removed afterwards; unique per process and name.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace segue {

class TempDirTest : public ::testing::Test {
 protected:
  explicit TempDirTest(const std::string& name)
      : dir_(std::filesystem::temp_directory_path() / ("segue_" + name + "_" + std::to_string(::getpid()))) {}
  void SetUp() override {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& file) const { return (dir_ / file).string(); }
  std::filesystem::path dir_;
};

}  // namespace segue
