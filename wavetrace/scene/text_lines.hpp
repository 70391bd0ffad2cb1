// Line-by-line reading of a text mesh file held in memory, and the parse of its fields:
// every failure names the file, the line and the field, and reads the same on every run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace wavetrace {

class TextLines {
 public:
  // `comment` starts a comment running to the end of its line ('\0': none); `first_line`
  // numbers the first line of `text` (a PLY body follows its header).
  TextLines(std::string_view text, std::string path, char comment = '#', std::size_t first_line = 1);

  // The next line that has a field once its comment is cut off, split on blanks (spaces,
  // tabs, CR, FF, VT); false at the end of the text.
  bool next(std::vector<std::string_view>& fields);
  // The number of the line `next` returned last (0 before the first).
  std::size_t line() const { return line_; }
  const std::string& path() const { return path_; }

  // Throws SceneError "PATH line N: PROBLEM".
  [[noreturn]] void fail(std::string_view problem) const;
  // `field` as a finite number that fits a float; `what` names it in the error
  // ("vertex 3 y coordinate 'nan' is not a finite number").
  float real(std::string_view field, std::string_view what) const;
  // `field` as an integer in [lowest, highest].
  std::int64_t integer(std::string_view field, std::string_view what, std::int64_t lowest, std::int64_t highest) const;

 private:
  std::string_view rest_;
  std::string path_;
  char comment_;
  std::size_t line_;
};

// The whole file, read into memory; throws SceneError when it cannot be read, or when
// memory runs out (naming the file and its size).
std::string read_whole_file(const std::string& path);

}  // namespace wavetrace
