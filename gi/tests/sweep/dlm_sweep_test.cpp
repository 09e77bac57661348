// The dlm sweep method (gi/src/sweep/dlm_sweep.h) run end to end through gi::run_sweep.
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

// The dlm method end to end on the glossy room (a coarse reference, 128 lobe samples per
// texel): every run valid, and the directional light maps beat the direction-less atlas term
// (E/pi x specular albedo) on the specular indirect light they add (docs/dlm.md, measured
// with 1024 samples: 0.46 against 0.66 at 32 directions x 1 M photons).
TEST(DlmSweep, GlossyRoomBeatsTheDirectionlessAtlasTerm) {
  TempDir dir("dlm");
  gi::SweepRequest request;
  request.method = "dlm";
  request.scene = fs::path(GI_SOURCE_DIR) / "assets" / "glossy_room.gltf";
  request.knobs = {"directions=32", "kphotons=300", "ref_spp=128"};
  request.out_dir = dir.path();
  auto report = gi::run_sweep(request);
  ASSERT_TRUE(report) << report.error().to_string();
  ASSERT_EQ(report->runs, 1u);
  EXPECT_TRUE(report->failures.empty());
  auto rows = sweeptest::read_rows(report->csv);
  ASSERT_TRUE(rows) << rows.error().to_string();
  ASSERT_EQ(rows->size(), 1u);
  const gi::SweepRow& row = rows->front();
  ASSERT_TRUE(row.ok()) << row.status;
  double atlas = std::numeric_limits<double>::quiet_NaN(), exact_lookup = atlas;
  for (const auto& [name, value] : row.extras) {
    if (name == "atlas_rel_rmse") atlas = value;
    if (name == "lookup4096_truth_rel_rmse") exact_lookup = value;  // the same bins, the lobe integrated over them
  }
  EXPECT_TRUE(std::isfinite(exact_lookup));
  std::printf("dlm on the glossy room: rel RMSE %.3f, direction-less atlas term %.3f\n", row.error.rel_rmse, atlas);
  EXPECT_TRUE(std::isfinite(row.error.rel_rmse));
  EXPECT_LT(row.error.rel_rmse, 0.6);
  EXPECT_LT(row.error.rel_rmse, 0.85 * atlas);
}

}  // namespace
