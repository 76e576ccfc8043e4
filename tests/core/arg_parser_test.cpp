#include <gtest/gtest.h>

#include "pspslam/core/arg_parser.h"
#include "pspslam/core/error.h"

namespace pspslam {
namespace {

ArgParser make_parser() {
  ArgParser parser("pspslam demo", "A demo command.");
  parser.add_option("gt", "ground truth", "", true);
  parser.add_option("max-dt", "window", "0.02");
  parser.add_option("count", "how many", "3");
  parser.add_multi_option("images", "images");
  parser.add_switch("json", "json output");
  return parser;
}

std::string error_of(ArgParser& parser, const std::vector<std::string>& args) {
  try {
    parser.parse(args);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ArgParser, ParsesValuesSwitchesAndDefaults) {
  ArgParser parser = make_parser();
  ASSERT_TRUE(
      parser.parse({"--gt", "a.txt", "--json", "--count=7", "--images", "x", "--images", "y"}));
  EXPECT_EQ(parser.get("gt"), "a.txt");
  EXPECT_TRUE(parser.flag("json"));
  EXPECT_EQ(parser.get_int("count"), 7);
  EXPECT_DOUBLE_EQ(parser.get_double("max-dt"), 0.02);
  EXPECT_FALSE(parser.has("max-dt"));
  EXPECT_EQ(parser.get_all("images"), (std::vector<std::string>{"x", "y"}));
}

TEST(ArgParser, UnknownFlagNamesTheFlag) {
  ArgParser parser = make_parser();
  EXPECT_EQ(error_of(parser, {"--gt", "a", "--bogus", "1"}),
            "pspslam demo: unknown flag --bogus (see 'pspslam demo --help')");
}

TEST(ArgParser, MissingRequiredFlag) {
  ArgParser parser = make_parser();
  EXPECT_EQ(error_of(parser, {"--json"}),
            "pspslam demo: missing required flag --gt (see 'pspslam demo --help')");
}

TEST(ArgParser, MissingValue) {
  ArgParser parser = make_parser();
  EXPECT_EQ(error_of(parser, {"--gt"}), "pspslam demo: flag --gt needs a value");
}

TEST(ArgParser, SwitchGivenAValue) {
  ArgParser parser = make_parser();
  EXPECT_EQ(error_of(parser, {"--gt", "a", "--json=1"}),
            "pspslam demo: flag --json takes no value");
}

TEST(ArgParser, PositionalArgumentRejected) {
  ArgParser parser = make_parser();
  EXPECT_EQ(error_of(parser, {"stray"}),
            "pspslam demo: unexpected argument 'stray' (see 'pspslam demo --help')");
}

TEST(ArgParser, MalformedNumbers) {
  ArgParser parser = make_parser();
  ASSERT_TRUE(parser.parse({"--gt", "a", "--max-dt", "0.02x", "--count", "2.5"}));
  try {
    parser.get_double("max-dt");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "pspslam demo: flag --max-dt expects a number, got '0.02x'");
  }
  try {
    parser.get_int("count");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "pspslam demo: flag --count expects an integer, got '2.5'");
  }
}

TEST(ArgParser, HelpListsEveryFlagAndStopsParsing) {
  ArgParser parser = make_parser();
  ::testing::internal::CaptureStdout();
  EXPECT_FALSE(parser.parse({"--help"}));
  const std::string printed = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(printed, parser.help());
  EXPECT_NE(printed.find("usage: pspslam demo [flags]"), std::string::npos);
  EXPECT_NE(printed.find("--gt VALUE              ground truth (required)"), std::string::npos);
  EXPECT_NE(printed.find("--max-dt VALUE          window (default: 0.02)"), std::string::npos);
  EXPECT_NE(printed.find("--images VALUE          images (repeatable)"), std::string::npos);
}

}  // namespace
}  // namespace pspslam
