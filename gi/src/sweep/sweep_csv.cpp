#include "sweep/sweep_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <system_error>

#include "sweep/knob_spec.h"

namespace gi {
namespace {

const char* const kMetricColumns[] = {"rel_rmse", "max_rel", "psnr_db", "fit_scale",     "fit_rel_rmse", "bake_s",
                                      "frame_ms", "bytes",   "wall_s",  "reference_key", "status"};
constexpr std::string_view kKnobPrefix = "knob:";
constexpr std::string_view kExtraPrefix = "extra:";

std::string csv_field(std::string_view s) {
  if (s.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(s);
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

bool parse_double(const std::string& s, double& out) {
  if (s.empty()) {
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace

std::string sweep_csv(std::span<const SweepRow> rows) {
  std::vector<std::string> knobs;
  for (const SweepRow& r : rows)
    for (const auto& e : r.knobs.entries())
      if (std::find(knobs.begin(), knobs.end(), e.first) == knobs.end()) knobs.push_back(e.first);
  std::vector<std::string> extras;
  for (const SweepRow& r : rows)
    for (const auto& e : r.extras)
      if (std::find(extras.begin(), extras.end(), e.first) == extras.end()) extras.push_back(e.first);
  std::string out = "method,scene";
  for (const std::string& k : knobs) out += "," + csv_field(std::string(kKnobPrefix) + k);
  for (const char* c : kMetricColumns) out += std::string(",") + c;
  for (const std::string& e : extras) out += "," + csv_field(std::string(kExtraPrefix) + e);
  out += "\n";
  for (const SweepRow& r : rows) {
    out += csv_field(r.method) + "," + csv_field(r.scene);
    for (const std::string& k : knobs) out += "," + (r.knobs.has(k) ? csv_field(r.knobs.text(k)) : std::string());
    const RunCosts& c = r.costs;
    out += "," + format_number(r.error.rel_rmse) + "," + format_number(r.error.max_rel) + "," +
           format_number(r.error.psnr_db) + "," + format_number(r.error.fit_scale) + "," +
           format_number(r.error.fit_rel_rmse) + "," + format_number(c.bake_seconds) + "," +
           (std::isnan(c.frame_ms) ? std::string() : format_number(c.frame_ms)) + "," + std::to_string(c.bytes) + "," +
           format_number(r.wall_seconds) + "," + csv_field(r.reference_key) + "," + csv_field(r.status);
    for (const std::string& e : extras) {
      const auto it = std::find_if(r.extras.begin(), r.extras.end(), [&](const auto& x) { return x.first == e; });
      out += "," + (it == r.extras.end() ? std::string() : format_number(it->second));
    }
    out += "\n";
  }
  return out;
}

engine::Result<std::vector<std::vector<std::string>>> parse_csv(std::string_view text, const std::string& source) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  std::size_t line = 1;
  std::size_t i = 0;
  bool field_started = false;
  auto end_record = [&] {
    record.push_back(std::move(field));
    field.clear();
    records.push_back(std::move(record));
    record.clear();
    field_started = false;
  };
  while (i < text.size()) {
    const char c = text[i];
    if (c == '"' && !field_started && field.empty()) {
      const std::size_t open_line = line;
      ++i;
      while (true) {
        if (i >= text.size()) return engine::Error{source, "line " + std::to_string(open_line), "unterminated quote"};
        if (text[i] == '"') {
          if (i + 1 < text.size() && text[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        if (text[i] == '\n') ++line;
        field += text[i++];
      }
      field_started = true;
      if (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r') {
        return engine::Error{source, "line " + std::to_string(line), "text after a closing quote"};
      }
      continue;
    }
    if (c == ',') {
      record.push_back(std::move(field));
      field.clear();
      field_started = false;
      ++i;
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      ++i;
    } else if (c == '\n') {
      end_record();
      ++line;
      ++i;
    } else {
      field += c;
      field_started = true;
      ++i;
    }
  }
  if (field_started || !field.empty() || !record.empty()) end_record();
  return records;
}

engine::Result<std::vector<SweepRow>> parse_sweep_csv(std::string_view text, const std::string& source) {
  engine::Result<std::vector<std::vector<std::string>>> records = parse_csv(text, source);
  if (!records) return records.error();
  if (records->empty()) return engine::Error{source, "line 1", "no header"};
  const std::vector<std::string>& header = records->front();
  std::map<std::string, std::size_t> column;
  std::vector<std::pair<std::string, std::size_t>> knob_columns;
  std::vector<std::pair<std::string, std::size_t>> extra_columns;
  for (std::size_t i = 0; i < header.size(); ++i) {
    column[header[i]] = i;
    if (header[i].starts_with(kKnobPrefix)) knob_columns.emplace_back(header[i].substr(kKnobPrefix.size()), i);
    if (header[i].starts_with(kExtraPrefix)) extra_columns.emplace_back(header[i].substr(kExtraPrefix.size()), i);
  }
  for (const char* required : {"method", "scene"})
    if (!column.count(required)) return engine::Error{source, "header", std::string("missing column ") + required};
  for (const char* required : kMetricColumns)
    if (!column.count(required)) return engine::Error{source, "header", std::string("missing column ") + required};

  std::vector<SweepRow> rows;
  for (std::size_t r = 1; r < records->size(); ++r) {
    const std::vector<std::string>& f = (*records)[r];
    const std::string where = "record " + std::to_string(r + 1);
    if (f.size() != header.size()) {
      return engine::Error{source, where,
                           std::to_string(f.size()) + " fields, the header has " + std::to_string(header.size())};
    }
    SweepRow row;
    row.method = f[column["method"]];
    row.scene = f[column["scene"]];
    for (const auto& [name, i] : knob_columns)
      if (!f[i].empty()) row.knobs.set(name, f[i]);
    const std::pair<const char*, double*> numbers[] = {
        {"rel_rmse", &row.error.rel_rmse},         {"max_rel", &row.error.max_rel},
        {"psnr_db", &row.error.psnr_db},           {"fit_scale", &row.error.fit_scale},
        {"fit_rel_rmse", &row.error.fit_rel_rmse}, {"bake_s", &row.costs.bake_seconds},
        {"frame_ms", &row.costs.frame_ms},         {"wall_s", &row.wall_seconds}};
    for (const auto& [name, target] : numbers) {
      if (!parse_double(f[column[name]], *target)) {
        return engine::Error{source, where + ", column " + name, "'" + f[column[name]] + "' is not a number"};
      }
    }
    const std::string& bytes = f[column["bytes"]];
    const auto br = std::from_chars(bytes.data(), bytes.data() + bytes.size(), row.costs.bytes);
    if (br.ec != std::errc() || br.ptr != bytes.data() + bytes.size()) {
      return engine::Error{source, where + ", column bytes", "'" + bytes + "' is not a byte count"};
    }
    for (const auto& [name, i] : extra_columns) {
      if (f[i].empty()) continue;  // this row's method did not report it
      double v = 0.0;
      if (!parse_double(f[i], v))
        return engine::Error{source, where + ", column extra:" + name, "'" + f[i] + "' is not a number"};
      row.extras.emplace_back(name, v);
    }
    row.reference_key = f[column["reference_key"]];
    row.status = f[column["status"]];
    if (!row.ok()) row.error.problem = row.status;
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace gi
