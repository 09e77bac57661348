// gi::bake_bundle: plan, bake each method, write the bundle (gi/bake.h).
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <gi/bake.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "antiradiance/antiradiance_io.h"
#include "antiradiance/antiradiance_region.h"
#include "bake/bake_shard.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_mesh.h"
#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "bundle/shard_set.h"
#include "core/thread_pool.h"
#include "dlm/dlm.h"
#include "dlm/dlm_io.h"
#include "io/atomic_file.h"
#include "io/blob_file.h"
#include "io/content_hash.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "plan/plan_json.h"
#include "prm/prm.h"
#include "prm/prm_io.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

__attribute__((format(printf, 1, 2))) std::string format(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

// One stage of a bake: its log and progress under a name.
struct Stage {
  const BakeHost& host;
  std::string name;

  void log(const std::string& line) const {
    if (host.log) host.log(LogLevel::Info, line);
  }
  ProgressCallback progress() const {
    if (!host.progress) return {};
    return [this](double f) { return host.progress(name, f); };
  }
};

// Sum of the sizes of the files the manifest lists for `method` (entry.files.<k>.file).
std::uint64_t method_bytes(const fs::path& bundle_dir, const std::string& method) {
  auto manifest = read_manifest(bundle_dir);
  if (!manifest || !manifest->methods.contains(method)) return 0;
  const nlohmann::json& entry = manifest->methods[method];
  if (!entry.contains("files") || !entry["files"].is_object()) return 0;
  std::uint64_t bytes = 0;
  for (const auto& [key, file] : entry["files"].items()) {
    if (!file.is_object() || !file.contains("file") || !file["file"].is_string()) continue;
    std::error_code ec;
    const auto size = fs::file_size(bundle_dir / file["file"].get<std::string>(), ec);
    if (!ec) bytes += static_cast<std::uint64_t>(size);
  }
  return bytes;
}

std::string scene_file_name(const BakeInput& input) {
  return input.name.empty() ? std::string("the scene") : fs::path(input.name).filename().string();
}

// What a method's bake cost, for bake_stats.json (stage name -> seconds).
using Timings = nlohmann::json;

// The shards' parts a merge bakes the sharded methods from (docs/distributed-bake.md).
struct MergedParts {
  std::vector<LightAtlasShardPart> atlas;
  std::vector<PrmShardPart> prm;
  std::vector<std::vector<Link>> antiradiance;  ///< Each shard's links, unpacked.
};

engine::Result<LightAtlasSettings> atlas_settings(const BakeOptions& o, const Stage& stage) {
  auto settings = light_atlas_preset(o.preset);
  if (!settings) return settings.error();
  if (o.vpls > 0) settings->vpl_count = o.vpls;
  if (o.bounces > 0) settings->bounces = o.bounces;
  if (o.texels_per_metre > 0.0f) settings->texels_per_metre = o.texels_per_metre;
  if (o.samples_per_vpl > 0) settings->samples_per_vpl = o.samples_per_vpl;
  settings->include_direct = o.include_direct;
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  return settings;
}

engine::Status bake_atlas(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const Stage& stage,
                          Timings& timings, const MergedParts* merged = nullptr) {
  auto settings = atlas_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format("light atlas of %s, preset %s: %d VPLs x %d samples, %d bounces, %g texels/m",
                   scene_file_name(input).c_str(), o.preset.c_str(), settings->vpl_count, settings->samples_per_vpl,
                   settings->bounces, double{settings->texels_per_metre}));
  auto bake = merged ? merge_light_atlas(input, *settings, merged->atlas) : bake_light_atlas(input, *settings);
  if (!bake) return bake.error();
  const LightAtlasStats& st = bake->stats;
  stage.log(
      format("  atlas %dx%d at %g texels/m, %zu texels lit; %zu VPLs, %zu sample points, %zu light points, %zu shots",
             bake->width, bake->height, double{bake->layout.texels_per_metre}, st.valid_texels, st.vpls,
             st.sample_points, st.light_points, st.shots));
  stage.log(
      format("  time: VPLs %.2f s, direct %.2f s, propagation %.2f s, final shooting %.2f s; total %.2f s; %.1f M rays",
             st.vpl_seconds, st.direct_seconds, st.propagate_seconds, st.final_seconds, st.total_seconds,
             static_cast<double>(st.rays) * 1e-6));
  timings = {{"vpl_seconds", st.vpl_seconds},
             {"direct_seconds", st.direct_seconds},
             {"propagate_seconds", st.propagate_seconds},
             {"final_seconds", st.final_seconds},
             {"total_seconds", st.total_seconds}};
  return save_light_atlas(dir, *bake, input);
}

