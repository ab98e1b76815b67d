#include "tetra/ground/record_files.hpp"

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/quaternion.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/ground/strict_json.hpp"

namespace tetra::ground {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kAttitudeHeader = "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps,sigma_deg,mode,gyros";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  return cells;
}

//! One attitude row as the stream's attitude object (without UTC), or an error naming the line.
Result<json> attitude_row(const std::vector<std::string>& cells, const std::string& where) {
  // The 11 columns first; the attitude filter's per-axis sigma and bias columns may follow.
  if (cells.size() < 11) return bad_input(where + ": expected at least 11 columns (" + kAttitudeHeader + ")");
  double v[9];
  for (std::size_t i = 0; i < 9; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(cells[i].c_str(), &end);
    if (end == cells[i].c_str())
      return bad_input(where + ": column " + std::to_string(i + 1) + " is not a number");
  }
  const EulerDeg e = euler_zyx_deg(from_wxyz(v[1], v[2], v[3], v[4]));
  return json{{"type", "attitude"},
              {"sensor_time_s", v[0]},
              {"q", json::array({v[1], v[2], v[3], v[4]})},
              {"euler_deg", {{"roll", e.roll_deg}, {"pitch", e.pitch_deg}, {"yaw", e.yaw_deg}}},
              {"rate_dps", json::array({v[5], v[6], v[7]})},
              {"sigma_total_deg", v[8]},
              {"mode", cells[9]},
              {"gyros", cells[10]}};
}

Result<json> event_row(const std::string& line, const std::string& where) {
  auto parsed = parse_strict_json(line);
  if (!parsed) return bad_input(where + ": " + parsed.error().message);
  json row = std::move(parsed).value();
  if (!row.is_object() || !row.contains("time_s") || !row["time_s"].is_number())
    return bad_input(where + ": not an event (a JSON object with time_s)");
  row["type"] = "event";
  row["sensor_time_s"] = row["time_s"];
  return row;
}

//! The file's rows in [start_s, end_s]; errors name the file by `name` (never the server's path).
Result<std::vector<json>> rows_of(const std::string& path, const std::string& name, double start_s,
                                  double end_s) {
  auto text = read_text_file(path);
  if (!text) return bad_input("record file '" + name + "': cannot be read");
  const bool csv = fs::path(path).extension() == ".csv";
  std::vector<json> rows;
  std::istringstream in(*text);
  std::string line;
  bool header_seen = !csv;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    if (!header_seen) {
      if (line.rfind(kAttitudeHeader, 0) != 0)
        return bad_input(name + ":" + std::to_string(number) + ": not an attitude file");
      header_seen = true;
      continue;
    }
    const std::string where = name + ":" + std::to_string(number);
    auto row = csv ? attitude_row(split(line), where) : event_row(line, where);
    if (!row) return row.error();
    const double t = (*row)["sensor_time_s"].get<double>();
    if (t >= start_s && t <= end_s) rows.push_back(std::move(row).value());
  }
  return rows;
}

}  // namespace

Result<json> list_records(const std::string& dir) {
  std::error_code ec;
  std::vector<json> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const auto ext = entry.path().extension();
    // A link is not listed (it may lead out of the folder), nor is a hidden file.
    if (entry.is_symlink() || !entry.is_regular_file() || (ext != ".csv" && ext != ".jsonl") ||
        entry.path().filename().string()[0] == '.')
      continue;
    if (ext == ".csv") {
      auto text = read_text_file(entry.path().string());
      if (!text || text->find(kAttitudeHeader) == std::string::npos) continue;  // a gyro log, not attitude
    }
    files.push_back(
        {{"name", entry.path().filename().string()}, {"kind", ext == ".csv" ? "attitude" : "events"}});
  }
  if (ec) return bad_input("the records folder cannot be read: " + ec.message());
  std::sort(files.begin(), files.end(), [](const json& a, const json& b) { return a["name"] < b["name"]; });
  return json(files);
}

Result<json> read_record(const std::string& dir, const std::string& name, double start_s, double end_s,
                         std::size_t max_points) {
  const fs::path path = fs::path(dir) / name;
  const auto ext = path.extension();
  std::error_code ec;
  if (name.empty() || name.size() > 255 || name.find('/') != std::string::npos ||
      name.find('\0') != std::string::npos || name[0] == '.' || (ext != ".csv" && ext != ".jsonl"))
    return bad_input("record file '" + name + "': a plain .csv or .jsonl file name of the records folder");
  // Never a link (it may lead out of the folder): the file itself must be a regular file.
  if (!fs::is_regular_file(fs::symlink_status(path, ec)))
    return bad_input("record file '" + name + "': no such file in the records folder");
  auto rows = rows_of(path.string(), name, start_s, end_s);
  if (!rows) return rows.error();
  const std::size_t stride = max_points == 0 ? 1 : (rows->size() + max_points - 1) / max_points;
  json out = json::array();
  for (std::size_t i = 0; i < rows->size(); i += std::max<std::size_t>(stride, 1)) out.push_back((*rows)[i]);
  return out;
}

}  // namespace tetra::ground
