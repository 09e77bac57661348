// GLB packing and temp-file-then-rename output for the glTF writer.
#include "gltf/gltf_file_output.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace engine::gltf {
namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

std::filesystem::path temp_path(const std::filesystem::path& path) {
  std::filesystem::path t = path;
  t += ".tmp";
  return t;
}

bool write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes, std::string& why) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    why = std::string("cannot open for writing: ") + std::strerror(errno);
    return false;
  }
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) {
    why = "write failed (disk full?)";
    return false;
  }
  return true;
}

}  // namespace

std::vector<std::uint8_t> make_glb(const std::string& json_text, const std::vector<std::uint8_t>& bin) {
  std::string json_chunk = json_text;
  while (json_chunk.size() % 4 != 0) json_chunk.push_back(' ');
  std::vector<std::uint8_t> bin_chunk = bin;
  while (bin_chunk.size() % 4 != 0) bin_chunk.push_back(0);
  const std::size_t total = 12 + 8 + json_chunk.size() + (bin_chunk.empty() ? 0 : 8 + bin_chunk.size());
  std::vector<std::uint8_t> out;
  out.reserve(total);
  put_u32(out, 0x46546C67u);  // "glTF"
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(total));
  put_u32(out, static_cast<std::uint32_t>(json_chunk.size()));
  put_u32(out, 0x4E4F534Au);  // "JSON"
  out.insert(out.end(), json_chunk.begin(), json_chunk.end());
  if (!bin_chunk.empty()) {
    put_u32(out, static_cast<std::uint32_t>(bin_chunk.size()));
    put_u32(out, 0x004E4942u);  // "BIN\0"
    out.insert(out.end(), bin_chunk.begin(), bin_chunk.end());
  }
  return out;
}

Status write_files_atomically(const std::vector<OutputFile>& files) {
  std::error_code ec;
  auto remove_temps = [&](std::size_t upto) {
    for (std::size_t i = 0; i < upto; ++i) std::filesystem::remove(temp_path(files[i].path), ec);
  };
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::string why;
    if (!write_bytes(temp_path(files[i].path), files[i].bytes, why)) {
      remove_temps(i + 1);
      return Error{files[i].path.string(), "", why};
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::filesystem::rename(temp_path(files[i].path), files[i].path, ec);
    if (ec) {
      const std::string why = "cannot rename temporary file: " + ec.message();
      // Take back the files already renamed so nothing half-written remains.
      for (std::size_t k = 0; k < i; ++k) std::filesystem::remove(files[k].path, ec);
      for (std::size_t k = i; k < files.size(); ++k) std::filesystem::remove(temp_path(files[k].path), ec);
      return Error{files[i].path.string(), "", why};
    }
  }
  return {};
}

}  // namespace engine::gltf