engine::Result<PrmSettings> prm_settings(const BakeOptions& o, const Stage& stage) {
  auto settings = prm_preset(o.preset);
  if (!settings) return settings.error();
  if (o.texels_per_metre > 0.0f) settings->texels_per_metre = o.texels_per_metre;
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  return settings;
}

engine::Status bake_prm_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const Stage& stage,
                               Timings& timings, const MergedParts* merged = nullptr) {
  auto settings = prm_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format("PRM of %s, preset %s: %d entry points, %d clusters, splitting %g, %g texels/m",
                   scene_file_name(input).c_str(), o.preset.c_str(), settings->entry_points, settings->clusters,
                   double{settings->splitting}, double{settings->texels_per_metre}));
  auto prm = merged ? merge_prm(input, *settings, merged->prm) : bake_prm(input, *settings);
  if (!prm) return prm.error();
  const PrmStats& st = prm->stats;
  stage.log(
      format("  panes %dx%d, %zu texels each, %d clusters (%.1f MB as half floats); %zu paths, %zu virtual lights",
             prm->width, prm->height, prm->pane_size(), prm->cluster_count,
             static_cast<double>(prm->pane_size()) * prm->cluster_count * 6.0 / 1e6, st.paths, st.path_nodes));
  stage.log(format("  time: walks %.2f s, panes %.2f s; total %.2f s; %.1f M rays", st.walk_seconds, st.pane_seconds,
                   st.total_seconds, static_cast<double>(st.rays) * 1e-6));
  timings = {{"walk_seconds", st.walk_seconds}, {"pane_seconds", st.pane_seconds}, {"total_seconds", st.total_seconds}};
  return save_prm(dir, *prm, input);
}

// Antiradiance (docs/antiradiance.md): the elements, static links and baseline of the
// deforming region; elements of 0.8 / 0.6 / 0.4 m at preview / medium / high.
AntiradianceSettings antiradiance_settings(const BakeOptions& o) {
  AntiradianceSettings s;
  s.patch_size_m = antiradiance_preset_patch_size(o.preset);
  s.seed = o.seed;
  return s;
}

engine::Status bake_antiradiance_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o,
                                        const Stage& stage, Timings& timings, const MergedParts* parts = nullptr) {
  const AntiradianceSettings s = antiradiance_settings(o);
  const auto start = Clock::now();
  // A merge (docs/distributed-bake.md): the links from the shards, the rest baked here.
  auto bake = parts != nullptr && !parts->antiradiance.empty()
                  ? bake_antiradiance_from_link_shards(input, s, parts->antiradiance)
                  : bake_antiradiance(input, s);
  if (!bake) return bake.error();
  stage.log(format("antiradiance of %s, preset %s: %zu elements (%zu leaves), %d bins, %zu static links, %.2f s",
                   scene_file_name(input).c_str(), o.preset.c_str(), bake->hierarchy.nodes.size(),
                   bake->hierarchy.leaf_count(), s.bins_per_side * s.bins_per_side, bake->static_links.links.size(),
                   seconds_since(start)));
  // links_seconds: linking (a merge: putting the shards' links in place).
  timings["links_seconds"] = bake->seconds.links;
  timings["static_links_seconds"] = bake->seconds.static_links;
  timings["direct_seconds"] = bake->seconds.direct;
  timings["solve_seconds"] = bake->seconds.solve;
  const auto save_start = Clock::now();
  auto saved = save_antiradiance(dir, *bake, input);
  timings["save_seconds"] = seconds_since(save_start);
  return saved;
}

