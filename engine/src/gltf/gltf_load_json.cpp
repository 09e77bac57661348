// JSON helpers of the glTF loader (gltf_load_internal.h): members read with their type
// checked, so a step reports "'byteOffset' must be a non-negative integer" instead of throwing.

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {

const Json* find_member(const Json& object, const char* key) {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

Result<double> number_member(const Context& ctx, const Json& object, const char* key, double fallback,
                             const std::string& location) {
  const Json* v = find_member(object, key);
  if (v == nullptr) return fallback;
  if (!v->is_number()) return ctx.error(location, std::string("'") + key + "' must be a number");
  return v->get<double>();
}

bool is_integer(const Json& v) { return v.is_number_integer() || v.is_number_unsigned(); }

Result<std::int64_t> index_member(const Context& ctx, const Json& object, const char* key, std::int64_t fallback,
                                  const std::string& location) {
  const Json* v = find_member(object, key);
  if (v == nullptr) return fallback;
  if (!is_integer(*v) || v->get<std::int64_t>() < 0) {
    return ctx.error(location, std::string("'") + key + "' must be a non-negative integer");
  }
  return v->get<std::int64_t>();
}

std::size_t array_size(const Json& doc, const char* key) {
  const Json* a = find_member(doc, key);
  return a != nullptr && a->is_array() ? a->size() : 0;
}

}  // namespace engine::gltf_load
