#!/usr/bin/env bash
# bbw-keys.sh DIR [--force]: test PKI and DDS Security documents for bbw (issue 7).
#
# Creates, with openssl only:
#   DIR/ca/ca.pem, ca.key                 test CA (ECDSA P-256, self-signed)
#   DIR/<id>/cert.pem, key.pem            identity of each process, signed by the CA
#                                         (id = ccu ccu_standby fl fr rl rr; subject /C=DE/O=bbw/CN=bbw_<id>)
#   DIR/governance.xml, governance.p7s    governance document, S/MIME-signed by the CA
#   DIR/<id>/permissions.xml, .p7s        permissions of each identity, S/MIME-signed by the CA
#   DIR/rogue/ca/...                      a rogue CA our CA never signed
#   DIR/rogue/intruder/...                an intruder identity signed by the rogue CA, with
#                                         governance/permissions signed by the rogue CA
#   DIR/MANIFEST                          the files above, one per line
#
# Idempotent: existing keys and certificates that still verify are kept; documents are
# rewritten only when their content changes or their signature no longer verifies.
# --force regenerates everything. Keys are test material: never commit them (.gitignore /keys/).
#
# Topic names (dds/include/bbw/dds/topics.hpp) and the per-corner partitions are fixed here:
#   CCU   publishes bbw/ClampCommand, bbw/CalibrationState (any partition: run_<id>, none)
#         subscribes bbw/MeasurementBlock, bbw/CornerHealth (partitions corner_*)
#   <c>   publishes bbw/MeasurementBlock, bbw/CornerHealth only in partitions corner_<C> and
#         corner_<C>.run_* (its partition in one run, issue 17)
#         subscribes bbw/ClampCommand, bbw/CalibrationState
set -euo pipefail

die() { echo "bbw keys: $*" >&2; exit 1; }

DIR=""
FORCE=0
for a in "$@"; do
  case "$a" in
    --force) FORCE=1 ;;
    -h|--help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown option '$a' (usage: bbw keys DIR [--force])" ;;
    *) [ -z "$DIR" ] || die "only one DIR allowed, got '$DIR' and '$a'"; DIR="$a" ;;
  esac
done
[ -n "$DIR" ] || die "usage: bbw keys DIR [--force]"
command -v openssl >/dev/null 2>&1 || die "openssl is not installed (./bbw setup installs it)"
mkdir -p "$DIR" || die "cannot create directory '$DIR'"
[ -w "$DIR" ] || die "directory '$DIR' is not writable"
DIR="$(cd "$DIR" && pwd)"
umask 077

IDS=(ccu ccu_standby fl fr rl rr)
DAYS=3650
SUBJ_PREFIX="/C=DE/O=bbw"
TOPIC_MEAS="bbw/MeasurementBlock"
TOPIC_HEALTH="bbw/CornerHealth"
TOPIC_CMD="bbw/ClampCommand"
TOPIC_CAL="bbw/CalibrationState"
# Domain ids 0..232 (dds/include/bbw/dds/domain.hpp kMaxDomainId): every test domain is covered.
DOMAIN_MAX=232

log() { echo "bbw keys: $*"; }

# Runs openssl quietly; on failure prints what it said and stops.
ossl() {
  local out
  if ! out="$(openssl "$@" 2>&1)"; then
    echo "$out" >&2
    die "openssl $1 failed"
  fi
}

new_key() {  # new_key FILE
  ossl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1"
}

new_ca() {  # new_ca DIR CN
  local d="$1" cn="$2"
  mkdir -p "$d"
  if [ "$FORCE" -eq 0 ] && [ -s "$d/ca.pem" ] && [ -s "$d/ca.key" ] &&
     openssl x509 -in "$d/ca.pem" -noout -checkend 86400 >/dev/null 2>&1; then
    return 0
  fi
  log "new CA $cn in $d"
  new_key "$d/ca.key"
  ossl req -new -x509 -sha256 -key "$d/ca.key" -out "$d/ca.pem" -days "$DAYS" \
    -subj "$SUBJ_PREFIX/CN=$cn" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature"
  # digitalSignature: the CA also S/MIME-signs the governance and permissions documents, and
  # PKCS7_verify (openssl smime -verify, Fast DDS) checks the signer for the S/MIME purpose.
  # A new CA invalidates everything it signed.
  FORCE_CHILDREN=1
}

