// The one CSV reader (lumar/base/csv.h) and input-file checks (lumar/base/input_file.h).
#include "lumar/base/csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"

namespace lumar {
namespace {

using ::testing::HasSubstr;

struct Read {
  std::vector<std::vector<double>> rows;
  std::string error;
};

Read read(std::string_view text, const csv::Columns& columns, csv::LastLine last = csv::LastLine::kRead) {
  Read r;
  try {
    csv::for_each_row("t.csv", text, columns, last, [&](const csv::Row& row) {
      std::vector<double> v;
      for (const auto& name : columns.required) v.push_back(row.real(name));
      r.rows.push_back(v);
    });
  } catch (const InputError& e) {
    r.error = e.what();
  }
  return r;
}

TEST(Csv, ColumnsAreFoundByNameInAnyOrder) {
  const csv::Columns xy{{"x", "y"}};
  const Read a = read("x,y\n1,2\n3,4\n", xy);
  const Read b = read("y, x ,label\r\n2,1,a\r\n\n4,3,b", xy);  // blanks, CRLF, a blank line, no final '\n'
  ASSERT_EQ(a.error, "");
  ASSERT_EQ(b.error, "");
  EXPECT_EQ(a.rows, b.rows);
  EXPECT_EQ(a.rows, (std::vector<std::vector<double>>{{1, 2}, {3, 4}}));
}

TEST(Csv, BadFilesAreOneLineNamingFileAndLine) {
  const csv::Columns xy{{"x", "y"}};
  EXPECT_THAT(read("x,z\n1,2\n", xy).error, HasSubstr("t.csv:1: the header has no column 'y'"));
  EXPECT_THAT(read("x,y,x\n1,2,3\n", xy).error, HasSubstr("t.csv:1: column 'x' appears twice"));
  EXPECT_THAT(read("x,y,w\n1,2,3\n", {{"x", "y"}, {}, false}).error, HasSubstr("t.csv:1: unknown column 'w'"));
  EXPECT_THAT(read("x,y\n1,2\n1\n", xy).error, HasSubstr("t.csv:3: expected 2 fields like the header, found 1"));
  EXPECT_THAT(read("x,y\n1,nan\n", xy).error, HasSubstr("t.csv:2: y 'nan' is not a finite number"));
  EXPECT_THAT(read("x,y\n1,1e400\n", xy).error, HasSubstr("t.csv:2: y '1e400' is not a finite number"));
  EXPECT_THAT(read("x,y\n1,2x\n", xy).error, HasSubstr("t.csv:2: y '2x'"));
  EXPECT_THAT(read("", xy).error, HasSubstr("t.csv: empty; expected a header naming x,y"));
  EXPECT_EQ(read("+1.5,2\n", {{"+1.5", "2"}}).rows.size(), 0u);  // header only: no rows, no error
}

TEST(Csv, ALogsTornLastLineIsIgnored) {
  const csv::Columns xy{{"x", "y"}};
  EXPECT_EQ(read("x,y\n1,2\n3,", xy, csv::LastLine::kIgnoreTorn).rows.size(), 1u);
  EXPECT_THAT(read("x,y\n1,2\n3,", xy, csv::LastLine::kRead).error, HasSubstr("t.csv:3"));
  EXPECT_EQ(read("", xy, csv::LastLine::kIgnoreTorn).error, "");  // a log whose writer died at once
}

TEST(Csv, NumbersWrittenReadBackExactly) {
  std::string text = "v,i\n";
  const double values[] = {0.1, -1e-300, 123456789.123456789, std::nextafter(1.0, 2.0)};
  for (double v : values) {
    csv::append_double(text, v);
    text += ',';
    csv::append_int(text, -9007199254740993);
    text += '\n';
  }
  std::vector<double> back;
  csv::for_each_row("n.csv", text, {{"v", "i"}}, csv::LastLine::kRead, [&](const csv::Row& row) {
    back.push_back(row.real("v"));
    EXPECT_EQ(row.integer("i"), -9007199254740993);
  });
  EXPECT_EQ(back, std::vector<double>(std::begin(values), std::end(values)));
}

TEST(InputFile, MissingDirectoryDeviceAndUnreadableAreToldApart) {
  const auto dir = std::filesystem::temp_directory_path() / ("lumar-input-file-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  EXPECT_EQ(input_file_problem(dir / "nope"), "not found");
  EXPECT_EQ(input_file_problem(dir), "is a directory, not a file");
  EXPECT_EQ(input_file_problem("/dev/zero"), "is a device or a pipe, not a file");
  std::ofstream(dir / "f.txt") << "hello";
  EXPECT_EQ(input_file_problem(dir / "f.txt"), std::nullopt);
  EXPECT_EQ(read_input_file(dir / "f.txt", "note"), "hello");
  try {
    read_input_file(dir / "f.txt", "note", 3);
    ADD_FAILURE() << "a file over the limit was read";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("f.txt: note of 5 bytes is larger than the 3 bytes allowed"));
  }
  try {
    check_input_file("/dev/null", "scene manifest");
    ADD_FAILURE() << "/dev/null was taken for a file";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("/dev/null: scene manifest is a device or a pipe, not a file"));
  }
  std::filesystem::remove_all(dir);
}

TEST(InputFile, ExtensionsAreComparedInLowerCase) {
  EXPECT_EQ(lower_case_extension("dir.v2/MAP.EXR"), ".exr");
  EXPECT_EQ(lower_case_extension("figurine.Ply"), ".ply");
  EXPECT_EQ(lower_case_extension("dir.v2/README"), "");
}

}  // namespace
}  // namespace lumar
