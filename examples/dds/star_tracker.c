/* A minimal star tracker in C, from idl/tetra.idl alone (docs/dds.md, "Your own star tracker"): publishes
 * one AttitudeReference per line read on stdin, `STAMP_NS QW QX QY QZ` — the sensor time the attitude was
 * taken at [ns] and the body -> reference quaternion, scalar first — as soon as the line is read, however
 * late that is: the service fuses a reference at its own stamp within its fusion horizon (default 0.5 s).
 * Build:  idlc -o gen idl/tetra.idl && cc -Igen examples/dds/star_tracker.c gen/tetra.c -lddsc
 * Run:    star_tracker UNIT [--domain N]   (waits up to 10 s for a reader, says `ready` on stderr, then
 * reads) */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "tetra.h"

int main(int argc, char** argv) {
  const int with_domain = argc == 4 && strcmp(argv[2], "--domain") == 0;
  if ((argc != 2 && !with_domain) || strlen(argv[1]) > 31) {
    fprintf(stderr, "usage: %s UNIT [--domain N]   (UNIT: 1-31 bytes)\n", argv[0]);
    return 2;
  }
  const dds_domainid_t domain = with_domain ? (dds_domainid_t)atoi(argv[3]) : DDS_DOMAIN_DEFAULT;
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "dds_create_participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  const dds_entity_t topic =
      dds_create_topic(participant, &tetra_AttitudeReference_desc, "AttitudeReference", NULL, NULL);
  dds_qos_t* qos = dds_create_qos(); /* docs/dds.md: reliable / volatile / keep-last 8 */
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 8);
  const dds_entity_t writer = dds_create_writer(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (writer < 0) {
    fprintf(stderr, "dds_create_writer: %s\n", dds_strretcode(writer));
    return 1;
  }
  /* A volatile reader receives only what is written after it matched: wait for the service's reader. */
  dds_publication_matched_status_t matched = {0};
  for (int i = 0; i < 1000 && matched.current_count == 0; ++i) {
    dds_get_publication_matched_status(writer, &matched);
    if (matched.current_count == 0) dds_sleepfor(DDS_MSECS(10));
  }
  if (matched.current_count == 0) {
    fprintf(stderr, "star_tracker: no AttitudeReference reader within 10 s\n");
    return 1;
  }
  fprintf(stderr, "ready\n");
  tetra_AttitudeReference ref;
  memset(&ref, 0, sizeof ref);
  strcpy(ref.unit, argv[1]);
  char line[256];
  unsigned long long written = 0;
  long line_no = 0;
  while (fgets(line, sizeof line, stdin)) {
    ++line_no;
    int64_t stamp_ns;
    if (line[0] == '#' || line[0] == '\n') continue;
    if (sscanf(line, "%" SCNd64 " %lf %lf %lf %lf", &stamp_ns, &ref.q_RB[0], &ref.q_RB[1], &ref.q_RB[2],
               &ref.q_RB[3]) != 5) {
      fprintf(stderr, "star_tracker: line %ld: expected STAMP_NS QW QX QY QZ\n", line_no);
      continue;
    }
    ref.stamp_ns = stamp_ns;
    const dds_return_t rc = dds_write(writer, &ref);
    if (rc != DDS_RETCODE_OK)
      fprintf(stderr, "dds_write: %s\n", dds_strretcode(rc));
    else
      ++written;
  }
  fprintf(stderr, "star_tracker: %llu references written\n", written);
  dds_sleepfor(DDS_MSECS(200)); /* reliable: let the last ones be acknowledged before the participant goes */
  dds_delete(participant);
  return 0;
}
