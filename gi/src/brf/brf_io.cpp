#include "brf/brf_io.h"

#include <engine/byte_stream.h>
#include <engine/finite.h>

#include <cmath>
#include <cstring>
#include <set>
#include <system_error>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"
#include "io/json_fields.h"
#include "io/zstd_stream.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// zstd level of the coefficient planes: the high preset's 14 MB field packs in well under a
// second on one core at this level.
constexpr int kZstdLevel = 6;
// Bounds a file may claim before anything is allocated (the bakers' settings limits).
constexpr int kMaxBasis = 1024;
constexpr int kMaxSpheres = 256;
constexpr int kMaxFaceResolution = 256;
constexpr std::size_t kMaxSingularValues = 65536;
constexpr std::uint64_t kMaxVertices = std::uint64_t{1} << 31;

std::string str(std::uint64_t v) { return std::to_string(v); }

engine::Error file_error(const fs::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

// Index of the first non-finite value, or npos.
std::size_t first_non_finite(const std::vector<float>& v) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) return i;
  return std::string::npos;
}

bool is_hex16(const std::string& s) {
  if (s.size() != 16) return false;
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

// The raw coefficient count a field's header implies (0 when out of range).
std::uint64_t field_values(int spheres, int res, int bands, int basis, int terms) {
  if (spheres < 1 || spheres > kMaxSpheres || res < 1 || res > kMaxFaceResolution || (bands != 3 && bands != 4) ||
      basis < 1 || basis > kMaxBasis || terms < 1 || terms > 1 + kMaxGlossyTerms)
    return 0;
  return static_cast<std::uint64_t>(spheres) * 6 * static_cast<std::uint64_t>(res) * static_cast<std::uint64_t>(res) *
         static_cast<std::uint64_t>(basis) * static_cast<std::uint64_t>(terms) * static_cast<std::uint64_t>(bands) *
         static_cast<std::uint64_t>(bands);
}

// Empty when a glossy separation's tables fit its header and hold finite values.
std::string check_glossy(const BrdfSeparation& g) {
  if (g.terms < 1 || g.terms > kMaxGlossyTerms || g.resolution < 4 || g.resolution > 64)
    return "glossy separation: " + std::to_string(g.terms) + " terms at resolution " + std::to_string(g.resolution) +
           " (1..15 terms, 4..64 expected)";
  if (!(g.lobe.f0 > 0.0f && g.lobe.f0 <= 1.0f) || !(g.lobe.alpha > 0.0f && g.lobe.alpha <= 1.0f) ||
      !std::isfinite(g.relative_error))
    return "glossy separation: f0 and alpha must lie in (0, 1] and the error be finite";
  const auto cells = static_cast<std::uint64_t>(g.terms) * static_cast<std::uint64_t>(g.resolution * g.resolution);
  if (g.g.size() != cells || g.h.size() != cells ||
      g.lobe_sh.size() != static_cast<std::uint64_t>(g.terms) * kMaxShCoefficients || g.singular_values.size() > 4096)
    return "glossy separation: table sizes do not match " + std::to_string(g.terms) + " terms at resolution " +
           std::to_string(g.resolution);
  for (const std::vector<float>* v : {&g.g, &g.h, &g.lobe_sh, &g.singular_values})
    if (std::size_t i = first_non_finite(*v); i != std::string::npos)
      return "glossy separation value " + str(i) + " is NaN or infinite";
  return {};
}

// Empty when the bake's parts fit together and hold finite values, else what is wrong.
std::string check_bake(const BrfMeshBake& bake) {
  const BrfModel& b = bake.model;
  if (b.name.empty() || !is_bundle_file_name(brf_file_name(b.name)))
    return "mesh name \"" + b.name + "\" is not usable in a file name";
  if (!is_hex16(bake.mesh_hash)) return "mesh_hash \"" + bake.mesh_hash + "\" is not 16 lowercase hex digits";
  const BrfBasis& s = b.basis;
  if (s.vertex_count < 1 || s.vertex_count > kMaxVertices)
    return "vertex_count " + str(s.vertex_count) + " is outside 1..2^31";
  if (s.basis_count < 1 || s.basis_count > kMaxBasis)
    return "basis_count " + std::to_string(s.basis_count) + " is outside 1..1024";
  const auto n = static_cast<std::uint64_t>(s.basis_count);
  if (s.psi.size() != n * s.vertex_count)
    return "psi has " + str(s.psi.size()) + " values, " + str(n) + " functions x " + str(s.vertex_count) +
           " vertices = " + str(n * s.vertex_count) + " expected";
  if (s.a_inverse.size() != n * n)
    return "a_inverse has " + str(s.a_inverse.size()) + " values, " + str(n * n) + " expected";
  if (s.singular_values.size() > kMaxSingularValues)
    return "singular_values has " + str(s.singular_values.size()) + " values, at most 65536 expected";
  if (!std::isfinite(s.condition) || !(s.condition >= 1.0))
    return "condition " + std::to_string(s.condition) + " is not a finite number >= 1";
  if (!engine::all_finite(s.centre) || !std::isfinite(s.radius) || !(s.radius > 0.0f))
    return "the basis's bounding sphere is not finite with a positive radius";
  if (std::size_t i = first_non_finite(s.psi); i != std::string::npos)
    return "psi value " + str(i) + " (function " + str(i / s.vertex_count) + ", vertex " + str(i % s.vertex_count) +
           ") is NaN or infinite";
  if (std::size_t i = first_non_finite(s.a_inverse); i != std::string::npos)
    return "a_inverse value " + str(i) + " is NaN or infinite";
  if (std::size_t i = first_non_finite(s.singular_values); i != std::string::npos)
    return "singular value " + str(i) + " is NaN or infinite";
  const BasisRadianceField& f = b.field;
  const int terms = 1 + (b.glossy ? b.glossy->terms : 0);
  if (b.glossy)
    if (std::string problem = check_glossy(*b.glossy); !problem.empty()) return problem;
  if (s.terms != terms || f.terms != terms)
    return "BRDF terms disagree: the basis was trained for " + std::to_string(s.terms) + ", the field holds " +
           std::to_string(f.terms) + ", the material has " + std::to_string(terms);
  const std::uint64_t values = field_values(f.spheres, f.face_resolution, f.sh_bands, f.basis_count, f.terms);
  if (values == 0)
    return "field settings out of range (spheres " + std::to_string(f.spheres) + ", face_resolution " +
           std::to_string(f.face_resolution) + ", sh_bands " + std::to_string(f.sh_bands) + ", basis_count " +
           std::to_string(f.basis_count) + ")";
  if (f.basis_count != s.basis_count)
    return "the field has " + std::to_string(f.basis_count) + " basis functions, the basis " +
           std::to_string(s.basis_count);
  // Radii from 1 micrometre to 1e6 m, at most 1e9 apart: log(outer / inner) and the lookups'
  // r / inner stay finite (a subnormal inner radius made the sphere index NaN).
  if (!engine::all_finite(f.centre) || !std::isfinite(f.inner_radius) || !std::isfinite(f.outer_radius) ||
      !(f.inner_radius >= 1e-6f) || !(f.outer_radius >= f.inner_radius) || !(f.outer_radius <= 1e6f))
    return "the field's centre and radii are not finite with 1e-6 m <= inner_radius <= outer_radius <= 1e6 m";
  if (f.coefficients.size() != values)
    return "the field has " + str(f.coefficients.size()) + " coefficients, " + std::to_string(f.spheres) +
           " spheres x 6 x " + std::to_string(f.face_resolution) + "^2 points x " + std::to_string(f.channel_count()) +
           " channels x " + std::to_string(f.coefficient_count()) + " = " + str(values) + " expected";
  if (std::size_t i = first_non_finite(f.coefficients); i != std::string::npos)
    return "field coefficient " + str(i) + " is NaN or infinite";
  return {};
}

// float32 values -> four byte planes (brf_io.h), and back.
std::vector<std::uint8_t> to_planes(const std::vector<float>& values) {
  const std::size_t n = values.size();
  std::vector<std::uint8_t> planes(n * 4);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &values[i], 4);
    for (std::size_t k = 0; k < 4; ++k) planes[k * n + i] = static_cast<std::uint8_t>(bits >> (8 * k));
  }
  return planes;
}

