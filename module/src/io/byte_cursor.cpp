#include "io/byte_cursor.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace meccano::readers {
namespace {

// from_chars rejects a leading '+', which text formats allow.
std::string_view without_plus(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  return text;
}

bool is_blank(char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\f' || ch == '\v'; }

}  // namespace

std::string read_file_bytes(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) throw InputError(path + ": cannot open file (it is a directory)");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path + ": cannot open file");
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path + ": cannot read file");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) throw InputError(path + ": cannot read file");
  if (bytes.empty()) throw InputError(path + ": empty file");
  return bytes;
}

std::string quoted(std::string_view text, std::size_t max_shown) {
  std::string shown;
  for (const char ch : text.substr(0, max_shown)) {
    const auto code = static_cast<unsigned char>(ch);
    shown += (code < 0x20 || code == 0x7f) ? '?' : ch;
  }
  if (text.size() > max_shown) shown += "...";
  return "'" + shown + "'";
}

bool iequals(std::string_view a, std::string_view b) {
  return std::ranges::equal(a, b, [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  });
}

std::optional<Token> ByteCursor::next_token() {
  skip_blanks(/*cross_lines=*/true);
  return token_here();
}

std::optional<Token> ByteCursor::next_token_on_line() {
  skip_blanks(/*cross_lines=*/false);
  return token_here();
}

Token ByteCursor::expect_token(std::string_view what) {
  if (auto token = next_token()) return *token;
  fail_at_end(what);
}

Token ByteCursor::expect_token_on_line(std::string_view what) {
  if (auto token = next_token_on_line()) return *token;
  if (pos_ == bytes_.size()) fail_at_end(what);
  fail("expected " + std::string(what) + " before the end of the line");
}

Token ByteCursor::expect_keyword(std::string_view keyword) {
  const Token token = expect_token(quoted(keyword));
  if (!iequals(token.text, keyword))
    fail_at(token.line, "expected " + quoted(keyword) + ", found " + quoted(token.text));
  return token;
}

std::string_view ByteCursor::rest_of_line() {
  const std::size_t end = bytes_.find('\n', pos_);
  const std::string_view rest = bytes_.substr(pos_, end == std::string_view::npos ? end : end - pos_);
  pos_ = end == std::string_view::npos ? bytes_.size() : end + 1;
  if (end != std::string_view::npos) ++line_;
  return rest;
}

std::optional<std::string_view> ByteCursor::text_until(std::string_view marker) {
  const std::size_t found = bytes_.find(marker, pos_);
  if (found == std::string_view::npos) return std::nullopt;
  const std::string_view text = bytes_.substr(pos_, found - pos_);
  const std::size_t end = found + marker.size();
  line_ += static_cast<int>(std::ranges::count(bytes_.substr(pos_, end - pos_), '\n'));
  pos_ = end;
  return text;
}

long long ByteCursor::integer(const Token& token, std::string_view what) const {
  const std::string_view text = without_plus(token.text);
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error == std::errc::invalid_argument || end != text.data() + text.size())
    fail_at(token.line, "malformed " + std::string(what) + " " + quoted(token.text));
  if (error == std::errc::result_out_of_range)
    fail_at(token.line, std::string(what) + " " + quoted(token.text) + " is out of range");
  return value;
}

double ByteCursor::number(const Token& token, std::string_view what) const {
  const std::string_view text = without_plus(token.text);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error == std::errc::invalid_argument || end != text.data() + text.size())
    fail_at(token.line, "malformed " + std::string(what) + " " + quoted(token.text));
  // from_chars leaves the value unset when out of range: overflow becomes infinite (and rejected
  // by the callers that need finite values), underflow is as good as zero.
  if (error == std::errc::result_out_of_range) value = std::strtod(std::string(text).c_str(), nullptr);
  return value;
}

double ByteCursor::coordinate(const Token& token) const {
  const double value = number(token, "coordinate");
  if (!std::isfinite(value)) fail_at(token.line, "non-finite coordinate " + quoted(token.text));
  return value;
}

void ByteCursor::check_count(std::uint64_t count, std::uint64_t min_bytes, std::string_view what) const {
  if (count > remaining() / min_bytes)
    fail("absurd " + std::string(what) + " count " + std::to_string(count) + ": cannot fit in the " +
         std::to_string(remaining()) + " bytes left in the file");
}

void ByteCursor::fail_at_end(std::string_view what) const {
  const bool final_newline = !bytes_.empty() && bytes_.back() == '\n';
  fail_at(final_newline ? line_ - 1 : line_, "unexpected end of file (expected " + std::string(what) + ")");
}

void ByteCursor::fail_at(int line, const std::string& defect) const {
  if (binary_seen_) throw InputError(path_ + ": byte " + std::to_string(pos_) + ": " + defect);
  throw InputError(path_ + ":" + std::to_string(line) + ": " + defect);
}

void ByteCursor::require_bytes(std::uint64_t count, std::string_view what) {
  binary_seen_ = true;
  if (count > remaining()) fail("unexpected end of file: truncated binary data (" + std::string(what) + ")");
}

void ByteCursor::skip_blanks(bool cross_lines) {
  while (pos_ < bytes_.size()) {
    const char ch = bytes_[pos_];
    if (ch == '\n') {
      if (!cross_lines) return;
      ++line_;
      ++pos_;
    } else if (is_blank(ch)) {
      ++pos_;
    } else if (comment_ != '\0' && ch == comment_) {
      const std::size_t end = bytes_.find('\n', pos_);
      pos_ = end == std::string_view::npos ? bytes_.size() : end;
    } else {
      return;
    }
  }
}

std::optional<Token> ByteCursor::token_here() {
  if (pos_ == bytes_.size() || bytes_[pos_] == '\n') return std::nullopt;
  const std::size_t begin = pos_;
  while (pos_ < bytes_.size() && bytes_[pos_] != '\n' && !is_blank(bytes_[pos_]) &&
         (comment_ == '\0' || bytes_[pos_] != comment_))
    ++pos_;
  return Token{bytes_.substr(begin, pos_ - begin), line_};
}

}  // namespace meccano::readers
