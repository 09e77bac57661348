// Quads, boxes, walls with openings and nodes for the generated scenes.
#include "scene_builder.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include <engine/check.h>

namespace scenegen {

glm::vec2 planar_uv(glm::vec3 p, glm::vec3 n) {
  if (std::abs(n.y) >= 0.7f) return {p.x, p.z};  // floors and ceilings
  // Walls: u to the right as seen from the front, v down (image rows run top to bottom).
  const glm::vec3 right = glm::normalize(glm::vec3(n.z, 0.0f, -n.x));  // cross(+y, n)
  return {glm::dot(p, right), -p.y};
}

void MeshBuilder::quad(int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 facing_hint) {
  // Newell-style normal from the diagonals: robust for slightly non-planar quads.
  glm::vec3 n = glm::normalize(glm::cross(p2 - p0, p3 - p1));
  if (glm::dot(n, facing_hint) < 0.0f) {
    std::swap(p1, p3);
    n = -n;
  }
  engine::Primitive& prim = by_material_[material];
  prim.material = material;
  const auto base = static_cast<std::uint32_t>(prim.positions.size());
  for (const glm::vec3& p : {p0, p1, p2, p3}) {
    prim.positions.push_back(p);
    prim.normals.push_back(n);
    prim.uv0.push_back(planar_uv(p, n));
  }
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) prim.indices.push_back(base + i);
}

void MeshBuilder::quad_grid(int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 facing_hint,
                            int n) {
  glm::vec3 nrm = glm::normalize(glm::cross(p2 - p0, p3 - p1));
  if (glm::dot(nrm, facing_hint) < 0.0f) {
    std::swap(p1, p3);
    nrm = -nrm;
  }
  engine::Primitive& prim = by_material_[material];
  prim.material = material;
  const auto base = static_cast<std::uint32_t>(prim.positions.size());
  const auto fn = static_cast<float>(n);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float u = static_cast<float>(i) / fn, v = static_cast<float>(j) / fn;
      const glm::vec3 p = (1.0f - v) * ((1.0f - u) * p0 + u * p1) + v * ((1.0f - u) * p3 + u * p2);
      prim.positions.push_back(p);
      prim.normals.push_back(nrm);
      prim.uv0.push_back(planar_uv(p, nrm));
    }
  const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (std::uint32_t k : {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)})
        prim.indices.push_back(k);
}

void MeshBuilder::tessellated_box(int material, glm::vec3 c, glm::vec3 h, int n) {
  for (int a = 0; a < 3; ++a)
    for (float sign : {-1.0f, 1.0f}) {
      glm::vec3 nrm(0.0f), t(0.0f), b(0.0f);
      nrm[a] = sign;
      t[(a + 1) % 3] = 1.0f;
      b[(a + 2) % 3] = 1.0f;
      const glm::vec3 f = c + nrm * h;
      const glm::vec3 tu = t * h, bv = b * h;
      quad_grid(material, f - tu - bv, f + tu - bv, f + tu + bv, f - tu + bv, nrm, n);
    }
}

void MeshBuilder::box(int material, glm::vec3 c, glm::vec3 h, bool inward) {
  const glm::vec3 top[4] = {c + glm::vec3(-h.x, h.y, -h.z), c + glm::vec3(h.x, h.y, -h.z), c + glm::vec3(h.x, h.y, h.z),
                            c + glm::vec3(-h.x, h.y, h.z)};
  if (!inward) {
    prism(material, top, c.y - h.y);
    return;
  }
  horizontal(material, c.y - h.y, c.x - h.x, c.x + h.x, c.z - h.z, c.z + h.z, 1.0f);
  horizontal(material, c.y + h.y, c.x - h.x, c.x + h.x, c.z - h.z, c.z + h.z, -1.0f);
  wall_x(material, c.x - h.x, c.z - h.z, c.z + h.z, c.y - h.y, c.y + h.y, 1.0f);
  wall_x(material, c.x + h.x, c.z - h.z, c.z + h.z, c.y - h.y, c.y + h.y, -1.0f);
  wall_z(material, c.z - h.z, c.x - h.x, c.x + h.x, c.y - h.y, c.y + h.y, 1.0f);
  wall_z(material, c.z + h.z, c.x - h.x, c.x + h.x, c.y - h.y, c.y + h.y, -1.0f);
}