engine::Status bake_brf_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const BakeHost& host,
                               Timings& timings) {
  auto settings = brf_preset(o.preset);
  if (!settings) return settings.error();
  if (o.brf_basis > 0) settings->basis.basis = o.brf_basis;
  if (o.brf_spheres > 0) settings->field.spheres = o.brf_spheres;
  settings->field.threads = o.threads;
  auto sources = dynamic_brf_meshes(input);
  if (!sources) return sources.error();
  const Stage header{host, "BRF"};
  const PcaBasisSettings& b = settings->basis;
  const RadianceFieldSettings& f = settings->field;
  header.log(
      format("basis radiance fields of %s, preset %s: %zu dynamic meshes; %d lights, N = %d, %d spheres x 6x%dx%d "
             "points, %d SH bands, %d directions",
             scene_file_name(input).c_str(), o.preset.c_str(), sources->size(), b.lights, b.basis, f.spheres,
             f.face_resolution, f.face_resolution, f.sh_bands, f.directions));
  if (sources->empty()) {
    header.log("  no dynamic mesh: nothing to bake");
    return {};
  }
  BrfBake bake{.settings = *settings, .meshes = {}};
  for (const BrfSource& s : *sources) {
    const Stage stage{host, "BRF " + s.name};
    auto mesh = bake_brf_mesh(s, *settings, stage.progress());
    if (!mesh) return mesh.error();
    stage.log(format("  %-16s %6zu vertices, %zu instances, basis %d of %d kept, condition %.3g, field %.2f MB, %.2f s",
                     s.name.c_str(), s.mesh.positions.size(), s.instances.size(), mesh->basis.basis_count, b.basis,
                     mesh->basis.condition, static_cast<double>(mesh->field.bytes()) / 1e6,
                     mesh->basis_seconds + mesh->field_seconds));
    if (mesh->glossy)
      stage.log(format("  %-16s glossy (GGX alpha %.3f, f0 %.2f): %d BRDF terms, weighted BRDF error %.2f", "",
                       static_cast<double>(mesh->glossy->lobe.alpha), static_cast<double>(mesh->glossy->lobe.f0),
                       mesh->glossy->terms, static_cast<double>(mesh->glossy->relative_error)));
    timings[s.name] = {{"basis_seconds", mesh->basis_seconds}, {"field_seconds", mesh->field_seconds}};
    bake.meshes.push_back(std::move(mesh).value());
  }
  return save_brf(dir, bake, input);
}

engine::Status bake_dlm_method(const BakeInput& input, const fs::path& dir, const BakeOptions& o, const Stage& stage,
                               Timings& timings) {
  auto settings = dlm_preset(o.preset);
  if (!settings) return settings.error();
  if (o.texels_per_metre > 0.0f) settings->texels_per_metre = o.texels_per_metre;
  if (o.dlm_directions > 0) settings->directions = o.dlm_directions;
  if (o.dlm_photons > 0) settings->photons = o.dlm_photons;
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  stage.log(
      format("directional light maps of %s, preset %s: %d directions, %llu photons, splat radius %g texels, "
             "%g texels/m, roughness < %g",
             scene_file_name(input).c_str(), o.preset.c_str(), settings->directions,
             static_cast<unsigned long long>(settings->photons), double{settings->splat_radius_texels},
             double{settings->texels_per_metre}, double{settings->glossy_roughness}));
  auto dlm = bake_dlm(input, *settings);
  if (!dlm) return dlm.error();
  const DlmStats& st = dlm->stats;
  stage.log(format("  %zu glossy texels, %zu stored (%.2f MB as halves, %zu B per texel); %llu deposits, %.1f M rays",
                   st.glossy_texels, dlm->texel_count(), static_cast<double>(dlm->radiance.size()) * 2.0 / 1e6,
                   dlm->directions.size() * 6, static_cast<unsigned long long>(st.deposits),
                   static_cast<double>(st.rays) * 1e-6));
  stage.log(format("  time: photons %.2f s; total %.2f s", st.trace_seconds, st.total_seconds));
  timings = {{"trace_seconds", st.trace_seconds}, {"total_seconds", st.total_seconds}};
  return save_dlm(dir, *dlm, input);
}

