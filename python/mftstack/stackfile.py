"""Multi-host stack files (`--stack FILE`, docs/guide/distributed.md): strict loading and the checks of the hosts
they name against this machine (network namespaces, addresses, the discovery server executable)."""
import ipaddress
import os
import re
import shutil
import socket
import subprocess
from pathlib import Path

from .errors import SupervisorError
from .processes import ALL_SERVICES


STACK_KEYS = {"hosts": "a mapping of host names", "services": "a mapping service: host",
              "discovery": "initial_peers or server", "discovery_server": "{host, port}"}
HOST_KEYS = ("address", "netns")
SERVER_KEYS = ("host", "port")
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class StackFile:
    """A validated stack file: hosts (address, optional network namespace), the host of every service and
    the discovery (initial peers or a discovery server on one of the hosts)."""

    def __init__(self, path, hosts, placement, discovery, server_host=None, server_port=11811):
        self.path = path
        self.hosts = hosts            # name -> {"address": str, "netns": str or None}
        self.placement = placement    # service -> host name
        self.discovery = discovery    # "initial_peers" | "server"
        self.server_host = server_host
        self.server_port = server_port
        self.server_exe = None        # fast-discovery-server, found by check_stack_environment

    def launcher(self, host):
        """The command prefix that runs a process on `host`: `ip netns exec NS` or nothing."""
        ns = self.hosts[host]["netns"]
        return ["ip", "netns", "exec", ns] if ns else []

    def used_hosts(self, services, only_host=None):
        if only_host:
            return [only_host]
        used = {self.placement[s] for s in services}
        if self.discovery == "server":
            used.add(self.server_host)
        return [h for h in self.hosts if h in used]  # in file order

    def runs_server(self, only_host=None):
        """True when this supervisor starts the discovery server."""
        return self.discovery == "server" and only_host in (None, self.server_host)

    def describe(self):
        return {"file": str(self.path), "discovery": self.discovery,
                "discovery_server": f"{self.server_host}:{self.server_port}" if self.discovery == "server" else None,
                "hosts": self.hosts}


def _load_yaml_strict(path):
    """YAML with duplicate keys refused (PyYAML silently keeps the last one)."""
    try:
        import yaml
    except ImportError:
        raise SupervisorError("--stack needs PyYAML (Debian: python3-yaml; scripts/install-deps.sh)")

    class Loader(yaml.SafeLoader):
        pass

    def mapping(loader, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = loader.construct_object(key_node, deep=deep)
            if key in seen:
                raise SupervisorError(f"{path}: line {key_node.start_mark.line + 1}: duplicate key {key}")
            seen.add(key)
        return yaml.SafeLoader.construct_mapping(loader, node, deep)

    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, mapping)
    try:
        return yaml.load(Path(path).read_text(), Loader=Loader)
    except UnicodeDecodeError as e:
        raise SupervisorError(f"{path}: not UTF-8 text (byte {e.start}: {e.reason})")
    except yaml.YAMLError as e:
        raise SupervisorError(f"{path}: not valid YAML: {str(e).splitlines()[0]} "
                              f"(line {getattr(getattr(e, 'problem_mark', None), 'line', -1) + 1})")


