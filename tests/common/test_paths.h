#pragma once
// Paths the tests need: the checkout, ../shared beside it, the lumar binary, scratch space.
#include <filesystem>
#include <string>

namespace lumar::test {

std::filesystem::path source_dir();
std::filesystem::path shared_dir();
std::filesystem::path lumar_binary();
// A fresh, empty directory for this test; removed by the caller if wanted.
std::filesystem::path scratch_dir(const std::string& name);

}  // namespace lumar::test
