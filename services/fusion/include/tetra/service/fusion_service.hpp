#pragma once
// The fusion service of `tetra fusion` (docs/dds.md): the pipeline of `tetra replay` on DDS. A library:
// the command runs it until SIGINT/SIGTERM, a test runs it in a thread and stops it with request_stop().
//
// Reads GyroSample, AttitudeReference and Command of its unit; writes Attitude (every accepted
// epoch), Health (every `health_period_s` and on every change) and FdiEvent (pipeline events and
// command acknowledgements). One waitset drives everything but the gyro samples themselves: the
// reference and command readers, the gyro reader's statuses (deadline, liveliness, matches), the
// latency limit of the oldest open epoch, silent gyros, the Health period, and a stop (request_stop()
// or, when asked for, SIGINT/SIGTERM).
// Gyro samples are handed to the same code by a data-available listener on Cyclone's receive thread
// (`gyro_dispatch: listener`, the default: an epoch is fused and its Attitude written without a
// thread wake-up) or by the waitset (`gyro_dispatch: waitset`). One mutex serializes the two threads.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/result.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/dds/entity.hpp"
#include "tetra/dds/ros2_view.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/fdi/pipeline.hpp"
#include "tetra/service/duplicate_watch.hpp"
#include "tetra/service/epoch_assembler.hpp"
#include "tetra/service/fusion_config.hpp"

namespace tetra::service {

//! One unit's service: open() creates its DDS entities, run() serves until a stop (or a DDS failure,
//! returned as an error) and publishes a last Health.
class FusionService {
 public:
  //! [s] wall clock: every gyro silent this long is reported as a `lost` event (shorter: counted only).
  static constexpr double kMinOutageReported_s = 2.0;
  FusionService(FusionConfig config, fdi::Pipeline pipeline, EpochAssembler assembler)
      : config_(std::move(config)),
        pipeline_(std::move(pipeline)),
        assembler_(std::move(assembler)),
        n_gyros_(pipeline_.gyro_count()),
        last_arrival_ns_(static_cast<std::size_t>(n_gyros_), 0) {}
  ~FusionService() { stop_listener(); }
  FusionService(const FusionService&) = delete;
  FusionService& operator=(const FusionService&) = delete;

  //! Participant, topics, readers, writers and the waitset on `domain`. With `shutdown`, SIGINT and
  //! SIGTERM stop run() too (it must outlive the service). Fails, before anything is written, when
  //! another service of the unit answers on the domain (duplicate_watch.hpp); run() fails when one
  //! appears later.
  Status open(dds_domainid_t domain, dds::ShutdownSignal* shutdown = nullptr);
  //! Serves until a stop is requested (request_stop(), or a signal through open()'s `shutdown`).
  Status run();
  //! Ends run() (from any thread; before run(), run() returns at once after its first Health).
  void request_stop();

 private:
  bool listener_dispatch() const { return config_.gyro_dispatch == GyroDispatch::kListener; }
  //! The check for another service of the unit (duplicate_watch.hpp), before any endpoint exists.
  Status open_duplicate_watch(dds_domainid_t domain);
  Status open_endpoints();
  Status open_waitset();
  bool stopping() const { return stop_requested_.load() || (shutdown_ != nullptr && shutdown_->requested()); }
  //! The gyro reader's listener, on Cyclone's receive thread.
  static void on_gyro_data(dds_entity_t reader, void* self);
  //! Removes the listener; returns once no callback runs (call without holding mutex_).
  void stop_listener();
  Status loop();
  //! --realtime (config_.realtime_priority): memory locked, this (the waitset) thread under SCHED_FIFO;
  //! what fails is warned about and the service goes on.
  void apply_realtime();
  static void make_step_thread_realtime(int priority, const char* thread);
  //! Everything a waitset wake-up calls for: statuses, samples, commands, deadlines, timers.
  Status handle_wakeup(const std::vector<std::intptr_t>& triggered, std::int64_t now_ns);
  //! The gyro reader's statuses: sets `deadline_missed`, `matched_changed`.
  Status take_gyro_statuses(bool& deadline_missed, bool& matched_changed);
  //! Takes gyro samples and references, and fuses the epochs they complete.
  Status ingest(std::int64_t now_ns);
  //! [ns] the next time the waitset thread has work without any sample arriving.
  std::int64_t next_wake_ns(std::int64_t now_ns) const;
  Status take_gyro_samples(std::int64_t now_ns);
  Status take_references();
  void warn_other_unit(std::int64_t now_ns);
  Status take_commands();
  //! Marks gyros silent for the deadline absent; true if any became absent.
  bool check_deadlines(std::int64_t now_ns, bool dds_reported);
  Status process_epochs(std::int64_t now_ns);
  Status publish_event(const fdi::FdiEvent& event, std::uint64_t command_id, const dds::CommandAudit& audit);
  //! An event when every gyro has gone silent, and when samples come back.
  Status report_silence(std::int64_t now_ns);
  //! A `reference_late` event for the first of a run of late references crowded out in the assembler.
  Status report_crowded_out(const CrowdedOutReference& crowded);
  Status publish_health(std::int64_t now_ns, bool force);
  //! The health to publish, into `out` (its storage is reused).
  void current_health(fdi::Health& out) const;

