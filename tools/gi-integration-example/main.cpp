// docs/integration.md as a program: GI for a scene from assets/ in a game's frame loop.
//   ./build/tools/gi-integration-example/gi-integration-example assets/crates_room.gltf out/crates_room.gibake
//   out/example
// Bakes the bundle through the bake API when it is not there yet (gi-bake does the same from
// the command line), renders 60 frames headless while the red crate slides next to the
// statue, writes every 20th as PNG, and prints the GI system's counters (what it recomputed
// and what it skipped). ctest runs it (IntegrationExample.*).
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

// Long because it is docs/integration.md's six numbered steps as one program, read top to
// bottom beside that page; split into functions, the example would hide the order a game
// must keep (the GI system before the renderer, reset before the GL context goes).
int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: gi-integration-example SCENE.gltf BUNDLE.gibake OUT_DIR\n";
    return 2;
  }
  // 1. The scene, as the game loads it.
  auto asset = engine::load_gltf(argv[1]);
  if (!asset) {
    std::cerr << asset.error().to_string() << '\n';
    return 1;
  }
  engine::Scene scene = engine::instantiate(std::move(asset).value());

  // 2. A GL context (here headless; a game has its window's).
  auto gpu = engine::GpuContext::create_headless();
  if (!gpu) {
    std::cerr << gpu.error().to_string() << '\n';
    return 1;
  }

  // 3. The bake, once per level edit (a pipeline or gi-bake does it offline): what the plan
  //    calls for, at the preview preset. The input is plain data; a studio's pipeline can
  //    fill gi::BakeInput from its own scene format instead.
  const auto log = [](gi::LogLevel level, std::string_view line) {
    std::cerr << gi::log_level_name(level) << ": " << line << '\n';
  };
  if (!std::filesystem::exists(argv[2])) {
    auto report = gi::bake_bundle(gi::bake_input_from(scene), argv[2], {.preset = "preview"}, {.log = log});
    if (!report) {
      std::cerr << report.error().to_string() << '\n';
      return 1;
    }
    for (const gi::BakedMethod& m : report->baked) std::cout << "baked " << m.method << " in " << m.seconds << " s\n";
  }

  // 4. The GI system from the bundle, BEFORE the renderer: it gives the static meshes their
  //    light-atlas UVs. A bundle of other geometry is refused with a message.
  auto gi = gi::GISystem::load(argv[2], scene, {.log = log});
  if (!gi) {
    std::cerr << gi.error().to_string() << '\n';
    return 1;
  }
  std::cout << (*gi)->label() << '\n' << (*gi)->describe();

  // 5. The renderer, with the GI system as its indirect light and automatic exposure
  //    (metered from each frame on the GPU, docs/exposure.md; ExposureMode::FixedLinear or
  //    FixedEv100 fix it).
  auto renderer = engine::Renderer::create(
      scene.assets,
      engine::RenderSettings{.width = 640, .height = 360, .exposure_mode = engine::ExposureMode::Automatic});
  if (!renderer) {
    std::cerr << renderer.error().to_string() << '\n';
    return 1;
  }
  (*renderer)->set_indirect_light(gi->get());

  // 6. The frame loop: gameplay moves things, then render. GISystem::frame() runs inside
  //    render() and recomputes only what changed since the last frame.
  const std::filesystem::path out = argv[3];
  std::filesystem::create_directories(out);
  const engine::Entity crate = engine::find_by_name(scene.registry, "crate_red");
  const engine::Entity camera = engine::find_camera(scene.registry);
  for (int frame = 0; frame < 60; ++frame) {
    if (!crate.is_null() && frame >= 20 && frame < 40) {  // slide it next to the statue, then hold
      scene.registry.write<engine::Transform>(crate).position += glm::vec3(-0.065f, 0.0f, 0.09f);
      engine::update_world_transforms(scene.registry);
    }
    (*renderer)->render(scene.registry, camera, 1.0 / 60.0);  // the game's time step drives the exposure's adaptation
    if (frame % 20 == 19) {
      char name[64];
      std::snprintf(name, sizeof name, "frame_%02d.png", frame);
      if (auto saved = engine::save_png(out / name, (*renderer)->read_ldr()); !saved) {
        std::cerr << saved.error().to_string() << '\n';
        return 1;
      }
    }
  }
  std::printf("exposure: automatic, EV100 %.2f at the last frame\n", double{(*renderer)->read_exposure().ev100});
  const gi::GISystem::Stats& st = (*gi)->stats();
  std::printf(
      "%llu frames: %llu with nothing to recompute, %llu BRF updates (%llu with motion), %llu atlas composites\n",
      static_cast<unsigned long long>(st.frames), static_cast<unsigned long long>(st.idle_frames),
      static_cast<unsigned long long>(st.brf_updates), static_cast<unsigned long long>(st.brf_moves),
      static_cast<unsigned long long>(st.world_composites));
  for (const std::string& off : st.disabled) std::printf("turned off: %s\n", off.c_str());
  gi->reset();  // before the GL context goes
  return 0;
}
