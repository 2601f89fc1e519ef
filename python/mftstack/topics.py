"""The topic registry (docs/reference/architecture.md#the-topic-registry): idl/topics.yaml (where each topic goes) with the
fields of its message from idl/mft_msgs.idl, read and checked. The one place the scripts learn the topics from
(scripts/fault-matrix.py, scripts/make-security.sh through idl/gen_topics.py), and what idl/gen_topics.py
generates the C++ descriptors, the ROS 2 package and the docs' table from."""
import re
from dataclasses import dataclass, field
from pathlib import Path

from .paths import REPO

IDL = REPO / "idl" / "mft_msgs.idl"
REGISTRY = REPO / "idl" / "topics.yaml"

# The DDS Security identities (scripts/make-security.sh): one per service, cmd for the operator's tools.
IDENTITIES = ("sim", "estimator", "planner", "wbc", "record", "cmd")
# The profiles of config/dds_profiles.xml each QoS class uses: (writers, readers).
QOS_PROFILES = {"chain": (("lockstep_writer", "control_writer"), ("lockstep_reader", "control_reader")),
                "event": (("command_writer", "verdict_writer", "event_writer"), ("event_reader",)),
                "progress": (("lockstep_writer",), ("lockstep_reader",))}
QOS_CLASSES = tuple(QOS_PROFILES)
ROW_KEYS = {"type", "wire", "qos", "chain", "record", "rawlog_id", "writers", "readers", "faults", "bad_values",
            "content"}
OPTIONAL_KEYS = {"bad_values", "rawlog_id"}


@dataclass(frozen=True)
class IdlType:
    cxx: str   # the C++ scalar
    ros2: str  # the ROS 2 .msg type
    kind: str  # its msg::fields::Kind (mft_msgs_fields.h)
    short: str  # its msg::FieldKind (mft_topics.hpp)


# The IDL's scalar types a message may use (each field: a scalar or a fixed-size array of one).
IDL_TYPES = {
    "unsigned long long": IdlType("std::uint64_t", "uint64", "UInt64", "U64"),
    "double": IdlType("double", "float64", "Double", "F64"),
    "boolean": IdlType("bool", "bool", "Bool", "Bool"),
    "octet": IdlType("std::uint8_t", "uint8", "Octet", "U8"),
    "short": IdlType("std::int16_t", "int16", "Int16", "I16"),
    "long": IdlType("std::int32_t", "int32", "Int32", "I32"),
    "char": IdlType("char", "uint8", "Char", "Char"),
    "unsigned short": IdlType("std::uint16_t", "uint16", "UInt16", "U16"),
    "unsigned long": IdlType("std::uint32_t", "uint32", "UInt32", "U32"),
    "long long": IdlType("std::int64_t", "int64", "Int64", "I64"),
    "float": IdlType("float", "float32", "Float", "F32"),
}
_FIELD = re.compile(r"(%s) (\w+) ?(?:\[ ?(\d+) ?\])? ?;" % "|".join(sorted(IDL_TYPES, key=len, reverse=True)))


class RegistryError(Exception):
    pass


@dataclass
class Field:
    name: str
    idl_type: str
    count: "int | None"  # array length, None for a scalar
    comment: str = ""


@dataclass
class Struct:
    name: str  # without the trailing underscore
    fields: list
    comment: list  # the comment lines above the struct


@dataclass
class Topic:
    type: str
    wire: str
    qos: str
    chain: bool
    record: bool
    writers: list
    readers: list
    faults: bool
    content: str
    bad_values: dict = field(default_factory=dict)
    rawlog_id: "int | None" = None  # recorded topics: the Topic value of the rawlog, never changed or reused
    struct: Struct = None

    def has_field(self, name):
        return any(f.name == name for f in self.struct.fields)

    def ticked(self):
        """In the rawlog: a stream of ticks stamped by the simulator's clock (tick, stamp_ns), not an event (seq,
        stamped on arrival)."""
        return self.qos != "event"

    def subscribers(self):
        """The identities allowed to read it: its readers, and the recorder when it is recorded."""
        return self.readers + (["record"] if self.record and "record" not in self.readers else [])


def ros2_topic_name(type_name):
    """"SensorData" -> "rt/mft/sensor_data": ROS 2's DDS name of topic /mft/sensor_data."""
    return "rt/mft/" + re.sub(r"(?<!^)([A-Z])", r"_\1", type_name).lower()


def _strip_comment(line):
    code, _, comment = line.partition("//")
    return code.strip(), comment.strip()


def parse_idl(text, source="idl"):
    """(constants {name: (value, comment)}, structs {name: Struct}) of module mft::msg(::dds_) in `text`."""
    consts, structs = {}, {}
    lines = text.splitlines()
    pending_comment, current = [], None
    for raw in lines:
        code, comment = _strip_comment(raw)
        if current is None:
            m = re.fullmatch(r"const octet (\w+) = (\d+);", code)
            if m:
                consts[m.group(1)] = (int(m.group(2)), comment)
                continue
            m = re.fullmatch(r"struct (\w+)_ \{", code)
            if m:
                current = Struct(m.group(1), [], pending_comment)
                pending_comment = []
                continue
            pending_comment = pending_comment + [comment] if (not code and comment) else []
            continue
        if code == "};":
            structs[current.name] = current
            current = None
            continue
        if not code:
            continue
        m = _FIELD.fullmatch(" ".join(code.split()))
        if not m:
            raise RegistryError(f"{source}: field '{code}' of {current.name} has a type the registry does not know "
                                f"(one of: {', '.join(IDL_TYPES)}; arrays of fixed size)")
        current.fields.append(Field(m.group(2), m.group(1), int(m.group(3)) if m.group(3) else None, comment))
    return consts, structs


