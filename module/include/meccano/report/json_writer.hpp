// A streaming JSON writer for reports: the document is built call by call, pretty-printed with a
// 2-space indent, and returned by str(); callers write it with write_file_atomically (io/atomic_file.hpp).
//
//   JsonWriter json;
//   json.begin_object().key("tets").value(summary.tets).key("min").value(0.29).end_object();
//
// Strings are UTF-8 and written as given, with quotes, backslashes and control characters escaped.
// Doubles take their shortest round-trip form; NaN and infinities, which JSON lacks, become null.
// Misuse throws std::logic_error: a value without a key in an object, a key outside an object, an end
// that does not match its begin, a second root value, or str() on an unfinished document.
#pragma once

#include <charconv>
#include <concepts>
#include <string>
#include <string_view>
#include <vector>

namespace meccano {

class JsonWriter {
 public:
  JsonWriter& begin_object() { return open(true, '{'); }
  JsonWriter& end_object() { return close(true, '}'); }
  JsonWriter& begin_array() { return open(false, '['); }
  JsonWriter& end_array() { return close(false, ']'); }
  JsonWriter& key(std::string_view name);

  JsonWriter& value(std::string_view text);
  JsonWriter& value(const char* text) { return value(std::string_view(text)); }  // not the bool overload
  JsonWriter& value(double number);
  JsonWriter& value(bool flag) { return scalar(flag ? "true" : "false"); }
  template <std::integral T>
  requires(!std::same_as<T, bool>) JsonWriter& value(T number) {
    char buffer[24];
    const char* end = std::to_chars(buffer, buffer + sizeof buffer, number).ptr;
    return scalar({buffer, static_cast<std::size_t>(end - buffer)});
  }
  JsonWriter& null() { return scalar("null"); }

  // The finished document, ending in a newline.
  std::string str() const;

 private:
  struct Frame {
    bool object;
    bool empty = true;
    bool keyed = false;  // an object's key is written and waits for its value
  };
  JsonWriter& open(bool object, char bracket);
  JsonWriter& close(bool object, char bracket);
  JsonWriter& scalar(std::string_view token);
  void begin_value();
  void begin_member(Frame& frame);

  std::string text_;
  std::vector<Frame> open_;
  bool finished_ = false;
};

}  // namespace meccano
