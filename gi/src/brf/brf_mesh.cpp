#include "brf/brf_mesh.h"

#include <engine/finite.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <span>
#include <utility>

#include "core/color.h"
#include "io/content_hash.h"
#include "raytrace/material_lookup.h"
#include "raytrace/scene_adapter.h"
#include "transport/vpl_set.h"

namespace gi {

namespace {

// A file-name fragment from a mesh name: [A-Za-z0-9_-] kept, anything else '_'.
std::string name_fragment(const std::string& name, std::uint32_t mesh_index) {
  std::string out;
  for (char c : name) {
    const bool plain =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    out += plain ? c : '_';
  }
  if (out.empty()) out = "mesh" + std::to_string(mesh_index);
  return out;
}

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

}  // namespace

namespace {

// The (first) material a source is drawn with; the glTF default material when none.
BakeMaterial source_material(const BakeInput& input, const BrfSource& source) {
  BakeInstance inst;
  inst.mesh = source.mesh_index;
  inst.material_override = source.material_override;
  if (source.mesh_index < input.meshes.size() && !input.meshes[source.mesh_index].primitives.empty())
    return bake_material(input, inst, input.meshes[source.mesh_index].primitives.front());
  return bake_material(input, inst, BakePrimitive{});
}

}  // namespace

BrfMesh brf_box_mesh(glm::vec3 half, int n, float inset) {
  BrfMesh m;
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a)
    for (float sign : {-1.0f, 1.0f}) {
      const glm::vec3 nrm = axes[a] * sign;
      const glm::vec3 t = axes[(a + 1) % 3] * sign, b = axes[(a + 2) % 3];
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          const float s = (2.0f * static_cast<float>(i) / static_cast<float>(n) - 1.0f) * inset;
          const float r = (2.0f * static_cast<float>(j) / static_cast<float>(n) - 1.0f) * inset;
          m.positions.push_back((nrm + s * t + r * b) * half);
          m.normals.push_back(nrm);
        }
      const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          m.indices.insert(m.indices.end(),
                           {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

std::string brf_mesh_hash(const BrfMesh& mesh, const std::optional<GlossyLobe>& glossy) {
  ContentHash h;
  h.add_value(static_cast<std::uint64_t>(mesh.positions.size()));
  for (const glm::vec3& p : mesh.positions) h.add_value(p.x), h.add_value(p.y), h.add_value(p.z);
  h.add_value(static_cast<std::uint64_t>(mesh.normals.size()));
  for (const glm::vec3& n : mesh.normals) h.add_value(n.x), h.add_value(n.y), h.add_value(n.z);
  h.add_values(std::span<const std::uint32_t>(mesh.indices));
  h.add_values(std::span<const float>(mesh.reflectance));
  if (glossy) h.add_value(glossy->f0), h.add_value(glossy->alpha);
  return h.hex();
}

// Long because it is one pass per primitive: check it, complete its normals, fold its
// material to a reflectance per vertex (area-weighted where textured) and append it, errors naming it.
engine::Result<BrfMesh> brf_mesh_from_input(const BakeInput& input, std::uint32_t mesh_index,
                                            std::int32_t material_override) {
  const std::string where = input.name.empty() ? std::string("the scene") : input.name;
  if (mesh_index >= input.meshes.size())
    return engine::Error{where, "meshes", "mesh " + std::to_string(mesh_index) + " does not exist"};
  const BakeMesh& m = input.meshes[mesh_index];
  const std::string location = "mesh " + std::to_string(mesh_index) + " \"" + m.name + "\"";
  BrfMesh out;
  std::optional<ReferenceScene> looks;  // the material lookup's data, built for the first textured primitive
  for (std::size_t pi = 0; pi < m.primitives.size(); ++pi) {
    const BakePrimitive& p = m.primitives[pi];
    const std::size_t n = p.positions.size();
    const auto base = static_cast<std::uint32_t>(out.positions.size());
    if (!p.normals.empty() && p.normals.size() != n)
      return engine::Error{where, location,
                           "primitive " + std::to_string(pi) + " has " + std::to_string(p.normals.size()) +
                               " normals for " + std::to_string(n) + " positions"};
    if (p.indices.size() % 3 != 0)
      return engine::Error{where, location, "primitive " + std::to_string(pi) + " index count is not a multiple of 3"};
    for (std::uint32_t i : p.indices)
      if (i >= n)
        return engine::Error{where, location,
                             "primitive " + std::to_string(pi) + " index " + std::to_string(i) + " is out of range (" +
                                 std::to_string(n) + " vertices)"};
    for (const glm::vec3& v : p.positions)
      if (!engine::all_finite(v)) return engine::Error{where, location, "a position is NaN or infinite"};
    std::vector<glm::vec3> normals = p.normals;
    if (normals.empty()) {
      normals.assign(n, glm::vec3(0.0f));
      for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
        const std::uint32_t a = p.indices[t], b = p.indices[t + 1], c = p.indices[t + 2];
        const glm::vec3 area_normal = glm::cross(p.positions[b] - p.positions[a], p.positions[c] - p.positions[a]);
        normals[a] += area_normal, normals[b] += area_normal, normals[c] += area_normal;
      }
    }
    for (glm::vec3& v : normals) {
      if (!engine::all_finite(v)) return engine::Error{where, location, "a normal is NaN or infinite"};
      const float len = glm::length(v);
      v = len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f, 0.0f, 1.0f);  // unused vertex or degenerate
    }
    BakeInstance drawn;
    drawn.material_override = material_override;
    const BakeMaterial mat = bake_material(input, drawn, p);
    // The reflectance the bakers fold every surface to: the BRDF's hemispherical albedo.
    const float rho =
        std::clamp(luminance(engine::gltf_hemispherical_albedo(reference_material(mat).brdf).sum()), 0.0f, 1.0f);
    if (!std::isfinite(rho)) return engine::Error{where, location, "the base colour is NaN or infinite"};
    out.positions.insert(out.positions.end(), p.positions.begin(), p.positions.end());
    out.normals.insert(out.normals.end(), normals.begin(), normals.end());
    if (mat.textured()) {
      // Per vertex: the texture's mean around it, over the corner regions of the triangles
      // that share it (each the half of the triangle nearest the vertex), area-weighted.
      if (!looks) looks = material_scene_from(input);  // once per mesh: the mip chains
      BakeInstance at_origin;
      at_origin.material_override = material_override;
      std::vector<double> sum(n, 0.0), weight(n, 0.0);
      for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
        const glm::vec3 corners[3] = {p.positions[p.indices[t]], p.positions[p.indices[t + 1]],
                                      p.positions[p.indices[t + 2]]};
        const ShadingTriangle tri = lookup_triangle(input, at_origin, p, t / 3, corners);
        const glm::vec2 corner_bary[3] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
        for (int k = 0; k < 3; ++k) {
          const glm::vec2 b = corner_bary[k];
          const glm::vec2 centre = b + 0.25f * (glm::vec2(1.0f / 3.0f) - b) * 2.0f;  // halfway to the centroid
          const glm::vec2 e1 = 0.5f * (corner_bary[(k + 1) % 3] - b), e2 = 0.5f * (corner_bary[(k + 2) % 3] - b);
          const float r = std::clamp(luminance(footprint_albedo(*looks, tri, centre, e1, e2)), 0.0f, 1.0f);
          const std::uint32_t v = p.indices[t + static_cast<std::size_t>(k)];
          sum[v] += static_cast<double>(r) * static_cast<double>(tri.area_m2);
          weight[v] += static_cast<double>(tri.area_m2);
        }
      }
      for (std::size_t v = 0; v < n; ++v)
        out.reflectance.push_back(weight[v] > 0.0 ? static_cast<float>(sum[v] / weight[v]) : rho);
    } else {
      out.reflectance.insert(out.reflectance.end(), n, rho);
    }
    for (std::uint32_t i : p.indices) out.indices.push_back(base + i);
  }
  if (out.indices.empty()) return engine::Error{where, location, "the mesh has no triangle"};
  return out;
}

