#!/usr/bin/env bash
# Demo PKI and signed DDS Security documents for tetra (docs/reliability.md, "DDS Security").
#   scripts/security/make_pki.sh OUT_DIR [DOMAIN_RANGE] [UNIT...]
#       DOMAIN_RANGE default 0-230; UNITs (default tetra-1): one sensor identity each
# Creates in OUT_DIR:
#   identity_ca.pem / identity_ca.key        signs every participant certificate
#   permissions_ca.pem / permissions_ca.key  signs governance and permissions
#   <role>.pem / <role>.key                  identity of each role: sensor-<UNIT> per unit, fusion,
#                                            ground
#   governance.xml(.p7s)                     unauthenticated participants refused; discovery,
#                                            liveliness and data encrypted; access control on
#   permissions.xml(.p7s)                    per role what it may publish and subscribe, in which
#                                            partitions (default DENY): a secured participant serving
#                                            unit U is in partition tetra.U (docs/reliability.md), so
#                                            sensor-U may write samples for unit U only
#   <role>.yaml                              the security profile a tetra DDS command takes
#                                            (fusion config `security:`, --security for the others)
# DEMO ONLY: unencrypted private keys, ten-year validity, no revocation. Never ship these keys.
set -euo pipefail
out=${1:?usage: make_pki.sh OUT_DIR [DOMAIN_MIN-DOMAIN_MAX] [UNIT...]}
range=${2:-0-230}
shift $(($# >= 2 ? 2 : $#))
units=("$@")
[ ${#units[@]} -gt 0 ] || units=(tetra-1)
for unit in "${units[@]}"; do
  case "$unit" in
    *[\*\?\[\]\\\ ,]* | "") echo "make_pki: unit '$unit': no blanks, commas or * ? [ ] \\ in a unit name" >&2; exit 2 ;;
  esac
done
dmin=${range%-*}
dmax=${range#*-}
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$out"
umask 077
roles=()
for unit in "${units[@]}"; do roles+=("sensor-$unit"); done
roles+=(fusion ground)
days=3650
# Subject names: the permissions document must repeat them exactly, written "CN=..,O=..,C=.." with
# no blank after the commas (with blanks the handshake fails, DDS_NOTES.md).
subject() { printf 'CN=%s,O=tetra,C=BR' "$1"; }
quiet() { "$@" >/dev/null 2>&1 || { echo "make_pki: failed: $*" >&2; "$@" >&2 || true; exit 1; }; }

# --- certificate authorities (self-signed, EC P-256) ---
for ca in identity permissions; do
  quiet openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days "$days" \
    -keyout "${ca}_ca.key" -out "${ca}_ca.pem" -subj "/C=BR/O=tetra/CN=tetra ${ca} CA (demo)" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature"
done

# --- one identity per role, signed by the identity CA ---
for role in "${roles[@]}"; do
  quiet openssl req -new -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes \
    -keyout "$role.key" -out "$role.csr" -subj "/C=BR/O=tetra/CN=$role"
  quiet openssl x509 -req -in "$role.csr" -CA identity_ca.pem -CAkey identity_ca.key -CAcreateserial \
    -days "$days" -out "$role.pem"
  rm -f "$role.csr"
done
rm -f identity_ca.srl

not_before=$(date -u +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "+$((days - 1)) days" +%Y-%m-%dT%H:%M:%S)

# --- governance: the rules of the domain ---
cat >governance.xml <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>$dmin</min><max>$dmax</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML

# --- permissions: one grant per role, everything else denied ---
topics() { for t in "$@"; do printf '            <topic>%s</topic>\n' "$t"; done; }
grant() {  # role, partition (pattern), published topics (space separated), subscribed topics
  local role=$1 partition=$2 pub=$3 sub=$4
  cat <<XML
    <grant name="${role}_grant">
      <subject_name>$(subject "$role")</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>$dmin</min><max>$dmax</max></id_range></domains>
XML
  if [ -n "$pub" ]; then
    printf '        <publish>\n          <topics>\n'
    # shellcheck disable=SC2086
    topics $pub
    printf '          </topics>\n          <partitions><partition>%s</partition></partitions>\n        </publish>\n' "$partition"
  fi
  if [ -n "$sub" ]; then
    printf '        <subscribe>\n          <topics>\n'
    # shellcheck disable=SC2086
    topics $sub
    printf '          </topics>\n          <partitions><partition>%s</partition></partitions>\n        </subscribe>\n' "$partition"
  fi
  cat <<XML
      </allow_rule>
      <default>DENY</default>
    </grant>
XML
}
{
  cat <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
XML
  # sensor-U: unit U's gyros and star tracker, `sim --dds` (which scores the service's Attitude), in
  # U's partition only. It may read the other topics only because a participant creates every topic
  # and Cyclone refuses to create a topic the grant does not name; it may write nothing but samples.
  for unit in "${units[@]}"; do
    grant "sensor-$unit" "tetra.$unit" "GyroSample AttitudeReference" "Attitude Health FdiEvent Command"
  done
  # fusion: the service, of any unit (it reads Health too: a second service of its unit is refused)
  grant fusion "tetra.*" "Attitude Health FdiEvent" "GyroSample AttitudeReference Command Health"
  # ground: monitor, command, record, of any unit
  grant ground "tetra.*" "Command" "GyroSample AttitudeReference Attitude Health FdiEvent"
  cat <<XML
  </permissions>
</dds>
XML
} >permissions.xml

for doc in governance permissions; do
  quiet openssl smime -sign -text -in "$doc.xml" -out "$doc.p7s" -signer permissions_ca.pem -inkey permissions_ca.key
done

# --- one profile per role, read by tetra (services/dds: security profile) ---
for role in "${roles[@]}"; do
  cat >"$role.yaml" <<YAML
# DDS Security profile of role '$role' (generated by scripts/security/make_pki.sh; paths absolute)
identity_ca: $out/identity_ca.pem
identity_certificate: $out/$role.pem
private_key: $out/$role.key
permissions_ca: $out/permissions_ca.pem
governance: $out/governance.p7s
permissions: $out/permissions.p7s
YAML
done
chmod 0644 ./*.pem ./*.xml ./*.p7s ./*.yaml
echo "make_pki: $out: identity CA, permissions CA, roles ${roles[*]}, domains $dmin-$dmax, units ${units[*]}"
