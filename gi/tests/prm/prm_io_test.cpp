// Saving a PRM into a bake bundle and loading it back, with hand-made data (no bake): exact
// texels, entry points and clusters, panes within the half-float bound, compression that
// pays, stale bundles and damaged files rejected with messages naming the file.
#include "prm/prm_io.h"

#include <zstd.h>
#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include <engine/byte_stream.h>
#include "bundle/bundle.h"
#include "io/content_hash.h"
#include "prm/prm_runtime.h"
#include "uv/atlas_input.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "prm_io_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

const engine::SceneAsset& cornell() {
  static const engine::SceneAsset asset = [] {
    auto a = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
    EXPECT_TRUE(a.ok()) << a.error().to_string();
    return std::move(a).value();
  }();
  return asset;
}

// A PRM made by hand on the real layout: two texels of every three, seven entry points in
// four clusters, and panes covering what a bake gives: a log ramp 1e-6..1e4 (pane 0), a
// smooth pattern with exact zeros (pane 1), a pane of zeros (pane 2) and values beyond the
// half range up to 2e5 (pane 3).
gi::Prm fake_prm(float texels_per_metre = 4.0f) {
  gi::Prm p;
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(gi::bake_input_from(cornell())),
                                       {.texels_per_metre = texels_per_metre});
  EXPECT_TRUE(layout.ok()) << layout.error().to_string();
  p.layout = std::move(layout).value();
  p.width = p.layout.width;
  p.height = p.layout.height;
  const auto atlas_texels = static_cast<std::uint32_t>(p.width * p.height);
  for (std::uint32_t t = 0; t < atlas_texels; ++t)
    if (t % 3 != 1) p.texels.push_back(t);
  p.cluster_count = 4;
  const std::uint32_t cluster_of[] = {0, 1, 0, 3, 1, 0, 3};
  p.cluster_size = {3, 2, 0, 2};
  for (std::uint32_t k = 0; k < 7; ++k) {
    const float f = static_cast<float>(k);
    p.entries.push_back({glm::vec3(0.1f * f, 1.0f / (f + 3.0f), -0.25f * f), glm::normalize(glm::vec3(1.0f, f, 2.0f)),
                         0.01f + 0.003f * f, cluster_of[k]});
  }
  const std::size_t n = p.texels.size();
  std::vector<float> panes(4 * n * 3);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / static_cast<double>(n - 1);
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const double shade = 1.0 + 0.25 * static_cast<double>(ch);
      panes[(0 * n + i) * 3 + ch] = static_cast<float>(std::pow(10.0, -6.0 + 10.0 * u) / shade);
      panes[(1 * n + i) * 3 + ch] =
          i % 7 == 0 ? 0.0f : static_cast<float>(0.3 * shade * (1.0 + 0.5 * std::sin(0.05 * static_cast<double>(i))));
      panes[(2 * n + i) * 3 + ch] = 0.0f;
      panes[(3 * n + i) * 3 + ch] = static_cast<float>(2e5 * shade / 1.5 * (0.5 + 0.5 * u));
    }
  }
  p.settings = {.texels_per_metre = texels_per_metre,
                .entry_points = 7,
                .clusters = 4,
                .splitting = 2.5f,
                .max_path_nodes = 33,
                .kmeans = true,
                .seed = 0xfedcba9876543210ull,
                .threads = 3};
  p.stats = {.paths = 1234,
             .path_nodes = 5678,
             .rays = 1ull << 40,
             .walk_seconds = 0.125,
             .pane_seconds = 1.0 / 3.0,
             .total_seconds = 4.2};
  gi::set_dense_panes(p, panes);
  return p;
}

fs::path saved_bundle(const std::string& name, const gi::Prm& prm = fake_prm()) {
  const fs::path dir = scratch_dir(name);
  const engine::Status s = gi::save_prm(dir, prm, gi::bake_input_from(cornell()));
  EXPECT_TRUE(s.ok()) << s.error().to_string();
  return dir;
}

void expect_error(const engine::Error& e, const std::string& file, const std::string& what) {
  std::printf("rejected as expected: %s\n", e.to_string().c_str());
  EXPECT_NE(e.to_string().find(file), std::string::npos) << e.to_string();
  EXPECT_NE(e.to_string().find(what), std::string::npos) << e.to_string();
}

