// The installed gi module as a game uses it: load a scene, bake its bundle through the public
// bake API when there is none, load the bundle into the GI system, render one frame headless,
// print the GI stats. Usage: consumer SCENE.gltf BUNDLE.gibake
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/gi_system.h>
#include <gi/version.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) return std::fprintf(stderr, "usage: consumer SCENE.gltf BUNDLE.gibake\n"), 2;
  const auto fail = [](const engine::Error& e) { return std::cerr << e.to_string() << '\n', 1; };
  auto asset = engine::load_gltf(argv[1]);
  if (!asset) return fail(asset.error());
  engine::Scene scene = engine::instantiate(std::move(asset).value());
  auto gpu = engine::GpuContext::create_headless();
  if (!gpu) return fail(gpu.error());
  if (!std::filesystem::exists(argv[2]))
    if (auto baked = gi::bake_bundle(gi::bake_input_from(scene), argv[2], {.preset = "preview"}); !baked)
      return fail(baked.error());
  auto gi = gi::GISystem::load(argv[2], scene);  // before the renderer: it gives the meshes their atlas UVs
  if (!gi) return fail(gi.error());
  auto renderer = engine::Renderer::create(scene.assets, {.width = 320, .height = 240});
  if (!renderer) return fail(renderer.error());
  (*renderer)->set_indirect_light(gi->get());
  (*renderer)->render(scene.registry, engine::find_camera(scene.registry));
  const gi::GISystem::Stats& st = (*gi)->stats();
  std::printf("gi %s: %s, %llu frame(s), %llu idle, %zu disabled\n%s", gi::kVersion, (*gi)->label(),
              static_cast<unsigned long long>(st.frames), static_cast<unsigned long long>(st.idle_frames),
              st.disabled.size(), (*gi)->describe().c_str());
  gi->reset();  // before the GL context goes
  return st.frames == 1 && st.disabled.empty() ? 0 : 1;
}