// fsync of one file or directory.
engine::Status sync_path(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return engine::Error{path.string(), "", std::string("cannot open to flush: ") + std::strerror(errno)};
  const bool ok = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) return engine::Error{path.string(), "", std::string("cannot flush to disk: ") + std::strerror(err)};
  return {};
}

// The files a bake copied or wrote into `dir` (one level: bundles have no subdirectories),
// then the directory itself, flushed to disk.
engine::Status sync_tree(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file(ec))
      if (auto ok = sync_path(e.path(), O_RDONLY); !ok) return ok;
  if (ec) return engine::Error{dir.string(), "", "cannot list the staging directory: " + ec.message()};
  return sync_path(dir, O_RDONLY | O_DIRECTORY);
}

// A bake writes into a staging copy of the bundle ("<dir>/../.<name>.staging"), which takes
// the bundle's place in one atomic exchange once every method is written: a bake that
// fails, is cancelled or is killed leaves the previous bundle exactly as it was (a killed
// one leaves the staging directory, which the next bake of that bundle clears).
class StagedBundle {
 public:
  static engine::Result<StagedBundle> begin(const fs::path& dir) {
    StagedBundle b;
    b.dir_ = dir;
    b.staging_ = dir.parent_path() / ("." + dir.filename().string() + ".staging");
    std::error_code ec;
    if (!dir.parent_path().empty()) fs::create_directories(dir.parent_path(), ec);
    // One bake per bundle at a time: an advisory lock next to it (released by the kernel
    // when the process ends, however it ends).
    const fs::path lock = dir.parent_path() / ("." + dir.filename().string() + ".lock");
    b.lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (b.lock_fd_ < 0)
      return engine::Error{lock.string(), "", std::string("cannot open the bake lock: ") + std::strerror(errno)};
    if (::flock(b.lock_fd_, LOCK_EX | LOCK_NB) != 0)
      return engine::Error{dir.string(), "", "another bake of this bundle is running (lock " + lock.string() + ")"};
    fs::remove_all(b.staging_, ec);
    if (ec) return engine::Error{b.staging_.string(), "", "cannot clear the staging directory: " + ec.message()};
    if (fs::exists(dir, ec)) {
      if (!fs::is_directory(dir, ec)) return engine::Error{dir.string(), "", "exists and is not a bundle directory"};
      fs::copy(dir, b.staging_, fs::copy_options::recursive, ec);
    } else {
      fs::create_directories(b.staging_, ec);
    }
    if (ec) return engine::Error{b.staging_.string(), "", "cannot prepare the staging directory: " + ec.message()};
    b.active_ = true;
    return b;
  }
  StagedBundle(StagedBundle&& o) noexcept
      : dir_(std::move(o.dir_)),
        staging_(std::move(o.staging_)),
        active_(std::exchange(o.active_, false)),
        lock_fd_(std::exchange(o.lock_fd_, -1)) {}
  StagedBundle& operator=(StagedBundle&&) = delete;
  ~StagedBundle() {
    if (active_) {
      std::error_code ec;
      fs::remove_all(staging_, ec);
    }
    if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
  }
  const fs::path& path() const { return staging_; }

