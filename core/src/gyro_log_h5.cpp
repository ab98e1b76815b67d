// HDF5 gyro logs: the reader (layout in docs/formats.md): every dataset's shape, type and storage checked
// before its rows are read, after the file passed the check in a child process (gyro_log_h5_probe.cpp).
// One thread at a time uses the HDF5 library here.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "gyro_log_h5_internal.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"

namespace tetra {

using h5io::gyro_name;
using h5io::H5Header;
using h5io::Handle;
using h5io::init_hdf5;
using h5io::kBlockRows;
using h5io::kChunkRows;
using h5io::kFormat;
using h5io::kRefNames;
using h5io::kVersion;
using h5io::read_int_attribute;
using h5io::read_string_attribute;
using h5io::VariableStrings;

namespace {

// --- reading ------------------------------------------------------------------------------------

bool has_filters(hid_t dataset) {
  Handle dcpl(H5Dget_create_plist(dataset), H5Pclose);
  return !dcpl.valid() || H5Pget_nfilters(dcpl.get()) != 0;
}

// The number types a dataset may be stored as (IEEE floats, integers of 8 to 64 bits, either byte
// order): libhdf5 converts these with its own code; other number formats are refused.
bool is_plain_number_type(hid_t type) {
  const std::array<hid_t, 20> plain = {H5T_IEEE_F32LE, H5T_IEEE_F32BE, H5T_IEEE_F64LE, H5T_IEEE_F64BE,
                                       H5T_STD_I8LE,   H5T_STD_I8BE,   H5T_STD_I16LE,  H5T_STD_I16BE,
                                       H5T_STD_I32LE,  H5T_STD_I32BE,  H5T_STD_I64LE,  H5T_STD_I64BE,
                                       H5T_STD_U8LE,   H5T_STD_U8BE,   H5T_STD_U16LE,  H5T_STD_U16BE,
                                       H5T_STD_U32LE,  H5T_STD_U32BE,  H5T_STD_U64LE,  H5T_STD_U64BE};
  return std::any_of(plain.begin(), plain.end(), [&](hid_t t) { return H5Tequal(type, t) > 0; });
}

// [bytes] largest chunk read: tetra's own chunks are 65 536 rows of at most 4096 one-byte or one
// 8-byte column, so 2 MiB per column and 256 MiB for the widest presence dataset.
constexpr hsize_t kMaxChunkBytes = hsize_t{256} << 20;
// Largest ratio deflate reaches (about 1032:1): a compressed dataset declares at most this many times
// its stored bytes (plus one chunk), so a small file never stands for gigabytes of rows.
constexpr hsize_t kMaxDeflateRatio = 1100;

// What tetra reads of a dataset's storage properties: no external files; chunked, contiguous or compact
// (no virtual dataset); deflate and shuffle only. Sets the layout and the number of filters.
Status check_storage_features(hid_t dcpl, const std::string& what, H5D_layout_t& layout, int& nfilters) {
  if (H5Pget_external_count(dcpl) != 0) {
    return bad_input(what + ": stored in external files, which tetra does not read (docs/formats.md)");
  }
  layout = H5Pget_layout(dcpl);
  if (layout != H5D_CHUNKED && layout != H5D_CONTIGUOUS && layout != H5D_COMPACT) {
    return bad_input(what +
                     ": a virtual or unknown storage layout, which tetra does not read (docs/formats.md)");
  }
  nfilters = H5Pget_nfilters(dcpl);
  if (nfilters < 0) return bad_input(what + ": cannot read its filters (damaged file?)");
  for (int f = 0; f < nfilters; ++f) {
    unsigned flags = 0;
    std::size_t nvalues = 0;
    unsigned config = 0;
    std::array<char, 64> name{};
    const H5Z_filter_t filter = H5Pget_filter2(dcpl, static_cast<unsigned>(f), &flags, &nvalues, nullptr,
                                               name.size(), name.data(), &config);
    if (filter != H5Z_FILTER_DEFLATE && filter != H5Z_FILTER_SHUFFLE) {
      return bad_input(what + ": filter " + std::to_string(filter) +
                       ", which tetra does not read (only deflate and shuffle; docs/formats.md)");
    }
  }
  return ok_status();
}

// Every chunk of a chunked dataset written, within the file, whole when unfiltered and with no filter
// skipped; `bytes` are the rows' declared bytes and `stored` what the file holds for them.
Status check_chunks(hid_t id, hid_t dcpl, hsize_t rows, hsize_t cols, int rank, std::size_t type_size,
                    int nfilters, hsize_t bytes, hsize_t stored, hsize_t file_size, const std::string& what) {
  std::array<hsize_t, 2> chunk{};
  if (H5Pget_chunk(dcpl, rank, chunk.data()) != rank || chunk[0] == 0 || (rank == 2 && chunk[1] == 0)) {
    return bad_input(what + ": cannot read its chunk shape (damaged file?)");
  }
  const hsize_t chunk_cols = rank == 2 ? chunk[1] : 1;
  hsize_t chunk_bytes = 0;
  if (__builtin_mul_overflow(chunk[0], chunk_cols, &chunk_bytes) ||
      __builtin_mul_overflow(chunk_bytes, hsize_t{type_size}, &chunk_bytes) || chunk_bytes > kMaxChunkBytes) {
    return bad_input(what + ": chunks of more than " + std::to_string(kMaxChunkBytes) + " bytes");
  }
  const hsize_t row_chunks = (rows - 1) / chunk[0] + 1;
  const hsize_t col_chunks = (cols - 1) / chunk_cols + 1;
  Handle space(H5Dget_space(id), H5Sclose);
  hsize_t allocated = 0;
  if (H5Dget_num_chunks(id, space.get(), &allocated) < 0 || allocated != row_chunks * col_chunks) {
    return bad_input(what + ": " + std::to_string(rows) + " rows declared in " +
                     std::to_string(row_chunks * col_chunks) + " chunks, " + std::to_string(allocated) +
                     " written (damaged or unfinished file?)");
  }
  if (nfilters > 0 && bytes > stored * kMaxDeflateRatio + chunk_bytes) {
    return bad_input(what + ": declares more rows than its compressed chunks can hold (damaged file?)");
  }
  if (nfilters == 0 && stored != allocated * chunk_bytes) {
    return bad_input(what + ": its chunks are not all stored whole (damaged file?)");
  }
  // Every chunk in the file: found by its coordinates, within the file, with no filter skipped.
  for (hsize_t r = 0; r < row_chunks; ++r) {
    for (hsize_t c = 0; c < col_chunks; ++c) {
      const std::array<hsize_t, 2> at{r * chunk[0], c * chunk_cols};
      unsigned mask = 0;
      haddr_t addr = HADDR_UNDEF;
      hsize_t size = 0;
      if (H5Dget_chunk_info_by_coord(id, at.data(), &mask, &addr, &size) < 0 || addr == HADDR_UNDEF ||
          addr > file_size || file_size - addr < size || mask != 0 ||
          (nfilters == 0 && size != chunk_bytes)) {
        return bad_input(what + ": the chunk of row " + std::to_string(at[0] + 1) +
                         " is missing or lies outside the file (damaged file?)");
      }
    }
  }
  return ok_status();
}

// The storage of dataset `id` (`rows`×`cols` elements of `type`) checked against the file's size
// before anything is read or allocated: only what tetra writes (check_storage_features), and every
// row stored in the file (no unwritten chunk whose fill value a read would invent, no 2^40 rows in a
// 7 KB file). `what` names the dataset in messages.
Status check_storage(hid_t id, hid_t type, hsize_t rows, hsize_t cols, int rank, hsize_t file_size,
                     const std::string& what) {
  Handle dcpl(H5Dget_create_plist(id), H5Pclose);
  if (!dcpl.valid()) return bad_input(what + ": cannot read its storage properties (damaged file?)");
  H5D_layout_t layout = H5D_LAYOUT_ERROR;
  int nfilters = 0;
  if (Status st = check_storage_features(dcpl.get(), what, layout, nfilters); !st) return st;
  const std::size_t type_size = H5Tget_size(type);
  hsize_t bytes = 0;  // declared
  if (type_size == 0 || __builtin_mul_overflow(rows, cols, &bytes) ||
      __builtin_mul_overflow(bytes, hsize_t{type_size}, &bytes) ||
      bytes > file_size * kMaxDeflateRatio + kMaxChunkBytes) {
    return bad_input(what + ": declares " + std::to_string(rows) + " rows, more than a file of " +
                     std::to_string(file_size) + " bytes can hold");
  }
  if (rows == 0) return ok_status();
  const hsize_t stored = H5Dget_storage_size(id);
  if (stored > file_size) return bad_input(what + ": its storage is larger than the file (damaged file?)");
  if (layout == H5D_COMPACT) {
    if (stored < bytes) return bad_input(what + ": rows declared but not stored (damaged file?)");
    return ok_status();
  }
  if (layout == H5D_CONTIGUOUS) {
    const haddr_t offset = H5Dget_offset(id);
    if (stored != bytes || offset == HADDR_UNDEF || offset > file_size || file_size - offset < stored) {
      return bad_input(what + ": " + std::to_string(rows) + " rows declared, " + std::to_string(stored) +
                       " bytes stored at the file's offset " + std::to_string(offset) + " (damaged file?)");
    }
    return ok_status();
  }
  return check_chunks(id, dcpl.get(), rows, cols, rank, type_size, nfilters, bytes, stored, file_size, what);
}

// An unfiltered dataset read with no chunk cache: HDF5 then reads the rows straight from the file into
// the caller's buffer (one copy fewer; about 15 % of reading an uncompressed log).
Handle reopen_uncached(hid_t file, const char* name, Handle opened) {
  Handle dapl(H5Pcreate(H5P_DATASET_ACCESS), H5Pclose);
  if (!dapl.valid() ||
      H5Pset_chunk_cache(dapl.get(), H5D_CHUNK_CACHE_NSLOTS_DEFAULT, 0, H5D_CHUNK_CACHE_W0_DEFAULT) < 0) {
    return opened;
  }
  Handle again(H5Dopen2(file, name, dapl.get()), H5Dclose);
  return again.valid() ? std::move(again) : std::move(opened);
}

struct Dataset {
  std::string name;
  Handle id;
  hsize_t cols = 1;  // second dimension of a 2-D dataset
  // Unfiltered chunks of `raw_chunk_rows` rows (a multiple of kBlockRows, at most kChunkRows) stored as
  // `raw_type` (a native type): read whole as raw bytes into `chunk` (H5Dread_chunk, past HDF5's
  // selection and copy), whence the blocks take their rows. Else raw_chunk_rows is 0.
  hsize_t raw_chunk_rows = 0;
  hid_t raw_type = H5I_INVALID_HID;
  std::vector<unsigned char> chunk;
  hsize_t chunk_first = std::numeric_limits<hsize_t>::max();  // first row of the chunk held
};

// Records in `d` whether its chunks can be read raw (see Dataset).
void find_raw_chunks(Dataset& d, int rank) {
  Handle dcpl(H5Dget_create_plist(d.id.get()), H5Pclose);
  if (!dcpl.valid() || H5Pget_layout(dcpl.get()) != H5D_CHUNKED || H5Pget_nfilters(dcpl.get()) != 0) return;
  std::array<hsize_t, 2> chunk{};
  if (H5Pget_chunk(dcpl.get(), rank, chunk.data()) != rank || chunk[0] % kBlockRows != 0 || chunk[0] == 0 ||
      chunk[0] > kChunkRows) {
    return;
  }
  if (rank == 2 && chunk[1] != d.cols) return;
  Handle type(H5Dget_type(d.id.get()), H5Tclose);
  for (const hid_t native : {H5T_NATIVE_DOUBLE, H5T_NATIVE_UINT8}) {
    if (H5Tequal(type.get(), native) > 0) {
      d.raw_chunk_rows = chunk[0];
      d.raw_type = native;
    }
  }
}

// The raw bytes of the chunk that holds rows [first, first + count) in d.chunk, when the dataset
// allows it and they lie in one chunk (false: read them through H5Dread).
bool load_raw_chunk(Dataset& d, hsize_t first, hsize_t count, hid_t mem_type) {
  if (d.raw_chunk_rows == 0 || mem_type != d.raw_type ||
      first / d.raw_chunk_rows != (first + count - 1) / d.raw_chunk_rows) {
    return false;
  }
  const hsize_t chunk_first = first - first % d.raw_chunk_rows;
  if (chunk_first == d.chunk_first) return true;
  const std::array<hsize_t, 2> offset{chunk_first, 0};
  const hsize_t expected = d.raw_chunk_rows * d.cols * H5Tget_size(mem_type);
  hsize_t bytes = 0;
  if (H5Dget_chunk_storage_size(d.id.get(), offset.data(), &bytes) < 0 || bytes != expected) return false;
  d.chunk.resize(static_cast<std::size_t>(expected));
  std::uint32_t filters = 0;
  d.chunk_first = std::numeric_limits<hsize_t>::max();
  if (H5Dread_chunk(d.id.get(), H5P_DEFAULT, offset.data(), &filters, d.chunk.data()) < 0 || filters != 0) {
    return false;
  }
  d.chunk_first = chunk_first;
  return true;
}

class H5Reader final : public GyroLogReader {
 public:
  // A file by name: checked first in a child process (probe_in_child), then opened here.
  Status open(const std::string& path);
  // The file already open as `file` (`file_size` bytes), read in this process: its header is read
  // here when `known` is null (variable-length strings then as `vlen` says).
  Status open_file(Handle file, const std::string& source, const H5Header* known, VariableStrings vlen);
  H5Header header_read() const { return {header_.gyro_count, header_.units_dps, header_.comments}; }
  Result<bool> next(GyroLog& block) override;
  double fraction_read() const override {
    return rows_ == 0 ? 1.0 : static_cast<double>(row_) / static_cast<double>(rows_);
  }
  std::size_t epochs_hint() const override { return static_cast<std::size_t>(rows_); }