void expect_load_error(const fs::path& dir, const std::string& file, const std::string& what) {
  auto r = gi::load_prm(dir, gi::bake_input_from(cornell()));
  ASSERT_FALSE(r.ok()) << "a bad bundle loaded (" << what << ")";
  expect_error(r.error(), file, what);
}

std::vector<std::byte> read_all(const fs::path& p) { return gi::read_file_bytes(p).value(); }

void write_all(const fs::path& p, const std::vector<std::byte>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// Makes the manifest agree with the panes file as it is now (so the checks behind the
// manifest's checksum are reached).
void resign(const fs::path& dir) {
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok());
  const auto bytes = read_all(dir / "prm_panes.bin");
  gi::ContentHash h;
  h.add_bytes(bytes.data(), bytes.size());
  m->methods["prm"]["files"]["panes"]["xxh3_64"] = h.hex();
  ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
}

// The payload of a saved bundle's panes file, and a way to put an edited one back.
std::vector<std::byte> payload_of(const fs::path& dir) {
  return gi::read_blob(dir / "prm_panes.bin", gi::kPrmPanesMagic, gi::kPrmPanesVersion).value();
}
void put_payload(const fs::path& dir, const std::vector<std::byte>& payload) {
  ASSERT_TRUE(gi::write_blob(dir / "prm_panes.bin", gi::kPrmPanesMagic, gi::kPrmPanesVersion, payload).ok());
  resign(dir);
}

// Offsets of fixed fields in the payload (geometry hash string of 16 characters first).
constexpr std::size_t kSettingsBytes = 4 + 4 + 4 + 4 + 4 + 4 + 1 + 8;  // pane density since version 4
constexpr std::size_t kClusterCountOffset = 8 + 16 + kSettingsBytes + 4 + 4;
constexpr std::size_t kTexelsOffset = kClusterCountOffset + 4;  // uint64 count, then the texels

template <class T>
void poke(std::vector<std::byte>& payload, std::size_t offset, T value) {
  std::memcpy(payload.data() + offset, &value, sizeof(T));
}

// Largest |decoded - original| / (the stated bound), and the largest relative error over
// values at least 1e-6 of their pane's maximum.
struct PaneError {
  double worst_of_bound = 0.0;
  double max_relative = 0.0;
};

PaneError pane_error(const gi::Prm& a, const gi::Prm& b) {
  PaneError e;
  const std::size_t per_pane = a.texels.size() * 3;
  const std::vector<float> ap = gi::dense_panes(a), bp = gi::dense_panes(b);
  for (std::size_t c = 0; c < static_cast<std::size_t>(a.cluster_count); ++c) {
    const auto first = ap.begin() + static_cast<std::ptrdiff_t>(c * per_pane);
    const double max_c = *std::max_element(first, first + static_cast<std::ptrdiff_t>(per_pane));
    for (std::size_t j = c * per_pane; j < (c + 1) * per_pane; ++j) {
      const double v = ap[j], d = bp[j];
      const double bound = gi::kPrmPaneRelativeError * v + gi::kPrmPaneAbsoluteErrorOfMax * max_c;
      if (bound > 0.0)
        e.worst_of_bound = std::max(e.worst_of_bound, std::abs(d - v) / bound);
      else
        EXPECT_EQ(d, v);
      if (v >= 1e-6 * max_c && v > 0.0) e.max_relative = std::max(e.max_relative, std::abs(d - v) / v);
    }
  }
  return e;
}

}  // namespace

TEST(PrmIo, HalfConversionIsExactAndRoundsToNearestEven) {
  for (std::uint32_t h = 0; h < 0x7c00u; ++h) {  // every finite non-negative half
    const float f = gi::half_to_float(static_cast<std::uint16_t>(h));
    ASSERT_EQ(gi::float_to_half(f), h) << h;
    if (h + 1 < 0x7c00u) {
      // Halfway to the next half rounds to the even one; just above rounds up.
      const float next = gi::half_to_float(static_cast<std::uint16_t>(h + 1));
      const float mid = f + (next - f) / 2.0f;
      EXPECT_EQ(gi::float_to_half(mid), (h & 1u) == 0 ? h : h + 1) << h;
      EXPECT_EQ(gi::float_to_half(std::nextafter(mid, next)), h + 1) << h;
      EXPECT_EQ(gi::float_to_half(std::nextafter(mid, 0.0f)), h) << h;
    }
  }
  EXPECT_EQ(gi::float_to_half(65504.0f), 0x7bffu);
  EXPECT_EQ(gi::float_to_half(65520.0f), 0x7c00u);  // rounds to infinity: why panes are scaled
  EXPECT_EQ(gi::float_to_half(1e-9f), 0u);
  EXPECT_EQ(gi::float_to_half(-2.0f), 0xc000u);
  EXPECT_TRUE(std::isnan(gi::half_to_float(gi::float_to_half(std::numeric_limits<float>::quiet_NaN()))));
}

