/* A minimal tetra subscriber in C, from idl/tetra.idl alone (docs/dds.md, "Your own subscriber"):
 * every Attitude, Health and FdiEvent of one unit as one JSON line each on stdout, in the wire's SI units.
 * Build:  idlc -o gen idl/tetra.idl && cc -Igen examples/dds/attitude_subscriber.c gen/tetra.c -lddsc
 * Run:    attitude_subscriber UNIT [--domain N] [--seconds S]   (stop after S seconds; default: never)
 * A program in any language can read its standard output (examples/dds/python_bridge.py). */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "tetra.h"

/* clang-format off */
static const char* kModes[] = {"NOMINAL", "DEGRADED", "SUSPECT", "LOST"};
static const char* kEvents[] = {"detected", "isolated", "unisolated", "reconfigured", "cleared", "lost", "command",
    "fdi_unavailable", "fdi_available", "gap", "reference_rejected", "reference_accepted", "reference_late"};
static const char* kReferenceStates[] = {"absent", "accepted", "rejected"};
static const char* kVerdicts[] = {"consistent", "rejected", "no call"};
/* clang-format on */

static const char* name_of(const char** names, size_t count, int value) {
  return value >= 0 && (size_t)value < count ? names[value] : "unknown";
}
#define NAME(names, value) name_of(names, sizeof names / sizeof names[0], (int)(value))

/* JSON has no Inf or NaN: null (a protection level of +Inf means no integrity bound). */
static void number(const char* prefix, double v) {
  isfinite(v) ? printf("%s%.17g", prefix, v) : printf("%snull", prefix);
}

static void vec(const char* key, const double* v, int n) {
  printf(", \"%s\": [", key);
  for (int i = 0; i < n; ++i) number(i ? ", " : "", v[i]);
  printf("]");
}

static void print_attitude(const void* sample) {
  const tetra_Attitude* a = sample;
  printf("{\"type\": \"attitude\", \"unit\": \"%s\", \"stamp_ns\": %" PRId64, a->unit, (int64_t)a->stamp_ns);
  vec("q_RB", a->q_RB, 4);
  vec("omega_BR_B_rad_s", a->omega_BR_B_rad_s, 3);
  vec("sigma_rad", a->sigma_rad, 3);
  vec("protection_level_rad", a->protection_level_rad, 3);
  printf(", \"mode\": \"%s\", \"gyros\": %" PRIu32 ", \"fdi_available\": %s}\n", NAME(kModes, a->mode),
         (uint32_t)a->gyros, a->fdi_available ? "true" : "false");
}

static void print_health(const void* sample) {
  const tetra_Health* h = sample;
  printf("{\"type\": \"health\", \"unit\": \"%s\", \"stamp_ns\": %" PRId64
         ", \"mode\": \"%s\", \"used\": %" PRIu32 ", \"epochs_accepted\": %" PRIu64
         ", \"reference_state\": \"%s\", \"reference_nis\": %.6g"
         ", \"references_delayed\": %" PRIu64 ", \"references_too_late\": %" PRIu64
         ", \"reference_horizon_s\": %.6g, \"samples_late\": %" PRIu64 "}\n",
         h->unit, (int64_t)h->stamp_ns, NAME(kModes, h->mode), (uint32_t)h->used,
         (uint64_t)h->counters.epochs_accepted, NAME(kReferenceStates, h->reference_state), h->reference_nis,
         (uint64_t)h->references_delayed, (uint64_t)h->references_too_late, h->reference_horizon_s,
         (uint64_t)h->counters.samples_late);
}

