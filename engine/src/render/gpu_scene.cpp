#include "render/gpu_scene.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <string>
#include <tuple>

#include <GL/glcorearb.h>

#include <engine/tangents.h>

#include "render/program_uniforms.h"

namespace engine::render {

namespace {

// Area-weighted vertex normals for primitives that have none.
std::vector<glm::vec3> computed_normals(const Primitive& p, const std::vector<std::uint32_t>& indices) {
  std::vector<glm::vec3> n(p.positions.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const glm::vec3& a = p.positions[indices[t]];
    const glm::vec3& b = p.positions[indices[t + 1]];
    const glm::vec3& c = p.positions[indices[t + 2]];
    const glm::vec3 face = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) n[indices[t + static_cast<std::size_t>(k)]] += face;
  }
  for (glm::vec3& v : n) {
    const float len = glm::length(v);
    v = len > 0.0f ? v / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return n;
}

// One GL sampler object's parameters for a glTF sampler. The default TextureSampler (repeat,
// linear, mipmaps) equals what upload_image sets on the texture itself.
GlSampler make_sampler(const TextureSampler& s) {
  const auto wrap = [](TextureWrap w) -> GLint {
    return w == TextureWrap::ClampToEdge      ? GL_CLAMP_TO_EDGE
           : w == TextureWrap::MirroredRepeat ? GL_MIRRORED_REPEAT
                                              : GL_REPEAT;
  };
  GlSampler out = GlSampler::create();
  glSamplerParameteri(out.id(), GL_TEXTURE_WRAP_S, wrap(s.wrap_s));
  glSamplerParameteri(out.id(), GL_TEXTURE_WRAP_T, wrap(s.wrap_t));
  glSamplerParameteri(out.id(), GL_TEXTURE_MAG_FILTER, s.mag_linear ? GL_LINEAR : GL_NEAREST);
  const GLint min = s.mipmaps ? (s.min_linear ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST_MIPMAP_LINEAR)
                              : (s.min_linear ? GL_LINEAR : GL_NEAREST);
  glSamplerParameteri(out.id(), GL_TEXTURE_MIN_FILTER, min);
  return out;
}

// KHR_texture_transform as two rows of a 2x3 matrix (engine::transformed_uv's formula).
void transform_rows(const TextureTransform& t, glm::vec4& row0, glm::vec4& row1) {
  const float c = std::cos(t.rotation_rad);
  const float s = std::sin(t.rotation_rad);
  row0 = glm::vec4(c * t.scale.x, s * t.scale.y, t.offset.x, 0.0f);
  row1 = glm::vec4(-s * t.scale.x, c * t.scale.y, t.offset.y, 0.0f);
}

GlTexture upload_image(const Image& image, bool srgb) {
  const int levels = 1 + static_cast<int>(std::floor(std::log2(std::max(image.width, image.height))));
  GlTexture t = GlTexture::create_2d(srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, image.width, image.height, levels);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  // Rows top to bottom as in the file: glTF's UV (0, 0) is the image's top-left corner,
  // which lands at texture coordinate (0, 0) this way.
  glTextureSubImage2D(t.id(), 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba8.data());
  // Every level is made: a texture's samplers (TextureSampler::mipmaps) may read them.
  glGenerateTextureMipmap(t.id());
  glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return t;
}

}  // namespace

void set_material_texturing(const GpuMaterial& m, const MaterialUniforms& at) {
  glUniform1i(at.alpha_mode, static_cast<int>(m.alpha_mode));
  glUniform1f(at.alpha_cutoff, m.alpha_cutoff);
  glUniform4iv(at.texcoord_sets, 1, &m.texcoord_sets.x);
  glUniform4fv(at.uv_transforms, 8, &m.uv_transforms[0].x);
}

void bind_alpha_test(const GpuMaterial& m, float cutoff, const MaterialUniforms& at) {
  set_material_texturing(m, at);
  glUniform1f(at.alpha_cutoff, cutoff);
  glUniform1f(at.base_alpha, m.base_color.w);
  glBindTextureUnit(kMaterialBaseColorUnit, m.base_color_texture);
  glBindSampler(kMaterialBaseColorUnit, m.samplers[kBaseColorSlot]);
}

void unbind_material_samplers() {
  for (GLuint unit :
       {kMaterialBaseColorUnit, kMaterialMetallicRoughnessUnit, kMaterialEmissiveUnit, kMaterialNormalUnit})
    glBindSampler(unit, 0);
}

const GpuMaterial& GpuScene::material(int index) const {
  if (index < 0 || static_cast<std::size_t>(index) >= materials_.size()) return default_material_;
  return materials_[static_cast<std::size_t>(index)];
}

namespace {

// Where a mesh's errors point: the file and the mesh's name in it.
struct MeshSource {
  const std::string& file;
  std::string mesh;  ///< "meshes[3]", "atlas mesh of entity 12"
};

Error primitive_error(const MeshSource& at, std::size_t prim, const std::string& what) {
  return Error{at.file, at.mesh + ".primitives[" + std::to_string(prim) + "]", what};
}

// A primitive's indices, checked against its vertices (0, 1, 2, ... when it has none).
Result<std::vector<std::uint32_t>> checked_indices(const Primitive& p, const MeshSource& at, std::size_t pi,
                                                   std::size_t material_count) {
  const std::size_t n = p.positions.size();
  if (!p.normals.empty() && p.normals.size() != n)
    return primitive_error(at, pi, "normals count differs from positions count");
  if (!p.uv0.empty() && p.uv0.size() != n) return primitive_error(at, pi, "uv0 count differs from positions count");
  if (!p.uv1.empty() && p.uv1.size() != n) return primitive_error(at, pi, "uv1 count differs from positions count");
  if (p.material >= 0 && static_cast<std::size_t>(p.material) >= material_count)
    return primitive_error(at, pi, "material index " + std::to_string(p.material) + " out of range");
  std::vector<std::uint32_t> prim_indices = p.indices;
  if (prim_indices.empty()) {
    prim_indices.resize(n);
    for (std::size_t i = 0; i < n; ++i) prim_indices[i] = static_cast<std::uint32_t>(i);
  }
  if (prim_indices.size() % 3 != 0) return primitive_error(at, pi, "index count is not a multiple of 3");
  for (std::uint32_t i : prim_indices)
    if (i >= n) return primitive_error(at, pi, "index " + std::to_string(i) + " out of range");
  if (!p.tangents.empty() && p.tangents.size() != n)
    return primitive_error(at, pi, "tangents count differs from positions count");
  return prim_indices;
}

// Tangents where the material has a normal map: the file's, else generated from the normal
// texture's UV set (engine/tangents.h). A material_override with a normal map on a mesh whose
// own material has none finds zero tangents and shades without it.
std::vector<glm::vec4> primitive_tangents(const Primitive& p, const std::vector<glm::vec3>& normals,
                                          const std::vector<std::uint32_t>& prim_indices,
                                          const std::vector<int>& normal_texcoords) {
  const int set = p.material >= 0 ? normal_texcoords[static_cast<std::size_t>(p.material)] : -1;
  if (set < 0) return {};
  if (!p.tangents.empty()) return p.tangents;
  const std::vector<glm::vec2>& uvs = set == 1 ? p.uv1 : p.uv0;
  if (uvs.size() != p.positions.size()) return {};
  return generate_tangents(p.positions, normals, uvs, prim_indices);
}

}  // namespace

Result<GpuMesh> GpuScene::append_mesh(const Mesh& mesh, const std::string& file, const std::string& name,
                                      MeshGeometry& out) const {
  const MeshSource at{file, name};
  const auto vertex_at = [&] { return static_cast<std::int32_t>(out.first_vertex + out.vertices.size()); };
  GpuMesh gm;
  gm.first_vertex = vertex_at();
  gm.bounds_min = glm::vec3(std::numeric_limits<float>::max());
  gm.bounds_max = glm::vec3(-std::numeric_limits<float>::max());
  for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
    const Primitive& p = mesh.primitives[pi];
    auto checked = checked_indices(p, at, pi, normal_texcoords_.size());
    if (!checked) return checked.error();
    const std::vector<std::uint32_t>& prim_indices = checked.value();
    const std::vector<glm::vec3> normals = p.normals.empty() ? computed_normals(p, prim_indices) : p.normals;
    const std::vector<glm::vec4> tangents = primitive_tangents(p, normals, prim_indices, normal_texcoords_);
    GpuPrimitive gp;
    gp.first_index = static_cast<std::uint32_t>(out.first_index + out.indices.size());
    gp.index_count = static_cast<std::uint32_t>(prim_indices.size());
    gp.base_vertex = vertex_at();
    gp.material = p.material;
    for (std::size_t i = 0; i < p.positions.size(); ++i) {
      out.vertices.push_back(GpuVertex{p.positions[i], normals[i], p.uv0.empty() ? glm::vec2(0.0f) : p.uv0[i],
                                       p.uv1.empty() ? glm::vec2(0.0f) : p.uv1[i],
                                       tangents.empty() ? glm::vec4(0.0f) : tangents[i]});
      gm.bounds_min = glm::min(gm.bounds_min, p.positions[i]);
      gm.bounds_max = glm::max(gm.bounds_max, p.positions[i]);
    }
    out.indices.insert(out.indices.end(), prim_indices.begin(), prim_indices.end());
    for (std::uint32_t i : prim_indices) gm.triangle_corners.push_back(p.positions[i]);
    gm.primitives.push_back(gp);
  }
  gm.vertex_count = static_cast<std::uint32_t>(vertex_at() - gm.first_vertex);
  if (gm.vertex_count == 0) gm.bounds_min = gm.bounds_max = glm::vec3(0.0f);
  return gm;
}