TEST(PrmIo, RoundTripKeepsStructureExactAndPanesWithinTheHalfBound) {
  const gi::Prm prm = fake_prm();
  const fs::path dir = saved_bundle("round_trip", prm);
  EXPECT_TRUE(fs::exists(dir / "prm_panes.bin"));
  EXPECT_TRUE(fs::exists(dir / "manifest.json"));

  auto back = gi::load_prm(dir, gi::bake_input_from(cornell()));
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->width, prm.width);
  EXPECT_EQ(back->height, prm.height);
  EXPECT_EQ(back->layout.width, prm.width);
  EXPECT_EQ(back->layout.requested_texels_per_metre, 4.0f);
  EXPECT_EQ(back->layout.charts.size(), prm.layout.charts.size());
  EXPECT_EQ(back->texels, prm.texels);
  EXPECT_EQ(back->cluster_count, prm.cluster_count);
  EXPECT_EQ(back->cluster_size, prm.cluster_size);
  ASSERT_EQ(back->entries.size(), prm.entries.size());
  for (std::size_t k = 0; k < prm.entries.size(); ++k) {
    EXPECT_EQ(std::memcmp(&back->entries[k].position, &prm.entries[k].position, sizeof(glm::vec3)), 0);
    EXPECT_EQ(std::memcmp(&back->entries[k].normal, &prm.entries[k].normal, sizeof(glm::vec3)), 0);
    EXPECT_EQ(back->entries[k].area_m2, prm.entries[k].area_m2);
    EXPECT_EQ(back->entries[k].cluster, prm.entries[k].cluster);
  }
  EXPECT_EQ(back->panes.blocks, prm.panes.blocks);
  EXPECT_EQ(back->panes.cluster_first, prm.panes.cluster_first);
  EXPECT_EQ(back->panes.tiles, prm.panes.tiles);
  const std::vector<float> before = gi::dense_panes(prm), after = gi::dense_panes(*back);
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t j = 0; j < before.size(); ++j)
    if (before[j] == 0.0f) {
      ASSERT_EQ(after[j], 0.0f) << "zeros stay zero, element " << j;
    }
  const std::size_t n = prm.texels.size();
  EXPECT_GT(after[(3 * n + n - 1) * 3 + 2], 65504.0f) << "values beyond the half range survive";
  const PaneError e = pane_error(prm, *back);
  std::printf("half panes: worst error %.3f of the stated bound, max relative error %.3g (bound %.3g)\n",
              e.worst_of_bound, e.max_relative, gi::kPrmPaneRelativeError);
  EXPECT_LE(e.worst_of_bound, 1.0);
  EXPECT_LE(e.max_relative, gi::kPrmPaneRelativeError);

  const gi::PrmSettings &s = back->settings, &t = prm.settings;
  EXPECT_EQ(s.texels_per_metre, t.texels_per_metre);
  EXPECT_EQ(s.entry_points, t.entry_points);
  EXPECT_EQ(s.clusters, t.clusters);
  EXPECT_EQ(s.splitting, t.splitting);
  EXPECT_EQ(s.max_path_nodes, t.max_path_nodes);
  EXPECT_EQ(s.kmeans, t.kmeans);
  EXPECT_EQ(s.seed, t.seed);
  EXPECT_EQ(s.threads, 0u) << "the thread count is not part of a bundle (bake_stats.json holds it)";
  const gi::PrmStats &x = back->stats, &y = prm.stats;
  EXPECT_EQ(x.paths, y.paths);
  EXPECT_EQ(x.path_nodes, y.path_nodes);
  EXPECT_EQ(x.rays, y.rays);
  // Timings are not part of a bundle (bake_stats.json holds them): a load reads none.
  EXPECT_EQ(x.total_seconds, 0.0);
  EXPECT_EQ(x.walk_seconds, 0.0);

  // Loading again gives the same values (the format is deterministic).
  auto again = gi::load_prm(dir, gi::bake_input_from(cornell()));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->panes, back->panes);
}