  /// The staging directory becomes the bundle (renameat2 RENAME_EXCHANGE when one exists),
  /// its files and directory flushed to disk first and the exchange after.
  engine::Status commit() {
    std::error_code ec;
    if (auto ok = sync_tree(staging_); !ok) return ok;
    if (!fs::exists(dir_, ec)) {
      fs::rename(staging_, dir_, ec);
      if (ec) return engine::Error{dir_.string(), "", "cannot move the baked bundle into place: " + ec.message()};
    } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) != 0) {
      return engine::Error{dir_.string(), "",
                           std::string("cannot exchange the baked bundle with the old one: ") + std::strerror(errno)};
    }
    // staging_ now holds the previous bundle (or nothing).
    return sync_path(dir_.parent_path().empty() ? fs::path(".") : dir_.parent_path(), O_RDONLY | O_DIRECTORY);
  }

 private:
  StagedBundle() = default;
  fs::path dir_, staging_;
  bool active_ = false;
  int lock_fd_ = -1;
};

// The manifest's method entry name of a plan key.
std::string manifest_key(const std::string& key) { return key == "atlas" ? "light_atlas" : key; }

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string host_name() {
  char buf[256] = {};
  return ::gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string();
}

// bake_stats.json (docs/bake-bundle.md): per method, when and where it was baked, with how
// many threads and how long each stage took. Everything that differs between two bakes of
// the same scene, settings and seed lives here and nowhere else, so the manifest and the
// method files are byte-identical across runs and thread counts. No loader reads it.
// Entries of methods baked earlier are kept while the manifest still lists them.
engine::Status update_bake_stats(const fs::path& dir, const nlohmann::json& baked, unsigned threads_requested) {
  const fs::path path = dir / kBakeStatsFileName;
  nlohmann::json methods = nlohmann::json::object();
  if (auto old = read_file_bytes(path)) {
    const auto* text = reinterpret_cast<const char*>(old->data());
    nlohmann::json doc = nlohmann::json::parse(text, text + old->size(), nullptr, /*allow_exceptions=*/false);
    if (doc.is_object() && doc.contains("methods") && doc["methods"].is_object()) methods = doc["methods"];
  }
  auto manifest = read_manifest(dir);
  for (auto it = methods.begin(); it != methods.end();) {
    if (manifest && manifest->methods.contains(it.key()))
      ++it;
    else
      it = methods.erase(it);
  }
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const unsigned used = std::min(threads_requested == 0 ? hardware : threads_requested, ThreadPool::kMaxThreads);
  const std::string when = utc_now();
  const std::string host = host_name();
  for (const auto& [method, entry] : baked.items()) {
    nlohmann::json e = entry;
    e["threads"] = used;
    e["hardware_threads"] = hardware;
    e["host"] = host;
    e["baked_utc"] = when;
    methods[method] = std::move(e);
  }
  const nlohmann::json doc{{"methods", methods}};
  return write_file_atomically(path, doc.dump(2) + "\n");
}

// The methods a bake bakes, in order: options.methods, or what the plan calls for and this
// build can bake (the rest in report.skipped); a sky-lit PRM brings the atlas with it.
engine::Result<std::vector<std::string>> methods_to_bake(const BakeInput& input, const BakeOptions& options,
                                                         const BakeHost& host, BakeReport& report) {
  const std::vector<std::string> bakeable = bakeable_methods();
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) {
    for (const PlannedEffect& e : report.plan.effects) {
      if (!e.enabled) continue;
      const std::string key(effect_key(e.method));
      if (std::find(bakeable.begin(), bakeable.end(), key) != bakeable.end() && e.available)
        methods.push_back(key);
      else
        report.skipped.push_back(key);
    }
    for (const std::string& key : report.skipped)
      if (host.log)
        host.log(LogLevel::Warning, "skipping " + key + ": the scene calls for it but this build cannot bake it");
  }
  for (const std::string& key : methods)
    if (std::find(bakeable.begin(), bakeable.end(), key) == bakeable.end())
      return engine::invalid_request(
          "method '" + key + "' is not available in this build (available: atlas, prm, dlm, brf, antiradiance)");

  // The sky in a PRM bake (docs/prm.md "The sky"): the sky is a static source, so its light
  // lives in the light atlas the PRM provider composes with (the atlas's final gather
  // resolves it per texel, the PRM's entry points only per cluster and compete for the K
  // active panes). A PRM asked for alone on a sky-lit scene bakes that atlas too, first.
  if (engine::sky_lit(input.environment.sky_radiance, input.environment.sky_gradient) &&
      std::find(methods.begin(), methods.end(), "prm") != methods.end() &&
      std::find(methods.begin(), methods.end(), "atlas") == methods.end()) {
    methods.insert(methods.begin(), "atlas");
    if (host.log)
      host.log(LogLevel::Info, "baking the light atlas too: it carries the sky the PRM composes with (docs/prm.md)");
  }
  return methods;
}