void MeshBuilder::prism(int material, const glm::vec3 (&top)[4], float y_bottom) {
  glm::vec3 centre(0.0f);
  for (const glm::vec3& p : top) centre += p;
  centre /= 4.0f;
  centre.y = 0.5f * (centre.y + y_bottom);
  auto down = [&](glm::vec3 p) { return glm::vec3(p.x, y_bottom, p.z); };
  quad(material, top[0], top[1], top[2], top[3], glm::vec3(0, 1, 0));
  quad(material, down(top[0]), down(top[1]), down(top[2]), down(top[3]), glm::vec3(0, -1, 0));
  for (int i = 0; i < 4; ++i) {
    const glm::vec3 a = top[i], b = top[(i + 1) % 4];
    const glm::vec3 mid = 0.5f * (a + b);
    quad(material, a, b, down(b), down(a), glm::vec3(mid.x - centre.x, 0.0f, mid.z - centre.z));
  }
}

namespace {
// Splits the rectangle [a0,a1] x [y0,y1] minus the openings into rectangles (a, y ranges).
std::vector<Opening> wall_pieces(float a0, float a1, float y0, float y1, std::vector<Opening> openings) {
  std::sort(openings.begin(), openings.end(), [](const Opening& l, const Opening& r) { return l.a0 < r.a0; });
  std::vector<Opening> pieces;
  float a = a0;
  for (const Opening& o : openings) {
    if (o.a0 > a) pieces.push_back({a, o.a0, y0, y1});
    if (o.y0 > y0) pieces.push_back({o.a0, o.a1, y0, o.y0});
    if (o.y1 < y1) pieces.push_back({o.a0, o.a1, o.y1, y1});
    a = o.a1;
  }
  if (a < a1) pieces.push_back({a, a1, y0, y1});
  return pieces;
}
}  // namespace

void MeshBuilder::wall_x(int material, float x, float z0, float z1, float y0, float y1, float facing,
                         std::vector<Opening> openings) {
  for (const Opening& r : wall_pieces(z0, z1, y0, y1, std::move(openings)))
    quad(material, {x, r.y0, r.a0}, {x, r.y0, r.a1}, {x, r.y1, r.a1}, {x, r.y1, r.a0}, {facing, 0, 0});
}

void MeshBuilder::wall_z(int material, float z, float x0, float x1, float y0, float y1, float facing,
                         std::vector<Opening> openings) {
  for (const Opening& r : wall_pieces(x0, x1, y0, y1, std::move(openings)))
    quad(material, {r.a0, r.y0, z}, {r.a1, r.y0, z}, {r.a1, r.y1, z}, {r.a0, r.y1, z}, {0, 0, facing});
}

void MeshBuilder::horizontal(int material, float y, float x0, float x1, float z0, float z1, float facing) {
  quad(material, {x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}, {0, facing, 0});
}

engine::Mesh MeshBuilder::build(std::string name) const {
  engine::Mesh mesh;
  mesh.name = std::move(name);
  for (const auto& [material, prim] : by_material_) mesh.primitives.push_back(prim);
  return mesh;
}

std::size_t MeshBuilder::triangle_count() const {
  std::size_t n = 0;
  for (const auto& [material, prim] : by_material_) n += prim.indices.size() / 3;
  return n;
}

int SceneBuilder::material(std::string name, glm::vec3 base_color, float roughness, float metallic,
                           glm::vec3 emissive_radiance) {
  engine::Material m;
  m.name = std::move(name);
  m.base_color = glm::vec4(base_color, 1.0f);
  m.roughness = roughness;
  m.metallic = metallic;
  m.emissive = emissive_radiance;
  asset_.materials.push_back(std::move(m));
  return static_cast<int>(asset_.materials.size()) - 1;
}

int SceneBuilder::image(engine::Image image) {
  asset_.images.push_back(std::move(image));
  return static_cast<int>(asset_.images.size()) - 1;
}

int SceneBuilder::textured_material(std::string name, int image, float roughness, glm::vec3 tint) {
  GI_EXPECTS(image >= 0 && image < static_cast<int>(asset_.images.size()), "textured_material needs an added image");
  const int m = material(std::move(name), tint, roughness);
  engine::Material& mat = asset_.materials[static_cast<std::size_t>(m)];
  mat.base_color_texture.image = image;  // TEXCOORD_0, REPEAT, linear with mipmaps: the defaults
  return m;
}

