// PNG through stb_image / stb_image_write and OpenEXR through tinyexr. The stb
// implementations are compiled in gltf/tinygltf_impl.cpp; tinyexr is a shared library.
#include <engine/image.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

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

// Reads a NUL-terminated name of at most 255 characters at bytes[at] (advancing `at`), or
// returns false when none ends in time.
bool read_exr_name(const std::vector<unsigned char>& bytes, std::size_t& at, std::string& name) {
  name.clear();
  while (at < bytes.size() && bytes[at] != 0) {
    if (name.size() == 255) return false;
    name.push_back(static_cast<char>(bytes[at++]));
  }
  if (at >= bytes.size()) return false;
  ++at;
  return true;
}

std::int32_t read_exr_int(const std::vector<unsigned char>& bytes, std::size_t at) {
  const std::uint32_t u = std::uint32_t{bytes[at]} | std::uint32_t{bytes[at + 1]} << 8 |
                          std::uint32_t{bytes[at + 2]} << 16 | std::uint32_t{bytes[at + 3]} << 24;
  return static_cast<std::int32_t>(u);
}

// What is wrong with a channel list's data (OpenEXR "chlist"): 1-4 channels of HALF or FLOAT
// samples, one per pixel. Empty when it is one the project reads.
std::string exr_channel_list_problem(const std::vector<unsigned char>& bytes, std::size_t at, std::size_t end) {
  const std::vector<unsigned char> list(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                                        bytes.begin() + static_cast<std::ptrdiff_t>(end));
  std::size_t k = 0;
  int channels = 0;
  std::string name;
  while (k < list.size() && list[k] != 0) {
    if (!read_exr_name(list, k, name) || k + 16 > list.size()) return "a channel list that ends inside a channel";
    const std::int32_t type = read_exr_int(list, k);
    if (type != 1 && type != 2)
      return "channel '" + name + "' of pixel type " + std::to_string(type) + " (half or float expected)";
    if (read_exr_int(list, k + 8) != 1 || read_exr_int(list, k + 12) != 1)
      return "channel '" + name + "' is subsampled (one sample per pixel expected)";
    k += 16;
    if (++channels > 4) return "more than 4 channels";
  }
  if (k >= list.size()) return "a channel list without its end";
  if (channels == 0) return "no channels";
  return {};
}

// Empty when a data window of width x height is within the reader's limits, else what is wrong.
std::string exr_window_problem(std::int64_t width, std::int64_t height) {
  if (width >= 1 && height >= 1 && width <= kMaxExrSide && height <= kMaxExrSide && width * height <= kMaxExrPixels)
    return {};
  return "data window " + std::to_string(width) + " x " + std::to_string(height) + " outside 1.." +
         std::to_string(kMaxExrSide) + " per side and " + std::to_string(kMaxExrPixels) + " pixels";
}

