// The option checks every tool shares. Numbers: decimal only, plain messages, and the value
// the option receives is the one checked. Texts: no empty value taken for "not given", and
// ids that can travel as DDS keys.

#include "agents/cli/number_checks.hpp"
#include "agents/cli/text_checks.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace drover::cli {
namespace {

/// Parses `--n VALUE` into an option of type T transformed by `check`. \return the error
/// message, or "" with `value` set.
template <class T>
std::string parse(const std::string& text, CLI::Validator check, T& value) {
  CLI::App app;
  app.add_option("--n", value)->transform(std::move(check));
  std::vector<std::string> arguments{text, "--n"};  // CLI11 takes them in reverse order
  try {
    app.parse(arguments);
  } catch (const CLI::ParseError& error) {
    return error.what();
  }
  return "";
}

TEST(NumberChecks, WholeNumbersAreReadAsDecimalsWhateverTheirLeadingZeros) {
  std::size_t count = 0;
  EXPECT_EQ(parse("010", whole_in(1, 100), count), "");
  EXPECT_EQ(count, 10u) << "not octal";
  EXPECT_EQ(parse("1e2", whole_in(1, 100), count), "");
  EXPECT_EQ(count, 100u);
  EXPECT_EQ(parse("+7", whole_in(1, 100), count), "");
  EXPECT_EQ(count, 7u);
  int domain = -1;
  EXPECT_EQ(parse("007", whole_in(0, 232), domain), "");
  EXPECT_EQ(domain, 7);
}

TEST(NumberChecks, OtherNotationsAreNotNumbers) {
  std::size_t count = 0;
  for (const char* text : {"0x0A", "0b11", "abc", "inf", "nan", "1e", " 3", "", "1,5", "+-0", "++1"}) {
    SCOPED_TRACE(text);
    EXPECT_NE(parse(text, whole_in(1, 100), count).find("is not a number"), std::string::npos);
    double seconds = 0;
    EXPECT_NE(parse(text, positive(), seconds).find("is not a number"), std::string::npos);
  }
}

TEST(NumberChecks, RangesAndSignsAreNamedWithTheValueAsGiven) {
  std::size_t count = 0;
  EXPECT_NE(parse("1.5", whole_in(1, 100), count).find("must be a whole number, got 1.5"),
            std::string::npos);
  EXPECT_NE(parse("0", whole_in(1, 100), count).find("must be from 1 to 100, got 0"),
            std::string::npos);
  EXPECT_NE(parse("99999999999999999999", whole_in(1, 1000000), count)
                .find("must be from 1 to 1000000, got 99999999999999999999"),
            std::string::npos)
      << "not clamped to the type's largest value";
  double seconds = 0;
  EXPECT_NE(parse("0", positive(), seconds).find("must be > 0, got 0"), std::string::npos);
  EXPECT_NE(parse("-0.5", non_negative(), seconds).find("must be >= 0, got -0.5"),
            std::string::npos);
  EXPECT_NE(parse("1e400", number_in(0.01, 1000), seconds).find("is not a number"),
            std::string::npos);
  EXPECT_EQ(parse("0.25", number_in(0.01, 1000), seconds), "");
  EXPECT_DOUBLE_EQ(seconds, 0.25);
  EXPECT_EQ(parse("1e-3", positive(), seconds), "");
  EXPECT_DOUBLE_EQ(seconds, 0.001);
  EXPECT_EQ(parse("-0", non_negative(), seconds), "");
  EXPECT_EQ(seconds, 0.0);
  // Seconds beyond any use would overflow as nanoseconds.
  EXPECT_NE(parse("1e300", positive(), seconds).find("must be at most 1000000000, got 1e300"),
            std::string::npos);
  EXPECT_EQ(parse("1e9", non_negative(), seconds), "");
}

TEST(NumberChecks, DecimalsInsideOptionValuesAreReadTheSameWay) {
  EXPECT_EQ(parse_decimal("2.5"), 2.5);
  EXPECT_EQ(parse_decimal("+3"), 3.0);
  EXPECT_EQ(parse_decimal("010"), 10.0);
  for (const char* text : {"0x5", " 1", "1 ", "inf", "", "+-1", "5s"}) {
    EXPECT_FALSE(parse_decimal(text).has_value()) << text;
  }
}

TEST(NumberChecks, NanosecondTimesAreReadExactlyBeyondWhatADoubleHolds) {
  std::int64_t ns = 0;
  // 2^53 + 1: a double would read 9007199254740992.
  EXPECT_EQ(parse("9007199254740993", exact_whole_in(0, INT64_MAX), ns), "");
  EXPECT_EQ(ns, 9007199254740993);
  EXPECT_EQ(parse("0001800000000000000001", exact_whole_in(0, INT64_MAX), ns), "");
  EXPECT_EQ(ns, 1800000000000000001) << "leading zeros are not octal";
  EXPECT_EQ(parse("9223372036854775807", exact_whole_in(0, INT64_MAX), ns), "");
  EXPECT_EQ(ns, INT64_MAX);
  EXPECT_EQ(parse("-9223372036854775808", exact_whole_in(INT64_MIN, 0), ns), "");
  EXPECT_EQ(ns, INT64_MIN);
  EXPECT_EQ(parse("+12", exact_whole_in(0, 100), ns), "");
  EXPECT_EQ(ns, 12);
}

TEST(NumberChecks, NanosecondTimesOutOfRangeOrNotInDigitsAreRefused) {
  std::int64_t ns = 0;
  EXPECT_NE(parse("9223372036854775808", exact_whole_in(0, INT64_MAX), ns)
                .find("must be from 0 to 9223372036854775807, got 9223372036854775808"),
            std::string::npos);
  EXPECT_NE(parse("99999999999999999999999", exact_whole_in(0, 100), ns).find("must be from 0 to 100"),
            std::string::npos);
  EXPECT_NE(parse("-1", exact_whole_in(0, 100), ns).find("must be from 0 to 100, got -1"),
            std::string::npos);
  EXPECT_NE(parse("1e9", exact_whole_in(0, INT64_MAX), ns).find("must be a whole number in digits, got 1e9"),
            std::string::npos);
  EXPECT_NE(parse("1.0", exact_whole_in(0, INT64_MAX), ns).find("must be a whole number in digits"),
            std::string::npos);
  for (const char* text : {"0x10", "abc", "", "-", "+", "+-1", " 5", "5 "}) {
    SCOPED_TRACE(text);
    EXPECT_NE(parse(text, exact_whole_in(0, INT64_MAX), ns).find("is not a number"), std::string::npos);
  }
}

TEST(TextChecks, IdsMustBeFitToTravelAsDdsKeys) {
  std::string id;
  EXPECT_EQ(parse("V1", identifier(), id), "");
  EXPECT_EQ(id, "V1");
  EXPECT_EQ(parse(std::string(255, 'v'), identifier(), id), "");
  EXPECT_NE(parse("", identifier(), id).find("--n: must not be empty"), std::string::npos);
  EXPECT_NE(parse(std::string(256, 'v'), identifier(), id).find("is 256 bytes long, at most 255 are allowed"),
            std::string::npos);
  EXPECT_NE(parse("V\n1", identifier(), id).find("'V\\x0a1' contains the control character 0x0a at byte 1"),
            std::string::npos)
      << parse("V\n1", identifier(), id);
}

TEST(TextChecks, AnEmptyTextIsRefusedNotTakenForNotGiven) {
  std::string file;
  EXPECT_EQ(parse("journal.db", non_empty(), file), "");
  EXPECT_NE(parse("", non_empty(), file).find("--n: must not be empty"), std::string::npos);
}

}  // namespace
}  // namespace drover::cli
