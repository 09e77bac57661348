#pragma once
// Typed reads of dotted paths in a JSON document (a bundle manifest entry), collecting the
// first error with the file and the full path, so a loader reads all its fields and checks
// once.
//   gi::JsonFields f(entry, "level.gibake/manifest.json", "methods.light_atlas");
//   int width = f.get<int>("layout.width");
//   if (f.error()) return *f.error();

#include <engine/result.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <nlohmann/json.hpp>

namespace gi {

class JsonFields {
 public:
  /// `prefix` is the path of `root` inside its file (shown in errors; may be empty).
  JsonFields(const nlohmann::json& root, std::string file, std::string prefix)
      : root_(root), file_(std::move(file)), prefix_(std::move(prefix)) {}

  /// The value at `path` ("a.b.c"), or T{} after recording an error (missing field, wrong
  /// type, out of T's range). T: bool, an integer type, float, double or std::string.
  template <class T>
  T get(const std::string& path) {
    const nlohmann::json* node = find(path);
    if (node == nullptr) return T{};
    if constexpr (std::is_same_v<T, bool>) {
      if (node->is_boolean()) return node->get<bool>();
      fail(path, "must be true or false");
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (node->is_string()) return node->get<std::string>();
      fail(path, "must be a string");
    } else if constexpr (std::is_floating_point_v<T>) {
      if (node->is_number()) return static_cast<T>(node->get<double>());
      fail(path, "must be a number");
    } else {
      static_assert(std::is_integral_v<T>, "unsupported field type");
      if (node->is_number_unsigned()) {
        const auto v = node->get<std::uint64_t>();
        if (v <= static_cast<std::uint64_t>(std::numeric_limits<T>::max())) return static_cast<T>(v);
      } else if (node->is_number_integer()) {
        const auto v = node->get<std::int64_t>();
        if (std::is_signed_v<T> && v >= static_cast<std::int64_t>(std::numeric_limits<T>::min()) &&
            v <= static_cast<std::int64_t>(std::numeric_limits<T>::max()))
          return static_cast<T>(v);
      } else {
        fail(path, "must be an integer");
        return T{};
      }
      fail(path, "integer out of range");
    }
    return T{};
  }

  /// The first error recorded, if any.
  const std::optional<engine::Error>& error() const { return error_; }

 private:
  const nlohmann::json* find(const std::string& path) {
    const nlohmann::json* node = &root_;
    std::size_t start = 0;
    while (start <= path.size()) {
      const std::size_t dot = path.find('.', start);
      const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (!node->is_object() || !node->contains(key)) {
        fail(path, "missing field");
        return nullptr;
      }
      node = &(*node)[key];
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    return node;
  }
  void fail(const std::string& path, const std::string& message) {
    if (!error_) error_ = engine::Error{file_, prefix_.empty() ? path : prefix_ + "." + path, message};
  }

  const nlohmann::json& root_;
  std::string file_;
  std::string prefix_;
  std::optional<engine::Error> error_;
};

}  // namespace gi
