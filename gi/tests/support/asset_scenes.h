#pragma once
// A scene of the project's assets/ folder, loaded and instantiated for a test; a load error
// fails the test with the loader's message.
//   engine::Scene scene = gitest::asset_scene("corridor.gltf");

#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>

#include <string>
#include <utility>

namespace gitest {

inline engine::Scene asset_scene(const std::string& file) {
  auto asset = engine::load_gltf(std::string(GI_SOURCE_DIR "/assets/") + file);
  EXPECT_TRUE(asset) << asset.error().to_string();
  return engine::instantiate(std::move(asset).value());
}

}  // namespace gitest
