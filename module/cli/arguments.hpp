// The command line of the project's programs (meccano-immerse, reference-gmsh, reference-tetgen and the
// deal.II demo's poisson_interface and convergence_study): declared options, the numbers they take and
// the usage error, exit status 2. Header-only and apart from the library, which stays Eigen + OpenMP only.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace meccano::tools {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// What main() of a program does with its body: a UsageError becomes "PROGRAM: MESSAGE" and a pointer to
// --help on stderr with status 2, any other exception "PROGRAM: error: MESSAGE" with status 1.
inline int run_reporting_errors(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const UsageError& error) {
    std::cerr << program << ": " << error.what() << "\n(see " << program << " --help)\n";
    return 2;
  } catch (const std::exception& error) {
    std::cerr << program << ": error: " << error.what() << '\n';
    return 1;
  }
}

// Options declared by their names ({"--quiet", "-q"}): flags, and value options that take the argument
// after them whatever it is (--box -1,0,0,1,1,1). Each handler runs where its option stands, so that an
// option may apply to those after it (meccano-immerse's --msh-version) and the first bad argument is the
// one reported; a value option's handler runs at every occurrence, to keep the last value, collect them
// (--surface) or refuse a second. Errors are prefixed by `context` ("check: ").
class ArgumentParser {
 public:
  using ValueHandler = std::function<void(const std::string& value)>;

  explicit ArgumentParser(std::string context = "") : context_(std::move(context)) {}

  ArgumentParser& flag(std::vector<std::string> names, std::function<void()> handler) {
    return declare(std::move(names), false, false, [handler = std::move(handler)](const std::string&) { handler(); });
  }

  // --help and -h: the usage text on stdout, and exit status 0.
  ArgumentParser& help(const char* usage_text) {
    return flag({"--help", "-h"}, [usage_text] {
      std::cout << usage_text;
      std::exit(0);
    });
  }

  ArgumentParser& value(std::vector<std::string> names, ValueHandler handler) {
    return declare(std::move(names), true, false, std::move(handler));
  }

  // Checked once the whole command line is read, in the order of declaration: "NAME is required".
  ArgumentParser& required_value(std::vector<std::string> names, ValueHandler handler) {
    return declare(std::move(names), true, true, std::move(handler));
  }

  // The arguments that do not start with '-' (the mesh file of `meccano-immerse check`); without this
  // handler they are unknown options.
  ArgumentParser& positional(ValueHandler handler) {
    positional_ = std::move(handler);
    return *this;
  }

  // For a handler whose option takes several values (reference-gmsh's --box X0 Y0 Z0 X1 Y1 Z1): the next
  // argument, consumed, unless there is none or it starts with "--" (a negative number does not).
  std::optional<std::string> next_value() {
    if (next_ >= args_.size() || args_[next_].starts_with("--")) return std::nullopt;
    return args_[next_++];
  }

  void parse(std::vector<std::string> args) {
    args_ = std::move(args);
    for (next_ = 0; next_ < args_.size();) {
      const std::string& arg = args_[next_++];
      Option* option = find(arg);
      if (!option && positional_ && !arg.starts_with('-')) {
        positional_(arg);
      } else if (!option) {
        throw UsageError(context_ + "unknown option '" + arg + "'");
      } else if (option->takes_value && next_ >= args_.size()) {
        throw UsageError(context_ + arg + " needs a value");
      } else {
        option->given = true;
        option->handler(option->takes_value ? args_[next_++] : "");
      }
    }
    for (const Option& option : options_)
      if (option.required && !option.given) throw UsageError(context_ + option.names.front() + " is required");
  }

 private:
  struct Option {
    std::vector<std::string> names;
    bool takes_value, required;
    ValueHandler handler;
    bool given = false;
  };

  ArgumentParser& declare(std::vector<std::string> names, bool takes_value, bool required, ValueHandler handler) {
    options_.push_back({std::move(names), takes_value, required, std::move(handler)});
    return *this;
  }

  Option* find(const std::string& arg) {
    for (Option& option : options_)
      for (const std::string& name : option.names)
        if (name == arg) return &option;
    return nullptr;
  }

  std::string context_;
  std::vector<Option> options_;
  ValueHandler positional_;
  std::vector<std::string> args_;
  std::size_t next_ = 0;
};

// The value of the choice that `text` names; UsageError "OPTION TEXT: LISTING" otherwise.
template <class Value>
Value parse_choice(const std::string& option, const std::string& text,
                   std::initializer_list<std::pair<const char*, Value>> choices, const std::string& listing) {
  for (const auto& [name, value] : choices)
    if (text == name) return value;
  throw UsageError(option + " " + text + ": " + listing);
}

// A finite number that is the whole text; UsageError naming the option otherwise.
inline double parse_finite_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw UsageError(option + ": '" + text + "' is not a finite number");
  return value;
}

// `count` comma-separated finite numbers (--box X0,Y0,Z0,X1,Y1,Z1).
inline std::vector<double> parse_numbers(const std::string& option, const std::string& text, std::size_t count) {
  std::vector<double> values;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) values.push_back(parse_finite_number(option, item));
  if (values.size() != count)
    throw UsageError(option + " takes " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  return values;
}

// One finite number of at least 0 (a single number goes through the comma-separated reader, as it always
// did: "1," reads as 1).
inline double parse_non_negative(const std::string& option, const std::string& text) {
  const double value = parse_numbers(option, text, 1)[0];
  if (value < 0) throw UsageError(option + " must not be negative");
  return value;
}

// An integer of type Int that is the whole text, in std::stoll's syntax (leading spaces and '+' allowed).
template <class Int = int>
Int parse_integer(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long long value = 0;
  try {
    value = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::in_range<Int>(value))
    throw UsageError(option + ": '" + text + "' is not an integer");
  return static_cast<Int>(value);
}

// An integer of at least 1 in plain digits, the whole text.
inline int parse_positive_integer(const std::string& option, const std::string& text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || value < 1)
    throw UsageError(option + ": '" + text + "' is not a positive integer");
  return value;
}

}  // namespace meccano::tools
