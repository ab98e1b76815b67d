// tetra.dds (docs/python.md, "DDS"): a Python simulator on the wire through the project's own DDS layer —
// gyro epochs out (tetra play's link: services/player, lockstep included), attitude references out, the
// service's Attitude, Health and FdiEvent in, operator commands (tetra command's sender). python/tetra/dds.py
// wraps these classes. Every wait releases the GIL and polls Python's signals (Ctrl-C) at least every 10 ms
// through a Watch, and is bounded by a timeout.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "common.hpp"
#include "dds_values.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/clock.hpp"
#include "tetra/dds/session.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/dds_tools/command.hpp"
#include "tetra/player/player_link.hpp"
#include "tetra/service/unit_name.hpp"
#include "watch.hpp"

namespace tetra::python {

namespace {

using namespace pybind11::literals;

dds_domainid_t domain_id(std::optional<int> domain) {
  if (!domain) return DDS_DOMAIN_DEFAULT;
  if (*domain < 0 || *domain > 232)
    throw py::value_error("domain: " + std::to_string(*domain) + " is not a DDS domain id (0..232)");
  return static_cast<dds_domainid_t>(*domain);
}

std::int64_t timeout_ns(double timeout_s, const char* name) {
  if (!(timeout_s >= 0.0) || timeout_s > 1e6)
    throw py::value_error(std::string(name) + ": " + std::to_string(timeout_s) +
                          " is not a timeout in [0, 1e6] s");
  return seconds_to_ns(timeout_s);
}

void check_unit(const std::string& unit) {
  check(service::check_unit_name(unit, "unit"));
}

[[noreturn]] void raise_timeout(const std::string& message) {
  PyErr_SetString(PyExc_TimeoutError, message.c_str());
  throw py::error_already_set();
}

// One method call's hold on a tetra.dds object, taken with the GIL held: a second call while one runs (from
// another thread, while the first has released the GIL) raises RuntimeError instead of sharing its state.
class InUse {
 public:
  InUse(bool& busy, const char* what) : busy_(busy) {
    if (busy_) {
      throw std::runtime_error(
          std::string(what) +
          ": another call is running on this object (in another thread); it serves one call "
          "at a time: give each thread its own, or hold a threading.Lock around the calls");
    }
    busy_ = true;
  }
  InUse(const InUse&) = delete;
  InUse& operator=(const InUse&) = delete;
  ~InUse() { busy_ = false; }

 private:
  bool& busy_;
};

// Runs `work` with the GIL released while `slot` points at a Watch over Python's signal handlers (the
// link's stop poll asks it), then raises what stopped it (KeyboardInterrupt) before any error of `work`.
template <class Work>
auto watched(Watch*& slot, Work&& work) {
  Watch watch{py::none()};
  slot = &watch;
  struct Clear {
    Watch*& s;
    ~Clear() { s = nullptr; }
  } clear{slot};
  auto result = [&] {
    py::gil_scoped_release release;
    return work();
  }();
  watch.raise_if_stopped();
  return result;
}

// The gyro stream of one unit: tetra play's link (publish, lockstep wait) and the attitudes it hears.
class GyroLink {
 public:
  GyroLink(const std::string& unit, int gyros, double rate_hz, std::optional<int> domain, bool lockstep,
           bool reference, int wait_readers, double timeout_s)
      : unit_(unit), n_(gyros), lockstep_(lockstep) {
    check_unit(unit);
    if (gyros < 1 || gyros > dds::kMaxGyrosOnWire)
      throw py::value_error("gyros: " + std::to_string(gyros) + " is not in 1.." +
                            std::to_string(dds::kMaxGyrosOnWire));
    if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
      throw py::value_error("rate_hz: expected a positive sample rate [Hz]");
    player::PlayOptions options;
    options.domain = domain_id(domain);
    options.speed = lockstep ? 0.0 : 1.0;
    options.wait_readers = wait_readers;
    options.wait_timeout_s = static_cast<double>(timeout_ns(timeout_s, "timeout_s")) * 1e-9;
    raw_.resize(static_cast<std::size_t>(n_));
    present_.resize(static_cast<std::size_t>(n_));
    auto opened = watched(watch_, [&] {
      return player::PlayerLink::open(unit, rate_hz, reference, options, nullptr,
                                      [this] { return watch_ != nullptr && watch_->poll(0, 0); });
    });
    link_ = take(std::move(opened));
    if (lockstep_) link_->require_one_attitude_writer();  // a second service would mix into the run
  }

