// The report JSON writer: layout, escaping, numbers that read back exactly, null for non-finite
// doubles, and misuse reported as std::logic_error.

#include <meccano/report/json_writer.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace meccano {
namespace {

TEST(JsonWriter, NestsObjectsAndArraysWithTwoSpaceIndent) {
  JsonWriter json;
  json.begin_object()
      .key("name")
      .value("cube")
      .key("tets")
      .value(std::int64_t{6144})
      .key("threads")
      .value(2)
      .key("ok")
      .value(true)
      .key("quality")
      .begin_object()
      .key("min")
      .value(0.5)
      .key("bins")
      .begin_array()
      .value(1)
      .value(2)
      .end_array()
      .end_object()
      .key("empty_array")
      .begin_array()
      .end_array()
      .key("empty_object")
      .begin_object()
      .end_object()
      .key("none")
      .null()
      .end_object();
  EXPECT_EQ(json.str(), R"({
  "name": "cube",
  "tets": 6144,
  "threads": 2,
  "ok": true,
  "quality": {
    "min": 0.5,
    "bins": [
      1,
      2
    ]
  },
  "empty_array": [],
  "empty_object": {},
  "none": null
}
)");
}

TEST(JsonWriter, EscapesQuotesBackslashesAndControlCharacters) {
  JsonWriter json;
  json.begin_array().value("say \"hi\"\\").value(std::string("tab\tnew\nline\x01\x1f end"));
  json.value("µm ✓").end_array();
  EXPECT_EQ(json.str(), "[\n  \"say \\\"hi\\\"\\\\\",\n  \"tab\\u0009new\\u000aline\\u0001\\u001f end\",\n"
                        "  \"µm ✓\"\n]\n");
  JsonWriter keyed;
  keyed.begin_object().key("a\"b").value(false).end_object();
  EXPECT_EQ(keyed.str(), "{\n  \"a\\\"b\": false\n}\n");
}

TEST(JsonWriter, DoublesReadBackExactlyAndNonFiniteOnesAreNull) {
  for (double x : {0.1, 1e-300, -2.5, 1.0 / 3, 6.02214076e23, std::numeric_limits<double>::denorm_min(),
                   std::numeric_limits<double>::max()}) {
    JsonWriter json;
    const std::string text = json.value(x).str();
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), x) << text;
  }
  EXPECT_EQ(JsonWriter().value(0.1).str(), "0.1\n");
  EXPECT_EQ(JsonWriter().value(1e-300).str(), "1e-300\n");
  JsonWriter json;
  json.begin_array()
      .value(std::numeric_limits<double>::quiet_NaN())
      .value(std::numeric_limits<double>::infinity())
      .value(-std::numeric_limits<double>::infinity())
      .end_array();
  EXPECT_EQ(json.str(), "[\n  null,\n  null,\n  null\n]\n");
  EXPECT_EQ(JsonWriter().value(std::numeric_limits<std::int64_t>::min()).str(), "-9223372036854775808\n");
}

TEST(JsonWriter, MisuseThrowsLogicError) {
  EXPECT_THROW(JsonWriter().begin_object().value(1), std::logic_error);               // value without key
  EXPECT_THROW(JsonWriter().begin_object().key("a").key("b"), std::logic_error);      // key after key
  EXPECT_THROW(JsonWriter().begin_array().key("a"), std::logic_error);                // key in an array
  EXPECT_THROW(JsonWriter().key("a"), std::logic_error);                              // key at the root
  EXPECT_THROW(JsonWriter().begin_object().end_array(), std::logic_error);            // mismatched end
  EXPECT_THROW(JsonWriter().end_object(), std::logic_error);                          // end without begin
  EXPECT_THROW(JsonWriter().begin_object().key("a").end_object(), std::logic_error);  // key without value
  EXPECT_THROW(JsonWriter().value(1).value(2), std::logic_error);                     // two roots
  EXPECT_THROW(JsonWriter().begin_array().end_array().begin_array(), std::logic_error);
  EXPECT_THROW(JsonWriter().begin_array().str(), std::logic_error);  // unfinished
  EXPECT_THROW(JsonWriter().str(), std::logic_error);                // empty
}

}  // namespace
}  // namespace meccano