 private:
  Result<Dataset> open_dataset(const char* name, int rank, hsize_t cols);
  Status read_rows(const Dataset& d, hsize_t first, hsize_t count, hid_t mem_type, void* out) const;
  Result<const void*> rows_of(Dataset& d, hsize_t count, hid_t mem_type, void* fallback);
  Status read_header(VariableStrings vlen);
  Status use_header(const H5Header& h);
  std::string where(const std::string& dataset, std::size_t row) const {
    return header_.source + ": dataset '" + dataset + "' row " + std::to_string(row + 1) + ": ";
  }
  Status check_block(const GyroLog& block, hsize_t first) const;
  void shape_block(GyroLog& block, std::size_t n) const;
  Status read_gyros(GyroLog& block, hsize_t count);
  Status read_reference(GyroLog& block, hsize_t count);

  Handle file_;
  hsize_t file_size_ = 0;  // [bytes]
  Dataset time_;
  std::vector<Dataset> gyros_;
  Dataset present_;
  std::array<Dataset, 4> ref_{};
  Dataset ref_present_;
  hsize_t rows_ = 0;
  hsize_t row_ = 0;
  std::vector<double> columns_;  // the block's columns of one kind read by H5Dread, side by side, reused
  std::vector<const double*> column_ptrs_;  // each gyro's rows of the block
};

Result<Dataset> H5Reader::open_dataset(const char* name, int rank, hsize_t cols) {
  const std::string& src = header_.source;
  if (H5Lexists(file_.get(), name, H5P_DEFAULT) <= 0) {
    return bad_input(src + ": dataset '" + name + "' is missing (docs/formats.md)");
  }
  Dataset d;
  d.name = name;
  d.id = Handle(H5Dopen2(file_.get(), name, H5P_DEFAULT), H5Dclose);
  if (!d.id.valid()) return bad_input(src + ": dataset '" + name + "' cannot be opened");
  Handle space(H5Dget_space(d.id.get()), H5Sclose);
  std::array<hsize_t, 2> dims{};
  const int got = H5Sget_simple_extent_ndims(space.get());
  if (got == 1 && rank == 2 && cols == 1) rank = 1;  // one gyro's 'present' as tetra wrote it before 2-D
  if (got != rank || H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0) {
    return bad_input(src + ": dataset '" + name + "' has " + std::to_string(got) +
                     " dimension(s), expected " + std::to_string(rank));
  }
  if (rank == 2 && dims[1] != cols) {
    return bad_input(src + ": dataset '" + name + "' has " + std::to_string(dims[1]) + " columns, expected " +
                     std::to_string(cols));
  }
  Handle type(H5Dget_type(d.id.get()), H5Tclose);
  if (!type.valid() || !is_plain_number_type(type.get())) {
    return bad_input(src + ": dataset '" + name +
                     "' is not stored as plain numbers (IEEE floats or integers)");
  }
  if (name != std::string("time_s") && dims[0] != rows_) {
    return bad_input(src + ": dataset '" + name + "' has " + std::to_string(dims[0]) +
                     " rows, 'time_s' has " + std::to_string(rows_));
  }
  if (Status s = check_storage(d.id.get(), type.get(), dims[0], cols, rank, file_size_,
                               src + ": dataset '" + name + "'");
      !s) {
    return s.error();
  }
  if (name == std::string("time_s")) rows_ = dims[0];
  if (!has_filters(d.id.get())) d.id = reopen_uncached(file_.get(), name, std::move(d.id));
  d.cols = cols;
  find_raw_chunks(d, rank);
  return d;
}

Status H5Reader::read_rows(const Dataset& d, hsize_t first, hsize_t count, hid_t mem_type, void* out) const {
  Handle fspace(H5Dget_space(d.id.get()), H5Sclose);
  const std::array<hsize_t, 2> start{first, 0};
  const std::array<hsize_t, 2> size{count, d.cols};
  const int rank = H5Sget_simple_extent_ndims(fspace.get());
  H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, size.data(), nullptr);
  Handle mspace(H5Screate_simple(rank, size.data(), nullptr), H5Sclose);
  if (H5Dread(d.id.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, out) < 0) {
    return bad_input(header_.source + ": dataset '" + d.name + "': cannot read rows " +
                     std::to_string(first + 1) + ".." + std::to_string(first + count) + " (damaged file?)");
  }
  return ok_status();
}

Status H5Reader::read_header(VariableStrings vlen) {
  const std::string& src = header_.source;
  const hid_t root = file_.get();
  const auto format = read_string_attribute(root, "format", src, vlen);
  if (!format) return format.error();
  if (!*format || (*format)->size() != 1 || (*format)->front() != kFormat) {
    return bad_input(src + ": attribute 'format' is not '" + kFormat +
                     "': not a tetra gyro log (docs/formats.md)");
  }
  const auto version = read_int_attribute(root, "version");
  if (!version || *version != kVersion) {
    return bad_input(src + ": attribute 'version': expected " + std::to_string(kVersion));
  }
  const auto count = read_int_attribute(root, "gyro_count");
  if (!count || *count < 1 || *count > 4096) {
    return bad_input(src + ": attribute 'gyro_count': expected an integer from 1 to 4096");
  }
  const auto units = read_string_attribute(root, "units", src, vlen);
  if (!units) return units.error();
  if (!*units || (*units)->size() != 1 || ((*units)->front() != "V" && (*units)->front() != "dps")) {
    return bad_input(src + ": attribute 'units': expected 'V' or 'dps'");
  }
  auto comments = read_string_attribute(root, "comments", src, vlen);
  if (!comments) return comments.error();
  H5Header h;
  h.gyro_count = static_cast<int>(*count);
  h.units_dps = (*units)->front() == "dps";
  if (*comments) h.comments = std::move(**comments);
  return use_header(h);
}

// The header into header_, with the checks every header gets (read here or sent by the child): each
// comment is one line (it becomes a CSV comment line on conversion), and a 'units' entry among the
// comments says what the 'units' attribute says (one rule: the attribute; a conflict is an error).
Status H5Reader::use_header(const H5Header& h) {
  const std::string& src = header_.source;
  header_.gyro_count = h.gyro_count;
  header_.units_dps = h.units_dps;
  header_.comments = h.comments;
  header_.metadata.clear();
  for (std::size_t i = 0; i < h.comments.size(); ++i) {
    if (h.comments[i].find_first_of("\n\r") != std::string::npos) {
      return bad_input(src + ": attribute 'comments' entry " + std::to_string(i + 1) +
                       " holds a line break (a comment is one line)");
    }
    // The metadata is read from the comment lines, as from a CSV's ("metadata" is for other readers).
    parse_metadata_comment(h.comments[i], header_.metadata);
  }
  const std::string units = h.units_dps ? "dps" : "V";
  if (const auto said = last_meta(header_.metadata, "units"); said && *said != units) {
    return bad_input(src + ": attribute 'units' is '" + units + "' but the comments say units=" + *said +
                     " (the attribute and the comments must agree)");
  }
  return ok_status();
}

Status H5Reader::open_file(Handle file, const std::string& source, const H5Header* known,
                           VariableStrings vlen) {
  header_.source = source;
  file_ = std::move(file);
  if (!file_.valid() || H5Fget_filesize(file_.get(), &file_size_) < 0) {
    return bad_input(source + ": cannot open as HDF5");
  }
  if (Status s = known != nullptr ? use_header(*known) : read_header(vlen); !s) return s;
  const auto ng = static_cast<hsize_t>(header_.gyro_count);
  auto time = open_dataset("time_s", 1, 1);
  if (!time) return time.error();
  time_ = std::move(time.value());
  for (std::size_t g = 0; g < ng; ++g) {
    auto d = open_dataset(gyro_name(g).c_str(), 1, 1);
    if (!d) return d.error();
    gyros_.push_back(std::move(d.value()));
  }
  auto present = open_dataset("present", 2, ng);
  if (!present) return present.error();
  present_ = std::move(present.value());
  int refs = 0;
  for (const char* name : kRefNames) refs += H5Lexists(file_.get(), name, H5P_DEFAULT) > 0 ? 1 : 0;
  if (refs != 0 && refs != 4) {
    return bad_input(header_.source + ": reference datasets must be all of ref_qw,ref_qx,ref_qy,ref_qz");
  }
  header_.has_reference = refs == 4;
  if (header_.has_reference) {
    for (std::size_t k = 0; k < 4; ++k) {
      auto d = open_dataset(kRefNames[k], 1, 1);
      if (!d) return d.error();
      ref_[k] = std::move(d.value());
    }
    auto rp = open_dataset("ref_present", 1, 1);
    if (!rp) return rp.error();
    ref_present_ = std::move(rp.value());
  }
  return ok_status();
}

// The whole check of `path` in this process: open, header (variable-length strings included), every
// dataset's shape, type and storage. What the child runs.
Result<H5Header> inspect_here(const std::string& path) {
  if (H5Fis_hdf5(path.c_str()) <= 0) return bad_input(path + ": not an HDF5 file");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.valid()) return bad_input(path + ": cannot open as HDF5");
  H5Reader reader;
  if (Status s = reader.open_file(std::move(file), path, nullptr, VariableStrings::kRead); !s)
    return s.error();
  return reader.header_read();
}

