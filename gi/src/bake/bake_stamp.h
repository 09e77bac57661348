#pragma once
// Where and when a bake ran, for bake_stats.json (never for the manifest or the method
// files, which must be byte-identical across runs and machines).
//   e["baked_utc"] = gi::utc_now();  // "2026-11-29T01:02:03Z"
//   e["host"] = gi::host_name();

#include <string>

namespace gi {

/// The current time in UTC, ISO 8601 to the second ("YYYY-MM-DDTHH:MM:SSZ").
std::string utc_now();

/// This machine's host name (gethostname); empty when it cannot be read.
std::string host_name();

}  // namespace gi
