// HDF5 gyro logs: the writer (layout in docs/formats.md). One thread at a time uses the HDF5 library here.
#include <algorithm>
#include <cstring>

#include "gyro_log_h5_internal.hpp"
#include "tetra/core/csv.hpp"

namespace tetra {

using h5io::gyro_name;
using h5io::Handle;
using h5io::init_hdf5;
using h5io::kChunkRows;
using h5io::kDeflateLevel;
using h5io::kFormat;
using h5io::kRefNames;
using h5io::kVersion;
using h5io::write_int_attribute;
using h5io::write_string_attribute;

struct GyroLogH5Writer::Impl {
  std::string path;  // the output's name, for messages
  Handle file;
  int gyro_count = 0;
  bool with_reference = false;
  bool compress = false;
  hsize_t rows = 0;  // rows written to the file
  // Rows buffered for the next chunk.
  std::vector<double> time_s;
  std::vector<std::vector<double>> gyro;  // per gyro
  std::vector<std::uint8_t> present;      // rows×N
  std::array<std::vector<double>, 4> ref;
  std::vector<std::uint8_t> ref_present;

  Status create_dataset(const char* name, hid_t type, hsize_t cols) const;
  Status append_rows(const char* name, hid_t mem_type, const void* data, hsize_t count, hsize_t cols) const;
  Status flush();
};

namespace {
// 'present' is rows×N, 2-D even for one gyro (docs/formats.md); the other datasets are 1-D.
int rank_of(const char* name) {
  return std::strcmp(name, "present") == 0 ? 2 : 1;
}
}  // namespace

Status GyroLogH5Writer::Impl::create_dataset(const char* name, hid_t type, hsize_t cols) const {
  const int rank = rank_of(name);
  const std::array<hsize_t, 2> dims{0, cols};
  const std::array<hsize_t, 2> max{H5S_UNLIMITED, cols};
  const std::array<hsize_t, 2> chunk{kChunkRows, cols};
  Handle space(H5Screate_simple(rank, dims.data(), max.data()), H5Sclose);
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(plist.get(), rank, chunk.data());
  if (compress) {
    H5Pset_shuffle(plist.get());
    H5Pset_deflate(plist.get(), kDeflateLevel);
  }
  Handle d(H5Dcreate2(file.get(), name, type, space.get(), H5P_DEFAULT, plist.get(), H5P_DEFAULT), H5Dclose);
  if (!d.valid()) return failure(path + ": cannot create dataset '" + name + "'");
  return ok_status();
}

Status GyroLogH5Writer::Impl::append_rows(const char* name, hid_t mem_type, const void* data, hsize_t count,
                                          hsize_t cols) const {
  Handle d(H5Dopen2(file.get(), name, H5P_DEFAULT), H5Dclose);
  const int rank = rank_of(name);
  const std::array<hsize_t, 2> new_dims{rows + count, cols};
  if (!d.valid() || H5Dset_extent(d.get(), new_dims.data()) < 0) {
    return failure(path + ": dataset '" + name + "': cannot extend");
  }
  Handle fspace(H5Dget_space(d.get()), H5Sclose);
  const std::array<hsize_t, 2> start{rows, 0};
  const std::array<hsize_t, 2> size{count, cols};
  H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, size.data(), nullptr);
  Handle mspace(H5Screate_simple(rank, size.data(), nullptr), H5Sclose);
  if (H5Dwrite(d.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, data) < 0) {
    return failure(path + ": dataset '" + name + "': write failed");
  }
  return ok_status();
}

Status GyroLogH5Writer::Impl::flush() {
  const hsize_t count = time_s.size();
  if (count == 0) return ok_status();
  const auto ng = static_cast<hsize_t>(gyro_count);
  if (Status s = append_rows("time_s", H5T_NATIVE_DOUBLE, time_s.data(), count, 1); !s) return s;
  for (std::size_t g = 0; g < gyro.size(); ++g) {
    if (Status s = append_rows(gyro_name(g).c_str(), H5T_NATIVE_DOUBLE, gyro[g].data(), count, 1); !s)
      return s;
    gyro[g].clear();
  }
  // A 2-D dataset of one column is still 2-D: rank follows the dataset, so write it as rows×1.
  if (Status s = append_rows("present", H5T_NATIVE_UINT8, present.data(), count, ng); !s) return s;
  if (with_reference) {
    for (std::size_t k = 0; k < 4; ++k) {
      if (Status s = append_rows(kRefNames[k], H5T_NATIVE_DOUBLE, ref[k].data(), count, 1); !s) return s;
      ref[k].clear();
    }
    if (Status s = append_rows("ref_present", H5T_NATIVE_UINT8, ref_present.data(), count, 1); !s) return s;
    ref_present.clear();
  }
  rows += count;
  time_s.clear();
  present.clear();
  return ok_status();
}