std::vector<float> from_planes(const std::vector<std::uint8_t>& planes) {
  const std::size_t n = planes.size() / 4;
  std::vector<float> values(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t bits = 0;
    for (std::size_t k = 0; k < 4; ++k) bits |= static_cast<std::uint32_t>(planes[k * n + i]) << (8 * k);
    std::memcpy(&values[i], &bits, 4);
  }
  return values;
}

json settings_json(const BrfSettings& s) {
  return json{{"basis",
               {{"lights", s.basis.lights},
                {"basis", s.basis.basis},
                {"light_radius_scale", s.basis.light_radius_scale},
                {"rank_tolerance", s.basis.rank_tolerance},
                {"max_condition", s.basis.max_condition}}},
              {"field",
               {{"spheres", s.field.spheres},
                {"face_resolution", s.field.face_resolution},
                {"sh_bands", s.field.sh_bands},
                {"inner_radius_scale", s.field.inner_radius_scale},
                {"outer_radius_scale", s.field.outer_radius_scale},
                {"directions", s.field.directions}}}};
}

BrfSettings read_settings(JsonFields& f) {
  BrfSettings s;
  s.basis.lights = f.get<int>("settings.basis.lights");
  s.basis.basis = f.get<int>("settings.basis.basis");
  s.basis.light_radius_scale = f.get<float>("settings.basis.light_radius_scale");
  s.basis.rank_tolerance = f.get<float>("settings.basis.rank_tolerance");
  s.basis.max_condition = f.get<double>("settings.basis.max_condition");
  s.field.spheres = f.get<int>("settings.field.spheres");
  s.field.face_resolution = f.get<int>("settings.field.face_resolution");
  s.field.sh_bands = f.get<int>("settings.field.sh_bands");
  s.field.inner_radius_scale = f.get<float>("settings.field.inner_radius_scale");
  s.field.outer_radius_scale = f.get<float>("settings.field.outer_radius_scale");
  s.field.directions = f.get<int>("settings.field.directions");
  return s;
}

}  // namespace

