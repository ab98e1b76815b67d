// TDMS 2.0 reader: segments, lead-in, metadata (full or incremental), raw data contiguous or interleaved.
// Layout from NI's published description of the TDMS file format; every size read from the file is checked
// against the bytes that remain before anything is allocated or skipped.
#include "tetra/core/tdms.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <optional>
#include <set>
#include <unordered_map>

#include "tetra/core/input_files.hpp"

namespace tetra {

namespace {

constexpr std::size_t kLeadInBytes = 28;
constexpr std::uint64_t kIncompleteSegment = 0xFFFFFFFFFFFFFFFFULL;  // LabVIEW stopped while writing it
// ToC flags of the lead-in
constexpr std::uint32_t kTocMetaData = 1U << 1;
constexpr std::uint32_t kTocNewObjList = 1U << 2;
constexpr std::uint32_t kTocRawData = 1U << 3;
constexpr std::uint32_t kTocInterleavedData = 1U << 5;
constexpr std::uint32_t kTocBigEndian = 1U << 6;
constexpr std::uint32_t kTocDAQmxRawData = 1U << 7;
// Raw data index markers
constexpr std::uint32_t kNoRawData = 0xFFFFFFFFU;
constexpr std::uint32_t kSameIndexAsBefore = 0;
constexpr std::uint32_t kDaqmxFormatChanging = 0x00001269U;
constexpr std::uint32_t kDaqmxDigitalLine = 0x00001369U;
// tdsDataType codes
constexpr std::uint32_t kTdsString = 0x20;
constexpr std::uint32_t kTdsBoolean = 0x21;
constexpr std::uint32_t kTdsTimeStamp = 0x44;
constexpr std::int64_t kSeconds1904To1970 = 2082844800;
// Bounds that keep a hostile file's work linear in its size
constexpr std::size_t kMaxChannels = 65536;
constexpr std::uint32_t kMaxPropertiesPerObject = 4096;

std::string hex_type(std::uint32_t type) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%X", type);
  return hex;
}

// Size in bytes of one value of a fixed-size type, 0 for strings and unknown types.
std::size_t type_size(std::uint32_t type) {
  switch (type) {
    case 1:
    case 5:
    case kTdsBoolean:
      return 1;  // I8, U8, Boolean
    case 2:
    case 6:
      return 2;  // I16, U16
    case 3:
    case 7:
    case 9:
    case 0x19:
      return 4;  // I32, U32, SingleFloat (with unit)
    case 4:
    case 8:
    case 10:
    case 0x1A:
      return 8;  // I64, U64, DoubleFloat (with unit)
    case 0x08000C:
      return 8;  // ComplexSingleFloat
    case kTdsTimeStamp:
    case 0x10000D:
      return 16;  // TimeStamp, ComplexDoubleFloat
    default:
      return 0;
  }
}

bool is_numeric(std::uint32_t type) {
  return (type >= 1 && type <= 10) || type == 0x19 || type == 0x1A || type == kTdsBoolean;
}

// Bounded reading of one region of the image in the segment's byte order.
class Cursor {
 public:
  Cursor(std::span<const std::uint8_t> bytes, std::size_t begin, std::size_t end, bool big_endian)
      : bytes_(bytes), pos_(begin), end_(end), big_(big_endian) {}
  std::size_t pos() const { return pos_; }
  std::size_t left() const { return end_ - pos_; }
  bool take(std::size_t n, const std::uint8_t*& at) {
    if (n > left()) return false;
    at = bytes_.data() + pos_;
    pos_ += n;
    return true;
  }
  template <class T>
  bool get(T& out) {
    const std::uint8_t* at = nullptr;
    if (!take(sizeof(T), at)) return false;
    out = load<T>(at, big_);
    return true;
  }
  bool text(std::string& out) {
    std::uint32_t n = 0;
    const std::uint8_t* at = nullptr;
    if (!get(n) || !take(n, at)) return false;
    out.assign(reinterpret_cast<const char*>(at), n);
    return true;
  }
  template <class T>
  static T load(const std::uint8_t* at, bool big_endian) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, at, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_;
  std::size_t end_;
  bool big_;
};

// A value of a fixed-size numeric type as a double.
double load_number(const std::uint8_t* at, std::uint32_t type, bool big) {
  switch (type) {
    case 1:
      return Cursor::load<std::int8_t>(at, big);
    case 2:
      return Cursor::load<std::int16_t>(at, big);
    case 3:
      return Cursor::load<std::int32_t>(at, big);
    case 4:
      return static_cast<double>(Cursor::load<std::int64_t>(at, big));
    case 5:
    case kTdsBoolean:
      return Cursor::load<std::uint8_t>(at, big);
    case 6:
      return Cursor::load<std::uint16_t>(at, big);
    case 7:
      return Cursor::load<std::uint32_t>(at, big);
    case 8:
      return static_cast<double>(Cursor::load<std::uint64_t>(at, big));
    case 9:
    case 0x19:
      return Cursor::load<float>(at, big);
    default:
      return Cursor::load<double>(at, big);  // 10, 0x1A
  }
}

// A timestamp (seconds since 1904-01-01 UTC and 2^-64 fractions) as ISO 8601 UTC text.
std::string timestamp_text(std::int64_t seconds, std::uint64_t fractions) {
  const std::int64_t unix_s = seconds - kSeconds1904To1970;
  const auto t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  if (gmtime_r(&t, &tm) == nullptr) return std::to_string(seconds) + " s after 1904-01-01";
  char date[40];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S", &tm);
  char micro[16];
  std::snprintf(micro, sizeof micro, ".%06llu",
                static_cast<unsigned long long>(static_cast<double>(fractions) * 0x1p-64 * 1e6) % 1000000ULL);
  return std::string(date) + micro + "Z";
}

// The raw data index of one object in one segment.
struct RawIndex {
  std::uint32_t type = 0;
  std::uint64_t count = 0;        // values per chunk
  std::uint64_t chunk_bytes = 0;  // bytes per chunk (strings: the index's total size)
};

// An object of the segment's list: a channel index (into TdmsFile::channels) and its data this segment
// (has_data: at least one value per chunk).
struct ListedObject {
  std::size_t channel = 0;
  bool has_data = false;
  RawIndex index;
};

// Names of an object's properties → their place in its Metadata (a later segment updates in place).
using PropertyIndex = std::unordered_map<std::string, std::size_t>;

class TdmsParser {
 public:
  TdmsParser(std::span<const std::uint8_t> bytes, const std::string& source) : bytes_(bytes) {
    file_.source = source;
  }
  Result<TdmsFile> run();