// Panes coarser than the atlas (issue 38): the bundle keeps both layouts, and the load
// rebuilds the same upsampler, so the atlas it sums is the saved PRM's within half precision.
TEST(PrmIo, CoarsePanesKeepTheirAtlasLayoutAndUpsampler) {
  gi::Prm prm = fake_prm(8.0f);
  prm.settings.texels_per_metre = 16.0f;
  prm.settings.pane_texels_per_metre = 8.0f;
  const gi::BakeInput input = gi::bake_input_from(cornell());
  auto fine = gi::build_atlas_layout(gi::atlas_inputs_from(input), {.texels_per_metre = 16.0f});
  ASSERT_TRUE(fine.ok());
  auto read = gi::prm_atlas_read(prm, std::move(fine).value(), input);
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  prm.atlas = std::move(read).value();
  ASSERT_GT(prm.atlas_width() * prm.atlas_height(), prm.width * prm.height);
  const fs::path dir = saved_bundle("coarse", prm);
  EXPECT_TRUE(fs::exists(dir / gi::kPrmAtlasLayoutFile));

  auto back = gi::load_prm(dir, input);
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->settings.pane_texels_per_metre, 8.0f);
  EXPECT_EQ(back->width, prm.width);
  EXPECT_EQ(back->layout.requested_texels_per_metre, 8.0f);
  ASSERT_TRUE(back->atlas.has_value());
  EXPECT_EQ(back->atlas_width(), prm.atlas_width());
  EXPECT_EQ(back->atlas_height(), prm.atlas_height());
  EXPECT_EQ(back->atlas_layout().requested_texels_per_metre, 16.0f);
  const gi::PaneUpsampler &a = *prm.atlas->upsampler, &b = *back->atlas->upsampler;
  EXPECT_TRUE(std::ranges::equal(a.reads(), b.reads()));
  EXPECT_TRUE(std::ranges::equal(a.ring_texels(), b.ring_texels()));
  EXPECT_TRUE(std::ranges::equal(a.ring_first(), b.ring_first()));
  // The atlas summed from both: pane 1 (values 0.2-0.5) at weight 1, read at the atlas.
  const std::vector<gi::ClusterWeight> one{{1, glm::vec3(1.0f)}};
  const std::vector<glm::vec3> before = gi::sum_panes(prm, one), after = gi::sum_panes(*back, one);
  ASSERT_EQ(before.size(), static_cast<std::size_t>(prm.atlas_width() * prm.atlas_height()));
  ASSERT_EQ(after.size(), before.size());
  std::size_t lit = 0;
  for (std::size_t t = 0; t < before.size(); ++t) {
    lit += before[t].x > 0.0f;
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(after[t][ch], before[t][ch], (gi::kPrmPaneRelativeError + 1e-6) * double(before[t][ch]) + 1e-7) << t;
  }
  EXPECT_GT(lit, a.fine_texels().size() / 2) << "the coarse pane reaches the atlas's texels";

  // An entry that lost its atlas layout is refused, naming the manifest.
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok());
  m->methods["prm"].erase(gi::kPrmAtlasLayoutKey);
  ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
  expect_load_error(dir, "manifest.json", "no atlas layout");
}