std::string brf_file_name(const std::string& mesh_name) { return "brf_" + mesh_name + ".bin"; }

engine::Status write_brf_mesh(const fs::path& path, const BrfMeshBake& bake, std::uint64_t* compressed_bytes) {
  if (std::string problem = check_bake(bake); !problem.empty())
    return file_error(path, "", "cannot save the basis radiance field: " + problem);
  const BrfModel& model = bake.model;
  const std::vector<std::uint8_t> planes = to_planes(model.field.coefficients);
  auto packed = write_zstd_stream(path, planes, kZstdLevel);
  if (!packed) return packed.error();
  const std::vector<std::uint8_t>& frame = *packed;
  if (compressed_bytes != nullptr) *compressed_bytes = frame.size();

  const BrfBasis& b = model.basis;
  const BasisRadianceField& f = model.field;
  engine::ByteWriter w;
  w.put_string(model.name);
  w.put_string(bake.mesh_hash);
  w.put(static_cast<std::uint64_t>(b.vertex_count));
  w.put(static_cast<std::int32_t>(b.basis_count));
  w.put(b.condition);
  w.put(b.centre);
  w.put(b.radius);
  w.put_array(b.psi);
  w.put_array(b.a_inverse);
  w.put_array(b.singular_values);
  w.put(static_cast<std::int32_t>(b.terms));
  w.put(static_cast<std::int32_t>(f.spheres));
  w.put(static_cast<std::int32_t>(f.face_resolution));
  w.put(static_cast<std::int32_t>(f.sh_bands));
  w.put(static_cast<std::int32_t>(f.basis_count));
  w.put(static_cast<std::int32_t>(f.terms));
  w.put(f.centre);
  w.put(f.inner_radius);
  w.put(f.outer_radius);
  w.put(static_cast<std::uint64_t>(planes.size()));
  w.put_array(frame);
  w.put(static_cast<std::int32_t>(model.glossy ? model.glossy->terms : 0));
  if (model.glossy) {
    const BrdfSeparation& g = *model.glossy;
    w.put(g.lobe.f0);
    w.put(g.lobe.alpha);
    w.put(static_cast<std::int32_t>(g.resolution));
    w.put(g.relative_error);
    w.put_array(g.g);
    w.put_array(g.h);
    w.put_array(g.lobe_sh);
    w.put_array(g.singular_values);
  }
  return write_blob(path, kBrfMeshMagic, kBrfMeshVersion, w.bytes());
}

