// A TDMS file as the table a CSV log would give (columns by channel name, metadata from file properties),
// with the optional channel map beside the file.
#include <sys/stat.h>

#include <algorithm>
#include <new>
#include <string_view>
#include <unordered_map>

#include "tetra/core/input_files.hpp"
#include "tetra/core/tdms.hpp"
#include "tetra/core/yaml_reader.hpp"

namespace tetra {

namespace {

// The channel a map entry names: "Channel" (one group holds that name) or "Group/Channel".
Result<const TdmsChannel*> find_channel(const TdmsFile& file, const std::string& ref,
                                        const std::string& where) {
  const TdmsChannel* found = nullptr;
  for (const TdmsChannel& ch : file.channels) {
    if (ch.name != ref) continue;
    if (found != nullptr) {
      return bad_input(where + "channel '" + ref + "' is in groups '" + found->group + "' and '" + ch.group +
                       "': name it 'Group/Channel'");
    }
    found = &ch;
  }
  if (found != nullptr) return found;
  for (const TdmsChannel& ch : file.channels) {
    if (ch.group + "/" + ch.name == ref) return &ch;
  }
  std::string names;
  for (const TdmsChannel& ch : file.channels) names += (names.empty() ? "" : ", ") + ch.group + "/" + ch.name;
  return bad_input(where + "no channel '" + ref + "' in " + file.source + " (channels: " + names + ")");
}

// The columns: (name, channel) pairs.
Result<std::vector<std::pair<std::string, const TdmsChannel*>>> pick_columns(const TdmsFile& file,
                                                                             const TdmsChannelMap& map) {
  std::vector<std::pair<std::string, const TdmsChannel*>> cols;
  const auto too_many = [&] {
    return bad_input(file.source + ": more than " + std::to_string(kMaxColumns) + " channels");
  };
  if (map.channels.empty()) {
    std::unordered_map<std::string_view, const TdmsChannel*> by_name;
    for (const TdmsChannel& ch : file.channels) {
      if (ch.type == 0) continue;  // an object without values (e.g. a property holder)
      if (cols.size() == kMaxColumns) return too_many();
      if (const auto [other, fresh] = by_name.emplace(ch.name, &ch); !fresh) {
        return bad_input(file.source + ": channel '" + ch.name + "' is in groups '" + other->second->group +
                         "' and '" + ch.group + "': choose one in a channel map (" +
                         tdms_channel_map_path(file.source) + ")");
      }
      cols.emplace_back(ch.name, &ch);
    }
  } else {
    const std::string where = map.source + ": channels: ";
    std::unordered_map<const TdmsChannel*, std::string_view> column_of;
    for (const auto& [column, ref] : map.channels) {
      if (cols.size() == kMaxColumns) return too_many();
      auto ch = find_channel(file, ref, where);
      if (!ch) return ch.error();
      // One channel is one sensor: two columns of it would make two gyros agree by construction.
      if (const auto [other, fresh] = column_of.emplace(*ch, column); !fresh)
        return bad_input(where + column + ": channel '" + ref + "' is also column " +
                         std::string(other->second));
      cols.emplace_back(column, *ch);
    }
  }
  if (cols.empty()) return bad_input(file.source + ": no channel holds values");
  for (const auto& [name, ch] : cols) {
    if (!ch->numeric) {
      return bad_input(file.source + ": channel '" + ch->group + "/" + ch->name + "' (column '" + name +
                       "') does not hold numbers (text, timestamps or complex values)");
    }
    if (ch->values.size() != cols.front().second->values.size()) {
      return bad_input(file.source + ": channel '" + ch->name + "' has " + std::to_string(ch->values.size()) +
                       " values, channel '" + cols.front().second->name + "' has " +
                       std::to_string(cols.front().second->values.size()) +
                       ": every column needs one per row");
    }
  }
  return cols;
}

}  // namespace

std::string tdms_channel_map_path(const std::string& tdms_path) {
  return tdms_path.substr(0, is_tdms_path(tdms_path) ? tdms_path.size() - 5 : tdms_path.size()) +
         ".channels.yaml";
}

Result<TdmsChannelMap> parse_tdms_channel_map(const std::string& text, const std::string& source) {
  YamlReader yaml(source);
  auto root = yaml.load(text);
  if (!root) return root.error();
  TdmsChannelMap map;
  map.source = source;
  if (!root->IsMap()) return yaml.error(*root, "", "expected a mapping with 'channels' and/or 'properties'");
  if (Status s = yaml.check_keys(*root, {"channels", "properties"}, ""); !s) return s.error();
  for (const char* key : {"channels", "properties"}) {
    const YAML::Node node = (*root)[key];
    if (!node || node.IsNull()) continue;
    if (!node.IsMap())
      return yaml.error(node, key, "expected a mapping 'name in tetra: name in the TDMS file'");
    auto& into = std::string(key) == "channels" ? map.channels : map.properties;
    for (const auto& kv : node) {
      auto name = yaml.text(kv.first, key);
      if (!name) return name.error();
      auto value = yaml.text(kv.second, YamlReader::child(key, *name));
      if (!value) return value.error();
      into.emplace_back(*name, *value);
    }
  }
  return map;
}

Result<CsvTable> tdms_to_table(const TdmsFile& file, const TdmsChannelMap& map) {
  auto cols = pick_columns(file, map);
  if (!cols) return cols.error();
  CsvTable t;
  t.source = file.source;
  for (const auto& [name, value] : file.properties) {
    // A key the map gives another property is the map's: a file property of that name, before or after
    // the mapped one, does not override it.
    std::string key = name;
    bool mapped = false;
    bool shadowed = false;
    for (const auto& [tetra_key, property] : map.properties) {
      if (property == name) {
        key = tetra_key;
        mapped = true;
      }
      shadowed = shadowed || (tetra_key == name && property != name);
    }
    if (!mapped && shadowed) continue;
    std::string line;
    append_metadata(line, key, value);
    t.comments.push_back(line.substr(1, line.size() - 2));  // without '#' and the newline
    t.metadata.emplace_back(std::move(key), value);
  }
  for (const auto& [name, ch] : *cols) t.columns.push_back(name);
  t.rows = cols->front().second->values.size();
  const std::size_t nc = t.columns.size();
  t.cells.resize(t.rows * nc);
  t.empty.assign(t.rows * nc, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const std::vector<double>& v = (*cols)[c].second->values;
    for (std::size_t r = 0; r < t.rows; ++r) t.cells[r * nc + c] = v[r];
  }
  t.lines.resize(t.rows);
  for (std::size_t r = 0; r < t.rows; ++r) t.lines[r] = r + 1;
  return t;
}

Result<CsvTable> read_tdms_table(const std::string& path) try {
  auto file = read_tdms(path);
  if (!file) return file.error();
  TdmsChannelMap map;
  const std::string map_path = tdms_channel_map_path(path);
  struct stat st {};
  if (::lstat(map_path.c_str(), &st) == 0) {  // a link to nothing is read (and refused), never ignored
    auto text = read_input(map_path, kMaxYamlBytes);
    if (!text) return text.error();
    auto parsed = parse_tdms_channel_map(*text, map_path);
    if (!parsed) return parsed.error();
    map = std::move(*parsed);
  }
  return tdms_to_table(*file, map);
} catch (const std::bad_alloc&) {
  // Each numeric value takes 8 bytes as read and 9 as a table cell: a file of small integers (int8) needs
  // about 17 times its size.
  return failure(path +
                 ": its values do not fit in memory (about 17 bytes each as read and as a table, "
                 "against 1 in an int8 file): convert it in parts");
}

}  // namespace tetra
