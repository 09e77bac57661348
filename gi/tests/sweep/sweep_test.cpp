// The sweep harness (gi/src/sweep): knob grids, runs against a cached reference, the
// Pareto front and presets, CSV round trips, the reference cache's integrity checks and
// atomic writes. The method and the reference provider here are synthetic and exist in
// this test only. The built-in methods' own runs are tested in <method>_sweep_test.cpp.
#include <gtest/gtest.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <gi/sweep.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "io/atomic_file.h"
#include "sweep/builtin_methods.h"
#include "sweep/knob_grid.h"
#include "sweep/pareto_front.h"
#include "sweep/reference_cache.h"
#include "sweep/reference_sweep.h"
#include "sweep/sweep_csv.h"
#include "sweep/sweep_runner.h"
#include "sweep/sweep_summary.h"
#include "sweep_fixtures.h"

namespace fs = std::filesystem;

namespace {

using sweeptest::make_scene;
using sweeptest::TempDir;

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
}

/// The synthetic world of these tests: a provider that counts its calls, and a method whose
/// output is the reference plus deterministic noise of amplitude 1/quality, costing
/// 0.1 * quality "seconds" (reported, not measured, so the test is fast and exact).
struct Synthetic {
  int provider_calls = 0;
  int reference_spp = 64;
  gi::SweepRegistry registry;

  Synthetic() {
    registry.add_reference_provider(
        {.kind = "synthetic_image", .version = "test-1", .compute = [this](const gi::ReferenceJob& job) {
           ++provider_calls;
           job.progress(0.5);
           const int w = 8, h = 4;
           gi::RgbField f = gi::RgbField::filled(w, h, 0.0f);
           const float red = job.scene.asset.lights.empty() ? 1.0f : job.scene.asset.lights[0].light.color.x;
           for (std::size_t i = 0; i < f.count(); ++i) {
             f.rgb[3 * i] = red * (1.0f + static_cast<float>(i % 5));
             f.rgb[3 * i + 1] = 0.5f + static_cast<float>(i % 3);
             f.rgb[3 * i + 2] = 2.0f;
           }
           return engine::Result<gi::RgbField>(std::move(f));
         }});
    registry.add_method({
        .name = "noisy",
        .description = "reference + noise / quality (test only)",
        .knobs = {{.name = "quality",
                   .description = "inverse noise amplitude",
                   .kind = gi::KnobKind::Integer,
                   .default_grid = {"1", "4", "16"},
                   .min_value = 1,
                   .max_value = 1024},
                  {.name = "mode",
                   .description = "a choice knob",
                   .kind = gi::KnobKind::Choice,
                   .default_grid = {"a"},
                   .choices = {"a", "b"}}},
        .reference_for =
            [this](const gi::SweepScene&, const gi::KnobSetting&) {
              return gi::ReferenceRequest{"synthetic_image", {{"spp", std::to_string(reference_spp)}}};
            },
        .run = [](const gi::RunContext& ctx) -> engine::Result<gi::MethodOutput> {
          const double q = ctx.knobs.real("quality");
          gi::MethodOutput out;
          out.field = ctx.reference;
          for (std::size_t k = 0; k < out.field.rgb.size(); ++k) {
            const double noise = (k % 2 == 0 ? 1.0 : -1.0) * (0.3 + 0.1 * static_cast<double>(k % 7));
            out.field.rgb[k] += static_cast<float>(noise / q);
          }
          if (!ctx.progress(1.0)) return engine::Error{"noisy", "", "cancelled"};
          out.costs = {.bake_seconds = 0.1 * q, .frame_ms = 2.0, .bytes = static_cast<std::uint64_t>(1000 * q)};
          return out;
        },
    });
  }

