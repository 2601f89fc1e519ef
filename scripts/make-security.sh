#!/usr/bin/env bash
# make-security.sh: makes the DDS Security material of a secured mft-wbc stack (docs/guide/security.md) in DIR:
# a test CA, one identity per service (sim, estimator, planner, wbc, record) and one for the operator tool
# mft-cmd (cmd), the governance document and one permissions document per identity, all signed by the CA
# with openssl smime. Key material is never written inside the repository.
#
#   scripts/make-security.sh DIR [--profile data|full] [--days N] [--cn-prefix TEXT] [--force]
#
# Per identity: <name>.pem (certificate), <name>.key (private key, mode 600), permissions_<name>.p7s;
# shared: ca.pem, governance.p7s (ca.key stays in DIR too: this is a test CA, see docs/guide/security.md).
# Permissions: those of the topic registry idl/topics.yaml (its writers and readers; the recorder reads every
# recorded topic): each service may publish only its own topics (only the sim SensorData/GroundTruth, only the
# WBC JointCommand); cmd publishes the operator's commands and reads the CommandVerdict answering them.
set -euo pipefail

usage() {
  sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'
  echo
  echo "Options:"
  echo "  --profile data   governance with data-only ENCRYPT on every topic, discovery and liveliness encrypted,"
  echo "                   RTPS messages and submessage metadata not protected (the cheaper option, docs/reference/dds.md#security; default)"
  echo "  --profile full   everything ENCRYPT (rtps, metadata, data, discovery, liveliness)"
  echo "  --days N         validity of the certificates and permissions (default 365)"
  echo "  --cn-prefix T    prefix of every certificate's common name (default empty; a second CA made with the"
  echo "                   same names is a 'rogue' CA the stack must refuse)"
  echo "  --force          overwrite DIR's existing material"
}

DIR=""
PROFILE="data"
DAYS=365
CN_PREFIX=""
FORCE=0
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --profile) PROFILE="${2:-}"; shift 2 ;;
    --days) DAYS="${2:-}"; shift 2 ;;
    --cn-prefix) CN_PREFIX="${2:-}"; shift 2 ;;
    --force) FORCE=1; shift ;;
    -*) echo "make-security: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) if [ -n "$DIR" ]; then echo "make-security: one DIR only (got '$DIR' and '$1')" >&2; exit 2; fi
       DIR="$1"; shift ;;
  esac
done
[ -n "$DIR" ] || { echo "make-security: give the target directory (see --help)" >&2; exit 2; }
case "$PROFILE" in data|full) ;; *) echo "make-security: --profile must be data or full, got '$PROFILE'" >&2; exit 2 ;; esac
[[ "$DAYS" =~ ^[0-9]+$ ]] && [ "$DAYS" -ge 1 ] || { echo "make-security: --days must be a positive integer" >&2; exit 2; }
command -v openssl >/dev/null || { echo "make-security: openssl not found (apt-get install openssl)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "make-security: python3 not found (it reads the topic registry)" >&2; exit 2; }

REPO="$(cd "$(dirname "$0")/.." && pwd -P)"
mkdir -p "$DIR"
DIR="$(cd "$DIR" && pwd -P)"
case "$DIR/" in
  "$REPO/"*) rmdir "$DIR" 2>/dev/null || true
             echo "make-security: $DIR is inside the repository: key material must never be committed; choose a directory outside $REPO" >&2
             exit 2 ;;
esac
if [ -e "$DIR/ca.pem" ] && [ "$FORCE" -ne 1 ]; then
  echo "make-security: $DIR already holds security material (use --force to overwrite)" >&2; exit 2
fi
chmod 700 "$DIR"
umask 077
cd "$DIR"

# Who may publish / subscribe what: the writers and readers of the topic registry (idl/topics.yaml,
# docs/reference/architecture.md#the-topic-registry), one line per identity and direction: "<id> pub|sub <topics...>".
GRANTS="$(python3 "$REPO/idl/gen_topics.py" security)" || { echo "make-security: cannot read the topic registry idl/topics.yaml" >&2; exit 2; }
IDENTITIES=()
declare -A PUB=() SUB=()
while read -r id dir topics; do
  [ "$dir" = pub ] && { IDENTITIES+=("$id"); PUB[$id]="$topics"; } || SUB[$id]="$topics"
done <<< "$GRANTS"

