#pragma once
// Outputs that appear whole or not at all. Each is written under a temporary name
// beside the final one, ".NAME.partial-PID-N.EXT" (unique to the writer; the extension
// kept, so that a writer that picks its format by extension picks the same one), and
// renamed into place by commit(), after an fsync; without commit() the temporary is
// removed. A reader sees the old file or the new one, never a mix, and a crash leaves
// at most a hidden ".*.partial-*" beside the output.
//
// Errors: InputError when the output's folder does not exist or the path is a folder;
// RuntimeError, naming the final path, when writing, syncing or renaming fails.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace lumar {

class OutputFile {
 public:
  explicit OutputFile(std::filesystem::path path);
  ~OutputFile();  // removes the temporary unless committed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  const std::filesystem::path& path() const { return path_; }            // the final name
  const std::filesystem::path& temporary() const { return temporary_; }  // where to write
  // Syncs the temporary, renames it over path(), syncs the folder. Once only.
  void commit();

 private:
  std::filesystem::path path_, temporary_;
  bool committed_ = false;
};

// The same for a folder of files: write into temporary(), then commit(). The final
// folder must not exist yet (InputError).
class OutputFolder {
 public:
  explicit OutputFolder(std::filesystem::path path);
  ~OutputFolder();  // removes the temporary folder unless committed
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& temporary() const { return temporary_; }
  void commit();

 private:
  std::filesystem::path path_, temporary_;
  bool committed_ = false;
};

// `contents` into `path` through an OutputFile.
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

// InputError when `output` (given as `option`) is the same file as one of `inputs`
// (std::filesystem::equivalent, so links and other spellings count), checked before
// anything is written: an output is never allowed to replace what it is made from.
void refuse_output_over_input(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs,
                              const std::string& option = "--out");

// fsync(2) of a file or a folder (a folder must be synced to make a rename or a new
// entry durable). RuntimeError naming it on failure.
void fsync_path(const std::filesystem::path& path);

}  // namespace lumar
