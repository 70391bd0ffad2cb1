// TextLines: splitting lines into fields and parsing numbers with std::from_chars (no
// locale, no errno, and a field that is not wholly a number is refused, not half read).
#include "wavetrace/scene/text_lines.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <new>

#include <fmt/format.h>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Shown in messages as written, cut short and with control bytes escaped, so a binary
// file's garbage cannot garble the terminal.
std::string printable(std::string_view field) {
  constexpr std::size_t kShown = 24;
  std::string shown;
  for (const char c : field.substr(0, kShown)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f) shown += c;
    else shown += fmt::format("\\x{:02x}", byte);
  }
  if (field.size() > kShown) shown += "...";
  return shown;
}

}  // namespace

TextLines::TextLines(std::string_view text, std::string path, char comment, std::size_t first_line)
    : rest_(text), path_(std::move(path)), comment_(comment), line_(first_line - 1) {}

bool TextLines::next(std::vector<std::string_view>& fields) {
  while (!rest_.empty()) {
    const std::size_t end = rest_.find('\n');
    std::string_view text = rest_.substr(0, end);
    rest_ = end == std::string_view::npos ? std::string_view() : rest_.substr(end + 1);
    ++line_;
    if (const std::size_t comment = text.find(comment_); comment_ != '\0' && comment != std::string_view::npos) {
      text = text.substr(0, comment);
    }
    fields.clear();
    std::size_t at = 0;
    while (at < text.size()) {
      while (at < text.size() && is_blank(text[at])) ++at;
      std::size_t stop = at;
      while (stop < text.size() && !is_blank(text[stop])) ++stop;
      if (stop > at) fields.push_back(text.substr(at, stop - at));
      at = stop;
    }
    if (!fields.empty()) return true;
  }
  return false;
}

void TextLines::fail(std::string_view problem) const {
  throw SceneError(fmt::format("{} line {}: {}", path_, line_, problem));
}

float TextLines::real(std::string_view field, std::string_view what) const {
  std::string_view digits = field;
  if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);  // from_chars takes no '+'
  double value = 0.0;
  const auto [stop, status] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (status == std::errc::result_out_of_range) {
    fail(fmt::format("{} '{}' is out of range", what, printable(field)));
  }
  if (status != std::errc() || stop != digits.data() + digits.size()) {
    fail(fmt::format("{} '{}' is not a number", what, printable(field)));
  }
  if (!std::isfinite(value)) fail(fmt::format("{} '{}' is not a finite number", what, printable(field)));
  if (std::fabs(value) > std::numeric_limits<float>::max()) {
    fail(fmt::format("{} '{}' is beyond a float's range", what, printable(field)));
  }
  return static_cast<float>(value);
}

std::int64_t TextLines::integer(std::string_view field, std::string_view what, std::int64_t lowest,
                                std::int64_t highest) const {
  std::string_view digits = field;
  if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
  std::int64_t value = 0;
  const auto [stop, status] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (status == std::errc() && stop == digits.data() + digits.size()) {
    if (value < lowest || value > highest) {
      fail(fmt::format("{} {} is out of range [{}, {}]", what, value, lowest, highest));
    }
    return value;
  }
  if (status == std::errc::result_out_of_range) fail(fmt::format("{} '{}' is out of range", what, printable(field)));
  fail(fmt::format("{} '{}' is not an integer", what, printable(field)));
}

std::string read_whole_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) throw SceneError(fmt::format("{}: cannot open the file", path));
  const std::streamoff size = file.tellg();
  if (size < 0) throw SceneError(fmt::format("{}: cannot read the file's size", path));
  std::string bytes;
  try {
    bytes.resize(static_cast<std::size_t>(size));
  } catch (const std::bad_alloc&) {
    throw SceneError(fmt::format("{}: out of memory reading the file ({} bytes)", path, size));
  }
  file.seekg(0);
  if (!file.read(bytes.data(), size)) throw SceneError(fmt::format("{}: cannot read the file", path));
  return bytes;
}

}  // namespace wavetrace