int SceneBuilder::add_mesh(const std::string& name, const MeshBuilder& mesh) {
  asset_.meshes.push_back(mesh.build(name));
  return static_cast<int>(asset_.meshes.size()) - 1;
}

int SceneBuilder::add_mesh_node(const std::string& name, const MeshBuilder& mesh, engine::Mobility mobility,
                                glm::vec3 translation, glm::quat rotation) {
  return add_instance_node(name, add_mesh(name, mesh), mobility, translation, rotation);
}

int SceneBuilder::add_instance_node(const std::string& name, int mesh, engine::Mobility mobility, glm::vec3 translation,
                                    glm::quat rotation) {
  engine::Node n;
  n.name = name;
  n.mesh = mesh;
  n.translation = translation;
  n.rotation = rotation;
  n.gi.mobility = mobility;
  asset_.nodes.push_back(std::move(n));
  return static_cast<int>(asset_.nodes.size()) - 1;
}

int SceneBuilder::add_child_mesh_node(const std::string& name, int mesh, int parent, glm::vec3 translation) {
  engine::Node n;
  n.name = name;
  n.mesh = mesh;
  n.parent = parent;
  n.translation = translation;
  n.gi.mobility = asset_.nodes[static_cast<std::size_t>(parent)].gi.mobility;
  asset_.nodes.push_back(std::move(n));
  return static_cast<int>(asset_.nodes.size()) - 1;
}

int SceneBuilder::add_light_node(const std::string& name, const engine::Light& light, glm::vec3 translation,
                                 glm::quat rotation, int parent) {
  asset_.lights.push_back({name, light});
  engine::Node n;
  n.name = name;
  n.parent = parent;
  n.light = static_cast<int>(asset_.lights.size()) - 1;
  n.translation = translation;
  n.rotation = rotation;
  n.gi.mobility = light.moves ? engine::Mobility::Dynamic : engine::Mobility::Static;
  asset_.nodes.push_back(std::move(n));
  return static_cast<int>(asset_.nodes.size()) - 1;
}

int SceneBuilder::add_camera_node(const std::string& name, glm::vec3 eye, glm::vec3 target, float yfov_rad) {
  engine::Camera cam;
  cam.yfov_rad = yfov_rad;
  cam.znear_m = 0.01f;
  cam.zfar_m = 100.0f;
  asset_.cameras.push_back({name, cam});
  const glm::vec3 z = glm::normalize(eye - target);  // the camera looks along -Z
  const glm::vec3 x = glm::normalize(glm::cross(glm::vec3(0, 1, 0), z));
  const glm::vec3 y = glm::cross(z, x);
  engine::Node n;
  n.name = name;
  n.camera = static_cast<int>(asset_.cameras.size()) - 1;
  n.translation = eye;
  n.rotation = glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
  asset_.nodes.push_back(std::move(n));
  return static_cast<int>(asset_.nodes.size()) - 1;
}

int SceneBuilder::add_group_node(const std::string& name, glm::vec3 translation, engine::Mobility mobility) {
  engine::Node n;
  n.name = name;
  n.translation = translation;
  n.gi.mobility = mobility;
  asset_.nodes.push_back(std::move(n));
  return static_cast<int>(asset_.nodes.size()) - 1;
}

glm::quat facing(glm::vec3 direction, glm::vec3 x_axis) {
  const glm::vec3 z = -glm::normalize(direction);
  const glm::vec3 x = glm::normalize(x_axis);
  const glm::vec3 y = glm::cross(z, x);
  return glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
}

engine::Light area_light(glm::vec2 size_m, glm::vec3 radiance) {
  engine::Light l;
  l.type = engine::LightType::Area;
  l.color = radiance;
  l.intensity = 1.0f;
  l.area_size_m = size_m;
  return l;
}

engine::Light point_light(float intensity_w_sr, glm::vec3 color, bool moves) {
  engine::Light l;
  l.type = engine::LightType::Point;
  l.color = color;
  l.intensity = intensity_w_sr;
  l.moves = moves;
  return l;
}

}  // namespace scenegen