  // One epoch on the wire; returns its stamp [ns].
  std::int64_t send(const py::handle& time_s, const py::handle& raw, const py::object& present,
                    const py::object& reference_wxyz) {
    const InUse in_use(busy_, "GyroPublisher.send");
    return publish(time_s, raw, present, reference_wxyz);
  }

  // Lockstep: the epoch on the wire and its Attitude back.
  py::dict step(const py::handle& time_s, const py::handle& raw, const py::object& present,
                const py::object& reference_wxyz, double timeout_s) {
    const InUse in_use(busy_, "Lockstep.step");
    if (!lockstep_) throw py::value_error("step: the publisher was opened with lockstep=False");
    const std::int64_t wait_ns = timeout_ns(timeout_s, "timeout_s");
    const std::int64_t stamp = publish(time_s, raw, present, reference_wxyz);
    auto came = watched(watch_, [&] { return link_->wait_for_stamp(stamp, wait_ns, newest_, sink()); });
    if (!take(std::move(came))) {
      raise_timeout("no Attitude of unit '" + unit_ + "' for the epoch at " +
                    std::to_string(ns_to_seconds(stamp)) + " s within " + std::to_string(timeout_s) +
                    " s: is `tetra fusion` running for this unit on this domain? (an epoch the service "
                    "rejects gets none: see its Health counters)");
    }
    return attitude_of(stamp);
  }

  // Every Attitude of the unit received and not yet taken, oldest first; waits up to `timeout_s` for one.
  py::list attitudes(double timeout_s) {
    const InUse in_use(busy_, "GyroPublisher.attitudes");
    const std::int64_t give_up = dds::monotonic_ns() + timeout_ns(timeout_s, "timeout_s");
    check(watched(watch_, [&] {
      Status s = link_->take_attitudes(sink());
      while (s && received_.empty() && dds::monotonic_ns() < give_up && !link_->stop_requested()) {
        s = link_->wait_until(give_up);
        if (s) s = link_->take_attitudes(sink());
      }
      return s;
    }));
    py::list out;
    for (const auto& a : received_) out.append(wire_attitude_dict(a, n_));
    received_.clear();
    return out;
  }

  void wait_for_acks() {
    const InUse in_use(busy_, "GyroPublisher.flush");
    watched(watch_, [&] {
      link_->wait_for_acks();
      return 0;
    });
  }

  const std::string& unit() const { return unit_; }
  int gyro_count() const { return n_; }
  bool lockstep() const { return lockstep_; }

 private:
  std::int64_t publish(const py::handle& time_s, const py::handle& raw, const py::object& present,
                       const py::object& reference_wxyz) {
    const std::int64_t stamp = epoch(time_s, raw, present, reference_wxyz);
    std::uint64_t samples = 0;
    check(watched(watch_, [&] {
      return link_->publish(stamp, ++seq_, raw_, present_, reference_, lockstep_, samples);
    }));
    last_stamp_ = stamp;
    return stamp;
  }

  // The attitude of `stamp` among those received (dropping the older ones).
  py::dict attitude_of(std::int64_t stamp) {
    std::optional<fdi::AttitudeEstimate> found;
    std::vector<fdi::AttitudeEstimate> rest;
    for (const auto& a : received_) {
      if (a.stamp_ns == stamp) found = a;
      if (a.stamp_ns > stamp) rest.push_back(a);
    }
    received_ = std::move(rest);
    if (!found) {
      raise(failure("Attitude of unit '" + unit_ + "' past the epoch at " +
                    std::to_string(ns_to_seconds(stamp)) +
                    " s but none of it: the service's epochs are not this publisher's (another publisher of "
                    "the unit?)"));
    }
    return wire_attitude_dict(*found, n_);
  }