Status H5Reader::open(const std::string& path) {
  init_hdf5();
  header_.source = path;
  if (Status s = check_input(path, kMaxStreamedLogBytes, true); !s) return s;
  const auto header = h5io::probe_in_child(path, inspect_here);
  if (!header) return header.error();
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  return open_file(std::move(file), path, &*header, VariableStrings::kRefuse);
}

Status H5Reader::check_block(const GyroLog& block, hsize_t first) const {
  for (std::size_t r = 0; r < block.epochs(); ++r) {
    if (auto why = log_time_problem(block.time_s[r])) return bad_input(where("time_s", first + r) + *why);
    if (block.has_reference && block.reference_present[r] != 0) {
      const auto& q = block.reference_wxyz[r];
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
        return bad_input(where("ref_qw", first + r) + "reference quaternion is not of unit norm");
      }
    }
  }
  return ok_status();
}

// The block's header fields and column sizes for `n` rows (buffers keep their capacity).
void H5Reader::shape_block(GyroLog& block, std::size_t n) const {
  const auto ng = static_cast<std::size_t>(header_.gyro_count);
  if (block.source != header_.source) {
    block.source = header_.source;
    block.metadata = header_.metadata;
    block.comments = header_.comments;
  }
  block.gyro_count = header_.gyro_count;
  block.units_dps = header_.units_dps;
  block.has_reference = header_.has_reference;
  block.time_s.resize(n);
  block.values.resize(n * ng);
  block.present.resize(n * ng);
  block.lines.resize(n);
  for (std::size_t r = 0; r < n; ++r) block.lines[r] = static_cast<std::size_t>(row_) + r + 1;
  block.reference_wxyz.resize(header_.has_reference ? n : 0);
  block.reference_present.resize(header_.has_reference ? n : 0);
}

