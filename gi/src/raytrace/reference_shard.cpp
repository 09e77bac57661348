// Distributed path-traced references (gi/reference_shard.h, docs/distributed-bake.md).
//
// The shard file (io/blob_file.h container, magic "GIREFSH1", version 1), little-endian:
//   uint32 index I, uint32 count N, string scene hash, string settings hash, uint64 seed,
//   uint8 parts (1 image, 2 atlas),
//   image: int32 width, int32 height, uint32[] pixel indices (ascending), vec3[] RGB
//   atlas: int32 width, int32 height, float texels per metre, uint64 valid texels,
//          uint32[] point indices (ascending, among the valid texels), vec3[] direct,
//          vec3[] indirect, vec3[] indirect variance
#include <engine/byte_stream.h>
#include <gi/reference_shard.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <system_error>
#include <vector>

#include "bundle/geometry_hash.h"
#include "bundle/shard_set.h"
#include "core/work_shard.h"
#include "io/blob_file.h"
#include "io/content_hash.h"
#include "raytrace/atlas_reference.h"
#include "raytrace/reference_render.h"
#include "raytrace/scene_adapter.h"
#include "raytrace/texel_samples.h"
#include "uv/atlas_layout.h"

namespace gi {

namespace fs = std::filesystem;

namespace {

constexpr BlobMagic kMagic{"GIREFSH1"};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint8_t kHasImage = 1, kHasAtlas = 2;
constexpr const char* kExtension = ".girefshard";

struct ImagePart {
  std::int32_t width = 0, height = 0;
  std::vector<std::uint32_t> pixels;
  std::vector<glm::vec3> rgb;
};

struct AtlasPart {
  std::int32_t width = 0, height = 0;
  float texels_per_metre = 0.0f;
  std::uint64_t points = 0;
  std::vector<std::uint32_t> indices;
  std::vector<glm::vec3> direct, indirect, variance;
};

struct ShardFile {
  std::uint32_t index = 0, count = 1;
  std::string scene_hash, settings_hash;
  std::uint64_t seed = 1;
  std::optional<ImagePart> image;
  std::optional<AtlasPart> atlas;
};

void add_vec(ContentHash& h, const glm::vec3& v) {
  h.add_value(v.x);
  h.add_value(v.y);
  h.add_value(v.z);
}

// Everything the path tracer and the atlas layout read of the scene: the static geometry
// hash of the bakes (ids, matrices, triangles, materials) and the path tracer's whole scene
// (dynamic instances, every light, the sky).
std::string reference_scene_hash(const BakeInput& input) {
  const ReferenceScene s = reference_scene_from(input);
  ContentHash h;
  h.add_string("gi-reference scene v1");
  h.add_string(scene_geometry_hash(input));
  h.add_value(static_cast<std::uint64_t>(s.geometry.geometries.size()));
  for (const RtGeometry& g : s.geometry.geometries) {
    h.add_value(static_cast<std::uint64_t>(g.positions.size()));
    for (const glm::vec3& p : g.positions) add_vec(h, p);
    h.add_values(std::span<const std::uint32_t>(g.indices));
  }
  h.add_value(static_cast<std::uint64_t>(s.geometry.instances.size()));
  for (const RtInstance& i : s.geometry.instances) {
    h.add_value(i.geometry);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(i.object_to_world[c][r]);
    h.add_value(static_cast<std::uint8_t>(i.dynamic ? 1 : 0));
  }
  for (const auto& n : s.normals) {
    h.add_value(static_cast<std::uint64_t>(n.size()));
    for (const glm::vec3& v : n) add_vec(h, v);
  }
  for (const auto& m : s.triangle_material) h.add_values(std::span<const std::uint32_t>(m));
  h.add_value(static_cast<std::uint64_t>(s.materials.size()));
  for (const ReferenceMaterial& m : s.materials) {
    add_vec(h, m.brdf.base_color);
    h.add_value(m.brdf.metallic);
    h.add_value(m.brdf.alpha);
    h.add_value(m.brdf.specular_weight);
    add_vec(h, m.brdf.dielectric_f0);
    add_vec(h, m.emission);
    h.add_value(static_cast<std::uint8_t>(m.double_sided ? 1 : 0));
  }
  h.add_value(static_cast<std::uint64_t>(s.lights.size()));
  for (const ReferenceLight& l : s.lights) {
    h.add_value(l.type);
    add_vec(h, l.position);
    add_vec(h, l.direction);
    add_vec(h, l.half_x);
    add_vec(h, l.half_y);
    add_vec(h, l.radiant);
    h.add_value(l.range_m);
    h.add_value(l.cos_outer);
    h.add_value(l.cos_inner);
    h.add_value(l.cos_disc);
  }
  add_vec(h, s.sky_radiance);
  add_vec(h, s.sky_gradient.zenith);
  add_vec(h, s.sky_gradient.horizon);
  add_vec(h, s.sky_gradient.ground);
  return h.hex();
}

// Every field of the job that changes the result (not threads, not progress).
std::string job_settings_hash(const ReferenceJob& job) {
  ContentHash h;
  h.add_string("gi-reference settings v1");
  const ReferenceSettings& s = job.settings;
  h.add_value(s.samples_per_pixel);
  h.add_value(s.max_bounces);
  h.add_value(s.russian_roulette_start);
  h.add_value(s.seed);
  h.add_value(static_cast<std::uint8_t>(s.jitter_pixels ? 1 : 0));
  h.add_value(static_cast<std::uint8_t>(job.image ? 1 : 0));
  if (job.image) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(job.image->camera.camera_to_world[c][r]);
    h.add_value(job.image->camera.yfov_rad);
    h.add_value(job.image->camera.aspect);
    h.add_value(job.image->width);
    h.add_value(job.image->height);
  }
  h.add_value(static_cast<std::uint8_t>(job.atlas ? 1 : 0));
  if (job.atlas) {
    h.add_value(job.atlas->texels_per_metre);
    h.add_value(job.atlas->placement);
  }
  return h.hex();
}

engine::Status check_job(const ReferenceJob& job) {
  if (!job.image && !job.atlas) return engine::invalid_request("reference job: neither an image nor an atlas");
  if (job.image &&
      (job.image->width < 1 || job.image->height < 1 || job.image->width > 16384 || job.image->height > 16384))
    return engine::invalid_request("reference job: image size must be in [1, 16384]^2");
  if (job.atlas && !(job.atlas->texels_per_metre > 0.0f && std::isfinite(job.atlas->texels_per_metre)))
    return engine::invalid_request("reference job: atlas texels per metre must be > 0");
  return {};
}

PinholeCamera pinhole(const ReferenceImageJob& j) {
  PinholeCamera pc;
  pc.camera_to_world = j.camera.camera_to_world;
  pc.yfov_rad = j.camera.yfov_rad;
  pc.aspect = j.camera.aspect;
  pc.width = j.width;
  pc.height = j.height;
  return pc;
}

// The atlas's layout and texels, as reference_atlas builds them.
struct AtlasSetup {
  float texels_per_metre = 0.0f;
  AtlasTexels texels;
  std::vector<SurfacePoint> points;
};

engine::Result<AtlasSetup> atlas_setup(const BakeInput& input, const ReferenceAtlasJob& job) {
  auto layout = static_world_layout(input, job.texels_per_metre);
  if (!layout) return layout.error();
  auto texels = sample_atlas_texels(input, *layout, job.placement);
  if (!texels) return texels.error();
  AtlasSetup out{.texels_per_metre = layout->texels_per_metre, .texels = std::move(texels).value(), .points = {}};
  out.points = atlas_sample_points(input, out.texels);
  return out;
}

AtlasReference to_reference(const AtlasSetup& setup, AtlasIrradiance truth) {
  return AtlasReference{.width = truth.width,
                        .height = truth.height,
                        .texels_per_metre = setup.texels_per_metre,
                        .direct = std::move(truth.direct),
                        .indirect = std::move(truth.indirect),
                        .total = std::move(truth.total),
                        .valid = std::move(truth.valid),
                        .indirect_variance = std::move(truth.indirect_variance)};
}

template <class T>
std::vector<std::uint32_t> as_u32(const std::vector<T>& v) {
  return std::vector<std::uint32_t>(v.begin(), v.end());
}

bool ascending(const std::vector<std::uint32_t>& v) {
  for (std::size_t i = 1; i < v.size(); ++i)
    if (v[i] <= v[i - 1]) return false;
  return true;
}

bool finite(const std::vector<glm::vec3>& v) {
  return std::all_of(v.begin(), v.end(),
                     [](const glm::vec3& x) { return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z); });
}