 private:
  Error fail(const std::string& what) const {
    return bad_input(file_.source + ": segment " + std::to_string(segment_) + " at byte " +
                     std::to_string(segment_start_) + ": " + what);
  }
  Status read_metadata(Cursor& c, std::uint32_t toc);
  Status read_object(Cursor& c);
  Status read_properties(Cursor& c, Metadata* into, PropertyIndex* index, const std::string& path);
  //! Puts `obj` in the list (in its place when the channel is listed already, else at the end).
  void list_object(const ListedObject& obj);
  //! A new object list: every channel unlisted.
  void clear_list();
  //! A property's value as text; an error names the object's path and the property.
  Result<std::string> property_value(Cursor& c, std::uint32_t type, const std::string& path,
                                     const std::string& name);
  Status read_raw(std::size_t begin, std::size_t end, std::uint32_t toc, bool incomplete);
  Status read_chunk(Cursor& c, bool interleaved);
  Result<std::vector<std::string>> split_path(const std::string& path) const;
  Result<std::size_t> channel_for(const std::vector<std::string>& parts, const std::string& path);
  static constexpr std::size_t kNotListed = static_cast<std::size_t>(-1);

  std::span<const std::uint8_t> bytes_;
  TdmsFile file_;
  std::size_t segment_ = 0;
  std::size_t segment_start_ = 0;
  bool big_ = false;
  // The work per segment is proportional to its own bytes, never to the objects listed before it: the
  // list is updated in place, the objects with data and their chunk size are kept as the list changes.
  std::vector<ListedObject> list_;                           // the current segment's objects, in data order
  std::set<std::size_t> with_data_;                          // places in list_ of the objects with data
  std::uint64_t chunk_bytes_ = 0;                            // one chunk: the sum over with_data_
  std::vector<std::size_t> data_order_;                      // with_data_ as a vector (read_raw's loop)
  bool data_order_stale_ = false;                            // with_data_ changed since data_order_
  std::vector<std::optional<RawIndex>> last_index_;          // per channel: its last raw data index
  std::unordered_map<std::string, std::size_t> channel_at_;  // object path → channel index
  std::vector<std::size_t> listed_at_;                       // per channel: its place in list_, or kNotListed
  std::vector<PropertyIndex> channel_properties_;            // per channel
  PropertyIndex file_properties_;
};

Result<std::vector<std::string>> TdmsParser::split_path(const std::string& path) const {
  std::vector<std::string> parts;
  if (path == "/") return parts;
  std::size_t i = 0;
  while (i < path.size()) {
    if (path[i] != '/' || i + 1 >= path.size() || path[i + 1] != '\'') {
      return fail("object path '" + path + "' is not of the form /'group'/'channel'");
    }
    i += 2;
    std::string name;
    while (true) {
      if (i >= path.size()) return fail("object path '" + path + "' has an unterminated name");
      if (path[i] == '\'') {
        if (i + 1 < path.size() && path[i + 1] == '\'') {
          name += '\'';
          i += 2;
          continue;
        }
        ++i;
        break;
      }
      name += path[i++];
    }
    parts.push_back(std::move(name));
  }
  if (parts.size() > 2) return fail("object path '" + path + "' is deeper than /'group'/'channel'");
  return parts;
}

Result<std::size_t> TdmsParser::channel_for(const std::vector<std::string>& parts, const std::string& path) {
  if (const auto it = channel_at_.find(path); it != channel_at_.end()) return it->second;
  if (file_.channels.size() >= kMaxChannels)
    return fail("more than " + std::to_string(kMaxChannels) + " channels");
  channel_at_.emplace(path, file_.channels.size());
  TdmsChannel ch;
  ch.group = parts[0];
  ch.name = parts[1];
  file_.channels.push_back(std::move(ch));
  last_index_.emplace_back();
  listed_at_.push_back(kNotListed);
  channel_properties_.emplace_back();
  return file_.channels.size() - 1;
}

Result<std::string> TdmsParser::property_value(Cursor& c, std::uint32_t type, const std::string& path,
                                               const std::string& name) {
  // The message is made only on failure: a file of many properties pays for none.
  const auto what = [&] { return "object '" + path + "', property '" + name + "'"; };
  if (type == kTdsString) {
    std::string s;
    if (!c.text(s)) return fail(what() + ": truncated text value");
    return s;
  }
  const std::uint8_t* at = nullptr;
  if (type == kTdsTimeStamp) {
    if (!c.take(16, at)) return fail(what() + ": truncated timestamp");
    // Little-endian: fractions then seconds; big-endian: seconds then fractions.
    const auto fractions = Cursor::load<std::uint64_t>(big_ ? at + 8 : at, big_);
    const auto seconds = Cursor::load<std::int64_t>(big_ ? at : at + 8, big_);
    return timestamp_text(seconds, fractions);
  }
  if (!is_numeric(type)) {
    return fail(what() + ": property type " + hex_type(type) +
                " is not supported (numbers, booleans, text and timestamps are)");
  }
  if (!c.take(type_size(type), at)) return fail(what() + ": truncated value");
  const double v = load_number(at, type, big_);
  std::string out;
  if (type == kTdsBoolean) return std::string(v != 0.0 ? "true" : "false");
  if (type == 4 || type == 8) {  // 64-bit integers exactly, not through a double
    out = type == 4 ? std::to_string(Cursor::load<std::int64_t>(at, big_))
                    : std::to_string(Cursor::load<std::uint64_t>(at, big_));
  } else {
    append_double(out, v);
  }
  return out;
}

Status TdmsParser::read_properties(Cursor& c, Metadata* into, PropertyIndex* index, const std::string& path) {
  std::uint32_t n = 0;
  if (!c.get(n)) return fail("object '" + path + "': truncated property count");
  if (n > kMaxPropertiesPerObject) {
    return fail("object '" + path + "': " + std::to_string(n) + " properties (at most " +
                std::to_string(kMaxPropertiesPerObject) + ")");
  }
  for (std::uint32_t k = 0; k < n; ++k) {  // each property takes at least 8 bytes: a bad n ends at the end
    std::string name;
    std::uint32_t type = 0;
    if (!c.text(name) || !c.get(type)) return fail("object '" + path + "': truncated property");
    auto value = property_value(c, type, path, name);
    if (!value) return value.error();
    if (into == nullptr) continue;
    const auto [at, fresh] = index->emplace(name, into->size());
    if (fresh) {
      into->emplace_back(std::move(name), std::move(*value));
    } else {
      (*into)[at->second].second = std::move(*value);  // a later segment updates the property
    }
  }
  return ok_status();
}

void TdmsParser::list_object(const ListedObject& obj) {
  std::size_t& place = listed_at_[obj.channel];
  if (place == kNotListed) {
    place = list_.size();
    list_.push_back(ListedObject{obj.channel, false, {}});
  }
  ListedObject& entry = list_[place];
  if (entry.has_data) chunk_bytes_ -= entry.index.chunk_bytes;
  if (entry.has_data != obj.has_data) {
    if (obj.has_data) {
      with_data_.insert(place);
    } else {
      with_data_.erase(place);
    }
    data_order_stale_ = true;
  }
  entry = obj;
  if (entry.has_data) chunk_bytes_ += entry.index.chunk_bytes;  // each at most the file's size
}

void TdmsParser::clear_list() {
  for (const ListedObject& o : list_) listed_at_[o.channel] = kNotListed;
  list_.clear();
  with_data_.clear();
  chunk_bytes_ = 0;
  data_order_stale_ = true;
}

Status TdmsParser::read_object(Cursor& c) {
  std::string path;
  std::uint32_t marker = 0;
  if (!c.text(path) || !c.get(marker)) return fail("truncated object entry");
  auto parts = split_path(path);
  if (!parts) return parts.error();
  const bool is_channel = parts->size() == 2;
  if (!is_channel && marker != kNoRawData)
    return fail("object '" + path + "' is not a channel but has raw data");
  if (!is_channel) {
    return read_properties(c, parts->empty() ? &file_.properties : nullptr, &file_properties_, path);
  }
  auto channel = channel_for(*parts, path);
  if (!channel) return channel.error();
  TdmsChannel& ch = file_.channels[*channel];
  ListedObject obj;
  obj.channel = *channel;
  if (marker == kDaqmxFormatChanging || marker == kDaqmxDigitalLine) {
    return fail("channel '" + path + "' holds DAQmx raw data, which is not supported: save numeric channels");
  } else if (marker == kSameIndexAsBefore) {
    if (!last_index_[*channel]) return fail("channel '" + path + "' reuses a raw data index it never had");
    obj.index = *last_index_[*channel];
    obj.has_data = obj.index.count > 0;
  } else if (marker != kNoRawData) {
    std::uint32_t dimension = 0;
    RawIndex idx;
    if (!c.get(idx.type) || !c.get(dimension) || !c.get(idx.count)) {
      return fail("channel '" + path + "': truncated raw data index");
    }
    if (dimension != 1)
      return fail("channel '" + path + "': array dimension " + std::to_string(dimension) + ", expected 1");
    const std::size_t size = type_size(idx.type);
    if (idx.type == kTdsString) {
      // count offsets of 4 bytes, then the text: a chunk of fewer bytes is no chunk of `count` strings.
      if (marker != 28 || !c.get(idx.chunk_bytes) || idx.count > bytes_.size() / 4 ||
          idx.chunk_bytes < 4 * idx.count)
        return fail("channel '" + path + "': bad string raw data index");
    } else if (size == 0) {
      return fail("channel '" + path + "': data type " + hex_type(idx.type) + " is not supported");
    } else {
      if (marker != 20)
        return fail("channel '" + path + "': raw data index of " + std::to_string(marker) +
                    " bytes, expected 20");
      if (idx.count > bytes_.size() / size) {
        return fail("channel '" + path + "': " + std::to_string(idx.count) +
                    " values per chunk cannot fit in the file");
      }
      idx.chunk_bytes = idx.count * size;
    }
    if (idx.chunk_bytes > bytes_.size()) return fail("channel '" + path + "': chunk larger than the file");
    if (ch.type != 0 && ch.type != idx.type) return fail("channel '" + path + "' changes its data type");
    ch.type = idx.type;
    ch.numeric = is_numeric(idx.type);
    obj.has_data = idx.count > 0;
    obj.index = idx;
    last_index_[*channel] = idx;
  }
  list_object(obj);
  return read_properties(c, &ch.properties, &channel_properties_[*channel], path);
}

Status TdmsParser::read_metadata(Cursor& c, std::uint32_t toc) {
  // Without a new object list, an update of the previous segment's: objects not named again keep their
  // data and index; those named again get theirs in read_object.
  if ((toc & kTocNewObjList) != 0) clear_list();
  std::uint32_t n = 0;
  if (!c.get(n)) return fail("truncated object count");
  for (std::uint32_t k = 0; k < n; ++k) {  // each object takes at least 12 bytes
    if (Status s = read_object(c); !s) return s;
  }
  return ok_status();
}

Status TdmsParser::read_chunk(Cursor& c, bool interleaved) {
  if (!interleaved) {
    for (const std::size_t place : data_order_) {
      const ListedObject& o = list_[place];
      TdmsChannel& ch = file_.channels[o.channel];
      const std::uint8_t* at = nullptr;
      if (!c.take(o.index.chunk_bytes, at)) return fail("raw data ends inside a chunk");
      ch.value_count += o.index.count;
      if (!ch.numeric) continue;
      const std::size_t size = type_size(o.index.type);
      for (std::uint64_t v = 0; v < o.index.count; ++v)
        ch.values.push_back(load_number(at + v * size, o.index.type, big_));
    }
    return ok_status();
  }
  std::uint64_t count = 0;
  std::size_t row_bytes = 0;
  for (const std::size_t place : data_order_) {
    const ListedObject& o = list_[place];
    if (o.index.type == kTdsString) return fail("interleaved raw data holds a text channel");
    if (count != 0 && o.index.count != count) return fail("interleaved channels have different value counts");
    count = o.index.count;
    row_bytes += type_size(o.index.type);
  }
  for (std::uint64_t v = 0; v < count; ++v) {
    const std::uint8_t* at = nullptr;
    if (!c.take(row_bytes, at)) return fail("raw data ends inside a chunk");
    for (const std::size_t place : data_order_) {
      const ListedObject& o = list_[place];
      TdmsChannel& ch = file_.channels[o.channel];
      ++ch.value_count;
      if (ch.numeric) ch.values.push_back(load_number(at, o.index.type, big_));
      at += type_size(o.index.type);
    }
  }
  return ok_status();
}

Status TdmsParser::read_raw(std::size_t begin, std::size_t end, std::uint32_t toc, bool incomplete) {
  const std::uint64_t chunk = chunk_bytes_;
  const std::size_t raw = end - begin;
  if (chunk == 0) {
    if (raw != 0)
      return fail(std::to_string(raw) + " bytes of raw data but no channel has data in this segment");
    return ok_status();
  }
  if (raw == 0) return ok_status();  // from here on the work is bounded by the segment's bytes
  if (data_order_stale_) {
    data_order_.assign(with_data_.begin(), with_data_.end());
    data_order_stale_ = false;
  }
  if (raw % chunk != 0) {
    return fail("raw data of " + std::to_string(raw) + " bytes is not a whole number of chunks of " +
                std::to_string(chunk) + " bytes" + (incomplete ? " (the segment was not finished)" : ""));
  }
  const std::size_t chunks = raw / chunk;
  for (const std::size_t place : data_order_) {  // room for this segment's values (bounded by its bytes)
    const ListedObject& o = list_[place];
    TdmsChannel& ch = file_.channels[o.channel];
    if (!ch.numeric) continue;
    // Geometric growth: a stream of many small segments is not copied once per segment.
    const std::size_t needed = ch.values.size() + chunks * o.index.count;
    if (needed > ch.values.capacity()) ch.values.reserve(std::max(needed, 2 * ch.values.capacity()));
  }
  Cursor c(bytes_, begin, end, big_);
  for (std::size_t k = 0; k < chunks; ++k) {
    if (Status s = read_chunk(c, (toc & kTocInterleavedData) != 0); !s) return s;
  }
  return ok_status();
}

Result<TdmsFile> TdmsParser::run() {
  std::size_t pos = 0;
  if (bytes_.empty()) return bad_input(file_.source + ": empty file: not a TDMS file");
  while (pos < bytes_.size()) {
    ++segment_;
    segment_start_ = pos;
    if (bytes_.size() - pos < kLeadInBytes) {
      return fail("truncated lead-in (" + std::to_string(bytes_.size() - pos) + " of 28 bytes)");
    }
    const std::uint8_t* lead = bytes_.data() + pos;
    if (std::memcmp(lead, "TDSh", 4) == 0)
      return fail("this is a .tdms_index file: give the .tdms file itself");
    if (std::memcmp(lead, "TDSm", 4) != 0) return fail("no 'TDSm' tag: not a TDMS segment");
    const auto toc = Cursor::load<std::uint32_t>(lead + 4, false);
    big_ = (toc & kTocBigEndian) != 0;
    const auto version = Cursor::load<std::uint32_t>(lead + 8, big_);
    const auto next_offset = Cursor::load<std::uint64_t>(lead + 12, big_);
    const auto raw_offset = Cursor::load<std::uint64_t>(lead + 20, big_);
    if (version != 4712 && version != 4713)
      return fail("version " + std::to_string(version) + ", expected 4712 or 4713");
    if ((toc & kTocDAQmxRawData) != 0) return fail("DAQmx raw data is not supported: save numeric channels");
    const std::size_t body = pos + kLeadInBytes;
    const std::size_t left = bytes_.size() - body;
    const bool incomplete = next_offset == kIncompleteSegment;
    if (!incomplete && next_offset > left) {
      return fail("next segment offset " + std::to_string(next_offset) + " runs past the end of the file (" +
                  std::to_string(left) + " bytes left): truncated segment");
    }
    const std::size_t end = body + (incomplete ? left : static_cast<std::size_t>(next_offset));
    if (raw_offset > end - body) {
      return fail("raw data offset " + std::to_string(raw_offset) + " is beyond the segment's " +
                  std::to_string(end - body) + " bytes");
    }
    const std::size_t raw_begin = body + static_cast<std::size_t>(raw_offset);
    if ((toc & kTocMetaData) != 0) {
      Cursor c(bytes_, body, raw_begin, big_);
      if (Status s = read_metadata(c, toc); !s) return s.error();
    } else if ((toc & kTocNewObjList) != 0) {
      clear_list();
    }
    if ((toc & kTocRawData) != 0) {
      if (Status s = read_raw(raw_begin, end, toc, incomplete); !s) return s.error();
    } else if (end > raw_begin) {
      return fail(std::to_string(end - raw_begin) +
                  " bytes after the metadata but the table of contents says the segment has no raw data");
    }
    pos = end;
  }
  return std::move(file_);
}

}  // namespace

bool is_tdms_path(const std::string& path) {
  if (path.size() < 5) return false;
  std::string ext = path.substr(path.size() - 5);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".tdms";
}

Result<TdmsFile> parse_tdms(std::span<const std::uint8_t> bytes, const std::string& source) {
  TdmsParser parser(bytes, source);
  return parser.run();
}

Result<TdmsFile> read_tdms(const std::string& path) {
  auto bytes = read_input(path, kMaxTdmsBytes);
  if (!bytes) return bytes.error();
  return parse_tdms(std::span(reinterpret_cast<const std::uint8_t*>(bytes->data()), bytes->size()), path);
}

}  // namespace tetra