void GpuScene::bind_vertex_array() {
  vao_ = GlVertexArray::create();
  const GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, vertices_.id(), 0, sizeof(GpuVertex));
  glVertexArrayElementBuffer(vao, indices_.id());
  const GLuint offsets[5] = {offsetof(GpuVertex, position), offsetof(GpuVertex, normal), offsetof(GpuVertex, uv0),
                             offsetof(GpuVertex, uv1), offsetof(GpuVertex, tangent)};
  const GLint sizes[5] = {3, 3, 2, 2, 4};
  for (GLuint a = 0; a < 5; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
    glVertexArrayAttribBinding(vao, a, 0);
  }
}

Result<GpuScene> GpuScene::upload(const SceneAsset& assets) {
  GpuScene scene;
  for (const Material& m : assets.materials)
    scene.normal_texcoords_.push_back(m.normal_texture.present() ? m.normal_texture.texcoord : -1);
  MeshGeometry geometry;
  for (std::size_t m = 0; m < assets.meshes.size(); ++m) {
    auto gm = scene.append_mesh(assets.meshes[m], assets.source, "meshes[" + std::to_string(m) + "]", geometry);
    if (!gm) return gm.error();
    scene.meshes_.push_back(std::move(gm).value());
  }
  scene.scene_meshes_ = scene.meshes_.size();
  scene.scene_vertices_ = geometry.vertices.size();
  scene.scene_indices_ = geometry.indices.size();
  // Copyable: set_atlas_meshes keeps the scene's part when it appends the atlas meshes.
  scene.vertices_ = GlBuffer::create(geometry.vertices.size() * sizeof(GpuVertex), geometry.vertices.data());
  scene.indices_ = GlBuffer::create(geometry.indices.size() * sizeof(std::uint32_t), geometry.indices.data());
  scene.bind_vertex_array();
  if (Status s = scene.upload_materials(assets); !s) return s.error();
  return scene;
}