engine::Result<BrfMeshBake> read_brf_mesh(const fs::path& path) {
  auto payload = read_blob(path, kBrfMeshMagic, kBrfMeshVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  BrfMeshBake out;
  BrfBasis& b = out.model.basis;
  BasisRadianceField& f = out.model.field;
  std::uint64_t vertex_count = 0, coefficient_bytes = 0;
  std::int32_t basis_count = 0, basis_terms = 0, spheres = 0, res = 0, bands = 0, field_basis = 0, field_terms = 0,
               glossy_terms = 0;
  std::vector<std::uint8_t> frame;
  bool complete = r.get_string(out.model.name) && r.get_string(out.mesh_hash) && r.get(vertex_count) &&
                  r.get(basis_count) && r.get(b.condition) && r.get(b.centre) && r.get(b.radius) &&
                  r.get_array(b.psi) && r.get_array(b.a_inverse) && r.get_array(b.singular_values) &&
                  r.get(basis_terms) && r.get(spheres) && r.get(res) && r.get(bands) && r.get(field_basis) &&
                  r.get(field_terms) && r.get(f.centre) && r.get(f.inner_radius) && r.get(f.outer_radius) &&
                  r.get(coefficient_bytes) && r.get_array(frame) && r.get(glossy_terms);
  if (complete && glossy_terms != 0) {
    BrdfSeparation& g = out.model.glossy.emplace();
    std::int32_t table = 0;
    complete = r.get(g.lobe.f0) && r.get(g.lobe.alpha) && r.get(table) && r.get(g.relative_error) && r.get_array(g.g) &&
               r.get_array(g.h) && r.get_array(g.lobe_sh) && r.get_array(g.singular_values);
    g.terms = glossy_terms;
    g.resolution = table;
  }
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return file_error(path, location, "truncated payload");
  if (r.remaining() != 0) return file_error(path, location, "unexpected data after the last field");
  if (vertex_count < 1 || vertex_count > kMaxVertices)
    return file_error(path, "vertex_count", "vertex_count " + str(vertex_count) + " is outside 1..2^31");
  b.vertex_count = static_cast<std::size_t>(vertex_count);
  b.basis_count = basis_count;
  b.terms = basis_terms;
  f.terms = field_terms;
  f.spheres = spheres;
  f.face_resolution = res;
  f.sh_bands = bands;
  f.basis_count = field_basis;

  // Sizes before the coefficients are allocated: a corrupt count must not ask for gigabytes.
  const std::uint64_t values = field_values(spheres, res, bands, field_basis, field_terms);
  if (values == 0)
    return file_error(path, "field",
                      "field settings out of range (spheres " + std::to_string(spheres) + ", face_resolution " +
                          std::to_string(res) + ", sh_bands " + std::to_string(bands) + ", basis_count " +
                          std::to_string(field_basis) + ", terms " + std::to_string(field_terms) + ")");
  if (coefficient_bytes != values * 4)
    return file_error(path, "coefficient_bytes",
                      "the file says " + str(coefficient_bytes) + " coefficient bytes, " + str(values) +
                          " float32 values (" + str(values * 4) + " bytes) expected");
  auto planes = read_zstd_stream(path, "coefficients", frame, coefficient_bytes);
  if (!planes) return planes.error();
  f.coefficients = from_planes(*planes);
  if (std::string problem = check_bake(out); !problem.empty()) return file_error(path, "", problem);
  return out;
}

engine::Status save_brf(const fs::path& bundle_dir, const BrfBake& bake, const BakeInput& input) {
  const std::string scene_name = fs::path(input.name).filename().string();
  const fs::path manifest_file = bundle_dir / kManifestFileName;
  if (bake.meshes.empty()) return file_error(manifest_file, "", "cannot save the BRF bake: it holds no mesh");
  // Checked before the directory is made, so a bad bake leaves nothing behind.
  std::set<std::string> names;
  for (const BrfMeshBake& m : bake.meshes) {
    const fs::path file = bundle_dir / brf_file_name(m.model.name);
    if (std::string problem = check_bake(m); !problem.empty())
      return file_error(file, "", "cannot save the basis radiance field: " + problem);
    if (!names.insert(m.model.name).second)
      return file_error(file, "", "cannot save the BRF bake: two meshes are named \"" + m.model.name + "\"");
  }
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};

  json files = json::object(), meshes = json::object();
  for (const BrfMeshBake& m : bake.meshes) {
    const std::string name = brf_file_name(m.model.name);
    const fs::path file = bundle_dir / name;
    std::uint64_t compressed = 0;
    if (engine::Status s = write_brf_mesh(file, m, &compressed); !s) return s;
    auto sum = file_checksum(file);
    if (!sum) return sum.error();
    const std::uintmax_t file_bytes = fs::file_size(file, ec);
    if (ec) return file_error(file, "", "cannot read the file size: " + ec.message());
    const BrfModel& model = m.model;
    files[model.name] = json{{"file", name}, {"xxh3_64", *sum}};
    meshes[model.name] =
        json{{"mesh_hash", m.mesh_hash},
             {"vertices", model.basis.vertex_count},
             {"basis_requested", bake.settings.basis.basis},
             {"basis_kept", model.basis.basis_count},
             {"condition", model.basis.condition},
             {"glossy_terms", model.glossy ? model.glossy->terms : 0},
             {"glossy_brdf_error", model.glossy ? static_cast<double>(model.glossy->relative_error) : 0.0},
             {"field_bytes", static_cast<std::uint64_t>(model.field.bytes())},
             {"field_compressed_bytes", compressed},
             {"file_bytes", static_cast<std::uint64_t>(file_bytes)}};
  }
  const json entry{{"files", files}, {"settings", settings_json(bake.settings)}, {"meshes", meshes}};
  return update_manifest_method(bundle_dir, scene_geometry_hash(input), scene_name, kBrfMethod, entry);
}

