// One glob rule (glob(3)) for every image pattern, in natural order.
#include "lumar/base/glob.h"

#include <gtest/gtest.h>

#include <fstream>

#include "lumar/base/error.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(Glob, NaturalOrder) {
  EXPECT_TRUE(natural_less("f2.png", "f10.png"));
  EXPECT_FALSE(natural_less("f10.png", "f2.png"));
  EXPECT_TRUE(natural_less("a/f9", "a/f009x"));
  EXPECT_TRUE(natural_less("f1", "f01"));
  EXPECT_FALSE(natural_less("f1", "f1"));
  EXPECT_TRUE(natural_less("f99999999999999999999999", "f100000000000000000000000"));
}

TEST(Glob, CharacterClassesMatchLikeTheShell) {
  // The shared checkerboard photographs are left01.jpg .. left14.jpg without left10.
  const std::string folder = (test::shared_dir() / "data/calib/checkerboard-9x6").string();
  const auto two_digits = glob_files(folder + "/left[0-9][0-9].jpg");
  ASSERT_EQ(two_digits.size(), 13u);
  EXPECT_EQ(two_digits.front().filename(), "left01.jpg");
  EXPECT_EQ(two_digits.back().filename(), "left14.jpg");
  EXPECT_EQ(glob_files(folder + "/left0[1-3].jpg").size(), 3u);
  EXPECT_EQ(glob_files(folder + "/left1[!0-2].jpg").size(), 2u);  // left13, left14
  EXPECT_EQ(glob_files(folder + "/left?.jpg").size(), 0u);
  EXPECT_TRUE(is_glob_pattern("left[0-9].jpg"));
  EXPECT_FALSE(is_glob_pattern("left01.jpg"));
}

TEST(Glob, NaturalOrderAndOnlyFiles) {
  const test::Scratch scratch("glob");
  for (const char* name : {"frame-10.png", "frame-2.png", "frame-1.png"}) std::ofstream(scratch.dir / name) << "x";
  std::filesystem::create_directory(scratch.dir / "frame-3.png");  // a folder is not a match
  const auto found = glob_files((scratch.dir / "frame-*.png").string());
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].filename(), "frame-1.png");
  EXPECT_EQ(found[1].filename(), "frame-2.png");
  EXPECT_EQ(found[2].filename(), "frame-10.png");
}

TEST(Glob, MissingFolderIsAnInputError) { EXPECT_THROW(glob_files("/no/such/folder/*.png"), InputError); }

}  // namespace
}  // namespace lumar
