#pragma once
// Output side of the glTF writer: the GLB container and all-or-nothing file writing.
//   std::vector<engine::gltf::OutputFile> files{{"a.bin", bytes}, {"a.gltf", json_bytes}};
//   engine::Status s = engine::gltf::write_files_atomically(files);

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <engine/result.h>

namespace engine::gltf {

struct OutputFile {
  std::filesystem::path path;
  std::vector<std::uint8_t> bytes;
};

/// A GLB 2.0 container: header, JSON chunk (space-padded), BIN chunk (zero-padded, omitted
/// when `bin` is empty).
std::vector<std::uint8_t> make_glb(const std::string& json_text, const std::vector<std::uint8_t>& bin);

/// Writes every file to "<path>.tmp" first and renames them all only when every write
/// succeeded; on failure removes what it wrote and returns an Error naming the path.
Status write_files_atomically(const std::vector<OutputFile>& files);

}  // namespace engine::gltf
