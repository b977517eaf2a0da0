#include "agents/cli/number_checks.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace drover::cli {

namespace {

/// The text CLI11 reads back as exactly `value`: an integer without a fraction where the
/// value is whole and exact as a double, the shortest round trip otherwise.
std::string plain(double value) {
  if (value == std::floor(value) && std::abs(value) <= kLargestWholeOption) {
    return fmt::format("{}", static_cast<long long>(value));
  }
  return fmt::format("{}", value);
}

enum class Sign { positive, non_negative };

CLI::Validator sign_check(Sign sign) {
  return CLI::Validator(
      [sign](std::string& input) -> std::string {
        const auto value = parse_decimal(input);
        if (!value) return "'" + input + "' is not a number";
        const bool fine = sign == Sign::positive ? *value > 0 : *value >= 0;
        if (!fine) return std::string(sign == Sign::positive ? "must be > 0" : "must be >= 0") + ", got " + input;
        if (*value > kLargestOptionValue) return "must be at most " + plain(kLargestOptionValue) + ", got " + input;
        input = plain(*value);
        return {};
      },
      sign == Sign::positive ? "POSITIVE" : "NONNEGATIVE");
}

CLI::Validator range_check(double low, double high, bool whole) {
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        const auto value = parse_decimal(input);
        if (!value) return "'" + input + "' is not a number";
        if (whole && *value != std::floor(*value)) return "must be a whole number, got " + input;
        if (!(*value >= low && *value <= high)) {
          return "must be from " + plain(low) + " to " + plain(high) + ", got " + input;
        }
        input = plain(*value);
        return {};
      },
      fmt::format("{} in [{} - {}]", whole ? "INT" : "FLOAT", plain(low), plain(high)));
}

}  // namespace

std::optional<double> parse_decimal(std::string_view text) {
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && text.front() == '-') return std::nullopt;  // "+-1"
  }
  if (text.empty() || !(std::isdigit(static_cast<unsigned char>(text.back())) || text.back() == '.')) {
    return std::nullopt;  // rejects "inf", "nan" and a trailing "e"
  }
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

CLI::Validator positive() { return sign_check(Sign::positive); }

CLI::Validator non_negative() { return sign_check(Sign::non_negative); }

CLI::Validator whole_in(long long low, long long high) {
  return range_check(static_cast<double>(low), static_cast<double>(high), true);
}

CLI::Validator number_in(double low, double high) { return range_check(low, high, false); }

}  // namespace drover::cli