  //! Serializes the waitset thread and the gyro listener: every member below is used under it.
  std::mutex mutex_;
  FusionConfig config_;
  fdi::Pipeline pipeline_;
  EpochAssembler assembler_;
  int n_gyros_;
  std::int64_t deadline_ns_ = 0;  //!< [ns] 3 sample periods
  std::int64_t started_ns_ = 0;   //!< [ns] local time the service started
  static constexpr std::int64_t kOtherUnitWarnPeriod_ns = 10'000'000'000;
  std::string other_unit_heard_;               //!< the last other unit a GyroSample was heard for
  std::uint64_t own_samples_ = 0;              //!< GyroSamples for this unit, ever
  std::uint64_t own_at_warning_ = 0;           //!< own_samples_ at the last check
  std::uint64_t other_at_warning_ = 0;         //!< samples_other_unit at the last check
  std::int64_t next_other_warning_ns_ = 0;     //!< [ns] local time before which no other-unit warning
  std::int64_t resumed_ns_ = 0;                //!< [ns] local time the unit last resumed after silence
  std::vector<std::int64_t> last_arrival_ns_;  //!< [ns] local time of each gyro's last sample
  std::int64_t next_health_ns_ = 0;
  std::optional<fdi::Health> last_health_;  //!< as last published
  fdi::Health health_scratch_;              //!< reused for each comparison
  std::uint64_t event_seq_ = 0;
  std::uint32_t gyro_writers_ = 0;  //!< matched GyroSample writers (published in Health)
  std::uint64_t last_restarts_ = 0;
  bool all_silent_ = false;           //!< every gyro absent since silent_since_ns_ (after a first epoch)
  bool lost_reported_ = false;        //!< the silence lasted kMinOutageReported_s: a `lost` event went out
  std::int64_t silent_since_ns_ = 0;  //!< [ns] local monotonic time
  std::uint64_t unit_silences_ = 0;   //!< outages of every gyro, in Health's counters
  bool fused_any_ = false;            //!< an epoch has been fused (commands are stamped with its time)
  std::vector<fdi::Epoch> epochs_;
  std::int64_t scheduled_wake_ns_ = 0;   //!< [ns] when the waitset thread wakes by itself next
  std::optional<Error> listener_error_;  //!< a failure inside the listener, for run() to return
  bool listening_ = false;
  bool listener_realtime_ = false;  //!< --realtime applied to the listener's thread (its first callback)

  std::atomic<bool> stop_requested_{false};
  dds::ShutdownSignal* shutdown_ = nullptr;  //!< SIGINT/SIGTERM stop run() too (optional)
  std::optional<dds::Session> session_;
  std::optional<dds::Reader<tetra_GyroSample>> gyro_reader_;
  std::optional<dds::Reader<tetra_AttitudeReference>> reference_reader_;
  std::optional<dds::Reader<tetra_Command>> command_reader_;
  std::optional<dds::Writer<tetra_Attitude>> attitude_writer_;
  std::optional<dds::Writer<tetra_Health>> health_writer_;
  std::optional<dds::Writer<tetra_FdiEvent2>> event_writer_;
  dds::WireEvent event_wire_;                 //!< the event being written, its ledger rows' storage with it
  std::optional<dds::Ros2View> ros2_view_;    //!< `ros2: enabled: true` (docs/ros2.md)
  std::optional<DuplicateWatch> duplicates_;  //!< another service of this unit on the domain
  const dds::Condition* wake_ = nullptr;  //!< the listener wakes the waitset thread for an epoch's deadline
  std::atomic<const dds::Condition*> stop_{nullptr};  //!< request_stop() wakes the waitset thread
};

}  // namespace tetra::service
