#pragma once
// TDMS files (the NI "Technical Data Management Streaming" format 2.0, as LabVIEW writes it; docs/formats.md,
// "TDMS"): a sequence of segments, each a 28-byte lead-in, optional metadata (objects with their raw data
// index and properties, given in full or as updates of the previous segment's) and raw data (the channels'
// values, contiguous or interleaved, in chunks). The reader keeps the numeric channels' values as doubles,
// the file's and channels' properties as text. A malformed or hostile file is an Error naming the file,
// the segment (1-based) and its byte offset; allocations are bounded by the file's own size. A log is read
// without holding the file (read_tdms_table).
// The optional ".tdms_index" file is never needed (the .tdms holds the same metadata).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/csv.hpp"
#include "tetra/core/result.hpp"

namespace tetra {

//! [bytes] largest TDMS file read from a FIFO (read whole: it cannot be read twice). A regular file is read
//! piece by piece, its size bounded only by the memory its table takes.
inline constexpr std::size_t kMaxTdmsBytes = std::size_t{1} << 30;

struct TdmsChannel {
  std::string group;            //!< the group's name
  std::string name;             //!< the channel's name
  Metadata properties;          //!< the channel's properties as text, in order of first appearance
  std::uint32_t type = 0;       //!< tdsDataType code of its raw data (0: it never had any)
  bool numeric = false;         //!< integer, floating-point or boolean values (kept in `values`)
  std::vector<double> values;   //!< [channel's unit] every value in file order (numeric channels)
  std::size_t value_count = 0;  //!< values in the file (also for strings and timestamps, not kept)
};

struct TdmsFile {
  std::string source;                 //!< file name used in messages
  Metadata properties;                //!< the file object's ("/") properties as text, in order
  std::vector<TdmsChannel> channels;  //!< in order of first appearance
};

//! True when `path` names a TDMS file (".tdms", any case).
bool is_tdms_path(const std::string& path);

//! Parses a TDMS file image; `source` names it in messages.
Result<TdmsFile> parse_tdms(std::span<const std::uint8_t> bytes, const std::string& source);
//! Reads and parses a file (a regular file, read piece by piece, or a FIFO of at most kMaxTdmsBytes).
Result<TdmsFile> read_tdms(const std::string& path);

//! Which TDMS channels and file properties make a table's columns and "# key=value" metadata when their
//! names differ from the CSV's (docs/formats.md, "TDMS"). Empty: every channel is a column by its own name.
struct TdmsChannelMap {
  std::string source;  //!< the map file's name, for messages ("" when none)
  //! column name ← channel name ("Channel", or "Group/Channel" where several groups hold the name)
  std::vector<std::pair<std::string, std::string>> channels;
  std::vector<std::pair<std::string, std::string>> properties;  //!< metadata key ← file property name
};

//! The channel map beside a TDMS log: "run.tdms" → "run.channels.yaml".
std::string tdms_channel_map_path(const std::string& tdms_path);
//! Parses a channel map (YAML: `channels:` and `properties:` mappings of text); `source` names it.
Result<TdmsChannelMap> parse_tdms_channel_map(const std::string& text, const std::string& source);

//! The table a CSV with the same columns and comments would give: columns = the mapped channels (every
//! channel when the map has none), rows = their values (all columns of equal length, none empty), metadata
//! and comment lines = the file's properties (renamed by the map), `lines` = 1-based rows.
Result<CsvTable> tdms_to_table(const TdmsFile& file, const TdmsChannelMap& map);
//! What read_tdms_table fills besides the cells.
enum class TdmsCells {
  with_flags,   //!< `empty` (all 0) and `lines` (1-based rows), as tdms_to_table
  values_only,  //!< `empty` and `lines` left empty (a reader serving the rows in blocks makes its own)
};
//! The table tdms_to_table gives for the file and the channel map beside it (when there is one), read in
//! two passes: the metadata and value counts, then each column's values decoded straight into its cells
//! (channels that are no column are never read). Memory: the table and a window of about 1 MB of the
//! file. A table that would not fit (more than 3/4 of the address-space limit or of the machine's memory)
//! is an error naming the file before anything is allocated.
Result<CsvTable> read_tdms_table(const std::string& path, TdmsCells cells = TdmsCells::with_flags);
//! The same two passes over a file image in memory with the map given: the table tdms_to_table gives for
//! parse_tdms of the same bytes (the fuzz target compares them).
Result<CsvTable> tdms_image_to_table(std::span<const std::uint8_t> bytes, const std::string& source,
                                     const TdmsChannelMap& map);

}  // namespace tetra