  std::vector<gi::KnobSetting> grid(std::vector<std::string> overrides = {}) const {
    auto g = gi::make_knob_grid(*registry.find_method("noisy"), overrides);
    EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.error().to_string());
    return g->settings();
  }

  gi::SweepResult sweep(const gi::SweepScene& scene, const fs::path& cache, std::vector<std::string> overrides = {},
                        std::vector<std::string>* log = nullptr) {
    const auto settings = grid(overrides);
    auto r = gi::run_sweep(registry, *registry.find_method("noisy"), scene, settings, {.cache_dir = cache}, {},
                           [&](const std::string& line) {
                             if (log) log->push_back(line);
                           });
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().to_string());
    return r.value();
  }
};

TEST(KnobGrid, DefaultsOverridesAndCartesianOrder) {
  Synthetic syn;
  const gi::SweepMethod& m = *syn.registry.find_method("noisy");
  auto g = gi::make_knob_grid(m, {});
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->size(), 3u);
  const std::vector<std::string> overrides = {"quality=2,008,2,3", "mode=a,b"};
  g = gi::make_knob_grid(m, overrides);
  ASSERT_TRUE(g.ok()) << g.error().to_string();
  const auto s = g->settings();
  ASSERT_EQ(s.size(), 6u);  // duplicates removed, "008" canonicalised to "8"
  EXPECT_EQ(s[0].label(), "quality=2 mode=a");
  EXPECT_EQ(s[1].label(), "quality=2 mode=b");
  EXPECT_EQ(s[2].label(), "quality=8 mode=a");
  EXPECT_EQ(s[5].label(), "quality=3 mode=b");
  EXPECT_EQ(s[2].integer("quality"), 8);
}

TEST(KnobGrid, BadOverridesNameTheProblem) {
  Synthetic syn;
  const gi::SweepMethod& m = *syn.registry.find_method("noisy");
  auto expect_error = [&](std::vector<std::string> o, const std::string& needle) {
    auto g = gi::make_knob_grid(m, o);
    ASSERT_FALSE(g.ok()) << o[0];
    EXPECT_NE(g.error().to_string().find(needle), std::string::npos) << g.error().to_string();
  };
  expect_error({"spp=1,2"}, "has no knob 'spp' (its knobs: quality, mode)");
  expect_error({"quality"}, "expected name=v1,v2");
  expect_error({"quality=1,x"}, "'x' is not a finite number");
  expect_error({"quality=1.5"}, "not an integer");
  expect_error({"quality=0"}, "outside [1, 1024]");
  expect_error({"quality=1,"}, "empty value");
  expect_error({"mode=c"}, "not one of: a, b");
  expect_error({"quality=1", "quality=2"}, "given twice");
}

TEST(ReferenceRequest, KeyIsStableAndSorted) {
  const gi::ReferenceRequest a{"camera_image", {{"width", "4"}, {"spp", "9"}}};
  const gi::ReferenceRequest b{"camera_image", {{"spp", "9"}, {"width", "4"}}};
  EXPECT_EQ(a.key(), "camera_image(spp=9,width=4)");
  EXPECT_EQ(a.key(), b.key());
  EXPECT_EQ(gi::ReferenceRequest::camera_image(0, 256, 128, 4096).key(),
            "camera_image(camera=0,height=128,spp=4096,width=256)");
  EXPECT_EQ(gi::ReferenceRequest::atlas_indirect_irradiance(32.5, 1024).key(),
            "atlas_indirect_irradiance(spp=1024,texels_per_m=32.5)");
}

