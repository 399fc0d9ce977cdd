// Result<T>: a value or an Error, returned by every validating factory (FromJson, FromModel,
// ...). Messages name the file, the field and what is allowed; the CLI prints them and exits
// with the code the Error's ErrorCode maps to (common/exit_codes.h), whatever the wording.
#pragma once

#include <cerrno>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <variant>

namespace recruit {

// The class of a failure: what the CLI's exit code and Python's exception type follow.
enum class ErrorCode {
  kBadInput,  // an input's content is invalid (task, model, log, MJCF, ...): the default
  kUsage,     // a bad option or option value, a missing input path
  kIo,        // a file cannot be read or written (permissions, full disk, ...)
  kInternal,  // a bug
};

// Error{"message"} is bad input; Error{"message", ErrorCode::kIo} or IoError("message") an I/O
// failure. Wrapping keeps the class: Error{"where: " + r.error(), r.code()} or r.failure().In(..).
struct Error {
  std::string message;
  ErrorCode code = ErrorCode::kBadInput;
  // The same failure, its message prefixed with where it happened.
  Error In(const std::string& prefix) const { return Error{prefix + message, code}; }
};

inline Error IoError(std::string message) { return Error{std::move(message), ErrorCode::kIo}; }

// The class of a failed filesystem call on a path an input named: a path that names no file (no
// such file or folder, a name too long, a loop of links) is bad input; a file that is there but
// cannot be opened, read or written (denied access, not a regular file, a full disk, an I/O
// error, ...) is an I/O failure. ReadFile, LoadJsonFile and the locks class their errors so.
inline ErrorCode CodeOf(const std::error_code& ec) {
  const bool errno_value =
      ec.category() == std::generic_category() || ec.category() == std::system_category();
  if (!errno_value) return ErrorCode::kIo;
  switch (ec.value()) {
    case ENOENT:
    case ENOTDIR:
    case ENAMETOOLONG:
    case ELOOP:
      return ErrorCode::kBadInput;
    default:
      return ErrorCode::kIo;
  }
}
inline ErrorCode CodeOfErrno(int err) {
  return CodeOf(std::error_code(err, std::generic_category()));
}

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : v_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  const T& value() const& { return std::get<0>(v_); }
  T& value() & { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  const std::string& error() const { return std::get<1>(v_).message; }
  ErrorCode code() const { return std::get<1>(v_).code; }
  const Error& failure() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

// Result<void>: success or an error.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)) {}  // NOLINT: implicit by design
  static Status Ok() { return Status(); }
  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& error() const { return error_->message; }
  ErrorCode code() const { return error_->code; }
  const Error& failure() const { return *error_; }

 private:
  std::optional<Error> error_;
};

}  // namespace recruit

// Returns the failure of a Status-valued expression from the enclosing function (which returns
// a Status or a Result), its code kept.
#define RECRUIT_TRY(expr)                                                                     \
  do {                                                                                        \
    if (::recruit::Status _recruit_s = (expr); !_recruit_s.ok()) return _recruit_s.failure(); \
  } while (0)