// The block's `count` rows of `d` from row_ on: in its raw chunk when it can be read so, else read into
// `fallback` (room for them) through H5Dread.
Result<const void*> H5Reader::rows_of(Dataset& d, hsize_t count, hid_t mem_type, void* fallback) {
  if (load_raw_chunk(d, row_, count, mem_type)) {
    const hsize_t offset = (row_ - d.chunk_first) * d.cols * H5Tget_size(mem_type);
    return static_cast<const void*>(d.chunk.data() + offset);
  }
  if (Status s = read_rows(d, row_, count, mem_type, fallback); !s) return s.error();
  return static_cast<const void*>(fallback);
}

// Copies `bytes` from `from` to `to` unless they are the same place.
void copy_into(void* to, const void* from, std::size_t bytes) {
  if (to != from) std::memcpy(to, from, bytes);
}

// Time and presence into the block; the gyro columns interleaved into epochs (absent samples NaN, as an
// empty CSV cell).
Status H5Reader::read_gyros(GyroLog& block, hsize_t count) {
  const auto n = static_cast<std::size_t>(count);
  const auto ng = static_cast<std::size_t>(header_.gyro_count);
  auto time = rows_of(time_, count, H5T_NATIVE_DOUBLE, block.time_s.data());
  if (!time) return time.error();
  copy_into(block.time_s.data(), *time, n * sizeof(double));
  auto flags = rows_of(present_, count, H5T_NATIVE_UINT8, block.present.data());
  if (!flags) return flags.error();
  copy_into(block.present.data(), *flags, n * ng);
  columns_.resize(n * ng);
  column_ptrs_.resize(ng);
  for (std::size_t g = 0; g < ng; ++g) {
    auto column = rows_of(gyros_[g], count, H5T_NATIVE_DOUBLE, columns_.data() + g * n);
    if (!column) return column.error();
    column_ptrs_[g] = static_cast<const double*>(*column);
  }
  // Plain pointers, and no store through a byte pointer in the copy (it could alias every other one).
  std::uint8_t* present = block.present.data();
  for (std::size_t k = 0; k < n * ng; ++k) present[k] = present[k] != 0 ? 1 : 0;
  double* values = block.values.data();
  const double* const* columns = column_ptrs_.data();
  for (std::size_t r = 0; r < n; ++r) {  // the epochs written in order, the columns read side by side
    for (std::size_t g = 0; g < ng; ++g) values[r * ng + g] = present[r * ng + g] != 0 ? columns[g][r] : kNaN;
  }
  return ok_status();
}