GyroLogH5Writer::GyroLogH5Writer() = default;

GyroLogH5Writer::~GyroLogH5Writer() = default;

Status GyroLogH5Writer::open(const std::string& file_path, const std::string& path, int gyro_count,
                             bool with_reference, const std::vector<std::string>& comments, bool compress) {
  if (impl_ && impl_->file.valid()) return failure(path + ": writer already open");
  if (gyro_count < 1) return bad_input(path + ": a gyro log needs at least one gyro column");
  init_hdf5();
  impl_ = std::make_unique<Impl>();
  Impl& w = *impl_;
  w.path = path;
  w.gyro_count = gyro_count;
  w.with_reference = with_reference;
  w.compress = compress;
  w.gyro.resize(static_cast<std::size_t>(gyro_count));
  // Object headers of HDF5 1.8 on: a string attribute larger than 64 KiB (many comment lines) is then
  // stored densely instead of failing.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) < 0) {
    return failure(path + ": cannot set up the HDF5 library");
  }
  w.file = Handle(H5Fcreate(file_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose);
  if (!w.file.valid()) return failure(path + ": cannot write: " + std::strerror(errno));

  Metadata metadata;
  for (const std::string& c : comments) parse_metadata_comment(c, metadata);
  std::vector<std::string> meta;
  for (const auto& [k, v] : metadata) meta.push_back(k + "=" + v);
  const auto meta_units = last_meta(metadata, "units");
  const bool dps = meta_units && *meta_units == "dps";
  const hid_t root = w.file.get();
  bool ok = write_string_attribute(root, "format", {kFormat}, true) &&
            write_int_attribute(root, "version", kVersion) &&
            write_int_attribute(root, "gyro_count", gyro_count) &&
            write_string_attribute(root, "units", {dps ? "dps" : "V"}, true);
  if (ok && !comments.empty()) ok = write_string_attribute(root, "comments", comments, false);
  if (ok && !meta.empty()) ok = write_string_attribute(root, "metadata", meta, false);
  if (!ok) return failure(path + ": cannot write the attributes");

  const auto ng = static_cast<hsize_t>(gyro_count);
  if (Status s = w.create_dataset("time_s", H5T_IEEE_F64LE, 1); !s) return s;
  for (std::size_t g = 0; g < w.gyro.size(); ++g) {
    if (Status s = w.create_dataset(gyro_name(g).c_str(), H5T_IEEE_F64LE, 1); !s) return s;
  }
  if (Status s = w.create_dataset("present", H5T_STD_U8LE, ng); !s) return s;
  if (with_reference) {
    for (const char* name : kRefNames) {
      if (Status s = w.create_dataset(name, H5T_IEEE_F64LE, 1); !s) return s;
    }
    if (Status s = w.create_dataset("ref_present", H5T_STD_U8LE, 1); !s) return s;
  }
  return ok_status();
}

Status GyroLogH5Writer::write(double time_s, std::span<const double> values,
                              std::span<const std::uint8_t> present,
                              const std::optional<std::array<double, 4>>& reference_wxyz) {
  if (!impl_ || !impl_->file.valid()) return failure("gyro log writer is not open");
  Impl& w = *impl_;
  if (values.size() != static_cast<std::size_t>(w.gyro_count) || present.size() != values.size()) {
    return failure(w.path + ": epoch has the wrong number of gyro values");
  }
  w.time_s.push_back(time_s);
  for (std::size_t g = 0; g < values.size(); ++g) {
    w.gyro[g].push_back(present[g] != 0 ? values[g] : kNaN);
    w.present.push_back(present[g] != 0 ? 1 : 0);
  }
  if (w.with_reference) {
    for (std::size_t k = 0; k < 4; ++k) w.ref[k].push_back(reference_wxyz ? (*reference_wxyz)[k] : kNaN);
    w.ref_present.push_back(reference_wxyz ? 1 : 0);
  }
  if (w.time_s.size() >= kChunkRows) return w.flush();
  return ok_status();
}

Status GyroLogH5Writer::close() {
  if (!impl_ || !impl_->file.valid()) return failure("gyro log writer is not open");
  Impl& w = *impl_;
  const Status flushed = w.flush();
  const bool closed = H5Fclose(w.file.release()) >= 0;
  if (!flushed) return flushed;
  if (!closed) return failure(w.path + ": write failed");
  return ok_status();
}

}  // namespace tetra