  // Checks one epoch's arrays into raw_, present_, reference_ (as Pipeline.step reads them); its stamp.
  std::int64_t epoch(const py::handle& time_s, const py::handle& raw, const py::object& present,
                     const py::object& reference_wxyz) {
    const double t = py::cast<double>(time_s);
    if (!std::isfinite(t)) throw py::value_error("time_s: NaN or infinite");
    const std::int64_t stamp = seconds_to_ns(t);
    if (stamp <= last_stamp_) {
      throw py::value_error("time_s " + std::to_string(t) + " does not follow the previous epoch's " +
                            std::to_string(ns_to_seconds(last_stamp_)) +
                            ": the service would reject it (sensor time must increase)");
    }
    const DoubleArray r = doubles(raw, "raw", 0, Finite::kNanAllowed);
    if (r.rows != static_cast<std::size_t>(n_))
      throw py::value_error("raw: expected " + std::to_string(n_) + " values [V], got " +
                            std::to_string(r.rows));
    const MaskArray m = present.is_none() ? MaskArray{} : mask(present, "present", r.rows, 0);
    for (std::size_t i = 0; i < r.rows; ++i) {
      raw_[i] = r.data[i];
      present_[i] = m.data == nullptr || m.data[i] != 0 ? 1 : 0;
    }
    reference_.reset();
    if (!reference_wxyz.is_none()) {
      const DoubleArray q = doubles(reference_wxyz, "reference_wxyz", 0, Finite::kRequired);
      if (q.rows != 4) throw py::value_error("reference_wxyz: expected 4 values (w, x, y, z)");
      reference_ = std::array<double, 4>{q.data[0], q.data[1], q.data[2], q.data[3]};
    }
    return stamp;
  }
  player::PlayerLink::AttitudeSink sink() {
    return [this](const fdi::AttitudeEstimate& a) { received_.push_back(a); };
  }

