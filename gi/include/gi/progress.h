#pragma once
// Progress and cancellation of long work (bakes, reference renders, sweeps): the work calls
// the callback with the fraction done; the callback returns false to cancel.
//   gi::ProgressCallback cb = [](double done) { draw_bar(done); return !user_pressed_escape(); };
//   auto image = gi::render_reference_image(scene, camera, {.progress = cb});

#include <functional>
#include <string_view>

namespace gi {

/// Called with the fraction of work done, in [0, 1], from the thread that started the work
/// (never concurrently). Return false to cancel: the work stops soon and reports it.
using ProgressCallback = std::function<bool(double fraction_done)>;

/// Progress of work made of named stages (a bake: "light atlas", "PRM", "BRF crate"): the
/// stage and the fraction of it done, in [0, 1]; same contract as ProgressCallback.
using StageProgressCallback = std::function<bool(std::string_view stage, double fraction_done)>;

}  // namespace gi