engine::Result<std::vector<BrfSource>> dynamic_brf_meshes(const BakeInput& input) {
  std::vector<BrfSource> out;
  std::set<std::string> taken;  // lower case: file names must not clash on case-insensitive file systems
  for (std::uint32_t i = 0; i < input.instances.size(); ++i) {
    const BakeInstance& inst = input.instances[i];
    if (inst.mobility != BakeMobility::Dynamic || inst.mesh >= input.meshes.size()) continue;
    auto it = std::find_if(out.begin(), out.end(), [&](const BrfSource& s) {
      return s.mesh_index == inst.mesh && s.material_override == inst.material_override;
    });
    if (it != out.end()) {
      it->instances.push_back(i);
      continue;
    }
    auto mesh = brf_mesh_from_input(input, inst.mesh, inst.material_override);
    if (!mesh) return mesh.error();
    BrfSource s;
    const std::string base = name_fragment(input.meshes[inst.mesh].name, inst.mesh);
    s.name = base;
    for (int k = 2; taken.count(lower(s.name)) != 0; ++k) s.name = base + "_" + std::to_string(k);
    taken.insert(lower(s.name));
    s.mesh_index = inst.mesh;
    s.material_override = inst.material_override;
    s.mesh = std::move(mesh).value();
    s.glossy = brf_glossy_lobe(source_material(input, s), &s.specular);
    s.mesh_hash = brf_mesh_hash(s.mesh, s.glossy);
    s.instances.push_back(i);
    out.push_back(std::move(s));
  }
  return out;
}

std::optional<GlossyLobe> brf_glossy_lobe(const BakeMaterial& material, glm::vec3* specular) {
  const engine::GltfBrdf b = reference_material(material).brdf;
  // Reflectance of the specular lobe at normal incidence: the metal's base colour, the
  // dielectric's weighted F0, mixed by metallic (glTF's material = mix(dielectric, metal)).
  const glm::vec3 f0 = (1.0f - b.metallic) * b.specular_weight * b.dielectric_f0 + b.metallic * b.base_color;
  const float top = std::max(f0.x, std::max(f0.y, f0.z));
  if (!(material.roughness < 0.6f) || !(top >= 0.2f)) return std::nullopt;
  const float mean = (f0.x + f0.y + f0.z) / 3.0f;
  if (specular != nullptr) *specular = f0 / mean;
  return GlossyLobe{.f0 = std::min(mean, 1.0f), .alpha = std::clamp(b.alpha, 1e-3f, 1.0f)};
}

glm::vec3 brf_source_albedo(const BakeInput& input, const BrfSource& source) {
  const ReferenceMaterial m = reference_material(source_material(input, source));
  // A glossy source carries its specular lobe in separated terms; only the diffuse lobe's
  // share is folded into the diffuse reflectance.
  const engine::GltfBrdfValue albedo = engine::gltf_hemispherical_albedo(m.brdf);
  return source.glossy ? albedo.diffuse : albedo.sum();
}

}  // namespace gi