  std::string unit_;
  int n_;
  bool lockstep_;
  Watch* watch_ = nullptr;  //!< the running call's, polled by the link's waits
  bool busy_ = false;       //!< a call is running (InUse)
  std::unique_ptr<player::PlayerLink> link_;
  std::vector<double> raw_;
  std::vector<std::uint8_t> present_;
  std::optional<std::array<double, 4>> reference_;
  std::uint64_t seq_ = 0;
  std::int64_t last_stamp_ = std::numeric_limits<std::int64_t>::min();
  std::int64_t newest_ = std::numeric_limits<std::int64_t>::min();
  std::vector<fdi::AttitudeEstimate> received_;
};

enum Token : std::intptr_t { kAttitudeData = 1, kHealthData, kEventData, kMatched };

// Waits on `session` until a token fires or the monotonic `until_ns` passes, polling `watch`.
Status wait_watched(const dds::Session& session, Watch& watch, std::int64_t until_ns,
                    std::vector<std::intptr_t>& fired) {
  fired.clear();
  for (std::int64_t now = dds::monotonic_ns(); fired.empty() && now < until_ns; now = dds::monotonic_ns()) {
    if (watch.poll(0, 0)) return ok_status();
    const auto slice = std::min<std::int64_t>(until_ns - now, player::PlayerLink::kStopPollEvery_ns);
    if (Status s = session.wait(std::chrono::nanoseconds(slice), fired); !s) return s;
  }
  return ok_status();
}

// A star tracker (or any attitude reference) of its own: AttitudeReference out, stamped by the caller.
class ReferenceLink {
 public:
  ReferenceLink(const std::string& unit, std::optional<int> domain, double timeout_s) {
    check_unit(unit);
    const std::int64_t wait_ns = timeout_ns(timeout_s, "timeout_s");
    session_.emplace(take(dds::Session::open(domain_id(domain), unit)));
    writer_.emplace(take(session_->writer<tetra_AttitudeReference>(dds::reference_qos())));
    check(session_->watch_statuses(writer_->handle(), DDS_PUBLICATION_MATCHED_STATUS, kMatched));
    check(dds::copy_bounded(msg_.unit, unit, "unit"));
    // A volatile reader gets only what is written after it matched: wait for the service's reader.
    const std::int64_t give_up = dds::monotonic_ns() + wait_ns;
    std::uint32_t matched = 0;
    watched(watch_, [&]() -> int {
      std::vector<std::intptr_t> fired;
      while (dds::monotonic_ns() < give_up && !watch_->stopped()) {
        auto m = writer_->matched_readers();
        if (m && *m > 0) return static_cast<int>(matched = *m);
        (void)wait_watched(*session_, *watch_, give_up, fired);
        std::uint32_t status = 0;
        (void)dds_take_status(writer_->handle(), &status, DDS_PUBLICATION_MATCHED_STATUS);
      }
      return 0;
    });
    if (matched == 0)
      raise_timeout("no AttitudeReference reader (a `tetra fusion` of unit '" + unit +
                    "' on this domain) within " + std::to_string(timeout_s) + " s");
  }
  void send(std::int64_t stamp_ns, const py::handle& q_RB_wxyz) {
    const DoubleArray q = doubles(q_RB_wxyz, "q_RB_wxyz", 0, Finite::kRequired);
    if (q.rows != 4) throw py::value_error("q_RB_wxyz: expected 4 values (w, x, y, z)");
    msg_.stamp_ns = stamp_ns;
    for (std::size_t i = 0; i < 4; ++i) msg_.q_RB[i] = q.data[i];
    check(writer_->write(msg_));
  }

 private:
  std::optional<dds::Session> session_;  // first: deleted last
  std::optional<dds::Writer<tetra_AttitudeReference>> writer_;
  tetra_AttitudeReference msg_{};
  Watch* watch_ = nullptr;
};

// The service's outputs of one unit: Attitude (every epoch kept), Health and FdiEvent (late joiners get
// the latest Health and the events so far).
class Subscriber {
 public:
  Subscriber(const std::string& unit, std::optional<int> domain, int gyros) : unit_(unit), n_(gyros) {
    check_unit(unit);
    session_.emplace(take(dds::Session::open(domain_id(domain), unit)));
    dds::Qos every_epoch;
    every_epoch.reliable().volatile_durability().keep_last(1024);
    attitude_.emplace(take(session_->reader<tetra_Attitude>(every_epoch)));
    health_.emplace(take(session_->reader<tetra_Health>(dds::health_qos())));
    event_.emplace(take(session_->reader<tetra_FdiEvent2>(dds::event_qos())));
    check(session_->watch_data(attitude_->handle(), kAttitudeData));
    check(session_->watch_data(health_->handle(), kHealthData));
    check(session_->watch_data(event_->handle(), kEventData));
  }

  // Waits up to `timeout_s` for any sample; then takes every sample of the unit: (attitudes, healths,
  // events).
  py::tuple take_all(double timeout_s) {
    const InUse in_use(busy_, "Subscriber.poll");
    const std::int64_t until = dds::monotonic_ns() + timeout_ns(timeout_s, "timeout_s");
    std::vector<std::intptr_t> fired;
    check(watched(watch_, [&] { return wait_watched(*session_, *watch_, until, fired); }));
    std::vector<fdi::AttitudeEstimate> attitudes;
    std::vector<dds::HealthView> healths;
    std::vector<dds::EventView> events;
    check(take_into(*attitude_, attitudes));
    check(take_into(*health_, healths));
    check(take_into(*event_, events));
    py::list a, h, e;
    for (const auto& x : attitudes) a.append(wire_attitude_dict(x, n_));
    for (const auto& x : healths) h.append(wire_health_dict(x));
    for (const auto& x : events) e.append(wire_event_dict(x, n_));
    return py::make_tuple(a, h, e);
  }