TEST(SweepRunner, RowsCarryKnobsAndErrorFallsWithQuality) {
  Synthetic syn;
  TempDir dir("rows");
  const gi::SweepScene scene = make_scene();
  const gi::SweepResult r = syn.sweep(scene, dir.path() / "cache");
  ASSERT_EQ(r.rows.size(), 3u);
  const double q[] = {1, 4, 16};
  for (std::size_t i = 0; i < 3; ++i) {
    const gi::SweepRow& row = r.rows[i];
    ASSERT_TRUE(row.ok()) << row.status;
    EXPECT_EQ(row.method, "noisy");
    EXPECT_EQ(row.scene, "<memory>");
    EXPECT_EQ(row.knobs.text("quality"), gi::format_number(q[i]));
    EXPECT_EQ(row.knobs.text("mode"), "a");
    EXPECT_DOUBLE_EQ(row.costs.bake_seconds, 0.1 * q[i]);
    EXPECT_EQ(row.costs.bytes, static_cast<std::uint64_t>(1000 * q[i]));
    EXPECT_NE(row.reference_key.find("request=synthetic_image(spp=64)"), std::string::npos) << row.reference_key;
    EXPECT_NE(row.reference_key.find("scene=" + scene.content_hash), std::string::npos);
  }
  // Noise amplitude 1/q: the error scales exactly by 1/4 per step (up to float rounding).
  EXPECT_GT(r.rows[0].error.rel_rmse, r.rows[1].error.rel_rmse);
  EXPECT_GT(r.rows[1].error.rel_rmse, r.rows[2].error.rel_rmse);
  EXPECT_NEAR(r.rows[0].error.rel_rmse / r.rows[1].error.rel_rmse, 4.0, 1e-3);
  EXPECT_NEAR(r.rows[1].error.rel_rmse / r.rows[2].error.rel_rmse, 4.0, 1e-3);
  EXPECT_EQ(r.references_computed, 1u);
  EXPECT_EQ(syn.provider_calls, 1);
}

TEST(SweepRunner, ReferenceIsCachedByKeyAndSceneContent) {
  Synthetic syn;
  TempDir dir("cache");
  const fs::path cache = dir.path() / "cache";
  syn.sweep(make_scene(), cache);
  EXPECT_EQ(syn.provider_calls, 1);
  gi::SweepResult again = syn.sweep(make_scene(), cache, {"quality=2"});
  EXPECT_EQ(syn.provider_calls, 1) << "same scene and request key: a cache hit";
  EXPECT_EQ(again.references_from_cache, 1u);
  syn.reference_spp = 128;  // the request key changes
  syn.sweep(make_scene(), cache);
  EXPECT_EQ(syn.provider_calls, 2);
  syn.sweep(make_scene(0.5f), cache);  // the scene's content changes
  EXPECT_EQ(syn.provider_calls, 3);
  syn.sweep(make_scene(0.5f), cache);
  EXPECT_EQ(syn.provider_calls, 3);
  // Without a cache directory, every sweep computes.
  syn.sweep(make_scene(0.5f), {});
  EXPECT_EQ(syn.provider_calls, 4);
}

TEST(SweepRunner, CorruptOrTruncatedCacheIsDetectedAndRecomputed) {
  Synthetic syn;
  TempDir dir("corrupt");
  const fs::path cache = dir.path() / "cache";
  const gi::SweepResult first = syn.sweep(make_scene(), cache);
  const gi::ReferenceCache rc(cache);
  const fs::path file = rc.file_for(first.rows[0].reference_key);
  ASSERT_TRUE(fs::exists(file));
  const std::string good = read_bytes(file);

  write_bytes(file, good.substr(0, good.size() / 2));  // truncated
  std::vector<std::string> log;
  gi::SweepResult r = syn.sweep(make_scene(), cache, {}, &log);
  EXPECT_EQ(syn.provider_calls, 2);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("truncated"), std::string::npos) << log[0];
  EXPECT_EQ(read_bytes(file), good) << "the recomputed reference replaces the bad file";
  EXPECT_EQ(r.rows[0].error.rel_rmse, first.rows[0].error.rel_rmse);

  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x10;  // one bit in the payload
  write_bytes(file, flipped);
  log.clear();
  syn.sweep(make_scene(), cache, {}, &log);
  EXPECT_EQ(syn.provider_calls, 3);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("checksum"), std::string::npos) << log[0];
  EXPECT_EQ(read_bytes(file), good);
}

