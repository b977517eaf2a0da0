#pragma once
// Errors are values inside Drover's libraries: a function that can fail returns
// Result<T> (or Result<T, E>), and tools turn the error into a message and an exit code.

#include <cassert>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

namespace drover {

/// Machine-readable error category; tools and replies carry it next to the text.
enum class ErrorCode {
  invalid_argument,  ///< a request or command is malformed or out of range
  not_found,         ///< an id names nothing known
  conflict,          ///< the operation collides with existing state (overlap, version, lock)
  not_permitted,     ///< the caller may not do this (not the holder, not the owner)
  unavailable,       ///< nothing can serve the request now (no route, no window, no server)
  io,                ///< a file or the network failed
  parse,             ///< input text is not well formed
  timeout,           ///< nobody answered in time
  internal,          ///< a bug; reported, never a crash
};

/// Stable lower-case name of a code, as printed by tools and sent in replies.
constexpr const char* to_string(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::invalid_argument: return "invalid_argument";
    case ErrorCode::not_found: return "not_found";
    case ErrorCode::conflict: return "conflict";
    case ErrorCode::not_permitted: return "not_permitted";
    case ErrorCode::unavailable: return "unavailable";
    case ErrorCode::io: return "io";
    case ErrorCode::parse: return "parse";
    case ErrorCode::timeout: return "timeout";
    case ErrorCode::internal: return "internal";
  }
  return "internal";
}

/// An error: a code and a human-readable message that names what and where.
struct Error {
  ErrorCode code = ErrorCode::internal;
  std::string message;

  friend bool operator==(const Error&, const Error&) = default;
};

/// Tag wrapper so that Result<T, E> can be built from an error even when T and E convert.
template <class E>
struct Unexpected {
  E error;
};

/// Builds the error alternative of a Result: `return fail(ErrorCode::not_found, "...")`.
inline Unexpected<Error> fail(ErrorCode code, std::string message) {
  return Unexpected<Error>{Error{code, std::move(message)}};
}
template <class E>
Unexpected<std::decay_t<E>> unexpected(E&& error) {
  return Unexpected<std::decay_t<E>>{std::forward<E>(error)};
}

/// A value of type T or an error of type E (a small std::expected for C++20).
/// Contract: value() requires has_value(); error() requires !has_value() (asserted).
template <class T, class E = Error>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}
  template <class G>
  Result(Unexpected<G> error) : state_(std::in_place_index<1>, std::move(error.error)) {}

  bool has_value() const noexcept { return state_.index() == 0; }
  explicit operator bool() const noexcept { return has_value(); }

  T& value() & { assert(has_value()); return std::get<0>(state_); }
  const T& value() const& { assert(has_value()); return std::get<0>(state_); }
  T&& value() && { assert(has_value()); return std::get<0>(std::move(state_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  E& error() & { assert(!has_value()); return std::get<1>(state_); }
  const E& error() const& { assert(!has_value()); return std::get<1>(state_); }
  E&& error() && { assert(!has_value()); return std::get<1>(std::move(state_)); }

 private:
  std::variant<T, E> state_;
};

/// Result of an operation that yields nothing but may fail.
template <class E>
class [[nodiscard]] Result<void, E> {
 public:
  Result() = default;
  template <class G>
  Result(Unexpected<G> error) : error_(std::move(error.error)), failed_(true) {}

  bool has_value() const noexcept { return !failed_; }
  explicit operator bool() const noexcept { return has_value(); }
  const E& error() const& { assert(failed_); return error_; }
  E&& error() && { assert(failed_); return std::move(error_); }

 private:
  E error_{};
  bool failed_ = false;
};

using Status = Result<void>;

}  // namespace drover