engine::Status write_shard(const fs::path& path, const ShardFile& f) {
  engine::ByteWriter w;
  w.put(f.index);
  w.put(f.count);
  w.put_string(f.scene_hash);
  w.put_string(f.settings_hash);
  w.put(f.seed);
  w.put<std::uint8_t>(static_cast<std::uint8_t>((f.image ? kHasImage : 0) | (f.atlas ? kHasAtlas : 0)));
  if (f.image) {
    w.put(f.image->width);
    w.put(f.image->height);
    w.put_array(f.image->pixels);
    w.put_array(f.image->rgb);
  }
  if (f.atlas) {
    const AtlasPart& a = *f.atlas;
    w.put(a.width);
    w.put(a.height);
    w.put(a.texels_per_metre);
    w.put(a.points);
    w.put_array(a.indices);
    w.put_array(a.direct);
    w.put_array(a.indirect);
    w.put_array(a.variance);
  }
  return write_blob(path, kMagic, kVersion, w.bytes());
}

engine::Result<ShardFile> read_shard(const fs::path& path) {
  auto payload = read_blob(path, kMagic, kVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  ShardFile f;
  std::uint8_t parts = 0;
  bool complete = r.get(f.index) && r.get(f.count) && r.get_string(f.scene_hash) && r.get_string(f.settings_hash) &&
                  r.get(f.seed) && r.get(parts);
  if (complete && (parts & kHasImage)) {
    ImagePart p;
    complete = r.get(p.width) && r.get(p.height) && r.get_array(p.pixels) && r.get_array(p.rgb);
    f.image = std::move(p);
  }
  if (complete && (parts & kHasAtlas)) {
    AtlasPart a;
    complete = r.get(a.width) && r.get(a.height) && r.get(a.texels_per_metre) && r.get(a.points) &&
               r.get_array(a.indices) && r.get_array(a.direct) && r.get_array(a.indirect) && r.get_array(a.variance);
    f.atlas = std::move(a);
  }
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return engine::Error{path.string(), location, "truncated payload"};
  if (r.remaining() != 0) return engine::Error{path.string(), location, "unexpected data after the last field"};
  if (parts == 0 || parts > (kHasImage | kHasAtlas)) return engine::Error{path.string(), "parts", "unknown part flags"};
  if (f.count == 0 || f.index >= f.count)
    return engine::Error{path.string(), "shard",
                         "shard " + std::to_string(f.index) + " of " + std::to_string(f.count) + " does not exist"};
  if (f.image &&
      (f.image->rgb.size() != f.image->pixels.size() || !ascending(f.image->pixels) || !finite(f.image->rgb)))
    return engine::Error{path.string(), "image", "pixel arrays differ in size, are not ascending or not finite"};
  if (f.atlas) {
    const AtlasPart& a = *f.atlas;
    const std::size_t n = a.indices.size();
    if (a.direct.size() != n || a.indirect.size() != n || a.variance.size() != n || !ascending(a.indices) ||
        !finite(a.direct) || !finite(a.indirect) || !finite(a.variance))
      return engine::Error{path.string(), "atlas", "texel arrays differ in size, are not ascending or not finite"};
  }
  return f;
}

std::vector<std::uint32_t> shard_items(std::uint32_t index, std::uint32_t count, std::size_t n) {
  return as_u32(WorkShard{.index = index, .count = count}.items(n));
}

}  // namespace