TEST(ReferenceCache, EveryTruncationAndTheWrongKeyAreRejected) {
  gi::RgbField f = gi::RgbField::filled(3, 2, 0.25f);
  f.valid = {1, 0, 1, 1, 1, 0};
  const std::string bytes = gi::encode_reference("key-a", f);
  auto back = gi::decode_reference(bytes, "key-a", "mem");
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->rgb, f.rgb);
  EXPECT_EQ(back->valid, f.valid);
  EXPECT_EQ(back->width, 3);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(gi::decode_reference(bytes.substr(0, n), "key-a", "mem").ok()) << "truncated to " << n;
  }
  const auto wrong = gi::decode_reference(bytes, "key-b", "mem");
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().to_string().find("key"), std::string::npos);
  EXPECT_FALSE(gi::decode_reference(bytes + "x", "key-a", "mem").ok());
}

TEST(ReferenceCache, TheVarianceBlockRoundTripsAndIsCheckedLikeTheRest) {
  gi::RgbField f = gi::RgbField::filled(2, 2, 0.5f);
  f.valid = {1, 1, 0, 1};
  f.variance = {1e-4f, 2e-4f, 3e-4f, 0.0f, 0.0f, 0.0f, 5e-5f, 6e-5f, 7e-5f, 1.0f, 2.0f, 3.0f};
  const std::string bytes = gi::encode_reference("key-v", f);
  auto back = gi::decode_reference(bytes, "key-v", "mem");
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->variance, f.variance);
  EXPECT_EQ(back->valid, f.valid);
  EXPECT_EQ(back->rgb, f.rgb);
  for (std::size_t n = 0; n < bytes.size(); n += 7)
    EXPECT_FALSE(gi::decode_reference(bytes.substr(0, n), "key-v", "mem").ok()) << "truncated to " << n;
  gi::RgbField plain = gi::RgbField::filled(2, 2, 0.5f);
  auto no_variance = gi::decode_reference(gi::encode_reference("k", plain), "k", "mem");
  ASSERT_TRUE(no_variance.ok());
  EXPECT_TRUE(no_variance->variance.empty());
}

TEST(AtomicFile, ReplacesWholeFileOrLeavesNothingBehind) {
  TempDir dir("atomic");
  const fs::path target = dir.path() / "out.csv";
  ASSERT_TRUE(gi::write_file_atomically(target, "first").ok());
  ASSERT_TRUE(gi::write_file_atomically(target, "second").ok());
  EXPECT_EQ(read_bytes(target), "second");
  // The rename cannot replace a non-empty directory: the write fails, nothing partial stays.
  const fs::path blocked = dir.path() / "blocked";
  fs::create_directories(blocked / "child");
  const engine::Status s = gi::write_file_atomically(blocked, "data");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("blocked"), std::string::npos) << s.error().to_string();
  // A missing directory: the temporary file cannot even be created.
  EXPECT_FALSE(gi::write_file_atomically(dir.path() / "missing" / "x.csv", "data").ok());
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.path())) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"blocked", "out.csv"})) << "no temporary file left";
  EXPECT_TRUE(fs::is_directory(blocked / "child"));
}

TEST(SweepRunner, BadOutputsBecomeRowStatusesNotCrashes) {
  Synthetic syn;
  int call = 0;
  syn.registry.add_method({.name = "broken",
                           .knobs = {{.name = "case", .kind = gi::KnobKind::Integer, .default_grid = {"0", "1", "2"}}},
                           .reference_for =
                               [](const gi::SweepScene&, const gi::KnobSetting&) {
                                 return gi::ReferenceRequest{"synthetic_image", {{"spp", "64"}}};
                               },
                           .run = [&call](const gi::RunContext& ctx) -> engine::Result<gi::MethodOutput> {
                             ++call;
                             gi::MethodOutput out{ctx.reference, {}};
                             switch (ctx.knobs.integer("case")) {
                               case 0:
                                 out.field = gi::RgbField::filled(2, 2, 1.0f);
                                 break;
                               case 1:
                                 out.field.rgb[5] = std::numeric_limits<float>::quiet_NaN();
                                 break;
                               default:
                                 return engine::Error{"broken", "", "out of memory"};
                             }
                             return out;
                           }});
  const auto grid = gi::make_knob_grid(*syn.registry.find_method("broken"), {})->settings();
  auto r = gi::run_sweep(syn.registry, *syn.registry.find_method("broken"), make_scene(), grid, {});
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r->rows.size(), 3u);
  EXPECT_NE(r->rows[0].status.find("2x2 but the reference is 8x4"), std::string::npos) << r->rows[0].status;
  EXPECT_NE(r->rows[1].status.find("non-finite"), std::string::npos) << r->rows[1].status;
  EXPECT_TRUE(std::isnan(r->rows[1].error.rel_rmse));
  EXPECT_NE(r->rows[2].status.find("out of memory"), std::string::npos) << r->rows[2].status;
}

