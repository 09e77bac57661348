#include "sweep/brf_sweep.h"

#include <gi/methods.h>

#include <engine/components.h>
#include <engine/scene.h>
#include <gi/reference.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>
#include <string>

#include "brf/brf_mesh.h"
#include "brf/brf_runtime.h"
#include "core/stopwatch.h"
#include "raytrace/reference_render.h"
#include "raytrace/scene_adapter.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"

namespace gi {
namespace {

constexpr std::uint64_t kReferenceSeed = 0x6272667265667074ULL;

// The scene's dynamic mesh nodes and lights only: static geometry is dropped. `apart`:
// objects whose world bounding boxes touch another's (within 1 cm, e.g. stacked crates) are
// dropped too: contact is the method's known weak case (docs/brf.md), measured separately.
// `metal` names a material made a glossy metal (metallic 1, roughness 0.5: GGX alpha 0.25),
// so the glossy terms are measured on the same scene ("none": unchanged).
engine::Scene objects_only(engine::SceneAsset asset, bool apart, const std::string& metal = "none") {
  for (engine::Node& n : asset.nodes)
    if (n.mesh >= 0 && n.gi.mobility != engine::Mobility::Dynamic) n.mesh = -1;
  if (metal == "red_crate")
    for (engine::Material& m : asset.materials)
      if (m.name == "crate_red") m.metallic = 1.0f, m.roughness = 0.5f;
  engine::Scene scene = engine::instantiate(asset);
  if (!apart) return scene;
  struct Box {
    std::string name;
    glm::vec3 lo, hi;
  };
  std::vector<Box> boxes;
  scene.registry.view<engine::MeshRenderer, engine::WorldTransform, engine::Name>().each(
      [&](engine::Entity, const engine::MeshRenderer& mr, const engine::WorldTransform& wt, const engine::Name& name) {
        Box b{name.value, glm::vec3(std::numeric_limits<float>::max()), glm::vec3(-std::numeric_limits<float>::max())};
        for (const engine::Primitive& p : scene.assets.meshes[mr.mesh].primitives)
          for (const glm::vec3& v : p.positions) {
            const glm::vec3 w = glm::vec3(wt.matrix * glm::vec4(v, 1.0f));
            b.lo = glm::min(b.lo, w);
            b.hi = glm::max(b.hi, w);
          }
        boxes.push_back(b);
      });
  std::vector<std::string> touching;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t j = 0; j < boxes.size(); ++j)
      if (i != j && glm::all(glm::lessThanEqual(boxes[i].lo, boxes[j].hi + 0.01f)) &&
          glm::all(glm::lessThanEqual(boxes[j].lo, boxes[i].hi + 0.01f)))
        touching.push_back(boxes[i].name);
  if (touching.empty()) return scene;
  for (engine::Node& n : asset.nodes)
    if (std::find(touching.begin(), touching.end(), n.name) != touching.end()) n.mesh = -1;
  return engine::instantiate(std::move(asset));
}

struct Objects {
  std::vector<BrfSource> sources;
  struct Instance {
    std::size_t source;
    glm::mat4 transform;
    glm::vec3 albedo;
    glm::vec3 specular;
  };
  std::vector<Instance> instances;  // entity order within each source, sources in order
};

engine::Result<Objects> scene_objects(const BakeInput& input) {
  auto sources = dynamic_brf_meshes(input);
  if (!sources) return sources.error();
  Objects o;
  o.sources = std::move(sources).value();
  if (o.sources.empty())
    return engine::Error{.message = "the scene has no dynamic mesh (basis radiance fields need one)"};
  for (std::size_t s = 0; s < o.sources.size(); ++s) {
    const BrfSource& src = o.sources[s];
    const glm::vec3 albedo = brf_source_albedo(input, src);
    for (std::uint32_t i : src.instances)
      o.instances.push_back({s, input.instances[i].object_to_world, albedo, src.specular});
  }
  return o;
}

std::vector<SurfacePoint> vertex_points(const Objects& o) {
  std::vector<SurfacePoint> points;
  for (const Objects::Instance& in : o.instances) {
    const BrfMesh& mesh = o.sources[in.source].mesh;
    const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(in.transform)));
    for (std::size_t j = 0; j < mesh.positions.size(); ++j)
      points.push_back(
          {glm::vec3(in.transform * glm::vec4(mesh.positions[j], 1.0f)), glm::normalize(nm * mesh.normals[j])});
  }
  return points;
}