std::string reference_shard_file_name(std::uint32_t index, std::uint32_t count) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "shard-%04u-of-%04u%s", index, count, kExtension);
  return buf;
}

engine::Result<ReferenceOutputs> render_reference_job(const BakeInput& input, const ReferenceJob& job) {
  if (auto ok = check_job(job); !ok) return ok.error();
  ReferenceOutputs out;
  if (job.image) {
    auto image = render_reference_image(input, job.image->camera, job.image->width, job.image->height, job.settings);
    if (!image) return image.error();
    out.image = std::move(image).value();
  }
  if (job.atlas) {
    auto atlas = reference_atlas(input, job.atlas->texels_per_metre, job.settings, job.atlas->placement);
    if (!atlas) return atlas.error();
    out.atlas = std::move(atlas).value();
  }
  return out;
}

engine::Result<fs::path> reference_shard(const BakeInput& input, const ReferenceJob& job, std::uint32_t index,
                                         std::uint32_t count, const fs::path& shard_dir) {
  if (count == 0 || index >= count)
    return engine::invalid_request("shard " + std::to_string(index) + "/" + std::to_string(count) +
                                   " does not exist (shards are 0..N-1)");
  if (auto ok = check_job(job); !ok) return ok.error();
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  const WorkShard shard{.index = index, .count = count};
  ShardFile f{.index = index,
              .count = count,
              .scene_hash = reference_scene_hash(input),
              .settings_hash = job_settings_hash(job),
              .seed = job.settings.seed,
              .image = {},
              .atlas = {}};
  const ReferenceScene scene = reference_scene_from(input);
  if (job.image) {
    auto image = render_reference(scene, pinhole(*job.image), job.settings, shard);
    if (!image) return image.error();
    ImagePart p{.width = job.image->width, .height = job.image->height, .pixels = {}, .rgb = {}};
    p.pixels = shard_items(index, count, static_cast<std::size_t>(p.width) * static_cast<std::size_t>(p.height));
    p.rgb.reserve(p.pixels.size());
    for (std::uint32_t i : p.pixels)
      p.rgb.emplace_back(image->pixels[4 * std::size_t{i}], image->pixels[4 * std::size_t{i} + 1],
                         image->pixels[4 * std::size_t{i} + 2]);
    f.image = std::move(p);
  }
  if (job.atlas) {
    auto setup = atlas_setup(input, *job.atlas);
    if (!setup) return setup.error();
    auto e = estimate_irradiance(scene, setup->points, job.settings, shard);
    if (!e) return e.error();
    AtlasPart a{.width = setup->texels.width,
                .height = setup->texels.height,
                .texels_per_metre = setup->texels_per_metre,
                .points = setup->points.size(),
                .indices = shard_items(index, count, setup->points.size()),
                .direct = {},
                .indirect = {},
                .variance = {}};
    for (std::uint32_t k : a.indices) {
      a.direct.push_back(e->direct[k]);
      a.indirect.push_back(e->indirect[k]);
      a.variance.push_back(e->indirect_variance[k]);
    }
    f.atlas = std::move(a);
  }
  std::error_code ec;
  fs::create_directories(shard_dir, ec);
  if (ec) return engine::Error{shard_dir.string(), "", "cannot create the shard directory: " + ec.message()};
  const fs::path path = shard_dir / reference_shard_file_name(index, count);
  if (auto ok = write_shard(path, f); !ok) return ok.error();
  return path;
}