TEST(SweepRunner, MissingProviderIsAnError) {
  gi::SweepRegistry reg;
  reg.add_method({.name = "orphan",
                  .reference_for =
                      [](const gi::SweepScene&, const gi::KnobSetting&) {
                        return gi::ReferenceRequest{"nobody", {}};
                      },
                  .run = [](const gi::RunContext&) -> engine::Result<gi::MethodOutput> { return gi::MethodOutput{}; }});
  const std::vector<gi::KnobSetting> one(1);
  auto r = gi::run_sweep(reg, *reg.find_method("orphan"), make_scene(), one, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().to_string().find("no reference provider is registered for kind 'nobody'"), std::string::npos);
}

TEST(SweepRunner, ProgressCoversAllUnitsAndCancelStops) {
  Synthetic syn;
  const auto settings = syn.grid();
  std::vector<gi::SweepProgress> seen;
  auto r = gi::run_sweep(syn.registry, *syn.registry.find_method("noisy"), make_scene(), settings, {},
                         [&](const gi::SweepProgress& p) {
                           seen.push_back(p);
                           return true;
                         });
  ASSERT_TRUE(r.ok());
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back().units_done, 4u);  // one reference + three runs
  EXPECT_EQ(seen.back().units_total, 4u);
  EXPECT_EQ(seen.front().current, "reference synthetic_image(spp=64)");

  r = gi::run_sweep(syn.registry, *syn.registry.find_method("noisy"), make_scene(), settings, {},
                    [&](const gi::SweepProgress& p) { return p.units_done < 2; });
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->cancelled);
  EXPECT_EQ(r->rows.size(), 1u);
}

TEST(ParetoFront, HandMadePoints) {
  // (error, cost)
  const std::vector<gi::ParetoPoint> p = {
      {0.50, 1.0},                                      // 0 front (cheapest)
      {0.30, 2.0},                                      // 1 front
      {0.35, 3.0},                                      // 2 dominated by 1
      {0.10, 8.0},                                      // 3 front
      {0.10, 9.0},                                      // 4 dominated by 3 (equal error, dearer)
      {0.02, 20.0},                                     // 5 front
      {std::numeric_limits<double>::quiet_NaN(), 0.1},  // 6 failed run: never on the front
      {0.60, 1.0},                                      // 7 dominated by 0 (equal cost, worse)
  };
  const auto front = gi::pareto_front(p);
  EXPECT_EQ(front, (std::vector<std::size_t>{0, 1, 3, 5}));

  const auto presets = gi::choose_presets(p, front, {.preview = 0.4, .medium = 0.1, .high = 0.01});
  ASSERT_EQ(presets.size(), 3u);
  EXPECT_EQ(presets[0].name, "preview");
  EXPECT_EQ(presets[0].index, 1u);  // cheapest with error <= 0.4
  EXPECT_TRUE(presets[0].target_met);
  EXPECT_EQ(presets[1].index, 3u);  // error 0.10 <= 0.1
  EXPECT_EQ(presets[2].index, 5u);  // nothing reaches 0.01: the most accurate, flagged
  EXPECT_FALSE(presets[2].target_met);
  EXPECT_TRUE(gi::choose_presets(p, {}, {}).empty());
}

