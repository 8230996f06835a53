// Result<T>: a value or a readable error, returned at every public boundary that takes input.
//
// An error message names the input, what is wrong with it and what to do about it, e.g.
//   "triangle 17 (vertices 4, 4, 9): repeated vertex index 4; every triangle needs three
//    distinct vertices"
// Nothing throws across the API; callers test ok() and read error().
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

namespace weft {

/// A failed operation: a message for people, ready to print.
struct Error {
  std::string message;  ///< which input, what is wrong with it, and what to do
};

/// Either a T or an Error. Cheap to move; value() asserts ok().
template <typename T>
class [[nodiscard]] Result {
 public:
  /// A success holding `value`.
  Result(T value) : m_value(std::move(value)) {}
  /// A failure holding `error`.
  Result(Error error) : m_error(std::move(error)) {}

  /// True when the result holds a value.
  bool ok() const { return m_value.has_value(); }
  /// ok().
  explicit operator bool() const { return ok(); }

  /// The value; asserts ok().
  const T& value() const& { assert(ok() && "Result::value() on an error; test ok() first"); return *m_value; }
  /// The value; asserts ok().
  T& value() & { assert(ok() && "Result::value() on an error; test ok() first"); return *m_value; }
  /// On a temporary, the value is moved out and returned by value, so that
  /// `for (auto& x : f().value())` does not iterate over a destroyed Result.
  T value() && { assert(ok() && "Result::value() on an error; test ok() first"); return std::move(*m_value); }

  /// Member access to the value; asserts ok().
  const T* operator->() const { return &value(); }
  /// Member access to the value; asserts ok().
  T* operator->() { return &value(); }

  /// The error; empty message when ok().
  const Error& error() const { return m_error; }

 private:
  std::optional<T> m_value;
  Error m_error;
};

/// Result of an operation with no value: ok, or an error.
class [[nodiscard]] Status {
 public:
  Status() = default;
  /// A failure holding `error`.
  Status(Error error) : m_error(std::move(error)), m_ok(false) {}
  /// A success (the same as Status()).
  static Status success() { return {}; }

  /// True on success.
  bool ok() const { return m_ok; }
  /// ok().
  explicit operator bool() const { return m_ok; }
  /// The error; empty message on success.
  const Error& error() const { return m_error; }

 private:
  Error m_error;
  bool m_ok = true;
};

}  // namespace weft