def _row(entry, structs, where):
    unknown = set(entry) - ROW_KEYS
    if unknown:
        raise RegistryError(f"{where}: unknown keys {sorted(unknown)} (known: {sorted(ROW_KEYS)})")
    missing = ROW_KEYS - OPTIONAL_KEYS - set(entry)
    if missing:
        raise RegistryError(f"{where}: missing {sorted(missing)}")
    t = Topic(**{k: entry[k] for k in ROW_KEYS if k in entry})
    t.bad_values = dict(t.bad_values or {})
    if t.type not in structs:
        raise RegistryError(f"{where}: no struct {t.type}_ in the IDL")
    t.struct = structs[t.type]
    if t.wire != ros2_topic_name(t.type):
        raise RegistryError(f"{where}: wire name {t.wire} is not ROS 2's name of the type, {ros2_topic_name(t.type)}")
    if t.qos not in QOS_CLASSES:
        raise RegistryError(f"{where}: qos {t.qos} is not one of {QOS_CLASSES}")
    for who in t.writers + t.readers:
        if who not in IDENTITIES:
            raise RegistryError(f"{where}: {who} is not a security identity ({', '.join(IDENTITIES)})")
    for name in t.bad_values:
        if not t.has_field(name):
            raise RegistryError(f"{where}: bad_values names {name}, not a field of {t.type}")
    if t.chain and t.qos != "chain":
        raise RegistryError(f"{where}: a topic on the chain channel needs qos chain")
    _check_recording(t, where)
    return t


def _check_recording(t, where):
    """A recorded row has its rawlog id, and the fields the rawlog stamps it by."""
    if t.record != (t.rawlog_id is not None):
        raise RegistryError(f"{where}: rawlog_id is given exactly when record is true (a new recorded topic takes "
                            "the next free id)")
    if t.rawlog_id is not None and (not isinstance(t.rawlog_id, int) or isinstance(t.rawlog_id, bool)
                                    or t.rawlog_id < 0):
        raise RegistryError(f"{where}: rawlog_id {t.rawlog_id!r} is not an integer >= 0")
    need = ("tick", "stamp_ns") if t.ticked() else ("seq",)
    if t.record and not all(t.has_field(f) for f in need):
        raise RegistryError(f"{where}: a recorded {'stream' if t.ticked() else 'event'} topic needs the fields "
                            f"{', '.join(need)}")


def _check_rawlog_ids(rows):
    """The rawlog ids are 0..n-1, each once: a message's id is its index in the rawlog's variant."""
    ids = sorted(t.rawlog_id for t in rows if t.record)
    if ids != list(range(len(ids))):
        raise RegistryError(f"the rawlog ids of the recorded topics are {ids}, not 0..{len(ids) - 1} each once "
                            "(a new recorded topic takes the one after the highest; never renumber one)")


@dataclass
class Registry:
    topics: list
    structs: dict
    consts: dict

    def topic(self, type_name):
        for t in self.topics:
            if t.type == type_name:
                return t
        raise RegistryError(f"unknown topic {type_name} (one of {', '.join(t.type for t in self.topics)})")

    def recorded(self):
        """The recorded topics by rawlog id."""
        return sorted((t for t in self.topics if t.record), key=lambda t: t.rawlog_id)

    def names(self, **where):
        """The topic types, in registry order, whose attributes equal `where` (e.g. faults=True)."""
        return [t.type for t in self.topics if all(getattr(t, k) == v for k, v in where.items())]

    def permissions(self, identity):
        """(topics `identity` may publish, topics it may subscribe to), in registry order."""
        return ([t.type for t in self.topics if identity in t.writers],
                [t.type for t in self.topics if identity in t.subscribers()])


def load(idl_paths=(IDL,), registry_paths=(REGISTRY,)):
    """The registry of the given IDL files and topic tables (a scratch build adds its own to the project's)."""
    import yaml
    consts, structs, rows = {}, {}, []
    for p in idl_paths:
        c, s = parse_idl(Path(p).read_text(), str(p))
        consts.update(c)
        structs.update(s)
    for p in registry_paths:
        try:
            doc = yaml.safe_load(Path(p).read_text())
        except (OSError, yaml.YAMLError) as e:
            raise RegistryError(f"{p}: {e}")
        for i, entry in enumerate((doc or {}).get("topics") or []):
            rows.append(_row(entry, structs, f"{p}: topic {i + 1} ({entry.get('type', '?')})"))
    names = [t.type for t in rows]
    if len(set(names)) != len(names):
        raise RegistryError("a topic is listed twice: " + ", ".join(sorted({n for n in names if names.count(n) > 1})))
    _check_rawlog_ids(rows)
    lonely = sorted(set(structs) - set(names))
    if lonely:
        raise RegistryError(f"messages without a row in the topic table: {', '.join(lonely)}")
    return Registry(rows, structs, consts)