engine::Result<BrfBake> load_brf(const fs::path& bundle_dir, std::span<const BrfSource> sources) {
  // Each mesh's file carries its mesh's hash, checked below: no whole-scene geometry check.
  auto bundle = BundleReader::open_any_geometry(bundle_dir, kBrfMethod);
  if (!bundle) return bundle.error();
  JsonFields fields = bundle->fields();
  BrfBake out;
  out.settings = read_settings(fields);
  if (fields.error()) return *fields.error();

  for (const BrfSource& source : sources) {
    if (!bundle->has_file(source.name))
      return bundle->entry_error("files." + source.name, "no basis radiance field for the scene's dynamic mesh \"" +
                                                             source.name + "\" (re-bake with --methods brf)");
    auto path = bundle->file(source.name);
    if (!path) return path.error();
    auto mesh = read_brf_mesh(*path);
    if (!mesh) return mesh.error();
    if (mesh->model.name != source.name)
      return file_error(*path, "name",
                        "holds mesh \"" + mesh->model.name + "\", the manifest lists it for \"" + source.name + "\"");
    if (mesh->mesh_hash != source.mesh_hash)
      return file_error(*path, "mesh_hash",
                        "stale basis radiance field: baked from mesh hash " + mesh->mesh_hash + ", but mesh \"" +
                            source.name + "\" of the scene hashes to " + source.mesh_hash +
                            " (re-bake with --methods brf)");
    if (mesh->model.basis.vertex_count != source.mesh.positions.size())
      return file_error(*path, "vertex_count",
                        "the basis has " + str(mesh->model.basis.vertex_count) + " vertices, mesh \"" + source.name +
                            "\" " + str(source.mesh.positions.size()));
    mesh->model.mesh = source.mesh;  // what the basis was baked on (its hash checked above)
    out.meshes.push_back(std::move(mesh).value());
  }
  return out;
}

engine::Result<BrfBake> load_brf(const fs::path& bundle_dir, const BakeInput& input) {
  auto sources = dynamic_brf_meshes(input);
  if (!sources) return sources.error();
  return load_brf(bundle_dir, std::span<const BrfSource>(*sources));
}

}  // namespace gi
