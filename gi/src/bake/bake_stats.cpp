#include "bake/bake_stats.h"

#include <gi/bake.h>

#include <algorithm>
#include <system_error>
#include <thread>
#include <utility>

#include "bake/bake_stamp.h"
#include "bundle/manifest.h"
#include "core/thread_pool.h"
#include "io/atomic_file.h"
#include "io/blob_file.h"

namespace gi {

namespace fs = std::filesystem;

engine::Status update_bake_stats(const fs::path& dir, const nlohmann::json& baked, unsigned threads_requested) {
  const fs::path path = dir / kBakeStatsFileName;
  nlohmann::json methods = nlohmann::json::object();
  if (auto old = read_file_bytes(path)) {
    const auto* text = reinterpret_cast<const char*>(old->data());
    nlohmann::json doc = nlohmann::json::parse(text, text + old->size(), nullptr, /*allow_exceptions=*/false);
    if (doc.is_object() && doc.contains("methods") && doc["methods"].is_object()) methods = doc["methods"];
  }
  auto manifest = read_manifest(dir);
  for (auto it = methods.begin(); it != methods.end();) {
    if (manifest && manifest->methods.contains(it.key()))
      ++it;
    else
      it = methods.erase(it);
  }
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const unsigned used = std::min(threads_requested == 0 ? hardware : threads_requested, ThreadPool::kMaxThreads);
  const std::string when = utc_now();
  const std::string host = host_name();
  for (const auto& [method, entry] : baked.items()) {
    nlohmann::json e = entry;
    e["threads"] = used;
    e["hardware_threads"] = hardware;
    e["host"] = host;
    e["baked_utc"] = when;
    methods[method] = std::move(e);
  }
  const nlohmann::json doc{{"methods", methods}};
  return write_file_atomically(path, doc.dump(2) + "\n");
}

std::uint64_t method_bytes(const fs::path& dir, const std::string& method) {
  auto manifest = read_manifest(dir);
  if (!manifest || !manifest->methods.contains(method)) return 0;
  const nlohmann::json& entry = manifest->methods[method];
  if (!entry.contains("files") || !entry["files"].is_object()) return 0;
  std::uint64_t bytes = 0;
  for (const auto& [key, file] : entry["files"].items()) {
    if (!file.is_object() || !file.contains("file") || !file["file"].is_string()) continue;
    std::error_code ec;
    const auto size = fs::file_size(dir / file["file"].get<std::string>(), ec);
    if (!ec) bytes += static_cast<std::uint64_t>(size);
  }
  return bytes;
}

}  // namespace gi
