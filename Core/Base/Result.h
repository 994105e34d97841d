#pragma once
// Result<T>: the value of an operation or a message a person can act on. Core and Logic never throw
// across their public APIs; they return a Result instead.

#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace fct {

/// The error half of a Result: one human-readable sentence saying what is wrong and what to do.
struct Error {
  std::string message;
};

/// Either a value of type T or an Error. Test with ok(), read with value() or error().
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : m_state(std::move(value)) {}              // NOLINT: implicit by design
  Result(Error error) : m_state(std::move(error)) {}          // NOLINT: implicit by design

  /// True when the operation succeeded and value() may be called.
  bool ok() const { return std::holds_alternative<T>(m_state); }
  explicit operator bool() const { return ok(); }

  /// The value; only valid when ok().
  const T& value() const& { return std::get<T>(m_state); }
  T& value() & { return std::get<T>(m_state); }
  T&& value() && { return std::get<T>(std::move(m_state)); }

  /// The error message; empty when ok().
  const std::string& error() const {
    static const std::string kEmpty;
    return ok() ? kEmpty : std::get<Error>(m_state).message;
  }

  /// Warnings gathered along the way (e.g. "resampled to a regular grid"); present on success too.
  const std::vector<std::string>& warnings() const { return m_warnings; }
  void addWarning(std::string warning) { m_warnings.push_back(std::move(warning)); }

 private:
  std::variant<T, Error> m_state;
  std::vector<std::string> m_warnings;
};

/// A Result with no value: success or an error message.
struct Ok {};
using Status = Result<Ok>;

/// Builds an Error from a message (shorthand for `return fct::fail("...")`).
inline Error fail(std::string message) { return Error{std::move(message)}; }

}  // namespace fct