// The four quaternion columns and their presence, interleaved into the block (NaN where absent).
Status H5Reader::read_reference(GyroLog& block, hsize_t count) {
  const auto n = static_cast<std::size_t>(count);
  columns_.resize(n * 4);
  std::array<const double*, 4> column{};
  for (std::size_t k = 0; k < 4; ++k) {
    auto rows = rows_of(ref_[k], count, H5T_NATIVE_DOUBLE, columns_.data() + k * n);
    if (!rows) return rows.error();
    column[k] = static_cast<const double*>(*rows);
  }
  auto flags = rows_of(ref_present_, count, H5T_NATIVE_UINT8, block.reference_present.data());
  if (!flags) return flags.error();
  copy_into(block.reference_present.data(), *flags, n);
  std::uint8_t* present = block.reference_present.data();
  std::array<double, 4>* wxyz = block.reference_wxyz.data();
  for (std::size_t r = 0; r < n; ++r) {
    present[r] = present[r] != 0 ? 1 : 0;
    for (std::size_t k = 0; k < 4; ++k) wxyz[r][k] = present[r] != 0 ? column[k][r] : kNaN;
  }
  return ok_status();
}

Result<bool> H5Reader::next(GyroLog& block) {
  if (row_ >= rows_) return false;
  const hsize_t count = std::min(kBlockRows, rows_ - row_);
  shape_block(block, static_cast<std::size_t>(count));
  if (Status s = read_gyros(block, count); !s) return s.error();
  if (header_.has_reference) {
    if (Status s = read_reference(block, count); !s) return s.error();
  }
  if (Status s = check_block(block, row_); !s) return s.error();
  row_ += count;
  return true;
}

