#include "tetra/report/attitude_writer.hpp"

#include <algorithm>
#include <cstring>
#include <span>
#include <utility>

#include "tetra/report/attitude_csv.hpp"

namespace tetra::report {

namespace {
constexpr std::size_t kWriteBytes = std::size_t{1} << 20;  // formatted text written in pieces of ~1 MB
}  // namespace

AttitudeWriter::AttitudeWriter(OutputFile& out, int n_gyros, std::string preamble)
    : out_(out),
      n_gyros_(n_gyros),
      preamble_(std::move(preamble)),
      text_(kWriteBytes + attitude_row_max_bytes(n_gyros), '\0'),
      cells_(n_gyros),
      worker_([this] { run(); }) {
  filling_.rows.reserve(kBatchRows);
}

AttitudeWriter::~AttitudeWriter() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
    done_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
}

Status AttitudeWriter::error() const {
  const std::lock_guard lock(mutex_);
  return status_;
}

// The estimate's fields are copied into the batch's storage; its bias vector goes into the batch's flat
// `biases` (N per row), so a row costs no allocation and no vector assignment.
Status AttitudeWriter::add(double time_s, const fdi::AttitudeEstimate& attitude) {
  if (filling_.used == filling_.rows.size()) {
    filling_.rows.emplace_back();
    filling_.biases.resize(filling_.rows.size() * static_cast<std::size_t>(n_gyros_));
  }
  const std::size_t k = filling_.used++;
  Row& row = filling_.rows[k];
  row.time_s = time_s;
  row.attitude.q_RB = attitude.q_RB;
  row.attitude.omega_BR_B_rad_s = attitude.omega_BR_B_rad_s;
  row.attitude.sigma_rad = attitude.sigma_rad;
  row.attitude.protection_level_rad = attitude.protection_level_rad;
  row.attitude.mode = attitude.mode;
  row.attitude.gyros = attitude.gyros;
  row.has_biases = static_cast<int>(attitude.gyro_bias_rad_s.size()) == n_gyros_;
  if (row.has_biases) {
    std::copy(attitude.gyro_bias_rad_s.begin(), attitude.gyro_bias_rad_s.end(),
              filling_.biases.begin() + static_cast<std::ptrdiff_t>(k * static_cast<std::size_t>(n_gyros_)));
  }
  if (filling_.used < kBatchRows) return ok_status();
  return hand_over();
}

// Queues the filled batch (waiting while kDepth batches are queued) and takes a spare one to fill.
Status AttitudeWriter::hand_over() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return queue_.size() < kDepth || !status_; });
  if (!status_) return status_;
  queue_.push_back(std::move(filling_));
  filling_ = Batch{};
  if (!spare_.empty()) {
    filling_ = std::move(spare_.back());
    spare_.pop_back();
  }
  filling_.used = 0;
  filling_.rows.reserve(kBatchRows);
  lock.unlock();
  changed_.notify_all();
  return ok_status();
}

Status AttitudeWriter::finish() {
  if (filling_.used > 0) {
    if (Status s = hand_over(); !s) return s;
  }
  {
    const std::lock_guard lock(mutex_);
    done_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
  return error();
}

// Rows are formatted straight into text_ (room for one more row past kWriteBytes), written out in
// pieces of about kWriteBytes.
Status AttitudeWriter::write_batch(const Batch& batch) {
  for (std::size_t i = 0; i < batch.used; ++i) {
    const Row& row = batch.rows[i];
    const auto n = static_cast<std::size_t>(n_gyros_);
    const std::span<const double> biases =
        row.has_biases ? std::span<const double>(batch.biases).subspan(i * n, n) : std::span<const double>();
    char* end = format_attitude_row(text_.data() + text_used_, row.time_s, row.attitude, biases, n_gyros_,
                                    cells_.cell(row.attitude.gyros));
    text_used_ = static_cast<std::size_t>(end - text_.data());
    if (text_used_ < kWriteBytes) continue;
    if (Status s = write_text(); !s) return s;
  }
  return ok_status();
}

Status AttitudeWriter::write_text() {
  const Status s = out_.write(std::string_view(text_.data(), text_used_));
  text_used_ = 0;
  return s;
}

void AttitudeWriter::run() {
  // The preamble goes out with the first rows (a run that fails before them writes nothing, as on
  // standard output a failed run should); one longer than the buffer is written at once.
  if (preamble_.size() <= kWriteBytes) {
    std::memcpy(text_.data(), preamble_.data(), preamble_.size());
    text_used_ = preamble_.size();
  } else if (Status s = out_.write(preamble_); !s) {
    const std::lock_guard lock(mutex_);
    status_ = s;
    changed_.notify_all();
    return;
  }
  while (true) {
    Batch batch;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty() || done_; });
      if (stop_ || queue_.empty()) break;
      batch = std::move(queue_.front());
      queue_.pop_front();
    }
    changed_.notify_all();
    const Status written = write_batch(batch);
    const std::lock_guard lock(mutex_);
    if (spare_.size() < kDepth) spare_.push_back(std::move(batch));
    if (!written) {
      status_ = written;
      break;
    }
  }
  {
    const std::lock_guard lock(mutex_);
    if (stop_ || !status_) {
      changed_.notify_all();
      return;
    }
  }
  if (Status s = write_text(); !s) {
    const std::lock_guard lock(mutex_);
    status_ = s;
  }
}

}  // namespace tetra::report