Status GpuScene::set_atlas_meshes(std::span<const AtlasMesh> atlas) {
  MeshGeometry geometry{.first_vertex = scene_vertices_, .first_index = scene_indices_};
  std::vector<GpuMesh> added;
  for (const AtlasMesh& a : atlas) {
    auto gm = append_mesh(a.mesh, "indirect light provider", "atlas mesh of entity " + std::to_string(a.entity.id()),
                          geometry);
    if (!gm) return gm.error();
    added.push_back(std::move(gm).value());
  }
  // The scene's vertices and indices first (copied on the GPU), the atlas meshes' after them.
  const auto grown = [](const GlBuffer& old, std::size_t kept, const void* more, std::size_t more_bytes) {
    GlBuffer b = GlBuffer::create(kept + more_bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    if (kept > 0) glCopyNamedBufferSubData(old.id(), b.id(), 0, 0, static_cast<GLsizeiptr>(kept));
    if (more_bytes > 0)
      glNamedBufferSubData(b.id(), static_cast<GLintptr>(kept), static_cast<GLsizeiptr>(more_bytes), more);
    return b;
  };
  vertices_ = grown(vertices_, scene_vertices_ * sizeof(GpuVertex), geometry.vertices.data(),
                    geometry.vertices.size() * sizeof(GpuVertex));
  indices_ = grown(indices_, scene_indices_ * sizeof(std::uint32_t), geometry.indices.data(),
                   geometry.indices.size() * sizeof(std::uint32_t));
  bind_vertex_array();
  meshes_.resize(scene_meshes_);
  for (GpuMesh& gm : added) meshes_.push_back(std::move(gm));
  return {};
}

// Long because it is one loop over the materials: the texture and sampler caches it fills are
// shared by every material, and each material's textures are checked where they are read.
Status GpuScene::upload_materials(const SceneAsset& assets) {
  GpuScene& scene = *this;
  const std::uint8_t white[4] = {255, 255, 255, 255};
  scene.white_ = GlTexture::create_2d(GL_RGBA8, 1, 1);
  glTextureSubImage2D(scene.white_.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
  scene.default_material_.base_color_texture = scene.white_.id();
  scene.default_material_.metallic_roughness_texture = scene.white_.id();
  scene.default_material_.emissive_texture = scene.white_.id();

  std::map<std::pair<int, bool>, std::uint32_t> uploaded;
  auto texture = [&](int image, bool srgb, std::size_t material, const char* slot) -> Result<std::uint32_t> {
    if (image < 0) return scene.white_.id();
    if (static_cast<std::size_t>(image) >= assets.images.size())
      return Error{assets.source, "materials[" + std::to_string(material) + "]." + slot,
                   "image index " + std::to_string(image) + " out of range"};
    const Image& img = assets.images[static_cast<std::size_t>(image)];
    if (img.width <= 0 || img.height <= 0 ||
        img.rgba8.size() != static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 4)
      return Error{assets.source, "images[" + std::to_string(image) + "]", "image has no or inconsistent RGBA8 pixels"};
    if (auto it = uploaded.find({image, srgb}); it != uploaded.end()) return it->second;
    scene.textures_.push_back(upload_image(img, srgb));
    uploaded[{image, srgb}] = scene.textures_.back().id();
    return scene.textures_.back().id();
  };
  std::map<std::tuple<TextureWrap, TextureWrap, bool, bool, bool>, std::uint32_t> samplers;
  auto sampler = [&](const TextureRef& ref) -> std::uint32_t {
    if (!ref.present()) return 0;
    const TextureSampler& s = ref.sampler;
    const auto key = std::make_tuple(s.wrap_s, s.wrap_t, s.mag_linear, s.min_linear, s.mipmaps);
    if (auto it = samplers.find(key); it != samplers.end()) return it->second;
    scene.samplers_.push_back(make_sampler(s));
    return samplers[key] = scene.samplers_.back().id();
  };
  for (std::size_t i = 0; i < assets.materials.size(); ++i) {
    const Material& src = assets.materials[i];
    GpuMaterial gm;
    gm.base_color = src.base_color;
    gm.metallic = src.metallic;
    gm.roughness = src.roughness;
    gm.emissive = src.emissive;
    gm.specular_factor = src.specular_factor;
    gm.specular_color_factor = src.specular_color_factor;
    gm.double_sided = src.double_sided;
    gm.alpha_mode = src.alpha_mode;
    gm.alpha_cutoff = src.alpha_cutoff;
    gm.normal_scale = src.normal_scale;
    auto base = texture(src.base_color_texture.image, true, i, "baseColorTexture");
    if (!base) return base.error();
    auto mr = texture(src.metallic_roughness_texture.image, false, i, "metallicRoughnessTexture");
    if (!mr) return mr.error();
    auto emissive = texture(src.emissive_texture.image, true, i, "emissiveTexture");
    if (!emissive) return emissive.error();
    auto normal = texture(src.normal_texture.image, false, i, "normalTexture");
    if (!normal) return normal.error();
    gm.base_color_texture = base.value();
    gm.metallic_roughness_texture = mr.value();
    gm.emissive_texture = emissive.value();
    gm.normal_texture = src.normal_texture.present() ? normal.value() : 0;
    const TextureRef* refs[4] = {&src.base_color_texture, &src.metallic_roughness_texture, &src.normal_texture,
                                 &src.emissive_texture};
    for (int slot = 0; slot < 4; ++slot) {
      const TextureRef& ref = *refs[slot];
      if (ref.texcoord != 0 && ref.texcoord != 1)
        return Error{assets.source, "materials[" + std::to_string(i) + "]",
                     "texture TEXCOORD_" + std::to_string(ref.texcoord) + " is not supported (0 or 1)"};
      gm.samplers[static_cast<std::size_t>(slot)] = sampler(ref);
      gm.texcoord_sets[slot] = ref.texcoord;
      transform_rows(ref.transform, gm.uv_transforms[static_cast<std::size_t>(2 * slot)],
                     gm.uv_transforms[static_cast<std::size_t>(2 * slot + 1)]);
    }
    scene.has_mask_ = scene.has_mask_ || gm.alpha_mode == AlphaMode::Mask;
    scene.has_cut_out_ = scene.has_cut_out_ || gm.cut_out();
    scene.materials_.push_back(gm);
  }
  return {};
}

}  // namespace engine::render
