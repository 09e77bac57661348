#pragma once
// Error values for bad input: a file, a location inside it and what is wrong.
//   engine::Result<SceneAsset> r = engine::load_gltf("level.gltf");
//   if (!r) std::cerr << r.error().to_string() << '\n';

#include <engine/check.h>

#include <string>
#include <utility>
#include <variant>

namespace engine {

/// Why an operation failed, for callers that react differently (a tool's exit code: 1, 2, 130).
enum class ErrorKind : unsigned char {
  Failure,    ///< Bad data, I/O, an operation that could not complete.
  Invalid,    ///< The caller's request itself is wrong (an unknown preset, a setting out of range).
  Cancelled,  ///< A progress callback asked to stop.
};

/// A data error: which file, where in it (accessor index, byte offset, JSON path...) and
/// what is wrong. `to_string()` gives "file: location: message".
struct Error {
  std::string file;
  std::string location;
  std::string message;
  ErrorKind kind = ErrorKind::Failure;

  std::string to_string() const {
    std::string s = file.empty() ? std::string("<memory>") : file;
    if (!location.empty()) s += ": " + location;
    s += ": " + message;
    return s;
  }
};

/// Either a value or an Error. Accessing the wrong alternative is a programmer error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    GI_EXPECTS(ok(), "Result holds an error");
    return std::get<0>(v_);
  }
  const T& value() const& {
    GI_EXPECTS(ok(), "Result holds an error");
    return std::get<0>(v_);
  }
  T&& value() && {
    GI_EXPECTS(ok(), "Result holds an error");
    return std::get<0>(std::move(v_));
  }
  const Error& error() const {
    GI_EXPECTS(!ok(), "Result holds a value");
    return std::get<1>(v_);
  }

  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Error> v_;
};

/// Result of an operation with no value: success, or an Error.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const {
    GI_EXPECTS(!ok_, "Result holds no error");
    return error_;
  }

 private:
  Error error_;
  bool ok_ = true;
};

using Status = Result<void>;

/// The error of work a progress callback stopped: "<what> cancelled".
inline Error cancelled_error(const std::string& what) {
  return Error{.file = {}, .location = {}, .message = what + " cancelled", .kind = ErrorKind::Cancelled};
}
/// The error of a request that is wrong in itself (ErrorKind::Invalid).
inline Error invalid_request(std::string message) {
  return Error{.file = {}, .location = {}, .message = std::move(message), .kind = ErrorKind::Invalid};
}

}  // namespace engine
