// PNG through stb_image / stb_image_write and OpenEXR through tinyexr. The stb
// implementations are compiled in gltf/tinygltf_impl.cpp; tinyexr is a shared library.
#include <engine/image.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <system_error>

#include <unistd.h>

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

namespace engine {

namespace {

namespace fs = std::filesystem;

fs::path temporary_path_for(const fs::path& path) {
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(static_cast<long>(::getpid()));
  return tmp;
}

// Moves the finished temporary file over `path`; removes it on failure.
Status commit_temporary(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Error{path.string(), "", "cannot rename the temporary file into place: " + ec.message()};
  }
  return {};
}

Status check_parent_exists(const fs::path& path) {
  const fs::path parent = path.parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec))
    return Error{path.string(), "", "directory " + parent.string() + " does not exist"};
  return {};
}

}  // namespace

Status save_png(const fs::path& path, const ImageRgba8& image) {
  GI_EXPECTS(image.width > 0 && image.height > 0, "image must not be empty");
  GI_EXPECTS(image.pixels.size() == static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4,
             "pixels must hold width*height*4 bytes");
  if (Status s = check_parent_exists(path); !s) return s;
  const fs::path tmp = temporary_path_for(path);
  const int ok = stbi_write_png(tmp.c_str(), image.width, image.height, 4, image.pixels.data(), image.width * 4);
  if (ok == 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    return Error{path.string(), "", std::string("cannot write PNG: ") + std::strerror(errno)};
  }
  return commit_temporary(tmp, path);
}

Result<ImageRgba8> load_png(const fs::path& path) {
  int w = 0;
  int h = 0;
  int channels = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
  if (data == nullptr) {
    const char* reason = stbi_failure_reason();
    return Error{path.string(), "", std::string("cannot read PNG: ") + (reason ? reason : "unknown error")};
  }
  ImageRgba8 image;
  image.width = w;
  image.height = h;
  image.pixels.assign(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  stbi_image_free(data);
  return image;
}

Status save_exr(const fs::path& path, const ImageRgbaF& image, ExrPixelType type) {
  GI_EXPECTS(image.width > 0 && image.height > 0, "image must not be empty");
  GI_EXPECTS(image.pixels.size() == static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4,
             "pixels must hold width*height*4 floats");
  if (Status s = check_parent_exists(path); !s) return s;
  const fs::path tmp = temporary_path_for(path);
  const char* err = nullptr;
  const int ret = SaveEXR(image.pixels.data(), image.width, image.height, 4,
                          /*save_as_fp16=*/type == ExrPixelType::Half ? 1 : 0, tmp.c_str(), &err);
  if (ret != TINYEXR_SUCCESS) {
    std::string message = std::string("cannot write EXR: ") + (err ? err : "error " + std::to_string(ret));
    if (err) FreeEXRErrorMessage(err);
    std::error_code ec;
    fs::remove(tmp, ec);
    return Error{path.string(), "", message};
  }
  return commit_temporary(tmp, path);
}

Result<ImageRgbaF> load_exr(const fs::path& path) {
  float* rgba = nullptr;
  int w = 0;
  int h = 0;
  const char* err = nullptr;
  const int ret = LoadEXR(&rgba, &w, &h, path.c_str(), &err);
  if (ret != TINYEXR_SUCCESS) {
    std::string message = std::string("cannot read EXR: ") + (err ? err : "error " + std::to_string(ret));
    if (err) FreeEXRErrorMessage(err);
    return Error{path.string(), "", message};
  }
  ImageRgbaF image;
  image.width = w;
  image.height = h;
  image.pixels.assign(rgba, rgba + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  std::free(rgba);
  return image;
}

}  // namespace engine