TEST(PrmIo, ManifestEntryDescribesTheBake) {
  const gi::Prm prm = fake_prm();
  const fs::path dir = saved_bundle("manifest", prm);
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok()) << m.error().to_string();
  EXPECT_EQ(m->scene, "cornell_box.gltf");
  EXPECT_EQ(m->geometry_hash, gi::scene_geometry_hash(gi::bake_input_from(cornell())));
  const nlohmann::json& e = m->methods["prm"];
  std::printf("%s\n", e.dump(2).c_str());
  EXPECT_EQ(e["files"]["panes"]["file"], "prm_panes.bin");
  const auto bytes = read_all(dir / "prm_panes.bin");
  gi::ContentHash h;
  h.add_bytes(bytes.data(), bytes.size());
  EXPECT_EQ(e["files"]["panes"]["xxh3_64"], h.hex());
  EXPECT_EQ(e["settings"]["seed"], prm.settings.seed);
  EXPECT_EQ(e["settings"]["entry_points"], 7);
  EXPECT_EQ(e["settings"]["clusters"], 4);
  EXPECT_EQ(e["settings"]["kmeans"], true);
  EXPECT_EQ(e["settings"]["splitting"], 2.5);
  EXPECT_EQ(e["settings"]["max_path_nodes"], 33);
  EXPECT_EQ(e["layout"]["requested_texels_per_metre"], 4.0);
  EXPECT_EQ(e["layout"]["texels_per_metre"], prm.layout.texels_per_metre);
  EXPECT_EQ(e["layout"]["padding_texels"], prm.layout.padding_texels);
  EXPECT_EQ(e["layout"]["width"], prm.width);
  EXPECT_EQ(e["layout"]["height"], prm.height);
  EXPECT_EQ(e["entry_points"], 7);
  EXPECT_EQ(e["clusters"], 4);
  EXPECT_EQ(e["pane_texels"], prm.texels.size());
  EXPECT_EQ(e["stats"]["paths"], 1234);
  EXPECT_EQ(e["stats"]["path_nodes"], 5678);
  EXPECT_EQ(e["stats"]["rays"], 1ull << 40);
  EXPECT_FALSE(e["stats"].contains("walk_seconds"));
  EXPECT_FALSE(e["stats"].contains("total_seconds"));
  EXPECT_FALSE(e["settings"].contains("threads"));
  // Pane 2 is all zeros: none of its blocks is stored.
  EXPECT_EQ(e["memory"]["pane_bytes_half"], 3 * prm.texels.size() * 3 * 2);
  EXPECT_EQ(e["memory"]["pane_blocks"], prm.panes.blocks.size());
  EXPECT_EQ(e["memory"]["file_bytes"], fs::file_size(dir / "prm_panes.bin"));
  EXPECT_FALSE(e.contains("lights_hash")) << "the PRM does not depend on the lights";
}

TEST(PrmIo, SavingKeepsOtherMethodsEntries) {
  const fs::path dir = scratch_dir("other_methods");
  fs::create_directories(dir);
  ASSERT_TRUE(gi::update_manifest_method(dir, gi::scene_geometry_hash(gi::bake_input_from(cornell())),
                                         "cornell_box.gltf", "light_atlas", nlohmann::json{{"marker", 7}})
                  .ok());
  ASSERT_TRUE(gi::save_prm(dir, fake_prm(), gi::bake_input_from(cornell())).ok());
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->methods["light_atlas"]["marker"], 7);
  EXPECT_TRUE(m->methods.contains("prm"));
}

TEST(PrmIo, CompressionShrinksSmoothPanes) {
  // Sixteen smooth panes over a denser atlas, as a bake's panes are smooth.
  gi::Prm prm = fake_prm(8.0f);
  prm.cluster_count = 16;
  prm.cluster_size.assign(16, 0);
  for (std::size_t k = 0; k < prm.entries.size(); ++k) {
    prm.entries[k].cluster = static_cast<std::uint32_t>(k);
    ++prm.cluster_size[k];
  }
  const std::size_t n = prm.texels.size();
  std::vector<float> panes(16 * n * 3, 0.0f);
  for (std::size_t c = 0; c < 16; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      const auto x = static_cast<double>(prm.texels[i] % static_cast<std::uint32_t>(prm.width));
      const auto y = static_cast<double>(prm.texels[i] / static_cast<std::uint32_t>(prm.width));
      const double dx = x - 2.0 * static_cast<double>(c), dy = y - 3.0 * static_cast<double>(c);
      for (std::size_t ch = 0; ch < 3; ++ch)
        panes[(c * n + i) * 3 + ch] =
            static_cast<float>((1.0 + 0.2 * static_cast<double>(ch)) * 50.0 / (10.0 + dx * dx + dy * dy));
    }
  gi::set_dense_panes(prm, panes);
  const fs::path dir = saved_bundle("compression", prm);
  const std::uintmax_t file_bytes = fs::file_size(dir / "prm_panes.bin");
  const std::size_t half_bytes = prm.panes.values.size() * 2;
  std::printf("%zu panes x %zu texels: halves %zu bytes, file %ju bytes (ratio %.2f; float32 would be %zu bytes)\n",
              std::size_t{16}, n, half_bytes, file_bytes,
              static_cast<double>(half_bytes) / static_cast<double>(file_bytes), prm.panes.values.size() * 4);
  EXPECT_LT(file_bytes, half_bytes);
  auto back = gi::load_prm(dir, gi::bake_input_from(cornell()));
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_LE(pane_error(prm, *back).worst_of_bound, 1.0);

  // The round-trip data set's ratio, for the record.
  const gi::Prm fake = fake_prm();
  const fs::path d2 = saved_bundle("compression_fake", fake);
  std::printf(
      "fake_prm: halves %zu bytes, file %ju bytes (ratio %.2f)\n", fake.panes.values.size() * 2,
      fs::file_size(d2 / "prm_panes.bin"),
      static_cast<double>(fake.panes.values.size() * 2) / static_cast<double>(fs::file_size(d2 / "prm_panes.bin")));
}