namespace {

// The camera image from every shard's pixels, each checked to be its shard's blocks.
engine::Result<engine::ImageRgbaF> merge_image(const ReferenceJob& job, const ShardSet<ShardFile>& set,
                                               std::uint32_t count) {
  const auto& shards = set.shards;
  const auto& where = set.where;
  const std::size_t w = static_cast<std::size_t>(job.image->width), h = static_cast<std::size_t>(job.image->height);
  engine::ImageRgbaF image;
  image.width = job.image->width;
  image.height = job.image->height;
  image.pixels.assign(w * h * 4, 1.0f);
  for (std::uint32_t i = 0; i < count; ++i) {
    const ImagePart& p = *shards[i]->image;
    if (p.width != job.image->width || p.height != job.image->height || p.pixels != shard_items(i, count, w * h))
      return engine::Error{where[i].string(), "image",
                           "image shard " + std::to_string(i) + " of " + std::to_string(count) +
                               ": its pixels are not that shard's blocks of this " + std::to_string(w) + "x" +
                               std::to_string(h) + " image"};
    for (std::size_t k = 0; k < p.pixels.size(); ++k)
      for (int c = 0; c < 3; ++c)
        image.pixels[4 * std::size_t{p.pixels[k]} + static_cast<std::size_t>(c)] = p.rgb[k][c];
  }
  return image;
}

// The atlas truth from every shard's texels, each checked to be its shard's blocks.
engine::Result<AtlasReference> merge_atlas(const BakeInput& input, const ReferenceJob& job,
                                           const ShardSet<ShardFile>& set, std::uint32_t count) {
  const auto& shards = set.shards;
  const auto& where = set.where;
  auto setup = atlas_setup(input, *job.atlas);
  if (!setup) return setup.error();
  const std::size_t n = setup->points.size();
  IrradianceEstimate e;
  e.direct.assign(n, glm::vec3(0.0f));
  e.indirect.assign(n, glm::vec3(0.0f));
  e.indirect_variance.assign(n, glm::vec3(0.0f));
  for (std::uint32_t i = 0; i < count; ++i) {
    const AtlasPart& a = *shards[i]->atlas;
    if (a.width != setup->texels.width || a.height != setup->texels.height || a.points != n ||
        a.texels_per_metre != setup->texels_per_metre || a.indices != shard_items(i, count, n))
      return engine::Error{where[i].string(), "atlas",
                           "atlas shard " + std::to_string(i) + " of " + std::to_string(count) +
                               ": its texels are not that shard's blocks of this scene's " +
                               std::to_string(setup->texels.width) + "x" + std::to_string(setup->texels.height) +
                               " atlas (" + std::to_string(n) + " valid texels)"};
    for (std::size_t k = 0; k < a.indices.size(); ++k) {
      e.direct[a.indices[k]] = a.direct[k];
      e.indirect[a.indices[k]] = a.indirect[k];
      e.indirect_variance[a.indices[k]] = a.variance[k];
    }
  }
  return to_reference(*setup, assemble_atlas_irradiance(setup->texels, e));
}

}  // namespace

