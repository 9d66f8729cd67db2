#include "bbw/common/strict_yaml.hpp"

#include <gtest/gtest.h>

using bbw::config::ConfigError;
using bbw::config::Range;
using bbw::config::Reader;

namespace {

// Runs f, expects a ConfigError, returns it.
template <class F>
ConfigError expect_error(F f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "expected ConfigError";
  return ConfigError("", 0, "", "");
}

}  // namespace

TEST(StrictYaml, ReadsValidValues) {
  auto r = Reader::from_string("a: 1.5\nb: 3\nc: true\nd: hello\ne: [1, 2]\nf: {g: 2}\n", "t.yaml");
  EXPECT_DOUBLE_EQ(r.number("a", Range::positive()), 1.5);
  EXPECT_EQ(r.integer("b", 0, 5), 3);
  EXPECT_TRUE(r.boolean("c"));
  EXPECT_EQ(r.string("d"), "hello");
  EXPECT_EQ(r.numbers("e").size(), 2u);
  auto f = r.map("f");
  EXPECT_DOUBLE_EQ(f.number("g"), 2.0);
  EXPECT_DOUBLE_EQ(r.number_or("missing", 7.0), 7.0);
  EXPECT_NO_THROW(f.finish());
  EXPECT_NO_THROW(r.finish());
}

TEST(StrictYaml, UnknownKeyNamesFileLineAndPath) {
  auto r = Reader::from_string("a: 1\nsub:\n  known: 2\n  typo_key: 3\n", "plant.yaml");
  r.number("a");
  auto sub = r.map("sub");
  sub.number("known");
  const auto e = expect_error([&] { sub.finish(); });
  EXPECT_EQ(e.file(), "plant.yaml");
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.key_path(), "sub.typo_key");
  EXPECT_EQ(e.rule(), "unknown key");
  EXPECT_NE(std::string(e.what()).find("plant.yaml:4: key 'sub.typo_key': unknown key"), std::string::npos)
      << e.what();
}

TEST(StrictYaml, MissingRequiredKey) {
  auto r = Reader::from_string("x:\n  a: 1\n", "m.yaml");
  auto x = r.map("x");
  const auto e = expect_error([&] { x.number("b"); });
  EXPECT_EQ(e.key_path(), "x.b");
  EXPECT_EQ(e.rule(), "required key is missing");
  EXPECT_EQ(e.line(), 2);
}

TEST(StrictYaml, WrongType) {
  auto r = Reader::from_string("a: fast\nb: [1]\nc: 3\nd: 1.5\n", "w.yaml");
  auto e = expect_error([&] { r.number("a"); });
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(e.rule().find("must be a number"), std::string::npos);
  e = expect_error([&] { r.number("b"); });
  EXPECT_NE(e.rule().find("got a list"), std::string::npos);
  e = expect_error([&] { r.boolean("c"); });
  EXPECT_NE(e.rule().find("true or false"), std::string::npos);
  e = expect_error([&] { r.integer("d", 0, 10); });
  EXPECT_NE(e.rule().find("integer"), std::string::npos);
}

TEST(StrictYaml, OutOfRangeAndNonFinite) {
  auto r = Reader::from_string("gain: -2\nn: .nan\nk: 11\nmode: fancy\nv: [1, -1]\n", "r.yaml");
  auto e = expect_error([&] { r.number("gain", Range::positive()); });
  EXPECT_EQ(e.rule(), "must be > 0, got -2");
  EXPECT_EQ(e.line(), 1);
  e = expect_error([&] { r.number("n"); });
  EXPECT_NE(e.rule().find("finite"), std::string::npos);
  e = expect_error([&] { r.integer("k", 0, 10); });
  EXPECT_EQ(e.rule(), "must be an integer in [0, 10], got 11");
  e = expect_error([&] { r.choice("mode", {"paper", "robust"}); });
  EXPECT_EQ(e.rule(), "must be one of {paper, robust}, got 'fancy'");
  e = expect_error([&] { r.numbers("v", Range::non_negative()); });
  EXPECT_EQ(e.key_path(), "v[1]");
}

TEST(StrictYaml, SyntaxErrorHasLine) {
  const auto e = expect_error([] { Reader::from_string("a: 1\nb: [1, 2\nc: 3\n", "s.yaml"); });
  EXPECT_GT(e.line(), 1);
  EXPECT_NE(e.rule().find("YAML syntax error"), std::string::npos);
}

TEST(StrictYaml, MissingFileAndNonMapping) {
  auto e = expect_error([] { Reader::from_file("/nonexistent/bbw.yaml"); });
  EXPECT_EQ(e.rule(), "cannot open file");
  e = expect_error([] { Reader::from_string("- 1\n- 2\n", "l.yaml"); });
  EXPECT_NE(e.rule().find("mapping"), std::string::npos);
}

TEST(StrictYaml, ResolveRelative) {
  EXPECT_EQ(bbw::config::resolve_relative("config/scenarios/a.yaml", "../plant/p.yaml"),
            "config/scenarios/../plant/p.yaml");
  EXPECT_EQ(bbw::config::resolve_relative("a.yaml", "p.yaml"), "p.yaml");
  EXPECT_EQ(bbw::config::resolve_relative("x/a.yaml", "/abs/p.yaml"), "/abs/p.yaml");
}

TEST(StrictYaml, StringListsAreReadAndEmptyOrNestedOnesRefused) {
  auto r = Reader::from_string("a: [x, y]\nb: []\nc: [x, [y]]\nd: 3\n", "s.yaml");
  EXPECT_EQ(r.strings("a"), (std::vector<std::string>{"x", "y"}));
  EXPECT_NE(std::string(expect_error([&] { r.strings("b"); }).what()).find("s.yaml:2: key 'b'"), std::string::npos);
  EXPECT_NE(expect_error([&] { r.strings("c"); }).rule().find("entry 1 must be a string"), std::string::npos);
  EXPECT_NE(expect_error([&] { r.strings("d"); }).rule().find("non-empty list of strings"), std::string::npos);
  EXPECT_NE(expect_error([&] { r.strings("missing"); }).rule().find("required"), std::string::npos);
  EXPECT_NO_THROW(r.finish());  // every key was read
}
