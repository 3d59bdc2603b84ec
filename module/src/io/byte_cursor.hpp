// The read position in a file's bytes that the file readers of io/ parse with, and what they share
// around it: loading a file, showing a token in a message.
//
// Input   a file's path (for messages) and its bytes, which must outlive the cursor; optionally a
//         comment character, whose text runs to the end of the line.
// Output  whitespace-separated text tokens with their line numbers, numbers parsed from them, raw
//         text up to a marker or the end of the line, binary values in native or little-endian order.
// Errors  InputError "PATH:LINE: defect" until binary data has been read, "PATH: byte OFFSET: defect"
//         after (binary data holds newline bytes by chance, so its line numbers mean nothing): a
//         malformed or out-of-range number, a non-finite coordinate, the end of the file where a token
//         or a value is expected, a count whose items cannot fit in the bytes left (checked before
//         anything is allocated from it, so a corrupt count is an error, not a bad_alloc).
#pragma once

#include <meccano/error.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace meccano::readers {

// The whole file. InputError: a directory, a file that cannot be opened or read, an empty file.
std::string read_file_bytes(const std::string& path);

// A token for an error message: file contents may be binary garbage or a megabyte without spaces.
std::string quoted(std::string_view text, std::size_t max_shown = 40);

bool iequals(std::string_view a, std::string_view b);  // ASCII, case-insensitive

struct Token {
  std::string_view text;
  int line = 0;
};

class ByteCursor {
 public:
  ByteCursor(std::string path, std::string_view bytes, char comment = '\0')
      : path_(std::move(path)), bytes_(bytes), comment_(comment) {}

  const std::string& path() const { return path_; }
  std::size_t remaining() const { return bytes_.size() - pos_; }

  std::optional<Token> next_token();
  std::optional<Token> next_token_on_line();  // none when the current line has none left
  Token expect_token(std::string_view what);
  Token expect_token_on_line(std::string_view what);
  Token expect_keyword(std::string_view keyword);  // case-insensitive
  void skip_line() { rest_of_line(); }
  // The raw rest of the current line (comments included), moving to the start of the next one.
  std::string_view rest_of_line();
  // Moves just past the next occurrence of `marker`; false (and no move) when there is none.
  bool skip_past(std::string_view marker) { return text_until(marker).has_value(); }
  // The raw text up to the next occurrence of `marker`, moving just past it; none (and no move) when
  // there is none.
  std::optional<std::string_view> text_until(std::string_view marker);

  long long integer(const Token& token, std::string_view what) const;
  double number(const Token& token, std::string_view what) const;  // overflow: infinite
  double coordinate(const Token& token) const;                     // finite

  template <class T>
  T binary(std::string_view what, std::endian order = std::endian::native) {
    require_bytes(sizeof(T), what);
    std::array<char, sizeof(T)> raw;
    std::memcpy(raw.data(), bytes_.data() + pos_, sizeof(T));
    if (order != std::endian::native) std::ranges::reverse(raw);
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  void skip_bytes(std::uint64_t count, std::string_view what) {
    require_bytes(count, what);
    pos_ += static_cast<std::size_t>(count);
  }

  // Refuses a header count whose items, at `min_bytes` each, cannot fit in the rest of the file.
  void check_count(std::uint64_t count, std::uint64_t min_bytes, std::string_view what) const;

  [[noreturn]] void fail(const std::string& defect) const { fail_at(line_, defect); }
  // At the end of the file, the last line: the one a final newline ends, not the empty one after it.
  [[noreturn]] void fail_at_end(std::string_view what) const;
  [[noreturn]] void fail_at(int line, const std::string& defect) const;

 private:
  // Marks binary data as read (errors give a byte offset from now on); refuses a read past the end.
  void require_bytes(std::uint64_t count, std::string_view what);
  void skip_blanks(bool cross_lines);
  std::optional<Token> token_here();

  std::string path_;
  std::string_view bytes_;
  char comment_;
  std::size_t pos_ = 0;
  int line_ = 1;
  bool binary_seen_ = false;
};

}  // namespace meccano::readers
