"""The topic registry (docs/architecture.md#the-topic-registry): idl/topics.yaml (where each topic goes) with the
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
ROW_KEYS = {"type", "wire", "qos", "chain", "record", "writers", "readers", "faults", "bad_values", "content"}
# IDL field types the messages use -> (C++ scalar, ROS 2 .msg type)
IDL_TYPES = {"unsigned long long": ("std::uint64_t", "uint64"), "double": ("double", "float64"),
             "boolean": ("bool", "bool"), "octet": ("std::uint8_t", "uint8"), "short": ("std::int16_t", "int16"),
             "long": ("std::int32_t", "int32"), "char": ("char", "uint8")}


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
    struct: Struct = None

    def has_field(self, name):
        return any(f.name == name for f in self.struct.fields)

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
        m = re.fullmatch(r"(unsigned long long|double|boolean|octet|short|long|char)\s+(\w+)(?:\[(\d+)\])?;", code)
        if not m:
            raise RegistryError(f"{source}: field '{code}' of {current.name} has a type the registry does not know")
        current.fields.append(Field(m.group(2), m.group(1), int(m.group(3)) if m.group(3) else None, comment))
    return consts, structs


def _row(entry, structs, where):
    unknown = set(entry) - ROW_KEYS
    if unknown:
        raise RegistryError(f"{where}: unknown keys {sorted(unknown)} (known: {sorted(ROW_KEYS)})")
    missing = ROW_KEYS - {"bad_values"} - set(entry)
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
    return t


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
    lonely = sorted(set(structs) - set(names))
    if lonely:
        raise RegistryError(f"messages without a row in the topic table: {', '.join(lonely)}")
    return Registry(rows, structs, consts)
