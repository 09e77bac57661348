#pragma once
// Nesting depth of a parsed JSON document, computed without recursion, so that files nested
// deeper than anything real (a crafted 300,000-level array) are refused before recursive
// code — a copy, a dump, a walk — runs out of stack on them.
//   if (engine::json_depth(doc, 256) > 256) return error("JSON nested deeper than 256 levels");
// Works on nlohmann::json (any type with is_array/is_object and iteration over children).

#include <cstddef>
#include <utility>
#include <vector>

namespace engine {

/// The depth of `root` (a scalar: 0, [] or {}: 1, [[1]]: 2), counted up to `limit` + 1:
/// the walk stops as soon as the limit is exceeded.
template <class Json>
std::size_t json_depth(const Json& root, std::size_t limit) {
  std::size_t deepest = 0;
  std::vector<std::pair<const Json*, std::size_t>> stack{{&root, 0}};
  while (!stack.empty()) {
    const auto [v, depth] = stack.back();
    stack.pop_back();
    if (!v->is_array() && !v->is_object()) continue;
    const std::size_t inner = depth + 1;
    if (inner > deepest) deepest = inner;
    if (deepest > limit) return deepest;
    for (const Json& child : *v) stack.emplace_back(&child, inner);
  }
  return deepest;
}

}  // namespace engine