engine::Result<ReferenceOutputs> merge_reference_shards(const BakeInput& input, const ReferenceJob& job,
                                                        const fs::path& shard_dir, std::uint32_t count) {
  if (auto ok = check_job(job); !ok) return ok.error();
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  auto files = list_shard_files(shard_dir, kExtension);
  if (!files) return files.error();

  const std::string scene_hash = reference_scene_hash(input);
  const std::string settings_hash = job_settings_hash(job);
  ShardSet<ShardFile> set;
  for (const fs::path& path : *files) {
    auto file = read_shard(path);
    if (!file) return file.error();
    const auto foreign = [&](const std::string& what) {
      return engine::Error{path.string(), "",
                           "foreign shard: " + what + "; compute it again with this scene and options"};
    };
    if (count == 0) count = file->count;
    if (file->count != count)
      return foreign("shard " + std::to_string(file->index) + " of " + std::to_string(file->count) +
                     ", the merge is of " + std::to_string(count));
    if (file->scene_hash != scene_hash)
      return foreign("traced in another scene (hash " + file->scene_hash + ", the scene's " + scene_hash + ")");
    if (file->settings_hash != settings_hash || file->seed != job.settings.seed)
      return foreign("traced with other settings (settings hash " + file->settings_hash + " seed " +
                     std::to_string(file->seed) + ", this merge's " + settings_hash + " seed " +
                     std::to_string(job.settings.seed) + ")");
    if (file->image.has_value() != job.image.has_value() || file->atlas.has_value() != job.atlas.has_value())
      return foreign("its parts (image, atlas) differ from this merge's");
    const std::uint32_t index = file->index;
    if (auto ok = set.place(path, index, count, std::move(file).value()); !ok) return ok.error();
  }
  if (auto ok = set.complete(count, [&](std::uint32_t i) { return shard_dir / reference_shard_file_name(i, count); });
      !ok)
    return ok.error();
  ReferenceOutputs out;
  if (job.image) {
    auto image = merge_image(job, set, count);
    if (!image) return image.error();
    out.image = std::move(image).value();
  }
  if (job.atlas) {
    auto atlas = merge_atlas(input, job, set, count);
    if (!atlas) return atlas.error();
    out.atlas = std::move(atlas).value();
  }
  return out;
}

}  // namespace gi