template <class T>
void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

}  // namespace

Result<std::unique_ptr<GyroLogReader>> open_gyro_log_h5_reader(const std::string& path) {
  auto reader = std::make_unique<H5Reader>();
  if (Status s = reader->open(path); !s) return s.error();
  return std::unique_ptr<GyroLogReader>(std::move(reader));
}

namespace {

// Every block of `reader` into one log.
Result<GyroLog> read_whole(GyroLogReader& reader, const std::string& path) {
  GyroLog log = reader.header();
  const std::size_t n = reader.epochs_hint();
  const auto ng = static_cast<std::size_t>(log.gyro_count);
  // A whole log in memory holds no more values than the largest CSV table read whole (2 bytes a cell).
  if (n > kMaxTableBytes / 2 / (ng + 1)) {
    return bad_input(path + ": dataset 'time_s': " + std::to_string(n) + " rows of " + std::to_string(ng) +
                     " gyros are more than a whole log read at once holds (" +
                     std::to_string(kMaxTableBytes / 2) + " values)");
  }
  log.time_s.reserve(n);
  log.values.reserve(n * ng);
  log.present.reserve(n * ng);
  log.lines.reserve(n);
  GyroLog block;
  while (true) {
    auto more = reader.next(block);
    if (!more) return more.error();
    if (!*more) break;
    append(log.time_s, block.time_s);
    append(log.values, block.values);
    append(log.present, block.present);
    append(log.lines, block.lines);
    append(log.reference_wxyz, block.reference_wxyz);
    append(log.reference_present, block.reference_present);
  }
  return log;
}

}  // namespace

