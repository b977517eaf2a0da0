#pragma once
// Checks of numeric command-line options, with plain messages, that also fix how a number
// is read: decimal only. CLI11 converts integers with base detection, so "010" would be 8
// and "0x0A" 10 while the check had read 10 and refused 0x0A; each check rewrites the text
// it accepted into the plain decimal that CLI11 then converts to the value checked.
// Add them with Option::transform: Option::check hands a validator a copy of the text.

#include <cstdint>
#include <optional>
#include <string_view>

#include <CLI/CLI.hpp>

namespace drover::cli {

/// The largest value positive() and non_negative() accept: far beyond any duration, speed
/// or factor an option gives, and small enough that seconds convert to nanoseconds.
inline constexpr double kLargestOptionValue = 1e9;
/// The largest whole number every check reads exactly (2^53 - 1): for counts and seeds.
inline constexpr long long kLargestWholeOption = (1LL << 53) - 1;

/// The number must be > 0 and at most kLargestOptionValue ("must be > 0, got 0"; CLI11's
/// PositiveNumber names a range from 0 to 1.8e308 instead).
CLI::Validator positive();
/// The number must be > 0 and at most `largest`. \pre 0 < largest <= kLargestOptionValue
CLI::Validator positive_at_most(double largest);
/// The number must be >= 0 and at most kLargestOptionValue.
CLI::Validator non_negative();

/// `text` as a plain decimal number (an optional sign, digits, a fraction, an exponent), or
/// nullopt: no hexadecimal, octal or binary forms, no "inf" or "nan", no blanks, nothing
/// after it. For numbers inside option values (NAME=SECONDS) that the checks cannot see.
std::optional<double> parse_decimal(std::string_view text);

/// A whole number in [low, high] ("'abc' is not a number", "must be a whole number, got
/// 1.5", "must be from 1 to 100, got 0"; CLI11's Range says "not in range" to all three and
/// lets NaN pass). \pre low <= high, both within +-2^53 (exact as doubles).
CLI::Validator whole_in(long long low, long long high);
/// A finite number in [low, high].
CLI::Validator number_in(double low, double high);
/// A whole number in [low, high] read exactly as a 64-bit integer, for nanosecond times
/// beyond 2^53 that whole_in would round: an optional sign and decimal digits only (no
/// fraction, no exponent), leading zeros allowed ("010" is ten). \pre low <= high
CLI::Validator exact_whole_in(std::int64_t low, std::int64_t high);

}  // namespace drover::cli