def load_stack(path, services):
    """Reads and validates a stack file strictly: every error names the file and the key. `services` are the
    services this run starts (each must be placed on a host)."""
    path = Path(path)
    if not path.is_file():
        raise SupervisorError(f"stack file {path} does not exist")
    doc = _load_yaml_strict(path)

    def err(key, msg):
        return SupervisorError(f"{path}: {key}: {msg}")

    def unknown(mapping, allowed, prefix):
        for k in mapping:
            if k not in allowed:
                raise SupervisorError(f"{path}: unknown key {prefix}{k} (expected: {', '.join(allowed)})")

    if not isinstance(doc, dict):
        raise SupervisorError(f"{path}: expected a mapping with the keys {', '.join(STACK_KEYS)}")
    unknown(doc, list(STACK_KEYS), "")
    for k in ("hosts", "services"):
        if k not in doc:
            raise SupervisorError(f"{path}: missing key {k} ({STACK_KEYS[k]})")
    if not isinstance(doc["hosts"], dict) or not doc["hosts"]:
        raise err("hosts", "expected a non-empty mapping host name: {address, netns}")
    hosts, seen_addr = {}, {}
    for name, h in doc["hosts"].items():
        key = f"hosts.{name}"
        if not isinstance(name, str) or not NAME_RE.match(name):
            raise err(key, "a host name is letters, digits, '_', '.', '-'")
        if not isinstance(h, dict):
            raise err(key, "expected a mapping with address (and optionally netns)")
        unknown(h, HOST_KEYS, key + ".")
        if "address" not in h:
            raise err(key, "missing key address")
        try:
            addr = ipaddress.IPv4Address(str(h["address"]))
        except ValueError:
            raise err(key + ".address", f"'{h['address']}' is not an IPv4 address")
        if addr.is_multicast or addr.is_unspecified or str(addr) == "255.255.255.255":
            raise err(key + ".address", f"{addr} is not a unicast host address")
        if str(addr) in seen_addr:
            raise err(key + ".address", f"{addr} is also the address of host {seen_addr[str(addr)]}")
        seen_addr[str(addr)] = name
        ns = h.get("netns")
        if ns is not None and (not isinstance(ns, str) or not NAME_RE.match(ns)):
            raise err(key + ".netns", f"'{ns}' is not a network namespace name")
        hosts[name] = {"address": str(addr), "netns": ns}
    if not isinstance(doc["services"], dict):
        raise err("services", "expected a mapping service: host")
    placement = {}
    for svc, host in doc["services"].items():
        if svc not in ALL_SERVICES:
            raise SupervisorError(f"{path}: unknown key services.{svc} (services: {', '.join(ALL_SERVICES)})")
        if host not in hosts:
            raise err(f"services.{svc}", f"unknown host '{host}' (hosts: {', '.join(hosts)})")
        placement[svc] = host
    missing = [s for s in services if s not in placement]
    if missing:
        raise err("services", f"no host for {', '.join(missing)}")
    discovery = doc.get("discovery", "initial_peers")
    if discovery not in ("initial_peers", "server"):
        raise err("discovery", f"unknown value '{discovery}' (expected initial_peers or server)")
    server_host, server_port = None, 11811
    if discovery == "server":
        ds = doc.get("discovery_server")
        if not isinstance(ds, dict):
            raise err("discovery_server", "discovery: server needs discovery_server: {host: HOST, port: 11811}")
        unknown(ds, SERVER_KEYS, "discovery_server.")
        server_host = ds.get("host")
        if server_host not in hosts:
            raise err("discovery_server.host", f"unknown host '{server_host}' (hosts: {', '.join(hosts)})")
        server_port = ds.get("port", 11811)
        if not isinstance(server_port, int) or isinstance(server_port, bool) or not 1 <= server_port <= 65535:
            raise err("discovery_server.port", f"'{server_port}' is not a UDP port (1..65535)")
    elif "discovery_server" in doc:
        raise err("discovery_server", "only used with discovery: server")
    return StackFile(path.resolve(), hosts, placement, discovery, server_host, server_port)


def _netns_addresses(ns):
    """IPv4 addresses and the state of lo in network namespace `ns` (raises SupervisorError)."""
    p = subprocess.run(["ip", "-n", ns, "-o", "-4", "addr", "show"], capture_output=True, text=True, timeout=10)
    if p.returncode != 0:
        raise SupervisorError(f"cannot look into network namespace {ns}: {p.stderr.strip()}")
    addrs = set(re.findall(r"\binet (\d+\.\d+\.\d+\.\d+)/", p.stdout))
    lo = subprocess.run(["ip", "-n", ns, "-o", "link", "show", "lo"], capture_output=True, text=True, timeout=10)
    lo_up = ",UP" in lo.stdout or "<UP" in lo.stdout
    return addrs, lo_up


def check_stack_environment(stack, services, only_host=None):
    """Everything the stack file names must exist before anything starts: each used host's namespace (with
    lo up) and address, or a local address; the discovery server executable. With --host only that host."""
    for host in stack.used_hosts(services, only_host):
        h = stack.hosts[host]
        key = f"{stack.path}: hosts.{host}"
        if h["netns"]:
            if os.geteuid() != 0:
                raise SupervisorError(f"{key}.netns: starting services in a network namespace needs root (ip netns exec)")
            if shutil.which("ip") is None:
                raise SupervisorError(f"{key}.netns: the 'ip' command (iproute2) is not installed")
            if not Path("/run/netns", h["netns"]).exists() and not Path("/var/run/netns", h["netns"]).exists():
                raise SupervisorError(f"{key}.netns: network namespace '{h['netns']}' does not exist (ip netns list)")
            addrs, lo_up = _netns_addresses(h["netns"])
            if h["address"] not in addrs:
                raise SupervisorError(f"{key}.address: {h['address']} is not an address of network namespace "
                                      f"'{h['netns']}' (it has: {', '.join(sorted(addrs)) or 'none'})")
            if not lo_up:
                raise SupervisorError(f"{key}.netns: lo is down in network namespace '{h['netns']}' (services on one "
                                      f"host talk over it: ip -n {h['netns']} link set lo up)")
        else:
            try:
                with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
                    sock.bind((h["address"], 0))
            except OSError:
                raise SupervisorError(f"{key}.address: {h['address']} is not an address of this machine (a host "
                                      f"without netns runs here)")
    if stack.runs_server(only_host):
        stack.server_exe = shutil.which("fast-discovery-server")
        if stack.server_exe is None:
            raise SupervisorError(f"{stack.path}: discovery: server needs fast-discovery-server (Debian: fastdds-tools)")
