// The container step's pre-validation of a glTF file's JSON (gltf_load_prevalidate.h):
// section by section (asset, top-level arrays, buffers, buffer views, images, accessors,
// textures, meshes), everything tinygltf would index without a bounds check is checked
// here first, and what the loader reads itself (Draco, primitive indices) is taken out.

#include <algorithm>
#include <iterator>
#include <string>

#include "gltf/gltf_load_prevalidate.h"

namespace engine::gltf_load {
namespace {

/// asset.version must be a 2.x string.
Status check_asset(const Context& ctx, const Json& doc) {
  const Json* asset = find_member(doc, "asset");
  const Json* version = asset != nullptr ? find_member(*asset, "version") : nullptr;
  if (version == nullptr || !version->is_string()) return ctx.error("asset", "missing asset.version");
  if (version->get<std::string>().rfind("2.", 0) != 0) {
    return ctx.error("asset", "unsupported glTF version '" + version->get<std::string>() + "' (need 2.x)");
  }
  return {};
}

/// The node count against the limit.
Status check_node_count(const Context& ctx, const Json& doc) {
  if (array_size(doc, "nodes") > ctx.options.limits.max_nodes) {
    return ctx.error("nodes", std::to_string(array_size(doc, "nodes")) + " nodes exceed the limit of " +
                                  std::to_string(ctx.options.limits.max_nodes));
  }
  return {};
}

/// The top-level collections, where present, are arrays of objects.
Status check_top_level_arrays(const Context& ctx, const Json& doc) {
  for (const char* key : {"buffers", "bufferViews", "accessors", "meshes", "nodes", "materials", "images", "textures",
                          "cameras", "scenes", "samplers"}) {
    const Json* a = find_member(doc, key);
    if (a != nullptr && !a->is_array()) return ctx.error(key, "must be an array");
    if (a == nullptr) continue;
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (!(*a)[i].is_object()) return ctx.error(std::string(key) + " " + std::to_string(i), "must be an object");
    }
  }
  return {};
}

/// accessors: the buffer view in range; an unknown type or componentType becomes a harmless
/// placeholder with its problem in out.accessor_problems.
Status check_accessors(const Context& ctx, std::size_t view_count, ParsedFile& out) {
  Json& doc = out.doc;
  if (Json* accessors = doc.contains("accessors") ? &doc["accessors"] : nullptr) {
    static const char* const kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    for (std::size_t i = 0; i < accessors->size(); ++i) {
      Json& acc = (*accessors)[i];
      const std::string where = "accessor " + std::to_string(i);
      auto view = index_member(ctx, acc, "bufferView", -1, where);
      if (!view) return view.error();
      if (*view >= 0 && static_cast<std::size_t>(*view) >= view_count) {
        return ctx.error(where, "'bufferView' " + std::to_string(*view) + " is out of range (" +
                                    std::to_string(view_count) + " buffer views)");
      }
      std::string problem;
      const Json* type = find_member(acc, "type");
      const Json* component = find_member(acc, "componentType");
      if (type == nullptr || !type->is_string() ||
          std::none_of(std::begin(kTypes), std::end(kTypes),
                       [&](const char* t) { return type->get<std::string>() == t; })) {
        problem = "unknown or missing accessor type";
      }
      if (component == nullptr || !is_integer(*component) ||
          (component->get<std::int64_t>() < 5120 || component->get<std::int64_t>() > 5126 ||
           component->get<std::int64_t>() == 5124)) {
        problem = "unknown or missing componentType";
      }
      if (!problem.empty()) {  // tinygltf would reject the whole file; unused, it is harmless
        acc["type"] = "SCALAR";
        acc["componentType"] = 5126;
      }
      out.accessor_problems.push_back(problem);
    }
  }
  return {};
}

/// textures: source image and sampler in range.
Status check_textures(const Context& ctx, const Json& doc) {
  if (const Json* textures = find_member(doc, "textures")) {
    for (std::size_t i = 0; i < textures->size(); ++i) {
      const std::string where = "texture " + std::to_string(i);
      auto source = index_member(ctx, (*textures)[i], "source", -1, where);
      if (!source) return source.error();
      if (*source >= 0 && static_cast<std::size_t>(*source) >= array_size(doc, "images")) {
        return ctx.error(where, "'source' " + std::to_string(*source) + " refers to a missing image");
      }
      auto sampler = index_member(ctx, (*textures)[i], "sampler", -1, where);
      if (!sampler) return sampler.error();
      if (*sampler >= 0 && static_cast<std::size_t>(*sampler) >= array_size(doc, "samplers")) {
        return ctx.error(where, "'sampler' " + std::to_string(*sampler) + " refers to a missing sampler");
      }
    }
  }
  return {};
}

/// Primitive p of mesh m: material, indices and attribute accessors in range (§3.7.2.1); its
/// indices move from the JSON into out.primitive_indices.
Status check_primitive_references(const Context& ctx, std::size_t m, std::size_t p, Json& prim, ParsedFile& out) {
  const Json& doc = out.doc;
  const std::string pwhere = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
  auto material = index_member(ctx, prim, "material", -1, pwhere);
  if (!material) return material.error();
  if (*material >= 0 && static_cast<std::size_t>(*material) >= array_size(doc, "materials")) {
    return ctx.error(pwhere, "material " + std::to_string(*material) + " is out of range");
  }
  const std::size_t accessor_count = array_size(doc, "accessors");
  auto indices_ref = index_member(ctx, prim, "indices", -1, pwhere);
  if (!indices_ref) return indices_ref.error();
  if (*indices_ref >= 0 && static_cast<std::size_t>(*indices_ref) >= accessor_count) {
    return ctx.error(pwhere, "indices accessor " + std::to_string(*indices_ref) + " is out of range");
  }
  if (const Json* attrs = find_member(prim, "attributes"); attrs != nullptr && attrs->is_object()) {
    for (const auto& [name, value] : attrs->items()) {
      if (!is_integer(value) || value.get<std::int64_t>() < 0 || value.get<std::uint64_t>() >= accessor_count) {
        return ctx.error(pwhere, "attribute " + name + " refers to a missing accessor");
      }
    }
  }
  if (prim.contains("indices")) {
    auto indices =
        index_member(ctx, prim, "indices", -1, "mesh " + std::to_string(m) + " primitive " + std::to_string(p));
    if (!indices) return indices.error();
    out.primitive_indices[{static_cast<int>(m), static_cast<int>(p)}] = static_cast<int>(*indices);
    prim.erase("indices");
  }
  return {};
}

/// Primitive p of mesh m's KHR_draco_mesh_compression, if any: buffer view in range, attribute
/// ids; moved from the JSON into out.draco.
Status take_draco_extension(const Context& ctx, std::size_t m, std::size_t p, Json& prim, std::size_t view_count,
                            ParsedFile& out) {
  if (!prim.contains("extensions") || !prim["extensions"].is_object()) return {};
  Json& exts = prim["extensions"];
  if (!exts.contains("KHR_draco_mesh_compression")) return {};
  const std::string where =
      "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + " KHR_draco_mesh_compression";
  const Json& ext = exts["KHR_draco_mesh_compression"];
  DracoRef ref;
  auto view = index_member(ctx, ext, "bufferView", -1, where);
  if (!view) return view.error();
  if (*view < 0 || static_cast<std::size_t>(*view) >= view_count) {
    return ctx.error(where, "'bufferView' missing or out of range");
  }
  ref.buffer_view = static_cast<int>(*view);
  const Json* attrs = find_member(ext, "attributes");
  if (attrs == nullptr || !attrs->is_object()) return ctx.error(where, "'attributes' must be an object");
  for (const auto& [name, id] : attrs->items()) {
    if (!is_integer(id) || id.get<std::int64_t>() < 0 || id.get<std::int64_t>() > 1 << 20) {
      return ctx.error(where, "attribute '" + name + "' must be a non-negative integer id");
    }
    ref.attributes[name] = id.get<int>();
  }
  out.draco[{static_cast<int>(m), static_cast<int>(p)}] = std::move(ref);
  exts.erase("KHR_draco_mesh_compression");
  return {};
}

/// meshes: every primitive's references and Draco extension, used or not (§3.7.2.1).
Status check_meshes(const Context& ctx, std::size_t view_count, ParsedFile& out) {
  Json& doc = out.doc;
  if (Json* meshes = doc.contains("meshes") ? &doc["meshes"] : nullptr) {
    for (std::size_t m = 0; m < meshes->size(); ++m) {
      Json* prims = (*meshes)[m].contains("primitives") ? &(*meshes)[m]["primitives"] : nullptr;
      if (prims == nullptr || !prims->is_array()) continue;
      for (std::size_t p = 0; p < prims->size(); ++p) {
        Json& prim = (*prims)[p];
        if (!prim.is_object()) continue;
        // References are checked for every mesh, used or not (§3.7.2.1).
        if (auto ok = check_primitive_references(ctx, m, p, prim, out); !ok) return ok;
        if (auto ok = take_draco_extension(ctx, m, p, prim, view_count, out); !ok) return ok;
      }
    }
  }
  return {};
}

}  // namespace

Status prevalidate(const Context& ctx, const Container& container, ParsedFile& out) {
  if (auto ok = check_asset(ctx, out.doc); !ok) return ok;
  if (auto ok = check_node_count(ctx, out.doc); !ok) return ok;
  if (auto ok = check_top_level_arrays(ctx, out.doc); !ok) return ok;
  auto buffer_lengths = check_buffers(ctx, container, out);
  if (!buffer_lengths) return buffer_lengths.error();
  auto views = check_buffer_views(ctx, out.doc, *buffer_lengths);
  if (!views) return views.error();
  if (auto ok = check_images(ctx, out.doc, *views, out.buffer_problems); !ok) return ok;
  if (auto ok = check_accessors(ctx, views->count, out); !ok) return ok;
  if (auto ok = check_textures(ctx, out.doc); !ok) return ok;
  return check_meshes(ctx, views->count, out);
}

}  // namespace engine::gltf_load