// ---- distributed bakes (docs/distributed-bake.md) ----

// The hash of every option that changes a bake's files (not threads, not the shard fields).
std::string bake_settings_hash(const BakeOptions& o) {
  ContentHash h;
  h.add_string("gi-bake settings v1");
  h.add_string(o.preset);
  h.add_value(static_cast<std::uint64_t>(o.methods.size()));
  for (const std::string& m : o.methods) h.add_string(m);
  h.add_value(o.texels_per_metre);
  h.add_value(o.vpls);
  h.add_value(o.bounces);
  h.add_value(o.samples_per_vpl);
  h.add_value(o.brf_basis);
  h.add_value(o.brf_spheres);
  h.add_value(o.dlm_directions);
  h.add_value(o.dlm_photons);
  h.add_value(static_cast<std::uint8_t>(o.include_direct ? 1 : 0));
  h.add_value(static_cast<std::uint64_t>(o.moving_lights.size()));
  for (const std::string& l : o.moving_lights) h.add_string(l);
  h.add_value(o.seed);
  return h.hex();
}

bool has_method(const std::vector<std::string>& methods, const char* key) {
  return std::find(methods.begin(), methods.end(), key) != methods.end();
}

ShardFile shard_header(const BakeInput& input, const BakeOptions& options, const std::vector<std::string>& methods,
                       std::uint32_t index, std::uint32_t count) {
  ShardFile f;
  f.index = index;
  f.count = count;
  f.geometry_hash = scene_geometry_hash(input);
  f.lights_hash = static_lights_hash(input);
  f.settings_hash = bake_settings_hash(options);
  f.seed = options.seed;
  f.methods = methods;
  return f;
}

