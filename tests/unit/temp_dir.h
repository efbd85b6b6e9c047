#pragma once
// A fresh, empty folder per test (named after the test and the process), removed afterwards.
#include <filesystem>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

namespace shadel::test {

struct TempDir {
    explicit TempDir(const std::string& prefix) {
        path = std::filesystem::temp_directory_path() /
               (prefix + "_" + std::to_string(getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    size_t entries() const {
        return size_t(std::distance(std::filesystem::directory_iterator(path),
                                    std::filesystem::directory_iterator()));
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
    std::filesystem::path path;
};

} // namespace shadel::test