TEST(PrmIo, StaleBundleIsRejectedWithBothHashes) {
  const fs::path dir = saved_bundle("stale");
  engine::SceneAsset changed = cornell();
  changed.meshes[1].primitives[0].positions[0].x += 0.02f;
  auto r = gi::load_prm(dir, gi::bake_input_from(changed));
  ASSERT_FALSE(r.ok());
  const std::string message = r.error().to_string();
  EXPECT_NE(message.find("stale"), std::string::npos) << message;
  EXPECT_NE(message.find(gi::scene_geometry_hash(gi::bake_input_from(cornell()))), std::string::npos) << message;
  EXPECT_NE(message.find(gi::scene_geometry_hash(gi::bake_input_from(changed))), std::string::npos) << message;
  EXPECT_NE(message.find("manifest.json"), std::string::npos) << message;
}

TEST(PrmIo, EditedLightsDoNotMakeThePrmStale) {
  const fs::path dir = saved_bundle("lights");
  engine::SceneAsset relit = cornell();
  ASSERT_FALSE(relit.lights.empty());
  relit.lights[0].light.intensity *= 3.0f;
  auto r = gi::load_prm(dir, gi::bake_input_from(relit));
  EXPECT_TRUE(r.ok()) << r.error().to_string();
}

TEST(PrmIo, MissingOrDamagedFilesAreRejected) {
  {
    const fs::path dir = saved_bundle("missing_panes");
    fs::remove(dir / "prm_panes.bin");
    expect_load_error(dir, "prm_panes.bin", "not found");
  }
  {
    const fs::path dir = saved_bundle("bit_flip");
    auto b = read_all(dir / "prm_panes.bin");
    b[b.size() / 2] ^= std::byte{0x04};
    write_all(dir / "prm_panes.bin", b);
    expect_load_error(dir, "prm_panes.bin", "checksum mismatch");
    resign(dir);  // the container's own checksum still catches it
    expect_load_error(dir, "prm_panes.bin", "checksum mismatch: the payload is corrupt");
  }
  {
    const fs::path dir = saved_bundle("truncated");
    auto b = read_all(dir / "prm_panes.bin");
    b.resize(b.size() - 9);
    write_all(dir / "prm_panes.bin", b);
    expect_load_error(dir, "prm_panes.bin", "checksum mismatch");
    resign(dir);
    expect_load_error(dir, "prm_panes.bin", "(truncated)");
  }
  {
    const fs::path dir = saved_bundle("wrong_magic");
    auto b = read_all(dir / "prm_panes.bin");
    std::memcpy(b.data(), "GIVPLSET", 8);
    write_all(dir / "prm_panes.bin", b);
    resign(dir);
    expect_load_error(dir, "prm_panes.bin", "wrong magic \"GIVPLSET\", expected \"GIPRMPAN\"");
  }
  {
    const fs::path dir = saved_bundle("wrong_version");
    auto b = read_all(dir / "prm_panes.bin");
    b[8] = std::byte{1};  // version 1 stored the thread count
    write_all(dir / "prm_panes.bin", b);
    resign(dir);
    expect_load_error(dir, "prm_panes.bin", "unsupported version 1, this build reads 4");
    b[8] = std::byte{2};  // version 2 stored dense panes (before the blocks of issue 38)
    write_all(dir / "prm_panes.bin", b);
    resign(dir);
    expect_load_error(dir, "prm_panes.bin", "unsupported version 2, this build reads 4");
    b[8] = std::byte{3};  // version 3 had no pane density (panes always at the atlas's)
    write_all(dir / "prm_panes.bin", b);
    resign(dir);
    expect_load_error(dir, "prm_panes.bin", "unsupported version 3, this build reads 4");
  }
  {
    const fs::path dir = saved_bundle("no_manifest");
    fs::remove(dir / "manifest.json");
    expect_load_error(dir, "manifest.json", "not found");
  }
  {
    const fs::path dir = saved_bundle("no_entry");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods.erase("prm");
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "no \"prm\" entry");
  }
  {
    const fs::path dir = saved_bundle("missing_field");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["prm"]["layout"].erase("padding_texels");
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "methods.prm.layout.padding_texels: missing field");
  }
  {
    const fs::path dir = saved_bundle("escaping_name");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["prm"]["files"]["panes"]["file"] = "../prm_panes.bin";
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "not a file name inside the bundle");
  }
  {
    const fs::path dir = saved_bundle("wrong_layout");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["prm"]["layout"]["requested_texels_per_metre"] = 6.0;
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "prm_layout.bin", "differs from the one the manifest describes");
  }
  {
    const fs::path dir = saved_bundle("wrong_counts");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["prm"]["clusters"] = 5;
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "the manifest describes");
  }
}

