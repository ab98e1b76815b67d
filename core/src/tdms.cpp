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

#include "tdms_internal.hpp"
#include "tdms_values.hpp"

namespace tetra {

namespace {

using tdms_detail::Cursor;
using tdms_detail::decode;
using tdms_detail::hex_type;
using tdms_detail::is_numeric;
using tdms_detail::kTdsBoolean;
using tdms_detail::kTdsString;
using tdms_detail::kTdsTimeStamp;
using tdms_detail::load_number;
using tdms_detail::timestamp_text;
using tdms_detail::type_size;

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
// Bounds that keep a hostile file's work linear in its size
constexpr std::size_t kMaxChannels = 65536;
constexpr std::uint32_t kMaxPropertiesPerObject = 4096;
constexpr std::uint64_t kMaxMetadataBytes = std::uint64_t{256} << 20;  // one segment's (LabVIEW's: kB)
// [bytes] raw data decoded from one read: memory for the file's bytes stays this, whatever its size
constexpr std::size_t kWindowBytes = std::size_t{1} << 20;

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
  TdmsParser(tdms_detail::Source& src, const std::string& source, tdms_detail::Pass pass,
             const tdms_detail::Fill* fill)
      : src_(src), size_(static_cast<std::size_t>(src.size())), pass_(pass), fill_(fill) {
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
  //! Checks an interleaved segment's objects; their row's bytes and values per chunk.
  Status interleaved_rows(std::size_t& row_bytes, std::uint64_t& count) const;
  //! Where this segment's values go (per place of data_order_: the first value's cell, or nullptr).
  Status value_targets(std::size_t chunks);
  Status decode_contiguous(std::size_t begin, std::size_t chunks);
  Status decode_interleaved(std::size_t begin, std::size_t rows, std::size_t row_bytes);
  //! Bytes [at, at + n) of the file, read through a window of about kWindowBytes.
  Result<const std::uint8_t*> window(std::size_t at, std::size_t n, std::size_t end);
  Status read_segment(std::size_t& pos);
  Result<std::vector<std::string>> split_path(const std::string& path) const;
  Result<std::size_t> channel_for(const std::vector<std::string>& parts, const std::string& path);
  static constexpr std::size_t kNotListed = static_cast<std::size_t>(-1);

  tdms_detail::Source& src_;
  std::size_t size_;
  tdms_detail::Pass pass_;
  const tdms_detail::Fill* fill_;
  TdmsFile file_;
  // The raw data read last (window): file bytes [window_at_, window_at_ + window_n_) at window_data_.
  std::size_t window_at_ = 0;
  std::size_t window_n_ = 0;
  const std::uint8_t* window_data_ = nullptr;
  std::vector<double*> target_;  // per place of data_order_: this segment's first value's cell
  std::size_t target_step_ = 1;  // cells from one value of a channel to the next
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
      if (marker != 28 || !c.get(idx.chunk_bytes) || idx.count > size_ / 4 || idx.chunk_bytes < 4 * idx.count)
        return fail("channel '" + path + "': bad string raw data index");
    } else if (size == 0) {
      return fail("channel '" + path + "': data type " + hex_type(idx.type) + " is not supported");
    } else {
      if (marker != 20)
        return fail("channel '" + path + "': raw data index of " + std::to_string(marker) +
                    " bytes, expected 20");
      if (idx.count > size_ / size) {
        return fail("channel '" + path + "': " + std::to_string(idx.count) +
                    " values per chunk cannot fit in the file");
      }
      idx.chunk_bytes = idx.count * size;
    }
    if (idx.chunk_bytes > size_) return fail("channel '" + path + "': chunk larger than the file");
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

Result<const std::uint8_t*> TdmsParser::window(std::size_t at, std::size_t n, std::size_t end) {
  if (window_data_ != nullptr && at >= window_at_ && at + n <= window_at_ + window_n_)
    return window_data_ + (at - window_at_);
  const std::size_t len = std::max(n, std::min(kWindowBytes, end - at));
  auto data = src_.read(at, len);
  if (!data) return data.error();
  window_at_ = at;
  window_n_ = len;
  window_data_ = *data;
  return *data;
}

Status TdmsParser::interleaved_rows(std::size_t& row_bytes, std::uint64_t& count) const {
  for (const std::size_t place : data_order_) {
    const ListedObject& o = list_[place];
    if (o.index.type == kTdsString) return fail("interleaved raw data holds a text channel");
    if (count != 0 && o.index.count != count) return fail("interleaved channels have different value counts");
    count = o.index.count;
    row_bytes += type_size(o.index.type);
  }
  return ok_status();
}

Status TdmsParser::value_targets(std::size_t chunks) {
  using tdms_detail::Pass;
  target_.assign(data_order_.size(), nullptr);
  target_step_ = pass_ == Pass::keep ? 1 : fill_->stride;
  for (std::size_t i = 0; i < data_order_.size(); ++i) {
    const ListedObject& o = list_[data_order_[i]];
    TdmsChannel& ch = file_.channels[o.channel];
    if (!ch.numeric) continue;
    const std::size_t first = ch.value_count;
    const std::size_t needed = first + chunks * o.index.count;  // bounded by the segment's bytes
    if (pass_ == Pass::keep) {
      // Geometric growth: a stream of many small segments is not copied once per segment.
      if (needed > ch.values.capacity()) ch.values.reserve(std::max(needed, 2 * ch.values.capacity()));
      ch.values.resize(needed);
      target_[i] = ch.values.data() + first;
      continue;
    }
    double* column = o.channel < fill_->column.size() ? fill_->column[o.channel] : nullptr;
    if (column == nullptr) continue;  // not a column: its bytes are never read
    if (needed > fill_->rows) {
      return fail("channel '" + ch.group + "/" + ch.name + "' has more values than " +
                  std::to_string(fill_->rows) + ": the file changed while it was read");
    }
    target_[i] = column + first * target_step_;
  }
  return ok_status();
}

Status TdmsParser::decode_contiguous(std::size_t begin, std::size_t chunks) {
  const std::size_t end = begin + chunks * chunk_bytes_;
  std::size_t at = begin;
  for (std::size_t k = 0; k < chunks; ++k) {
    for (std::size_t i = 0; i < data_order_.size(); ++i) {
      const ListedObject& o = list_[data_order_[i]];
      if (target_[i] != nullptr) {  // a numeric channel: a value has a fixed size
        const std::size_t size = type_size(o.index.type);
        const std::size_t per_read = std::max<std::size_t>(1, kWindowBytes / size);
        double* out = target_[i] + k * o.index.count * target_step_;
        for (std::size_t done = 0, n = 0; done < o.index.count; done += n) {
          n = static_cast<std::size_t>(std::min<std::uint64_t>(per_read, o.index.count - done));
          auto bytes = window(at + done * size, n * size, end);
          if (!bytes) return bytes.error();
          decode(*bytes, n, size, o.index.type, big_, out + done * target_step_, target_step_);
        }
      }
      at += o.index.chunk_bytes;
    }
  }
  return ok_status();
}

Status TdmsParser::decode_interleaved(std::size_t begin, std::size_t rows, std::size_t row_bytes) {
  const std::size_t end = begin + rows * row_bytes;
  const std::size_t per_read = std::max<std::size_t>(1, kWindowBytes / row_bytes);
  for (std::size_t done = 0, n = 0; done < rows; done += n) {
    n = std::min(per_read, rows - done);
    auto bytes = window(begin + done * row_bytes, n * row_bytes, end);
    if (!bytes) return bytes.error();
    std::size_t offset = 0;
    for (std::size_t i = 0; i < data_order_.size(); ++i) {
      const std::uint32_t type = list_[data_order_[i]].index.type;
      if (target_[i] != nullptr)
        decode(*bytes + offset, n, row_bytes, type, big_, target_[i] + done * target_step_, target_step_);
      offset += type_size(type);
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
  const bool interleaved = (toc & kTocInterleavedData) != 0;
  std::size_t row_bytes = 0;
  std::uint64_t per_chunk = 0;
  if (interleaved) {
    if (Status s = interleaved_rows(row_bytes, per_chunk); !s) return s;
  }
  if (pass_ != tdms_detail::Pass::count) {
    if (Status s = value_targets(chunks); !s) return s;
    Status decoded = interleaved ? decode_interleaved(begin, chunks * per_chunk, row_bytes)
                                 : decode_contiguous(begin, chunks);
    if (!decoded) return decoded;
  }
  for (const std::size_t place : data_order_) {
    const ListedObject& o = list_[place];
    file_.channels[o.channel].value_count += chunks * o.index.count;
  }
  return ok_status();
}

Status TdmsParser::read_segment(std::size_t& pos) {
  ++segment_;
  segment_start_ = pos;
  window_data_ = nullptr;  // the source's buffer is read again below
  if (size_ - pos < kLeadInBytes) {
    return fail("truncated lead-in (" + std::to_string(size_ - pos) + " of 28 bytes)");
  }
  auto lead_bytes = src_.read(pos, kLeadInBytes);
  if (!lead_bytes) return lead_bytes.error();
  std::uint8_t lead[kLeadInBytes];
  std::memcpy(lead, *lead_bytes, kLeadInBytes);
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
  const std::size_t left = size_ - body;
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
    if (raw_offset > kMaxMetadataBytes) {
      return fail("metadata of " + std::to_string(raw_offset) + " bytes (at most " +
                  std::to_string(kMaxMetadataBytes) + ")");
    }
    auto meta = src_.read(body, raw_begin - body);
    if (!meta) return meta.error();
    Cursor c(*meta, raw_begin - body, big_);
    if (Status s = read_metadata(c, toc); !s) return s;
  } else if ((toc & kTocNewObjList) != 0) {
    clear_list();
  }
  if ((toc & kTocRawData) != 0) {
    if (Status s = read_raw(raw_begin, end, toc, incomplete); !s) return s;
  } else if (end > raw_begin) {
    return fail(std::to_string(end - raw_begin) +
                " bytes after the metadata but the table of contents says the segment has no raw data");
  }
  pos = end;
  return ok_status();
}

Result<TdmsFile> TdmsParser::run() {
  if (size_ == 0) return bad_input(file_.source + ": empty file: not a TDMS file");
  std::size_t pos = 0;
  while (pos < size_) {
    if (Status s = read_segment(pos); !s) return s.error();
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
  tdms_detail::MemorySource src(bytes);
  return tdms_detail::parse(src, source, tdms_detail::Pass::keep);
}

Result<TdmsFile> read_tdms(const std::string& path) {
  auto src = tdms_detail::open_source(path);
  if (!src) return src.error();
  return tdms_detail::parse(**src, path, tdms_detail::Pass::keep);
}

Result<TdmsFile> tdms_detail::parse(Source& src, const std::string& name, Pass pass, const Fill* fill) {
  if (pass == Pass::fill && fill == nullptr) return failure(name + ": a fill pass needs its cells");
  TdmsParser parser(src, name, pass, fill);
  return parser.run();
}

}  // namespace tetra