 private:
  template <class T, class View>
  Status take_into(const dds::Reader<T>& reader, std::vector<View>& out) const {
    auto taken = reader.take([&](const T& msg, const dds_sample_info_t&) {
      if (dds::from_wire(msg.unit) == unit_) out.push_back(dds::from_wire(msg));
    });
    if (!taken) return taken.error();
    return ok_status();
  }

  std::string unit_;
  int n_;
  Watch* watch_ = nullptr;
  bool busy_ = false;
  std::optional<dds::Session> session_;  // first: deleted last
  std::optional<dds::Reader<tetra_Attitude>> attitude_;
  std::optional<dds::Reader<tetra_Health>> health_;
  std::optional<dds::Reader<tetra_FdiEvent2>> event_;
};

py::dict command(const std::string& unit, const std::string& action, int gyro, bool force,
                 const std::string& operator_id, const std::string& origin, std::optional<int> domain,
                 double timeout_s, int gyros) {
  check_unit(unit);
  dds_tools::CommandOptions o;
  o.request.unit = unit;
  o.request.gyro = gyro;
  o.request.force = force;
  o.request.operator_id = operator_id;
  o.request.origin = origin;
  o.action = action;
  o.timeout_s = static_cast<double>(timeout_ns(timeout_s, "timeout_s")) * 1e-9;
  o.domain = domain_id(domain);
  Result<dds::EventView> ack = [&] {
    py::gil_scoped_release release;
    return dds_tools::send_command(o);
  }();
  // No service, or no acknowledgement, within the timeout: TimeoutError (other failures: tetra.Error).
  if (!ack && ack.error().message.find(" within ") != std::string::npos) raise_timeout(ack.error().message);
  return wire_event_dict(take(std::move(ack)), gyros);
}

}  // namespace

void bind_dds(py::module_& m) {
  py::class_<GyroLink>(m, "_GyroLink")
      .def(py::init<const std::string&, int, double, std::optional<int>, bool, bool, int, double>(), "unit"_a,
           "gyros"_a, "rate_hz"_a, "domain"_a, "lockstep"_a, "reference"_a, "wait_readers"_a, "timeout_s"_a)
      .def("send", &GyroLink::send, "time_s"_a, "raw"_a, "present"_a, "reference_wxyz"_a)
      .def("step", &GyroLink::step, "time_s"_a, "raw"_a, "present"_a, "reference_wxyz"_a, "timeout_s"_a)
      .def("attitudes", &GyroLink::attitudes, "timeout_s"_a)
      .def("wait_for_acks", &GyroLink::wait_for_acks)
      .def_property_readonly("unit", &GyroLink::unit)
      .def_property_readonly("gyro_count", &GyroLink::gyro_count)
      .def_property_readonly("lockstep", &GyroLink::lockstep);
  py::class_<ReferenceLink>(m, "_ReferenceLink")
      .def(py::init<const std::string&, std::optional<int>, double>(), "unit"_a, "domain"_a, "timeout_s"_a)
      .def("send", &ReferenceLink::send, "stamp_ns"_a, "q_RB_wxyz"_a);
  py::class_<Subscriber>(m, "_Subscriber")
      .def(py::init<const std::string&, std::optional<int>, int>(), "unit"_a, "domain"_a, "gyros"_a)
      .def("take_all", &Subscriber::take_all, "timeout_s"_a);
  m.def("_command", &command, "unit"_a, "action"_a, "gyro"_a, "force"_a, "operator"_a, "origin"_a, "domain"_a,
        "timeout_s"_a, "gyros"_a);
  m.attr("_HAS_DDS") = true;
}

}  // namespace tetra::python