TEST(SweepCsv, RowsParseBack) {
  Synthetic syn;
  gi::SweepResult r = syn.sweep(make_scene(), {}, {"quality=1,4", "mode=a,b"});
  ASSERT_EQ(r.rows.size(), 4u);
  r.rows[1].status = "odd \"status\", with comma\nand newline";
  r.rows[2].costs.frame_ms = std::numeric_limits<double>::quiet_NaN();
  r.rows[3].error.psnr_db = std::numeric_limits<double>::infinity();
  const std::string plain = gi::sweep_csv(r.rows);
  EXPECT_EQ(plain.substr(0, plain.find('\n')),
            "method,scene,knob:quality,knob:mode,rel_rmse,max_rel,psnr_db,fit_scale,fit_rel_rmse,bake_s,frame_ms,"
            "bytes,wall_s,reference_key,status");
  // A method's own measurements: extra:<name> columns after status, empty where a row lacks one.
  r.rows[0].extras = {{"share", 0.25}};
  r.rows[2].extras = {{"share", 0.5}, {"count", 3.0}};
  const std::string csv = gi::sweep_csv(r.rows);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "method,scene,knob:quality,knob:mode,rel_rmse,max_rel,psnr_db,fit_scale,fit_rel_rmse,bake_s,frame_ms,"
            "bytes,wall_s,reference_key,status,extra:share,extra:count");
  auto back = gi::parse_sweep_csv(csv, "mem.csv");
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  ASSERT_EQ(back->size(), r.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const gi::SweepRow& a = r.rows[i];
    const gi::SweepRow& b = (*back)[i];
    EXPECT_EQ(b.method, a.method);
    EXPECT_EQ(b.scene, a.scene);
    EXPECT_EQ(b.knobs, a.knobs);
    EXPECT_EQ(b.error.rel_rmse, a.error.rel_rmse);  // shortest round-trip formatting: exact
    EXPECT_EQ(b.error.max_rel, a.error.max_rel);
    EXPECT_EQ(b.error.psnr_db, a.error.psnr_db);
    EXPECT_EQ(b.error.fit_scale, a.error.fit_scale);
    EXPECT_EQ(b.error.fit_rel_rmse, a.error.fit_rel_rmse);
    EXPECT_EQ(b.costs.bake_seconds, a.costs.bake_seconds);
    EXPECT_EQ(std::isnan(b.costs.frame_ms), std::isnan(a.costs.frame_ms));
    if (!std::isnan(a.costs.frame_ms)) {
      EXPECT_EQ(b.costs.frame_ms, a.costs.frame_ms);
    }
    EXPECT_EQ(b.costs.bytes, a.costs.bytes);
    EXPECT_EQ(b.wall_seconds, a.wall_seconds);
    EXPECT_EQ(b.reference_key, a.reference_key);
    EXPECT_EQ(b.status, a.status);
    EXPECT_EQ(b.extras, a.extras);
  }
  EXPECT_FALSE(gi::parse_sweep_csv("method,scene\nx,\"unterminated\n", "bad.csv").ok());
  const auto missing = gi::parse_sweep_csv("method,scene\nx,y\n", "bad.csv");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().to_string().find("missing column rel_rmse"), std::string::npos);
}

TEST(SweepSummary, MarkdownListsFrontAndPresetsWithTheRule) {
  Synthetic syn;
  const gi::SweepResult r = syn.sweep(make_scene(), {});
  const gi::SweepSummary s = gi::summarize_sweep(r.rows, {});
  // Error falls and cost rises with quality: every run is on the front.
  EXPECT_EQ(s.front, (std::vector<std::size_t>{0, 1, 2}));
  const std::string md = gi::sweep_summary_markdown(r.rows, s);
  EXPECT_NE(md.find("## Pareto front"), std::string::npos);
  EXPECT_NE(md.find("Rule: each preset is the cheapest Pareto-front run"), std::string::npos);
  EXPECT_NE(md.find("**high**"), std::string::npos);
  EXPECT_NE(md.find("quality=16 mode=a"), std::string::npos);
  EXPECT_EQ(md.find("Regenerate"), std::string::npos);  // no command given
  gi::SweepSummaryOptions with_command;
  with_command.command = "gi-sweep --method synthetic --scene s.gltf --out out";
  gi::SweepResult extra = r;
  extra.rows[1].extras = {{"dropped_energy", 0.125}};
  const std::string md2 = gi::sweep_summary_markdown(extra.rows, gi::summarize_sweep(extra.rows, with_command));
  EXPECT_NE(md2.find("```sh\ngi-sweep --method synthetic --scene s.gltf --out out\n```"), std::string::npos);
  EXPECT_NE(md2.find("| status | dropped_energy |"), std::string::npos);
  EXPECT_NE(md2.find("| 0.125 |"), std::string::npos);
}