// gi-bake --shard I/N: the sharded methods' work of shard I into its shard file.
engine::Result<BakeReport> bake_shard(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                      const BakeHost& host, const std::vector<std::string>& methods,
                                      BakeReport report) {
  const std::uint32_t index = options.shard_index, count = options.shard_count;
  if (index >= count)
    return engine::invalid_request("shard " + std::to_string(index) + "/" + std::to_string(count) +
                                   " does not exist (shards are 0..N-1)");
  ShardFile file = shard_header(input, options, methods, index, count);
  const WorkShard shard{.index = index, .count = count};
  const Stage log{host, "shard"};
  if (has_method(methods, "atlas")) {
    const Stage stage{host, "light atlas"};
    auto settings = atlas_settings(options, stage);
    if (!settings) return settings.error();
    const auto start = Clock::now();
    auto part = bake_light_atlas_shard(input, *settings, shard);
    if (!part) return part.error();
    stage.log(format("light atlas shard %u/%u: %zu texels gathered, %.2f s", index, count, part->texels.size(),
                     seconds_since(start)));
    report.baked.push_back({"atlas", seconds_since(start), 0});
    file.atlas = std::move(part).value();
  }
  if (has_method(methods, "prm")) {
    const Stage stage{host, "PRM"};
    auto settings = prm_settings(options, stage);
    if (!settings) return settings.error();
    const auto start = Clock::now();
    auto part = bake_prm_shard(input, *settings, shard);
    if (!part) return part.error();
    stage.log(format("PRM shard %u/%u: %zu texels x %d clusters, %.2f s", index, count, part->texels.size(),
                     part->cluster_count, seconds_since(start)));
    report.baked.push_back({"prm", seconds_since(start), 0});
    file.prm = std::move(part).value();
  }
  if (has_method(methods, "antiradiance")) {
    const Stage stage{host, "antiradiance"};
    const auto start = Clock::now();
    auto links = bake_antiradiance_links_shard(input, antiradiance_settings(options), shard);
    if (!links) return links.error();
    const fs::path path = shard_directory(bundle_dir) / shard_file_name(index, count);
    auto frame = pack_link_shard(path, links->links);
    if (!frame) return frame.error();
    stage.log(format("antiradiance shard %u/%u: links of %zu elements, %zu links, %.2f s", index, count,
                     links->relinked_elements, links->links.size(), seconds_since(start)));
    report.baked.push_back({"antiradiance", seconds_since(start), 0});
    file.antiradiance = AntiradianceShardPart{.links = links->links.size(), .frame = std::move(frame).value()};
  }
  for (const std::string& m : methods)
    if (m != "atlas" && m != "prm" && m != "antiradiance")
      log.log(m + ": not sharded, baked by the merge (docs/distributed-bake.md)");
  const fs::path dir = shard_directory(bundle_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return engine::Error{dir.string(), "", "cannot create the shard directory: " + ec.message()};
  const fs::path path = dir / shard_file_name(index, count);
  if (auto ok = write_shard_file(path, file); !ok) return ok.error();
  std::error_code size_ec;
  const auto bytes = fs::file_size(path, size_ec);
  for (BakedMethod& m : report.baked) m.bytes = size_ec ? 0 : static_cast<std::uint64_t>(bytes);
  log.log("wrote " + path.string());
  return report;
}

// gi-bake --merge: every shard file beside the bundle, checked (present once each, of this
// scene and these options), its parts in shard order. Errors name the shard file.
engine::Result<MergedParts> read_shards(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                        const std::vector<std::string>& methods, const BakeHost& host) {
  const fs::path dir = shard_directory(bundle_dir);
  auto files = list_shard_files(dir, ".gishard");
  if (!files) return files.error();
  const ShardFile expected = shard_header(input, options, methods, 0, options.shard_count);
  std::uint32_t count = options.shard_count;
  ShardSet<ShardFile> set;
  for (const fs::path& path : *files) {
    auto file = read_shard_file(path);
    if (!file) return file.error();
    const auto foreign = [&](const std::string& what) {
      return engine::Error{path.string(), "", "foreign shard: " + what + "; bake it again with this scene and options"};
    };
    if (count == 0) count = file->count;
    if (file->count != count)
      return foreign("shard " + std::to_string(file->index) + " of " + std::to_string(file->count) +
                     ", the merge is of " + std::to_string(count));
    if (file->geometry_hash != expected.geometry_hash)
      return foreign("baked from other geometry (hash " + file->geometry_hash + ", the scene's " +
                     expected.geometry_hash + ")");
    if (file->lights_hash != expected.lights_hash)
      return foreign("baked under other static lights (hash " + file->lights_hash + ", the scene's " +
                     expected.lights_hash + ")");
    if (file->settings_hash != expected.settings_hash || file->seed != expected.seed)
      return foreign("baked with other settings (settings hash " + file->settings_hash + " seed " +
                     std::to_string(file->seed) + ", this merge's " + expected.settings_hash + " seed " +
                     std::to_string(expected.seed) + ")");
    if (file->methods != expected.methods || file->atlas.has_value() != has_method(methods, "atlas") ||
        file->prm.has_value() != has_method(methods, "prm") ||
        file->antiradiance.has_value() != has_method(methods, "antiradiance"))
      return foreign("its methods differ from this merge's");
    const std::uint32_t index = file->index;
    if (auto ok = set.place(path, index, count, std::move(file).value()); !ok) return ok.error();
  }
  if (auto ok = set.complete(count, [&](std::uint32_t i) { return dir / shard_file_name(i, count); }); !ok)
    return ok.error();
  auto& shards = set.shards;
  const auto& where = set.where;
  MergedParts merged;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (shards[i]->atlas) merged.atlas.push_back(std::move(*shards[i]->atlas));
    if (shards[i]->prm) merged.prm.push_back(std::move(*shards[i]->prm));
    if (shards[i]->antiradiance) {
      auto links = unpack_link_shard(where[i], shards[i]->antiradiance->frame, shards[i]->antiradiance->links);
      if (!links) return links.error();
      merged.antiradiance.push_back(std::move(links).value());
    }
  }
  if (host.log) host.log(LogLevel::Info, format("merging %u shards from %s", count, dir.string().c_str()));
  return merged;
}

