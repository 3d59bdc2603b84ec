#include <meccano/report/json_writer.hpp>

#include <cmath>
#include <stdexcept>

namespace meccano {
namespace {

void append_quoted(std::string& out, std::string_view text) {
  static constexpr char hex[] = "0123456789abcdef";
  out += '"';
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (byte < 0x20) {
      out += "\\u00";
      out += hex[byte >> 4];
      out += hex[byte & 15];
    } else {
      out += ch;
    }
  }
  out += '"';
}

}  // namespace

// Every member starts on its own line, after a comma unless it is its container's first.
void JsonWriter::begin_member(Frame& frame) {
  if (!frame.empty) text_ += ',';
  frame.empty = false;
  text_ += '\n';
  text_.append(2 * open_.size(), ' ');
}

void JsonWriter::begin_value() {
  if (finished_) throw std::logic_error("JSON: a value after the end of the document");
  if (open_.empty()) return;
  Frame& frame = open_.back();
  if (!frame.object) {
    begin_member(frame);
  } else {
    if (!frame.keyed) throw std::logic_error("JSON: a value in an object without a key");
    frame.keyed = false;  // key() began the member
  }
}

JsonWriter& JsonWriter::key(std::string_view name) {
  if (open_.empty() || !open_.back().object) throw std::logic_error("JSON: a key outside an object");
  Frame& frame = open_.back();
  if (frame.keyed) throw std::logic_error("JSON: a key after a key");
  begin_member(frame);
  append_quoted(text_, name);
  text_ += ": ";
  frame.keyed = true;
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view text) {
  std::string quoted;
  append_quoted(quoted, text);
  return scalar(quoted);
}

JsonWriter& JsonWriter::value(double number) {
  if (!std::isfinite(number)) return null();
  char buffer[32];
  const char* end = std::to_chars(buffer, buffer + sizeof buffer, number).ptr;
  return scalar({buffer, static_cast<std::size_t>(end - buffer)});
}

JsonWriter& JsonWriter::scalar(std::string_view token) {
  begin_value();
  text_ += token;
  finished_ = open_.empty();
  return *this;
}

JsonWriter& JsonWriter::open(bool object, char bracket) {
  begin_value();
  text_ += bracket;
  open_.push_back({object});
  return *this;
}

JsonWriter& JsonWriter::close(bool object, char bracket) {
  if (open_.empty() || open_.back().object != object)
    throw std::logic_error(std::string("JSON: '") + bracket + "' without its '" + (object ? '{' : '[') + "'");
  if (open_.back().keyed) throw std::logic_error("JSON: a key without a value");
  const bool empty = open_.back().empty;
  open_.pop_back();
  if (!empty) {
    text_ += '\n';
    text_.append(2 * open_.size(), ' ');
  }
  text_ += bracket;
  finished_ = open_.empty();
  return *this;
}

std::string JsonWriter::str() const {
  if (!finished_) throw std::logic_error("JSON: the document is unfinished");
  return text_ + '\n';
}

}  // namespace meccano
