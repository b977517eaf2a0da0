#include "agents/cli/number_checks.hpp"

#include <algorithm>
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

CLI::Validator sign_check(Sign sign, double largest = kLargestOptionValue) {
  return CLI::Validator(
      [sign, largest](std::string& input) -> std::string {
        const auto value = parse_decimal(input);
        if (!value) return "'" + input + "' is not a number";
        const bool fine = sign == Sign::positive ? *value > 0 : *value >= 0;
        if (!fine) return std::string(sign == Sign::positive ? "must be > 0" : "must be >= 0") + ", got " + input;
        if (*value > largest) return "must be at most " + plain(largest) + ", got " + input;
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

CLI::Validator positive_at_most(double largest) { return sign_check(Sign::positive, largest); }

CLI::Validator non_negative() { return sign_check(Sign::non_negative); }

CLI::Validator whole_in(long long low, long long high) {
  return range_check(static_cast<double>(low), static_cast<double>(high), true);
}

CLI::Validator number_in(double low, double high) { return range_check(low, high, false); }

CLI::Validator exact_whole_in(std::int64_t low, std::int64_t high) {
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        std::string_view digits = input;
        const bool negative = !digits.empty() && digits.front() == '-';
        if (!digits.empty() && (digits.front() == '+' || negative)) digits.remove_prefix(1);
        const bool all_digits =
            !digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) {
              return std::isdigit(static_cast<unsigned char>(c)) != 0;
            });
        if (!all_digits) {
          return parse_decimal(input) ? "must be a whole number in digits, got " + input
                                      : "'" + input + "' is not a number";
        }
        const std::string range = fmt::format("must be from {} to {}, got {}", low, high, input);
        std::uint64_t magnitude = 0;
        const auto [end, error] =
            std::from_chars(digits.data(), digits.data() + digits.size(), magnitude);
        if (error != std::errc() || end != digits.data() + digits.size()) return range;
        // Within int64 either way, so that the comparisons below are exact.
        if (magnitude > std::uint64_t{1} << 63) return range;
        const std::int64_t value =
            negative ? static_cast<std::int64_t>(0 - magnitude) : static_cast<std::int64_t>(magnitude);
        if ((!negative && magnitude == std::uint64_t{1} << 63) || value < low || value > high) {
          return range;
        }
        input = fmt::format("{}", value);
        return {};
      },
      fmt::format("INT in [{} - {}]", low, high));
}

}  // namespace drover::cli