// Debian's tinyexr 1.0.1 asserts (aborts) on header values it does not expect (a "type" other
// than the four it knows, a pixel type or compression it cannot decode; found by the fuzz leg,
// tests/fuzz/regressions/exr/tinyexr_asserts_on_unknown_type*.exr), so the attributes are read
// here first and only what the project writes passes: one scanline part of 1-4 half or float
// channels, uncompressed or ZIP, its data window within the limits. Empty when the header is
// one of those, else its first problem (the window's before the others').
std::string exr_header_problem(const std::vector<unsigned char>& bytes) {
  std::size_t at = 8;  // after the magic number and the version field
  std::string name, type, window, part, compression, channels;
  bool listed = false;
  // Each problem is kept once found: an attribute repeated later (a second "type", empty)
  // must not clear what tinyexr may still act on.
  const auto note = [](std::string& slot, std::string problem) {
    if (slot.empty()) slot = std::move(problem);
  };
  for (;;) {
    if (at >= bytes.size()) return "the header ends before its attributes do";
    if (bytes[at] == 0) break;
    if (!read_exr_name(bytes, at, name) || !read_exr_name(bytes, at, type) || at + 4 > bytes.size())
      return "the header ends inside an attribute";
    const std::int32_t size = read_exr_int(bytes, at);
    at += 4;
    if (size < 0 || static_cast<std::size_t>(size) > bytes.size() - at)
      return "attribute '" + name + "' of " + std::to_string(size) + " bytes runs past the file's end";
    const std::size_t data = at, end = at + static_cast<std::size_t>(size);
    at = end;
    if (name == "dataWindow" && size == 16) {
      const std::int64_t min_x = read_exr_int(bytes, data), min_y = read_exr_int(bytes, data + 4);
      note(window, exr_window_problem(std::int64_t{read_exr_int(bytes, data + 8)} - min_x + 1,
                                      std::int64_t{read_exr_int(bytes, data + 12)} - min_y + 1));
    } else if (name == "type") {
      // tinyexr reads the value up to its first NUL; an empty one it ignores.
      const std::string value(bytes.begin() + static_cast<std::ptrdiff_t>(data),
                              std::find(bytes.begin() + static_cast<std::ptrdiff_t>(data),
                                        bytes.begin() + static_cast<std::ptrdiff_t>(end), 0));
      if (!value.empty() && value != "scanlineimage")
        note(part, "part type '" + value.substr(0, 64) + "' (scanlineimage expected)");
    } else if (name == "compression") {
      const unsigned c = size == 1 ? bytes[data] : 255u;
      if (c != TINYEXR_COMPRESSIONTYPE_NONE && c != TINYEXR_COMPRESSIONTYPE_ZIPS && c != TINYEXR_COMPRESSIONTYPE_ZIP)
        note(compression, "compression " + std::to_string(c) + " (none, ZIPS or ZIP expected)");
    } else if (name == "channels") {
      note(channels, exr_channel_list_problem(bytes, data, end));
      listed = true;
    }
  }
  if (!listed) note(channels, "no channel list");
  for (const std::string* problem : {&window, &part, &compression, &channels})
    if (!problem->empty()) return *problem;
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

// Long because it is one guarded sequence: read the bytes, judge version and header before
// tinyexr sizes anything from them, then decode; the checks must sit right before the call they protect.
Result<ImageRgbaF> load_exr(const fs::path& path) {
  const auto fail = [&](const std::string& message) { return Error{path.string(), "", "cannot read EXR: " + message}; };
  std::error_code ec;
  const std::uintmax_t file_bytes = fs::file_size(path, ec);
  if (ec) return fail(ec.message());
  if (file_bytes > kMaxExrFileBytes)
    return fail(std::to_string(file_bytes) + " bytes, above the " + std::to_string(kMaxExrFileBytes) + "-byte limit");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(file_bytes));
  {
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
      return fail("the file could not be read whole");
  }
  // The header is judged before tinyexr sizes anything from it: Debian's tinyexr 1.0.1 sizes
  // its scanline offset table from a data window whose height overflows its int arithmetic
  // (a crafted file asked for 2^63 bytes; found by the fuzz leg,
  // tests/fuzz/regressions/exr/tinyexr_data_window_overflow.exr), and its tile tables from
  // tile descriptions it checks as little. What the project writes and reads is one scanline
  // part of at most kMaxExrPixels pixels.
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, bytes.data(), bytes.size()) != TINYEXR_SUCCESS)
    return fail("not an OpenEXR file (bad magic or version)");
  if (version.tiled != 0 || version.multipart != 0 || version.non_image != 0)
    return fail("tiled, multi-part and deep files are not supported (one scanline part expected)");
  if (std::string problem = exr_header_problem(bytes); !problem.empty()) return fail(problem);
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRHeaderFromMemory(&header, &version, bytes.data(), bytes.size(), &err) != TINYEXR_SUCCESS) {
    std::string message = err ? err : "bad header";
    if (err) FreeEXRErrorMessage(err);
    FreeEXRHeader(&header);
    return fail(message);
  }
  const std::int64_t width = std::int64_t{header.data_window.max_x} - header.data_window.min_x + 1;
  const std::int64_t height = std::int64_t{header.data_window.max_y} - header.data_window.min_y + 1;
  const bool tiled = header.tiled != 0;
  const std::int64_t chunks = header.chunk_count;
  FreeEXRHeader(&header);
  if (tiled) return fail("tiled files are not supported (one scanline part expected)");
  if (std::string problem = exr_window_problem(width, height); !problem.empty()) return fail(problem);
  if (chunks < 0 || chunks > height)
    return fail("chunkCount " + std::to_string(chunks) + " for " + std::to_string(height) + " scanlines");

  float* rgba = nullptr;
  int w = 0;
  int h = 0;
  int ret = TINYEXR_ERROR_INVALID_DATA;
  try {
    ret = LoadEXRFromMemory(&rgba, &w, &h, bytes.data(), bytes.size(), &err);
  } catch (const std::exception& e) {  // tinyexr is C++: std::bad_alloc, std::length_error
    std::free(rgba);
    return fail(e.what());
  }
  if (ret != TINYEXR_SUCCESS) {
    std::string message = err ? err : "error " + std::to_string(ret);
    if (err) FreeEXRErrorMessage(err);
    return fail(message);
  }
  ImageRgbaF image;
  image.width = w;
  image.height = h;
  image.pixels.assign(rgba, rgba + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
  std::free(rgba);
  return image;
}

}  // namespace engine
