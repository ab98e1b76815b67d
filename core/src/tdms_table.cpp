// A TDMS file as the table a CSV log would give (columns by channel name, metadata from file properties),
// with the optional channel map beside the file.
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <new>
#include <string_view>
#include <unordered_map>

#include "tdms_internal.hpp"
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
    if (ch->value_count != cols.front().second->value_count) {
      return bad_input(file.source + ": channel '" + ch->name + "' has " + std::to_string(ch->value_count) +
                       " values, channel '" + cols.front().second->name + "' has " +
                       std::to_string(cols.front().second->value_count) + ": every column needs one per row");
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

namespace {

using ChannelColumns = std::vector<std::pair<std::string, const TdmsChannel*>>;

// The table without its cells: metadata, comments, columns and row count.
CsvTable table_header(const TdmsFile& file, const TdmsChannelMap& map, const ChannelColumns& cols) {
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
  for (const auto& [name, ch] : cols) t.columns.push_back(name);
  t.rows = cols.front().second->value_count;
  return t;
}

// Every cell present; row r is "line" r + 1.
void add_flags(CsvTable& t) {
  t.empty.assign(t.cells.size(), 0);
  t.lines.resize(t.rows);
  for (std::size_t r = 0; r < t.rows; ++r) t.lines[r] = r + 1;
}

std::string megabytes(double bytes) {
  std::string out;
  append_fixed(out, bytes / 1e6, 0);
  return out + " MB";
}

// The memory this process may still take: the address-space limit (ulimit -v) and the machine's memory.
double memory_available() {
  double bytes =
      static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  struct rlimit lim {};
  if (::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY)
    bytes = std::min(bytes, static_cast<double>(lim.rlim_cur));
  return bytes;
}

// Room for the table's cells (and flags), or an error naming the file before anything is allocated.
Status allocate_cells(CsvTable& t, TdmsCells cells) try {
  const double per_cell = cells == TdmsCells::with_flags ? 9.0 : 8.0;
  const double per_row = cells == TdmsCells::with_flags ? 8.0 : 0.0;
  const double need =
      static_cast<double>(t.rows) * (per_cell * static_cast<double>(t.columns.size()) + per_row);
  const auto refused = [&](const std::string& why) {
    return bad_input(t.source + ": its " + std::to_string(t.rows) + " rows of " +
                     std::to_string(t.columns.size()) + " columns need " + megabytes(need) + " as numbers, " +
                     why + ": split the recording into shorter files");
  };
  if (need > 0.75 * memory_available())
    return refused("more than this process may take (" + megabytes(memory_available()) +
                   ", ulimit -v or the machine)");
  t.cells.resize(t.rows * t.columns.size());
  if (cells == TdmsCells::with_flags) add_flags(t);
  return ok_status();
} catch (const std::bad_alloc&) {
  t.cells = {};
  return bad_input(t.source + ": its " + std::to_string(t.rows) + " rows of " +
                   std::to_string(t.columns.size()) +
                   " columns do not fit in memory: split the recording into shorter files");
}

// A second pass over the file that decodes the columns' values straight into the table's cells.
Status fill_cells(tdms_detail::Source& src, const TdmsFile& file, const ChannelColumns& cols, CsvTable& t) {
  if (t.cells.empty()) return ok_status();  // no rows: nothing to decode
  tdms_detail::Fill fill;
  fill.column.assign(file.channels.size(), nullptr);
  fill.stride = t.columns.size();
  fill.rows = t.rows;
  for (std::size_t c = 0; c < cols.size(); ++c)
    fill.column[static_cast<std::size_t>(cols[c].second - file.channels.data())] = t.cells.data() + c;
  auto again = tdms_detail::parse(src, file.source, tdms_detail::Pass::fill, &fill);
  if (!again) return again.error();
  for (const auto& [name, ch] : cols) {
    const TdmsChannel& now = again->channels[static_cast<std::size_t>(ch - file.channels.data())];
    if (now.value_count != ch->value_count)
      return bad_input(file.source + ": channel '" + ch->name + "' changed while the file was read");
  }
  return ok_status();
}

// The channel map beside `tdms_path`, when one is there, must be a regular file: a folder or a device is
// no map, a FIFO would block the read until a writer came, a link to nothing would be ignored as no map.
Status check_channel_map(const std::string& map_path, const std::string& tdms_path) {
  struct stat st {};
  const std::string what = map_path + ": the channel map of " + tdms_path + " is ";
  if (::stat(map_path.c_str(), &st) != 0) return bad_input(what + "a symbolic link to no file");
  if (!S_ISREG(st.st_mode)) return bad_input(what + file_kind(st.st_mode) + ", not a regular file");
  return ok_status();
}

Result<TdmsChannelMap> read_channel_map(const std::string& path) {
  TdmsChannelMap map;
  const std::string map_path = tdms_channel_map_path(path);
  struct stat st {};
  if (::lstat(map_path.c_str(), &st) != 0) return map;  // no map: every channel by its own name
  if (Status s = check_channel_map(map_path, path); !s) return s.error();
  auto text = read_input(map_path, kMaxYamlBytes);
  if (!text) return text.error();
  return parse_tdms_channel_map(*text, map_path);
}

}  // namespace

Result<CsvTable> tdms_to_table(const TdmsFile& file, const TdmsChannelMap& map) {
  auto cols = pick_columns(file, map);
  if (!cols) return cols.error();
  CsvTable t = table_header(file, map, *cols);
  const std::size_t nc = t.columns.size();
  t.cells.resize(t.rows * nc);
  for (std::size_t c = 0; c < nc; ++c) {
    const std::vector<double>& v = (*cols)[c].second->values;
    if (v.size() != t.rows)
      return bad_input(file.source + ": channel '" + (*cols)[c].second->name + "': values not kept");
    for (std::size_t r = 0; r < t.rows; ++r) t.cells[r * nc + c] = v[r];
  }
  add_flags(t);
  return t;
}

namespace {

// Pass 1 reads the metadata and counts the values; pass 2 decodes the columns' values into their cells.
// Memory: the table's cells and a window of the file's bytes, never the file or a copy of the values.
Result<CsvTable> table_from(tdms_detail::Source& src, const std::string& name,
                            const TdmsChannelMap* map_given, TdmsCells cells) try {
  auto file = tdms_detail::parse(src, name, tdms_detail::Pass::count);
  if (!file) return file.error();
  auto map = map_given != nullptr ? Result<TdmsChannelMap>(*map_given) : read_channel_map(name);
  if (!map) return map.error();
  auto cols = pick_columns(*file, *map);
  if (!cols) return cols.error();
  CsvTable t = table_header(*file, *map, *cols);
  if (Status s = allocate_cells(t, cells); !s) return s.error();
  if (Status s = fill_cells(src, *file, *cols, t); !s) return s.error();
  return t;
} catch (const std::bad_alloc&) {
  return failure(name + ": its metadata does not fit in memory");
}

}  // namespace

Result<CsvTable> read_tdms_table(const std::string& path, TdmsCells cells) {
  auto src = tdms_detail::open_source(path);
  if (!src) return src.error();
  return table_from(**src, path, nullptr, cells);
}

Result<CsvTable> tdms_image_to_table(std::span<const std::uint8_t> bytes, const std::string& source,
                                     const TdmsChannelMap& map) {
  tdms_detail::MemorySource src(bytes);
  return table_from(src, source, &map, TdmsCells::with_flags);
}

}  // namespace tetra