TEST(SceneFingerprint, FileBytesAndLoadedContentBothCount) {
  TempDir dir("fingerprint");
  const fs::path file = dir.path() / "scene.gltf";
  write_bytes(file, "{\"asset\":{\"version\":\"2.0\"}}");
  const gi::SweepScene s = make_scene();
  const std::string h1 = gi::scene_fingerprint(file, s.asset).value();
  EXPECT_EQ(h1.size(), 16u);
  EXPECT_EQ(gi::scene_fingerprint(file, s.asset).value(), h1);
  write_bytes(file, "{\"asset\":{\"version\":\"2.0\"} }");
  EXPECT_NE(gi::scene_fingerprint(file, s.asset).value(), h1);
  EXPECT_NE(gi::scene_fingerprint(file, make_scene(0.9f).asset).value(), gi::scene_fingerprint(file, s.asset).value());
  EXPECT_FALSE(gi::scene_fingerprint(dir.path() / "missing.gltf", s.asset).ok());
}

TEST(SceneFingerprint, LoadsARealScene) {
  auto scene = gi::load_sweep_scene(fs::path(GI_SOURCE_DIR) / "assets" / "cornell_box.gltf");
  ASSERT_TRUE(scene.ok()) << scene.error().to_string();
  EXPECT_EQ(scene->display_name(), "cornell_box.gltf");
  EXPECT_FALSE(scene->asset.meshes.empty());
  EXPECT_FALSE(gi::load_sweep_scene(fs::path(GI_SOURCE_DIR) / "assets" / "no_such.gltf").ok());
}

// The light atlas's reference world: the crates room without its five dynamic crates, the
// same static instances; a moving light dropped, a static one kept.
TEST(ReferenceSweep, TheAtlasReferenceWorldIsTheStaticOne) {
  auto scene = gi::load_sweep_scene(fs::path(GI_SOURCE_DIR) / "assets" / "crates_room.gltf");
  ASSERT_TRUE(scene.ok()) << scene.error().to_string();
  gi::BakeInput input = gi::bake_input_from(engine::instantiate(scene->asset));
  gi::BakeLight moving, fixed;
  moving.light.moves = true;
  input.lights.push_back(moving);
  input.lights.push_back(fixed);
  const gi::BakeInput world = gi::static_world(input);
  std::size_t statics = 0;
  for (const gi::BakeInstance& i : input.instances) statics += i.mobility == gi::BakeMobility::Static;
  EXPECT_GE(input.instances.size(), statics + 5);
  ASSERT_EQ(world.instances.size(), statics);
  for (const gi::BakeInstance& i : world.instances) EXPECT_EQ(i.mobility, gi::BakeMobility::Static) << i.name;
  EXPECT_EQ(world.lights.size(), input.lights.size() - 1);
  for (const gi::BakeLight& l : world.lights) EXPECT_FALSE(l.light.moves);
  EXPECT_EQ(world.meshes.size(), input.meshes.size());
}

TEST(BuiltinSweepMethods, RegisterOnlyRealMethods) {
  gi::SweepRegistry reg;
  gi::register_builtin_sweep_methods(reg);
  for (const gi::SweepMethod& m : reg.methods()) EXPECT_TRUE(m.run) << m.name;
}

}  // namespace