engine::Result<RgbField> brf_vertex_reference(const ReferenceJob& job) {
  const engine::Scene scene =
      objects_only(job.scene.asset, job.request.param("objects") == "apart", job.request.param("metal"));
  const BakeInput input = bake_input_from(scene);
  auto objects = scene_objects(input);
  if (!objects) return objects.error();
  const std::vector<SurfacePoint> points = vertex_points(*objects);
  ReferenceSettings rs;
  rs.samples_per_pixel = std::stoi(job.request.param("spp"));
  rs.seed = kReferenceSeed;
  rs.threads = job.threads;
  rs.progress = job.progress;
  auto truth = estimate_irradiance(reference_scene_from(input), points, rs);
  if (!truth) return truth.error();
  const std::vector<std::uint8_t> valid(points.size(), 1);
  return RgbField::from_texels(static_cast<int>(points.size()), 1, truth->indirect, valid);
}

// Long because it is one table, one entry per knob with its grid and range, read as a list.
std::vector<KnobSpec> brf_knobs() {
  return {
      {.name = "basis",
       .description = "PCA basis functions N (mean included)",
       .kind = KnobKind::Integer,
       .default_grid = {"4", "8", "16", "32"},
       .min_value = 1,
       .max_value = 256},
      {.name = "bands",
       .description = "spherical-harmonic bands of the field (3 or 4)",
       .kind = KnobKind::Integer,
       .default_grid = {"3", "4"},
       .min_value = 3,
       .max_value = 4},
      {.name = "spheres",
       .description = "concentric sample spheres",
       .kind = KnobKind::Integer,
       .default_grid = {"8", "16"},
       .min_value = 2,
       .max_value = 64},
      {.name = "face_res",
       .description = "sample points per sphere: 6 x face_res^2",
       .kind = KnobKind::Integer,
       .default_grid = {"8", "16"},
       .min_value = 1,
       .max_value = 64},
      {.name = "lights",
       .description = "training point lights N_light",
       .kind = KnobKind::Integer,
       .default_grid = {"256"},
       .min_value = 1,
       .max_value = 65536},
      {.name = "directions",
       .description = "rays per field sample point",
       .kind = KnobKind::Integer,
       .default_grid = {"512"},
       .min_value = 16,
       .max_value = 65536},
      {.name = "bounces",
       .description = "bounces between the objects",
       .kind = KnobKind::Integer,
       .default_grid = {"3"},
       .min_value = 1,
       .max_value = 64},
      {.name = "objects",
       .description = "which dynamic objects: apart (drop touching ones) or all",
       .kind = KnobKind::Choice,
       .default_grid = {"apart"},
       .choices = {"apart", "all"}},
      {.name = "occlusion",
       .description =
           "occlusion between the objects (BrfUpdateSettings::occlusion; the contact factor stays on): on or off",
       .kind = KnobKind::Choice,
       .default_grid = {"on"},
       .choices = {"on", "off"}},
      {.name = "ref_spp",
       .description = "path-traced samples per vertex of the reference",
       .kind = KnobKind::Integer,
       .default_grid = {"2048"},
       .min_value = 1,
       .max_value = 1 << 20},
      {.name = "metal",
       .description = "a material turned glossy metal (roughness 0.5): none or red_crate",
       .kind = KnobKind::Choice,
       .default_grid = {"none"},
       .choices = {"none", "red_crate"}},
      {.name = "glossy_terms",
       .description = "glossy BRDF terms K of glossy meshes (SVD of the lobe)",
       .kind = KnobKind::Integer,
       .default_grid = {"4"},
       .min_value = 1,
       .max_value = kMaxGlossyTerms},
      {.name = "brdf_res",
       .description = "hemisphere table of the BRDF separation: brdf_res^2 directions",
       .kind = KnobKind::Integer,
       .default_grid = {"16"},
       .min_value = 4,
       .max_value = 64},
  };
}

ReferenceRequest brf_reference_request(const SweepScene&, const KnobSetting& k) {
  ReferenceRequest r;
  r.kind = "brf_vertex_indirect";
  r.params.emplace_back("spp", std::to_string(k.integer("ref_spp")));
  r.params.emplace_back("objects", k.text("objects"));
  r.params.emplace_back("metal", k.text("metal"));
  return r;
}

// Each source object's bake: its glossy BRDF separation (glossy materials only), PCA basis
// and basis radiance field, with the bytes the fields and bases take.
struct BakedSources {
  std::vector<BrfBasis> bases;
  std::vector<BasisRadianceField> fields;
  std::vector<std::optional<BrdfSeparation>> glossy;
  std::uint64_t bytes = 0;
};

