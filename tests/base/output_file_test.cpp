// Outputs appear whole or not at all, under a temporary that never collides.
#include "lumar/base/output_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "lumar/base/error.h"
#include "test_paths.h"

namespace lumar {
namespace {

namespace fs = std::filesystem;

std::size_t entries(const fs::path& dir) {
  return std::distance(fs::directory_iterator(dir), fs::directory_iterator());
}

std::string contents(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(OutputFile, AppearsOnlyAtCommitAndKeepsTheExtension) {
  const test::Scratch scratch("output-file");
  const fs::path path = scratch.dir / "result.png";
  {
    OutputFile out(path);
    EXPECT_EQ(out.temporary().parent_path(), scratch.dir);
    EXPECT_EQ(out.temporary().extension(), ".png");  // writers that choose by extension
    EXPECT_EQ(out.temporary().filename().string().front(), '.');
    std::ofstream(out.temporary()) << "new";
    EXPECT_FALSE(fs::exists(path));
    out.commit();
  }
  EXPECT_EQ(contents(path), "new");
  EXPECT_EQ(entries(scratch.dir), 1u);
}

TEST(OutputFile, WithoutCommitNothingIsLeftAndTheOldFileStays) {
  const test::Scratch scratch("output-file-abandoned");
  const fs::path path = scratch.dir / "table.csv";
  write_file_atomically(path, "old\n");
  {
    OutputFile out(path);
    std::ofstream(out.temporary()) << "half";
  }
  EXPECT_EQ(contents(path), "old\n");
  EXPECT_EQ(entries(scratch.dir), 1u);
}

TEST(OutputFile, TwoWritersOfOnePathNeverShareATemporary) {
  const test::Scratch scratch("output-file-two");
  const fs::path path = scratch.dir / "cache.bin";
  OutputFile a(path), b(path);
  EXPECT_NE(a.temporary(), b.temporary());
  std::ofstream(a.temporary()) << "a";
  std::ofstream(b.temporary()) << "b";
  b.commit();
  a.commit();
  EXPECT_EQ(contents(path), "a");
  EXPECT_EQ(entries(scratch.dir), 1u);
}

TEST(OutputFile, BadPathsAreInputErrorsAndFailedRenamesRuntimeErrors) {
  const test::Scratch scratch("output-file-bad");
  EXPECT_THROW(OutputFile(scratch.dir / "missing" / "x.csv"), InputError);
  EXPECT_THROW(OutputFile(scratch.dir), InputError);  // a folder, not a file
  OutputFile out(scratch.dir / "taken");              // a file name now, a non-empty folder by commit time
  fs::create_directories(scratch.dir / "taken" / "inside");
  std::ofstream(out.temporary()) << "x";
  EXPECT_THROW(out.commit(), RuntimeError);
}

TEST(OutputFolder, AppearsWholeAtCommit) {
  const test::Scratch scratch("output-folder");
  const fs::path dir = scratch.dir / "frames";
  {
    OutputFolder out(dir);
    std::ofstream(out.temporary() / "frame-000000.png") << "x";
    EXPECT_FALSE(fs::exists(dir));
    out.commit();
  }
  EXPECT_TRUE(fs::exists(dir / "frame-000000.png"));
  EXPECT_EQ(entries(scratch.dir), 1u);
  EXPECT_THROW(OutputFolder{dir}, InputError);  // exists already
  {
    OutputFolder abandoned(scratch.dir / "other");
    std::ofstream(abandoned.temporary() / "a.png") << "x";
  }
  EXPECT_EQ(entries(scratch.dir), 1u);
}

}  // namespace
}  // namespace lumar