new_identity() {  # new_identity CA_DIR DIR CN
  local ca="$1" d="$2" cn="$3"
  mkdir -p "$d"
  if [ "$FORCE" -eq 0 ] && [ "${FORCE_CHILDREN:-0}" -eq 0 ] && [ -s "$d/cert.pem" ] && [ -s "$d/key.pem" ] &&
     openssl verify -CAfile "$ca/ca.pem" "$d/cert.pem" >/dev/null 2>&1 &&
     [ "$(openssl x509 -in "$d/cert.pem" -noout -pubkey)" = "$(openssl pkey -in "$d/key.pem" -pubout)" ]; then
    return 0
  fi
  log "new identity $cn in $d"
  new_key "$d/key.pem"
  ossl req -new -sha256 -key "$d/key.pem" -out "$d/cert.csr" -subj "$SUBJ_PREFIX/CN=$cn"
  local ext
  ext="$(mktemp)"
  printf 'basicConstraints=critical,CA:FALSE\nkeyUsage=critical,digitalSignature,keyAgreement\n' >"$ext"
  ossl x509 -req -sha256 -in "$d/cert.csr" -CA "$ca/ca.pem" -CAkey "$ca/ca.key" -CAcreateserial \
    -out "$d/cert.pem" -days "$DAYS" -extfile "$ext"
  rm -f "$ext" "$d/cert.csr" "$ca/ca.srl"
}

# sign_doc CA_DIR XML P7S: S/MIME-signs XML (clear text) unless P7S already signs this content.
sign_doc() {
  local ca="$1" xml="$2" p7s="$3" tmp
  if [ "$FORCE" -eq 0 ] && [ -s "$p7s" ]; then
    tmp="$(mktemp)"
    # S/MIME canonicalises line ends to CRLF; the signed text is the XML once they are undone.
    if openssl smime -verify -in "$p7s" -CAfile "$ca/ca.pem" -text -out "$tmp" >/dev/null 2>&1 &&
       tr -d '\r' <"$tmp" | cmp -s - "$xml"; then
      rm -f "$tmp"
      return 0
    fi
    rm -f "$tmp"
  fi
  log "signing $(basename "$p7s") for $(basename "$(dirname "$p7s")")"
  ossl smime -sign -text -in "$xml" -out "$p7s" -signer "$ca/ca.pem" -inkey "$ca/ca.key" -md sha256
}

# write_if_changed FILE: stdin becomes FILE unless FILE already has exactly that content.
write_if_changed() {
  local f="$1" tmp
  tmp="$(mktemp)"
  cat >"$tmp"
  if [ -f "$f" ] && cmp -s "$tmp" "$f"; then rm -f "$tmp"; return 0; fi
  mv "$tmp" "$f"
  chmod 644 "$f"
}

governance_xml() {
  cat <<GOV
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>$DOMAIN_MAX</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
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
GOV
}

# permissions_xml SUBJECT_RFC2253 PUBLISH_BLOCK SUBSCRIBE_BLOCK
permissions_xml() {
  cat <<PERM
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$4">
      <subject_name>$1</subject_name>
      <validity>
        <not_before>$NOT_BEFORE</not_before>
        <not_after>$NOT_AFTER</not_after>
      </validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>$DOMAIN_MAX</max></id_range></domains>
$2
$3
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
PERM
}

# rule publish|subscribe "PARTITION..." TOPIC...  (space-separated partition patterns; "" = only
# the default, partition-less one)
rule() {
  local kind="$1" parts="$2"
  shift 2
  echo "        <$kind>"
  echo "          <topics>"
  local t p list
  for t in "$@"; do echo "            <topic>$t</topic>"; done
  echo "          </topics>"
  if [ -n "$parts" ]; then
    read -r -a list <<< "$parts"  # no glob expansion of the patterns
    echo -n "          <partitions>"
    for p in "${list[@]}"; do echo -n "<partition>$p</partition>"; done
    echo "</partitions>"
  fi
  echo "        </$kind>"
}

# The validity window is fixed by the CA certificate, so re-running does not change documents.
validity_from_ca() {
  local ca="$1"
  NOT_BEFORE="$(date -u -d "$(openssl x509 -in "$ca/ca.pem" -noout -startdate | cut -d= -f2)" +%Y-%m-%dT%H:%M:%S)"
  NOT_AFTER="$(date -u -d "$(openssl x509 -in "$ca/ca.pem" -noout -enddate | cut -d= -f2)" +%Y-%m-%dT%H:%M:%S)"
}

rfc2253() { echo "CN=$1,O=bbw,C=DE"; }