Result<GyroLog> read_gyro_log_h5(const std::string& path) {
  auto reader = open_gyro_log_h5_reader(path);
  if (!reader) return reader.error();
  return read_whole(**reader, path);
}

namespace {

// The image opened into `reader` with `header` as the child sent it, reading no attribute.
Status open_image(std::span<const std::uint8_t> bytes, const std::string& name, const GyroLogH5Header& header,
                  H5Reader& reader) {
  init_hdf5();
  if (bytes.empty()) return bad_input(name + ": not an HDF5 file");
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  // The core driver on a copy of the image; nothing is written back.
  if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), std::size_t{1} << 16, 0) < 0 ||
      H5Pset_file_image(fapl.get(), const_cast<std::uint8_t*>(bytes.data()), bytes.size()) < 0) {
    return failure(name + ": cannot open the image");
  }
  Handle file(H5Fopen(name.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  if (!file.valid()) return bad_input(name + ": cannot open as HDF5");
  // As the process that opens a checked file: the header given, no attribute read.
  return reader.open_file(std::move(file), name, &header, VariableStrings::kRefuse);
}

}  // namespace

Status open_gyro_log_h5_image(std::span<const std::uint8_t> bytes, const std::string& name,
                              const GyroLogH5Header& header) {
  H5Reader reader;
  return open_image(bytes, name, header, reader);
}

Result<GyroLog> read_gyro_log_h5_image(std::span<const std::uint8_t> bytes, const std::string& name,
                                       const GyroLogH5Header& header) {
  H5Reader reader;
  if (Status s = open_image(bytes, name, header, reader); !s) return s.error();
  return read_whole(reader, name);
}

}  // namespace tetra