echo "make-security: test CA and ${#IDENTITIES[@]} identities in $DIR (profile $PROFILE, $DAYS days)"
# EC P-256 everywhere (docs/reference/dds.md#security: works with Fast DDS 2.9.1 and OpenSSL 3).
openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout ca.key -out ca.pem \
  -days "$DAYS" -sha256 -subj "/C=DE/O=mft-wbc/CN=${CN_PREFIX}mft-wbc test CA" 2>/dev/null
for id in "${IDENTITIES[@]}"; do
  openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout "$id.key" -out "$id.csr" -sha256 \
    -subj "/C=DE/O=mft-wbc/CN=${CN_PREFIX}${id}" 2>/dev/null
  openssl x509 -req -in "$id.csr" -CA ca.pem -CAkey ca.key -CAcreateserial -out "$id.pem" -days "$DAYS" -sha256 2>/dev/null
  rm -f "$id.csr"
done
rm -f ca.srl

if [ "$PROFILE" = data ]; then
  RTPS=NONE; META=NONE
else
  RTPS=ENCRYPT; META=ENCRYPT
fi
cat > governance.xml <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<!-- mft-wbc governance, profile '$PROFILE' (docs/guide/security.md): no unauthenticated participant may join;
     every topic is access controlled and its data encrypted. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="omg_shared_ca_domain_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>232</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>$RTPS</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>$META</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
openssl smime -sign -in governance.xml -text -out governance.p7s -signer ca.pem -inkey ca.key

NOT_BEFORE="$(date -u -d '-1 day' +%Y-%m-%dT%H:%M:%S)"
NOT_AFTER="$(date -u -d "+$DAYS days" +%Y-%m-%dT%H:%M:%S)"
# Topics by their DDS names, as the services create them (services/runtime/topic_names.hpp): ROS 2's
# rt/mft/<snake_case>, e.g. SensorData -> rt/mft/sensor_data.
dds_topic() { printf 'rt/mft/%s' "$(printf '%s' "$1" | sed -E 's/([a-z0-9])([A-Z])/\1_\2/g' | tr '[:upper:]' '[:lower:]')"; }
topics_xml() {
  local t
  for t in $1; do printf '            <topic>%s</topic>\n' "$(dds_topic "$t")"; done
}
for id in "${IDENTITIES[@]}"; do
  {
    echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo "<!-- mft-wbc permissions of '$id' (made by scripts/make-security.sh) -->"
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    echo "    <grant name=\"${id}_grant\">"
    # RFC 2253 order, the reverse of the -subj string (docs/reference/dds.md#security, trap 2).
    echo "      <subject_name>CN=${CN_PREFIX}${id}, O=mft-wbc, C=DE</subject_name>"
    echo "      <validity><not_before>$NOT_BEFORE</not_before><not_after>$NOT_AFTER</not_after></validity>"
    echo '      <allow_rule>'
    echo '        <domains><id_range><min>0</min><max>232</max></id_range></domains>'
    if [ -n "${PUB[$id]}" ]; then
      echo '        <publish>'
      echo '          <topics>'
      topics_xml "${PUB[$id]}"
      echo '          </topics>'
      echo '        </publish>'
    fi
    if [ -n "${SUB[$id]}" ]; then
      echo '        <subscribe>'
      echo '          <topics>'
      topics_xml "${SUB[$id]}"
      echo '          </topics>'
      echo '        </subscribe>'
    fi
    echo '      </allow_rule>'
    echo '      <default>DENY</default>'
    echo '    </grant>'
    echo '  </permissions>'
    echo '</dds>'
  } > "permissions_$id.xml"
  openssl smime -sign -in "permissions_$id.xml" -text -out "permissions_$id.p7s" -signer ca.pem -inkey ca.key
done
chmod 600 ./*.key
chmod 644 ./*.pem ./*.p7s ./*.xml
cat > README.txt <<EOF
mft-wbc DDS Security material made by scripts/make-security.sh on $(date -u +%Y-%m-%dT%H:%M:%SZ), profile $PROFILE.
Test CA only: ca.key is here. Use: services/mft-supervisor run SCENARIO --secure $DIR
EOF
echo "make-security: done: ca.pem, governance.p7s, and <id>.pem/<id>.key/permissions_<id>.p7s for: ${IDENTITIES[*]}"
