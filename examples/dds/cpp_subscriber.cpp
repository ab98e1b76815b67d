// A minimal tetra subscriber in C++, from idl/tetra.idl alone (docs/dds.md, "Your own programs on the wire"):
// every Attitude of one unit as one JSON line on stdout, in the wire's SI units. Debian 12's Cyclone DDS has
// no C++ binding (no libddscxx), so this is C++17 over the C API, each entity owned by an RAII handle. Build:
// idlc -o gen idl/tetra.idl && cc -c -Igen gen/tetra.c -o gen/tetra.o
//         c++ -std=c++17 -Igen examples/dds/cpp_subscriber.cpp gen/tetra.o -lddsc -o cpp_subscriber
// Run:    cpp_subscriber UNIT [--domain N] [--count N] [--seconds S]
//         (stops after N attitudes, exit 0, or after S seconds, default 10: exit 0 if any came, else 1)
#include <dds/dds.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

#include "tetra.h"

namespace {

// One DDS entity (participant, topic, reader, condition, waitset): deleted with its owner.
class Entity {
 public:
  Entity(dds_entity_t handle, const char* what) : handle_(handle) {
    if (handle < 0) throw std::runtime_error(std::string(what) + ": " + dds_strretcode(handle));
  }
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity& operator=(Entity&&) = delete;
  ~Entity() {
    if (handle_ > 0) dds_delete(handle_);
  }
  dds_entity_t get() const { return handle_; }

 private:
  dds_entity_t handle_;
};

// The QoS of docs/dds.md's table for Attitude, with a deeper history than the writer's 1: every epoch is
// kept.
class AttitudeQos {
 public:
  AttitudeQos() : qos_(dds_create_qos()) {
    dds_qset_reliability(qos_, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(qos_, DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, 256);
  }
  AttitudeQos(const AttitudeQos&) = delete;
  AttitudeQos& operator=(const AttitudeQos&) = delete;
  ~AttitudeQos() { dds_delete_qos(qos_); }
  const dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

const char* mode_name(tetra_Mode mode) {
  static const char* const kNames[] = {"NOMINAL", "DEGRADED", "SUSPECT", "LOST"};
  return mode >= 0 && mode <= tetra_MODE_LOST ? kNames[mode] : "unknown";
}

void print_vector(const char* key, const double* v, int n) {
  std::printf(", \"%s\": [", key);
  for (int i = 0; i < n; ++i) {
    if (std::isfinite(v[i]))
      std::printf("%s%.17g", i ? ", " : "", v[i]);
    else
      std::printf("%snull", i ? ", " : "");  // +Inf protection level: no integrity bound
  }
  std::printf("]");
}

void print(const tetra_Attitude& a) {
  std::printf("{\"type\": \"attitude\", \"unit\": \"%s\", \"stamp_ns\": %lld", a.unit,
              static_cast<long long>(a.stamp_ns));
  print_vector("q_RB", a.q_RB, 4);
  print_vector("omega_BR_B_rad_s", a.omega_BR_B_rad_s, 3);
  print_vector("sigma_rad", a.sigma_rad, 3);
  print_vector("protection_level_rad", a.protection_level_rad, 3);
  std::printf(", \"mode\": \"%s\", \"gyros\": %u, \"fdi_available\": %s}\n", mode_name(a.mode),
              static_cast<unsigned>(a.gyros), a.fdi_available ? "true" : "false");
}

// Takes every Attitude of `unit` the reader holds, printing each; returns how many were printed.
long take_all(const Entity& reader, const std::string& unit) {
  void* samples[16] = {};
  dds_sample_info_t infos[16];
  long printed = 0;
  for (int n; (n = dds_take(reader.get(), samples, infos, 16, 16)) > 0;) {
    for (int i = 0; i < n; ++i) {
      const auto* a = static_cast<const tetra_Attitude*>(samples[i]);
      if (!infos[i].valid_data || unit != a->unit) continue;
      print(*a);
      ++printed;
    }
    dds_return_loan(reader.get(), samples, n);
  }
  std::fflush(stdout);
  return printed;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2 || argc % 2 != 0) {
    std::fprintf(stderr, "usage: %s UNIT [--domain N] [--count N] [--seconds S]\n", argv[0]);
    return 2;
  }
  const std::string unit = argv[1];
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  long count = 0;  // 0: no limit
  double seconds = 10.0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--domain")
      domain = static_cast<dds_domainid_t>(std::atoi(argv[i + 1]));
    else if (key == "--count")
      count = std::atol(argv[i + 1]);
    else if (key == "--seconds")
      seconds = std::atof(argv[i + 1]);
    else
      throw std::invalid_argument("unknown option " + key);
  }
  const Entity participant(dds_create_participant(domain, nullptr, nullptr), "create participant");
  const Entity topic(dds_create_topic(participant.get(), &tetra_Attitude_desc, "Attitude", nullptr, nullptr),
                     "create topic Attitude");
  const AttitudeQos qos;
  const Entity reader(dds_create_reader(participant.get(), topic.get(), qos.get(), nullptr), "create reader");
  const Entity waitset(dds_create_waitset(participant.get()), "create waitset");
  const Entity data(dds_create_readcondition(reader.get(), DDS_ANY_STATE), "create read condition");
  if (const dds_return_t rc = dds_waitset_attach(waitset.get(), data.get(), 0); rc < 0)
    throw std::runtime_error(std::string("attach: ") + dds_strretcode(rc));

  const dds_time_t end = dds_time() + static_cast<dds_duration_t>(seconds * 1e9);
  long printed = 0;
  while ((count == 0 || printed < count) && dds_time() < end) {
    if (const dds_return_t rc = dds_waitset_wait_until(waitset.get(), nullptr, 0, end); rc < 0)
      throw std::runtime_error(std::string("wait: ") + dds_strretcode(rc));
    printed += take_all(reader, unit);
  }
  return printed > 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "cpp_subscriber: %s\n", e.what());
  return 1;
}
