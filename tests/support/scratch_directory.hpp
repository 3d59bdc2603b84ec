// A fresh directory per test for the tests that write files, removed when the test ends.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>

#include <unistd.h>

namespace meccano::testing {

class ScratchDirectoryTest : public ::testing::Test {
 protected:
  // The directory is <temp>/<prefix>-<pid>-<test name>: parallel test processes do not meet.
  explicit ScratchDirectoryTest(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    // A parameterized test's name holds a '/' ("Name/3"): kept, it would make a parent directory that
    // TearDown does not remove.
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::ranges::replace(test, '/', '_');
    dir_ = std::filesystem::temp_directory_path() / (prefix_ + "-" + std::to_string(::getpid()) + "-" + test);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace meccano::testing