engine::Result<BakedSources> bake_sources(const RunContext& ctx, const Objects& objects) {
  BakedSources b;
  b.glossy.resize(objects.sources.size());
  for (std::size_t s = 0; s < objects.sources.size(); ++s) {
    const BrfMesh& mesh = objects.sources[s].mesh;
    if (objects.sources[s].glossy) {
      auto sep = separate_glossy_brdf(*objects.sources[s].glossy,
                                      {.terms = static_cast<int>(ctx.knobs.integer("glossy_terms")),
                                       .resolution = static_cast<int>(ctx.knobs.integer("brdf_res"))});
      if (!sep) return sep.error();
      b.glossy[s] = std::move(sep).value();
    }
    const BrdfSeparation* g = b.glossy[s] ? &*b.glossy[s] : nullptr;
    auto basis = compute_pca_basis(mesh,
                                   {.lights = static_cast<int>(ctx.knobs.integer("lights")),
                                    .basis = static_cast<int>(ctx.knobs.integer("basis"))},
                                   g);
    if (!basis) return basis.error();
    auto field = compute_basis_radiance_field(mesh, *basis,
                                              {.spheres = static_cast<int>(ctx.knobs.integer("spheres")),
                                               .face_resolution = static_cast<int>(ctx.knobs.integer("face_res")),
                                               .sh_bands = static_cast<int>(ctx.knobs.integer("bands")),
                                               .directions = static_cast<int>(ctx.knobs.integer("directions")),
                                               .threads = ctx.threads},
                                              g);
    if (!field) return field.error();
    b.bytes += field->bytes() + basis->psi.size() * sizeof(float);
    b.bases.push_back(std::move(basis).value());
    b.fields.push_back(std::move(field).value());
    if (!ctx.progress(0.9 * static_cast<double>(s + 1) / static_cast<double>(objects.sources.size())))
      return engine::cancelled_error("BRF sweep run");
  }
  return b;
}

engine::Result<MethodOutput> run_brf(const RunContext& ctx) {
  const engine::Scene scene =
      objects_only(ctx.scene.asset, ctx.knobs.text("objects") == "apart", ctx.knobs.text("metal"));
  const BakeInput input = bake_input_from(scene);
  auto objects = scene_objects(input);
  if (!objects) return objects.error();
  const auto t0 = std::chrono::steady_clock::now();
  auto baked = bake_sources(ctx, *objects);
  if (!baked) return baked.error();
  const std::vector<BrfBasis>& bases = baked->bases;
  const std::vector<BasisRadianceField>& fields = baked->fields;
  const std::vector<std::optional<BrdfSeparation>>& glossy = baked->glossy;
  const double bake_s = seconds_since(t0);
  std::vector<BrfObject> brf;
  for (const Objects::Instance& in : objects->instances)
    brf.push_back({&objects->sources[in.source].mesh, &bases[in.source], &fields[in.source], in.transform, in.albedo,
                   glossy[in.source] ? &*glossy[in.source] : nullptr, in.specular});
  std::vector<ReferenceLight> lights = bake_lights(input, BakeLights::Static);
  for (ReferenceLight& l : bake_lights(input, BakeLights::Moving)) lights.push_back(l);
  const std::vector<PointEmitter> emitters = light_point_emitters(lights, 64, ctx.seed);
  const auto t1 = std::chrono::steady_clock::now();
  const BrfResult r = update_brf(brf, emitters,
                                 {.bounces = static_cast<int>(ctx.knobs.integer("bounces")),
                                  .cull_threshold = 0.0f,
                                  .occlusion = ctx.knobs.text("occlusion") == "on"});
  const double frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  std::vector<glm::vec3> values;  // the irradiance: each object's first block
  for (std::size_t i = 0; i < r.indirect.size(); ++i)
    values.insert(values.end(), r.indirect[i].begin(),
                  r.indirect[i].begin() + static_cast<std::ptrdiff_t>(brf[i].mesh->positions.size()));
  if (static_cast<int>(values.size()) != ctx.reference.width)
    return engine::Error{.message = "vertex count differs from the reference's"};
  MethodOutput out;
  out.field = RgbField::from_texels(ctx.reference.width, 1, values, ctx.reference.valid);
  out.costs.bake_seconds = bake_s;
  out.costs.frame_ms = frame_ms;
  out.costs.bytes = baked->bytes;
  return out;
}

}  // namespace

void register_brf_sweep(SweepRegistry& registry) {
  registry.add_reference_provider({.kind = "brf_vertex_indirect", .version = "pt-1", .compute = brf_vertex_reference});

  SweepMethod m;
  m.name = method_descriptor(EffectMethod::BasisRadianceFields).key;  // gi/methods.h
  m.description =
      "basis radiance fields (Iwasaki et al.): basis N x SH bands x spheres x face points x lights x bounces, dynamic "
      "objects' vertices";
  m.knobs = brf_knobs();
  m.reference_for = brf_reference_request;
  m.run = run_brf;
  registry.add_method(std::move(m));
}

}  // namespace gi
