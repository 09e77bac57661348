#include "sweep/reference_cache.h"

#include <engine/check.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include "io/atomic_file.h"
#include "io/content_hash.h"

namespace gi {
namespace {

static_assert(std::endian::native == std::endian::little, "the cache format is little-endian");

constexpr char kMagic[8] = {'G', 'I', 'R', 'E', 'F', 'C', 'H', '\0'};
// Version 2: the flags word carries bit 1 = a variance block follows the mask.
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kHasMask = 1u, kHasVariance = 2u;
constexpr std::size_t kHeaderBytes = 24;

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
T get(std::string_view bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

std::uint64_t checksum(std::string_view bytes) {
  ContentHash h;
  h.add_bytes(bytes.data(), bytes.size());
  return h.value();
}

}  // namespace

std::string reference_cache_key(const SweepScene& scene, const ReferenceProvider& provider,
                                const ReferenceRequest& request) {
  return "scene=" + scene.content_hash + ";provider=" + provider.kind + "@" + provider.version +
         ";request=" + request.key();
}

std::string encode_reference(std::string_view key, const RgbField& field) {
  GI_EXPECTS(field.consistent(), "encode_reference: rgb/valid sizes must match width x height");
  const std::uint32_t flags = (field.valid.empty() ? 0u : kHasMask) | (field.variance.empty() ? 0u : kHasVariance);
  const std::uint64_t payload = 12 + 4 * field.rgb.size() + field.valid.size() + 4 * field.variance.size();
  std::string out;
  out.reserve(kHeaderBytes + key.size() + payload + 8);
  out.append(kMagic, sizeof(kMagic));
  put(out, kVersion);
  put(out, static_cast<std::uint32_t>(key.size()));
  put(out, payload);
  out.append(key);
  put(out, static_cast<std::int32_t>(field.width));
  put(out, static_cast<std::int32_t>(field.height));
  put(out, flags);
  out.append(reinterpret_cast<const char*>(field.rgb.data()), 4 * field.rgb.size());
  out.append(reinterpret_cast<const char*>(field.valid.data()), field.valid.size());
  out.append(reinterpret_cast<const char*>(field.variance.data()), 4 * field.variance.size());
  put(out, checksum(out));
  return out;
}

engine::Result<RgbField> decode_reference(std::string_view bytes, std::string_view expected_key,
                                          const std::string& source) {
  auto fail = [&](std::string location, std::string message) {
    return engine::Error{source, std::move(location), std::move(message)};
  };
  if (bytes.size() < kHeaderBytes + 8) {
    return fail("header", "truncated: " + std::to_string(bytes.size()) + " bytes is shorter than a header");
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return fail("magic", "not a reference cache file");
  const auto version = get<std::uint32_t>(bytes, 8);
  if (version != kVersion) {
    return fail("version", "format version " + std::to_string(version) + ", expected " + std::to_string(kVersion));
  }
  const auto key_len = get<std::uint32_t>(bytes, 12);
  const auto payload = get<std::uint64_t>(bytes, 16);
  const std::uint64_t expected_size = kHeaderBytes + std::uint64_t{key_len} + payload + 8;
  if (payload > bytes.size() || expected_size != bytes.size()) {
    return fail("size", "file is " + std::to_string(bytes.size()) + " bytes, header says " +
                            std::to_string(expected_size) + " (truncated or corrupt)");
  }
  const std::size_t sum_at = bytes.size() - 8;
  if (get<std::uint64_t>(bytes, sum_at) != checksum(bytes.substr(0, sum_at))) {
    return fail("checksum", "checksum mismatch (corrupt)");
  }
  if (bytes.substr(kHeaderBytes, key_len) != expected_key) {
    return fail("key", "holds '" + std::string(bytes.substr(kHeaderBytes, key_len)) + "', expected '" +
                           std::string(expected_key) + "'");
  }
  const std::size_t p = kHeaderBytes + key_len;
  if (payload < 12) return fail("payload", "payload too short");
  RgbField field;
  field.width = get<std::int32_t>(bytes, p);
  field.height = get<std::int32_t>(bytes, p + 4);
  const auto flags = get<std::uint32_t>(bytes, p + 8);
  if (field.width < 0 || field.height < 0 || flags > (kHasMask | kHasVariance))
    return fail("payload", "bad dimensions or flags");
  const bool has_mask = (flags & kHasMask) != 0, has_variance = (flags & kHasVariance) != 0;
  const std::uint64_t n = field.count();
  if (payload != 12 + 12 * n + (has_mask ? n : 0) + (has_variance ? 12 * n : 0)) {
    return fail("payload",
                "payload size does not match " + std::to_string(field.width) + "x" + std::to_string(field.height));
  }
  field.rgb.resize(3 * n);
  std::memcpy(field.rgb.data(), bytes.data() + p + 12, 12 * n);
  if (has_mask)
    field.valid.assign(bytes.begin() + static_cast<std::ptrdiff_t>(p + 12 + 12 * n),
                       bytes.begin() + static_cast<std::ptrdiff_t>(p + 12 + 13 * n));
  if (has_variance) {
    field.variance.resize(3 * n);
    std::memcpy(field.variance.data(), bytes.data() + p + 12 + 12 * n + (has_mask ? n : 0), 12 * n);
  }
  return field;
}

std::filesystem::path ReferenceCache::file_for(std::string_view key) const {
  ContentHash h;
  h.add_string(key);
  return dir_ / (h.hex() + ".giref");
}

engine::Result<std::optional<RgbField>> ReferenceCache::load(std::string_view key) const {
  if (!enabled()) return std::optional<RgbField>();
  const std::filesystem::path file = file_for(key);
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return std::optional<RgbField>();
  std::ifstream in(file, std::ios::binary);
  if (!in) return engine::Error{file.string(), "", "cannot open the cache file"};
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return engine::Error{file.string(), "", "read error"};
  engine::Result<RgbField> field = decode_reference(bytes, key, file.string());
  if (!field) return field.error();
  return std::optional<RgbField>(std::move(field.value()));
}

engine::Status ReferenceCache::store(std::string_view key, const RgbField& field) const {
  if (!enabled()) return {};
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) return engine::Error{dir_.string(), "", "cannot create the cache directory: " + ec.message()};
  return write_file_atomically(file_for(key), encode_reference(key, field));
}

engine::Result<ReferenceFetch> fetch_reference(const ReferenceCache& cache, const ReferenceProvider& provider,
                                               const SweepScene& scene, const ReferenceRequest& request,
                                               unsigned threads, const ProgressFn& progress) {
  ReferenceFetch out;
  out.key = reference_cache_key(scene, provider, request);
  engine::Result<std::optional<RgbField>> cached = cache.load(out.key);
  if (cached && cached.value()) {
    out.field = std::move(*cached.value());
    out.from_cache = true;
    if (progress) progress(1.0);
    return out;
  }
  if (!cached) out.warning = "discarded cache entry: " + cached.error().to_string() + "; recomputing";
  const ProgressFn no_progress = [](double) { return true; };
  engine::Result<RgbField> computed =
      provider.compute(ReferenceJob{scene, request, threads, progress ? progress : no_progress});
  if (!computed) return computed.error();
  if (!computed->consistent()) {
    return engine::Error{"reference provider " + provider.kind, request.key(),
                         "returned a field whose vector sizes do not match its width x height"};
  }
  out.field = std::move(computed.value());
  if (engine::Status s = cache.store(out.key, out.field); !s) {
    out.warning += (out.warning.empty() ? "" : "; ") + ("cache not written: " + s.error().to_string());
  }
  return out;
}

}  // namespace gi