// Payloads that pass the container's checks but hold wrong content.
TEST(PrmIo, InconsistentPayloadsAreRejected) {
  {
    const fs::path dir = saved_bundle("cluster_count");
    auto p = payload_of(dir);
    poke(p, kClusterCountOffset, std::int32_t{1 << 30});
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "outside 1..65536");
    poke(p, kClusterCountOffset, std::int32_t{3});
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "elements for 3 clusters");
  }
  {
    const fs::path dir = saved_bundle("texel_order");
    auto p = payload_of(dir);
    std::uint32_t t0 = 0, t1 = 0;
    std::memcpy(&t0, p.data() + kTexelsOffset + 8, 4);
    std::memcpy(&t1, p.data() + kTexelsOffset + 12, 4);
    poke(p, kTexelsOffset + 8, t1);
    poke(p, kTexelsOffset + 12, t0);
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "not strictly ascending");
    poke(p, kTexelsOffset + 8, t0);
    poke(p, kTexelsOffset + 12, std::uint32_t{1u << 30});
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "outside the");
  }
  {
    const fs::path dir = saved_bundle("trailing");
    auto p = payload_of(dir);
    p.push_back(std::byte{0});
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "unexpected data after the last field");
    p.resize(p.size() - 40);
    put_payload(dir, p);
    expect_load_error(dir, "prm_panes.bin", "truncated payload");
  }
  {
    // A valid zstd frame whose halves hold a NaN and then a negative value.
    const gi::Prm prm = fake_prm();
    const fs::path dir = saved_bundle("nan_half", prm);
    const auto p = payload_of(dir);
    const std::size_t half_bytes = prm.panes.values.size() * 2;
    // The frame is the last field (uint64 size, then the frame): find where it starts.
    std::size_t frame_size = 0;
    for (std::size_t start = p.size() - 8; start > 0; --start) {
      std::uint64_t size = 0;
      std::memcpy(&size, p.data() + start - 8, 8);
      if (start + size == p.size() &&
          ZSTD_getFrameContentSize(p.data() + start, static_cast<std::size_t>(size)) == half_bytes) {
        frame_size = static_cast<std::size_t>(size);
        break;
      }
    }
    ASSERT_GT(frame_size, 0u);
    const std::size_t start = p.size() - frame_size;
    std::vector<std::byte> planes(half_bytes);
    ASSERT_EQ(ZSTD_decompress(planes.data(), planes.size(), p.data() + start, frame_size), half_bytes);
    for (std::uint16_t bad : {std::uint16_t{0x7e00}, std::uint16_t{0x8400}}) {  // NaN, -2^-14
      std::vector<std::byte> edited = planes;
      edited[5] = static_cast<std::byte>(bad & 0xff);
      edited[prm.panes.values.size() + 5] = static_cast<std::byte>(bad >> 8);
      std::vector<std::byte> frame(ZSTD_compressBound(half_bytes));
      const std::size_t packed = ZSTD_compress(frame.data(), frame.size(), edited.data(), edited.size(), 3);
      ASSERT_EQ(ZSTD_isError(packed), 0u);
      std::vector<std::byte> q(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(start) - 8);
      engine::ByteWriter w;
      w.put(static_cast<std::uint64_t>(packed));
      q.insert(q.end(), w.bytes().begin(), w.bytes().end());
      q.insert(q.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(packed));
      put_payload(dir, q);
      expect_load_error(dir, "prm_panes.bin", "negative, infinite or NaN");
    }
    // A corrupt frame whose size still reads.
    std::vector<std::byte> q = p;
    q[start + frame_size / 2] ^= std::byte{0xff};
    put_payload(dir, q);
    expect_load_error(dir, "prm_panes.bin", "panes");
  }
}