FORCE_CHILDREN=0
new_ca "$DIR/ca" "bbw test CA"
validity_from_ca "$DIR/ca"
for id in "${IDS[@]}"; do
  new_identity "$DIR/ca" "$DIR/$id" "bbw_$id"
done
governance_xml | write_if_changed "$DIR/governance.xml"
sign_doc "$DIR/ca" "$DIR/governance.xml" "$DIR/governance.p7s"

for id in "${IDS[@]}"; do
  if [ "$id" = ccu ] || [ "$id" = ccu_standby ]; then
    # Commands and calibration state in a run's partition run_<id> (issue 17) or none. The
    # hot-standby CCU (issue 16) has its own identity and the same rights: only these two command.
    pub="$(rule publish "*" "$TOPIC_CMD" "$TOPIC_CAL")"
    sub="$(rule subscribe "corner_*" "$TOPIC_MEAS" "$TOPIC_HEALTH")"
  else
    up="$(echo "$id" | tr '[:lower:]' '[:upper:]')"
    # corner_<C>.run_<id>: the corner's partition in one run (issue 17); corner_<C> alone is
    # what processes started without a run used before.
    pub="$(rule publish "corner_$up corner_$up.run_*" "$TOPIC_MEAS" "$TOPIC_HEALTH")"
    sub="$(rule subscribe "*" "$TOPIC_CMD" "$TOPIC_CAL")"
  fi
  permissions_xml "$(rfc2253 "bbw_$id")" "$pub" "$sub" "bbw_$id" | write_if_changed "$DIR/$id/permissions.xml"
  sign_doc "$DIR/ca" "$DIR/$id/permissions.xml" "$DIR/$id/permissions.p7s"
done

# The rogue side: its own CA, an intruder identity, and documents that would allow it anything.
FORCE_CHILDREN=0
new_ca "$DIR/rogue/ca" "bbw test CA"   # same subject as ours: only the key differs
validity_from_ca "$DIR/rogue/ca"
new_identity "$DIR/rogue/ca" "$DIR/rogue/intruder" "bbw_ccu"
governance_xml | write_if_changed "$DIR/rogue/governance.xml"
sign_doc "$DIR/rogue/ca" "$DIR/rogue/governance.xml" "$DIR/rogue/governance.p7s"
permissions_xml "$(rfc2253 bbw_ccu)" "$(rule publish "*" "*")" "$(rule subscribe "*" "*")" "intruder" |
  write_if_changed "$DIR/rogue/intruder/permissions.xml"
sign_doc "$DIR/rogue/ca" "$DIR/rogue/intruder/permissions.xml" "$DIR/rogue/intruder/permissions.p7s"

chmod 600 "$DIR"/ca/ca.key "$DIR"/*/key.pem "$DIR"/rogue/ca/ca.key "$DIR"/rogue/intruder/key.pem
chmod 644 "$DIR"/ca/ca.pem "$DIR"/*/cert.pem "$DIR"/*.p7s "$DIR"/*/permissions.p7s

# Final check: everything verifies, so a broken run never leaves a half-usable directory.
for id in "${IDS[@]}"; do
  openssl verify -CAfile "$DIR/ca/ca.pem" "$DIR/$id/cert.pem" >/dev/null 2>&1 ||
    die "$DIR/$id/cert.pem does not verify against $DIR/ca/ca.pem"
  openssl smime -verify -in "$DIR/$id/permissions.p7s" -CAfile "$DIR/ca/ca.pem" -text -out /dev/null >/dev/null 2>&1 ||
    die "$DIR/$id/permissions.p7s does not verify"
done
openssl smime -verify -in "$DIR/governance.p7s" -CAfile "$DIR/ca/ca.pem" -text -out /dev/null >/dev/null 2>&1 ||
  die "$DIR/governance.p7s does not verify"
if openssl verify -CAfile "$DIR/ca/ca.pem" "$DIR/rogue/intruder/cert.pem" >/dev/null 2>&1; then
  die "the rogue identity verifies against the real CA (key collision?)"
fi
{
  echo "ca/ca.pem"
  echo "governance.p7s"
  for id in "${IDS[@]}"; do echo "$id/cert.pem"; echo "$id/key.pem"; echo "$id/permissions.p7s"; done
  echo "rogue/ca/ca.pem"
  echo "rogue/governance.p7s"
  echo "rogue/intruder/cert.pem"; echo "rogue/intruder/key.pem"; echo "rogue/intruder/permissions.p7s"
} | write_if_changed "$DIR/MANIFEST"
log "ready in $DIR (CA, ${#IDS[@]} identities, governance, permissions, rogue CA + intruder)"
