// The reflection probes sweep method (gi/src/sweep/reflection_probes_sweep.h) run end to end
// through gi::run_sweep.
#include <gtest/gtest.h>
#include <gi/sweep.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include "sweep/sweep_csv.h"
#include "sweep_fixtures.h"

namespace fs = std::filesystem;

namespace {

using sweeptest::TempDir;

double extra(const gi::SweepRow& row, const std::string& name) {
  for (const auto& [n, v] : row.extras)
    if (n == name) return v;
  return std::numeric_limits<double>::quiet_NaN();
}

// The reflection probes end to end on the glossy room at roughness 0.2 (32^2 faces, a coarse
// 128-sample reference): inside the probe's box and at its borders the error against the path
// tracer's noise-free truth stays under the targets with a margin for the coarse
// reference (docs/reflection_probes.md, "Accuracy": 0.24 / 0.25 measured with 1024 samples).
TEST(ReflectionProbesSweep, GlossyRoomReflectionsFollowThePathTracer) {
  TempDir dir("reflection_probes");
  gi::SweepRequest request;
  request.method = "reflection_probes";
  request.scene = fs::path(GI_SOURCE_DIR) / "assets" / "glossy_room.gltf";
  request.knobs = {"resolution=32", "roughness=0.2", "ref_spp=128"};
  request.out_dir = dir.path();
  request.threads = 2;
  auto report = gi::run_sweep(request);
  ASSERT_TRUE(report) << report.error().to_string();
  ASSERT_EQ(report->runs, 1u);
  auto rows = sweeptest::read_rows(report->csv);
  ASSERT_TRUE(rows) << rows.error().to_string();
  ASSERT_EQ(rows->size(), 1u);
  const gi::SweepRow& row = rows->front();
  ASSERT_TRUE(row.ok()) << row.status;
  const double volume = extra(row, "volume_truth_rel_rmse"), border = extra(row, "border_truth_rel_rmse");
  std::printf("reflection probes on the glossy room: volume %.3f, border %.3f\n", volume, border);
  EXPECT_LT(volume, 0.35);
  EXPECT_LT(border, 0.4);
  EXPECT_EQ(extra(row, "uncovered_texels"), 0.0);
  EXPECT_LT(std::abs(extra(row, "bias_cos0.3_0.6")), 0.15);
}

}  // namespace