static void print_event(const void* sample) {
  const tetra_FdiEvent2* e = sample;
  printf("{\"type\": \"event\", \"unit\": \"%s\", \"event_seq\": %" PRIu64 ", \"stamp_ns\": %" PRId64
         ", \"event\": \"%s\", \"gyro\": %d, \"test\": \"%s\"",
         e->unit, (uint64_t)e->event_seq, (int64_t)e->stamp_ns, NAME(kEvents, e->type), (int)e->gyro,
         e->test);
  if (isfinite(e->statistic)) printf(", \"statistic\": %.9g", e->statistic);
  printf(", \"detail\": \""); /* the detail is plain text without quotes or backslashes */
  for (const char* c = e->detail; *c; ++c) putchar(*c == '"' || *c == '\\' ? '\'' : *c);
  /* Why: the ledger rows that decided it (hypothesis 0: H0, 1..N: that gyro, 255: the reference). */
  printf("\", \"ledger\": [");
  for (uint32_t i = 0; i < e->ledger._length; ++i) {
    const tetra_LedgerRow* r = &e->ledger._buffer[i];
    printf("%s{\"source\": \"%s\", \"hypothesis\": %u, \"verdict\": \"%s\", \"unit\": \"%s\"", i ? ", " : "",
           r->source, (unsigned)r->hypothesis, NAME(kVerdicts, r->verdict), r->unit);
    number(", \"statistic\": ", r->statistic);
    number(", \"threshold\": ", r->threshold);
    printf("}");
  }
  printf("]}\n");
}

/* Prints every sample of `reader` whose key is `unit` (every tetra type begins with its key). */
static void take_all(dds_entity_t reader, const char* unit, void (*print)(const void*)) {
  void* samples[16] = {NULL};
  dds_sample_info_t infos[16];
  int n;
  while ((n = dds_take(reader, samples, infos, 16, 16)) > 0) {
    for (int i = 0; i < n; ++i)
      if (infos[i].valid_data && strcmp((const char*)samples[i], unit) == 0) print(samples[i]);
    dds_return_loan(reader, samples, n);
  }
  fflush(stdout);
}

/* A reader of topic `name` (the type's name) with `qos`; negative on failure. */
static dds_entity_t reader_of(dds_entity_t participant, const dds_topic_descriptor_t* type, const char* name,
                              const dds_qos_t* qos) {
  const dds_entity_t topic = dds_create_topic(participant, type, name, NULL, NULL);
  return topic < 0 ? topic : dds_create_reader(participant, topic, qos, NULL);
}

int main(int argc, char** argv) {
  const char* unit = argc > 1 ? argv[1] : "";
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
  double seconds = 0.0;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (strcmp(argv[i], "--domain") == 0)
      domain = (dds_domainid_t)atoi(argv[i + 1]);
    else if (strcmp(argv[i], "--seconds") == 0)
      seconds = atof(argv[i + 1]);
    else
      argc = 0;
  }
  if (argc < 2 || argc % 2 != 0) {
    fprintf(stderr, "usage: %s UNIT [--domain N] [--seconds S]\n", argv[0]);
    return 2;
  }
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL); /* checked with the readers */
  /* QoS as docs/dds.md's table; the Attitude reader keeps more than the writer's 1 so none is lost here. */
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 256);
  const dds_entity_t attitude_reader = reader_of(participant, &tetra_Attitude_desc, "Attitude", qos);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL); /* Health and events: a late joiner's history */
  const dds_entity_t health_reader = reader_of(participant, &tetra_Health_desc, "Health", qos);
  const dds_entity_t event_reader = reader_of(participant, &tetra_FdiEvent2_desc, "FdiEvent", qos);
  dds_delete_qos(qos);
  if (attitude_reader < 0 || health_reader < 0 || event_reader < 0) {
    fprintf(stderr, "could not create the participant or its readers (domain %d)\n", (int)domain);
    return 1;
  }
  const dds_entity_t waitset = dds_create_waitset(participant);
  const dds_entity_t readers[3] = {attitude_reader, health_reader, event_reader};
  for (int i = 0; i < 3; ++i)
    dds_waitset_attach(waitset, dds_create_readcondition(readers[i], DDS_ANY_STATE), readers[i]);
  const dds_time_t end = seconds > 0.0 ? dds_time() + (dds_duration_t)(seconds * 1e9) : DDS_NEVER;
  while (dds_time() < end) {
    if (dds_waitset_wait_until(waitset, NULL, 0, end) < 0) break;
    take_all(event_reader, unit, print_event); /* an epoch's events before its attitude */
    take_all(attitude_reader, unit, print_attitude);
    take_all(health_reader, unit, print_health);
  }
  dds_delete(participant);
  return 0;
}