// Random damage to the payload, re-wrapped with valid checksums so every check behind them
// is exercised: never a crash, and whatever loads is a consistent PRM.
TEST(PrmIo, RandomByteFlipsNeverCrash) {
  const fs::path dir = saved_bundle("fuzz");
  const std::vector<std::byte> payload = payload_of(dir);
  std::mt19937 rng(12345);
  int rejected = 0, loaded = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::byte> p = payload;
    const int flips = 1 + trial % 4;
    for (int k = 0; k < flips; ++k) {
      const std::size_t at = rng() % p.size();
      p[at] ^= static_cast<std::byte>(1u << (rng() % 8));
    }
    put_payload(dir, p);
    auto r = gi::load_prm(dir, gi::bake_input_from(cornell()));
    if (r.ok()) {
      ++loaded;
      EXPECT_EQ(r->panes.cluster_count(), static_cast<std::size_t>(r->cluster_count));
      EXPECT_EQ(r->panes.tiles.elements.size(), r->texels.size());
    } else {
      ++rejected;
      EXPECT_NE(r.error().to_string().find("prm_panes.bin"), std::string::npos) << r.error().to_string();
    }
  }
  std::printf("random flips: %d rejected, %d loaded (flips in values that stay valid)\n", rejected, loaded);
  EXPECT_GT(rejected, 100);
}

TEST(PrmIo, InvalidPrmRefusesToSaveAndWritesNothing) {
  const auto expect_refused = [](gi::Prm prm, const std::string& what) {
    const fs::path dir = scratch_dir("refused");
    auto s = gi::save_prm(dir, prm, gi::bake_input_from(cornell()));
    ASSERT_FALSE(s.ok()) << what;
    expect_error(s.error(), "prm_panes.bin", what);
    EXPECT_FALSE(fs::exists(dir)) << "nothing written";
    // Over an existing bundle: the saved files stay as they were.
    const fs::path existing = saved_bundle("refused_existing");
    const auto before = read_all(existing / "prm_panes.bin");
    const auto manifest_before = read_all(existing / "manifest.json");
    ASSERT_FALSE(gi::save_prm(existing, prm, gi::bake_input_from(cornell())).ok());
    EXPECT_EQ(read_all(existing / "prm_panes.bin"), before);
    EXPECT_EQ(read_all(existing / "manifest.json"), manifest_before);
    EXPECT_TRUE(gi::load_prm(existing, gi::bake_input_from(cornell())).ok());
  };
  gi::Prm p = fake_prm();
  p.panes.values[17] = std::numeric_limits<float>::quiet_NaN();
  expect_refused(p, "NaN");
  p = fake_prm();
  p.panes.values[4] = -1e-3f;
  expect_refused(p, "negative");
  p = fake_prm();
  p.panes.values.back() = std::numeric_limits<float>::infinity();
  expect_refused(p, "infinite");
  p = fake_prm();
  p.panes.values.pop_back();
  expect_refused(p, "panes hold");
  p = fake_prm();
  std::swap(p.texels[3], p.texels[4]);
  expect_refused(p, "not strictly ascending");
  p = fake_prm();
  p.entries[2].cluster = 9;
  expect_refused(p, "cluster 9");
  p = fake_prm();
  p.cluster_size[0] = 5;
  expect_refused(p, "cluster_size[0]");
  p = fake_prm();
  p.settings.splitting = std::numeric_limits<float>::quiet_NaN();
  expect_refused(p, "settings out of range");
  p = fake_prm();
  p.width += 1;
  expect_refused(p, "differs from its layout");
}
