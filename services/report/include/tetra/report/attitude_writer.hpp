#pragma once
// Attitude rows (attitude_csv.hpp) formatted and written on a worker thread: formatting numbers in
// shortest round-trip form and writing them to the file cost about three quarters of the pipeline step
// (16 numbers a row; docs/formats.md, "Replay throughput"), so the caller hands over the estimates in
// batches and goes on. At most kDepth batches wait (bounded memory); the file is the one
// append_attitude_row would give, byte for byte.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tetra/core/output_files.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/report/attitude_csv.hpp"

namespace tetra::report {

class AttitudeWriter {
 public:
  static constexpr std::size_t kBatchRows = 4096;
  static constexpr std::size_t kDepth = 4;

  //! Writes `preamble` (comment lines and the header) first, then the rows as they come.
  AttitudeWriter(OutputFile& out, int n_gyros, std::string preamble);
  AttitudeWriter(const AttitudeWriter&) = delete;
  AttitudeWriter& operator=(const AttitudeWriter&) = delete;
  //! Stops the worker; rows not finished are dropped (the run failed).
  ~AttitudeWriter();

  //! One row stamped `time_s` [s]. A failed write of an earlier batch is returned here (or by finish()).
  Status add(double time_s, const fdi::AttitudeEstimate& attitude);
  //! Writes every row added and stops the worker; the first write error, if any.
  Status finish();

 private:
  struct Row {
    double time_s = 0.0;
    fdi::AttitudeEstimate attitude;  // its bias vector stays empty: the biases are the batch's
    bool has_biases = false;         // the estimate carried N biases (else they are written nan)
  };
  // Rows are assigned in place (rows[used] = ...), never pushed, and row k's biases are biases[k*N ..
  // k*N+N): a refilled batch reuses its storage, so a batch costs no allocation after its first use.
  struct Batch {
    std::vector<Row> rows;
    std::vector<double> biases;
    std::size_t used = 0;
  };

  Status hand_over();
  Status error() const;
  void run();
  Status write_batch(const Batch& batch);
  Status write_text();

  OutputFile& out_;
  const int n_gyros_;
  std::string preamble_;       // worker: written first
  std::string text_;           // worker: formatted rows not yet written, text_used_ bytes of it
  std::size_t text_used_ = 0;  // (its size is fixed: one row's room past kWriteBytes)
  GyrosCellCache cells_;       // worker
  Batch filling_;              // caller: the batch being filled
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Batch> queue_;
  std::vector<Batch> spare_;  // written batches, to be refilled (no allocation per batch)
  Status status_ = ok_status();
  bool done_ = false;  // no more batches will come
  bool stop_ = false;  // drop what is left
  std::thread worker_;
};

}  // namespace tetra::report