// ---- end of distributed bakes ----

}  // namespace

std::vector<std::string> bakeable_methods() { return {"atlas", "prm", "dlm", "brf", "antiradiance"}; }

fs::path shard_directory(const fs::path& bundle_dir) {
  fs::path dir = bundle_dir;
  if (!dir.has_filename()) dir = dir.parent_path();  // "out/level.gibake/"
  return dir.parent_path() / (dir.filename().string() + ".shards");
}

std::string shard_file_name(std::uint32_t index, std::uint32_t count) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "shard-%04u-of-%04u.gishard", index, count);
  return buf;
}

engine::Result<BakeReport> bake_bundle(const BakeInput& input, const fs::path& bundle_dir, const BakeOptions& options,
                                       const BakeHost& host) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  BakeReport report;
  report.plan = plan(input, {.preset = options.preset,
                             .moving_lights = options.moving_lights,
                             .texels_per_metre = options.texels_per_metre,
                             .vpls = options.vpls,
                             .samples_per_vpl = options.samples_per_vpl,
                             .bounces = options.bounces});
  // The preset is checked before anything is baked or written.
  if (auto density = light_atlas_preset(options.preset); !density) return density.error();

  auto resolved = methods_to_bake(input, options, host, report);
  if (!resolved) return resolved.error();
  const std::vector<std::string> methods = std::move(resolved).value();

  // Distributed bakes (docs/distributed-bake.md): one shard's work into its shard file, or
  // the merge of every shard's, which then bakes through the same staging + swap below.
  if (options.shard_count > 0 && !options.merge_shards)
    return bake_shard(input, bundle_dir, options, host, methods, std::move(report));
  std::optional<MergedParts> merged;
  if (options.merge_shards) {
    auto parts = read_shards(input, bundle_dir, options, methods, host);
    if (!parts) return parts.error();
    merged = std::move(parts).value();
  }

  if (methods.empty()) return report;
  auto staged = StagedBundle::begin(bundle_dir);
  if (!staged) return staged.error();
  const fs::path& dir = staged->path();
  nlohmann::json method_stats = nlohmann::json::object();
  for (const std::string& key : methods) {
    const auto start = Clock::now();
    Timings timings = nlohmann::json::object();
    const MergedParts* parts = merged ? &*merged : nullptr;
    engine::Status done = key == "atlas" ? bake_atlas(input, dir, options, {host, "light atlas"}, timings, parts)
                          : key == "prm" ? bake_prm_method(input, dir, options, {host, "PRM"}, timings, parts)
                          : key == "dlm" ? bake_dlm_method(input, dir, options, {host, "DLM"}, timings)
                          : key == "antiradiance"
                              ? bake_antiradiance_method(input, dir, options, {host, "antiradiance"}, timings, parts)
                              : bake_brf_method(input, dir, options, host, timings);
    if (!done) return done.error();
    report.baked.push_back({key, seconds_since(start), method_bytes(dir, manifest_key(key))});
    method_stats[manifest_key(key)] = {{"seconds", report.baked.back().seconds}, {"stages", timings}};
  }
  if (auto ok = update_manifest_plan(dir, scene_geometry_hash(input), scene_file_name(input),
                                     plan_to_json_value(report.plan));
      !ok)
    return ok.error();
  if (auto ok = update_bake_stats(dir, method_stats, options.threads); !ok) return ok.error();
  if (auto ok = staged->commit(); !ok) return ok.error();
  return report;
}

}  // namespace gi
