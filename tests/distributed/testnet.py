#!/usr/bin/env python3
"""Test hosts as Linux network namespaces (docs/guide/distributed.md), for the distributed tests and by hand.

A TestNet is N host namespaces, each with `lo` up and one veth `eth0` on a private /24, plugged into a bridge
`br0` in a "switch" namespace of its own. Every command runs inside a namespace this module created (`ip -n`,
`tc -n`, `ip netns exec NS nft`): the root namespace's interfaces, routes and nftables are never touched, and
destroy() deletes exactly the namespaces create() made. IPv6 is off in them (no neighbour-discovery chatter
in the byte counters).

Faults on a host's link (its eth0, egress, so a packet between two hosts meets each fault once):
  loss:  an nftables table `inet mft_fault` in the host's namespace: `numgen random mod 100 < N drop`
         (whole percent; set_loss(host, 0) removes it);
  rate:  `tc qdisc replace dev eth0 root tbf rate R burst B latency L` (clear_rate removes it);
  cut:   `ip link set eth0 down`, then up (the kernel drops what is sent meanwhile; the address stays).
The kernel here has no netem: no delay emulation.

By hand (root), from a stack file whose hosts name their netns (config/stacks/three-hosts.yaml):
  python3 tests/distributed/testnet.py up config/stacks/three-hosts.yaml      # make the namespaces
  python3 tests/distributed/testnet.py loss config/stacks/three-hosts.yaml 1  # 1 % loss on every host
  python3 tests/distributed/testnet.py rate config/stacks/three-hosts.yaml ctrl 20mbit
  python3 tests/distributed/testnet.py cut config/stacks/three-hosts.yaml ctrl 0.2
  python3 tests/distributed/testnet.py clear config/stacks/three-hosts.yaml   # no faults
  python3 tests/distributed/testnet.py stats config/stacks/three-hosts.yaml   # bytes/packets per link
  python3 tests/distributed/testnet.py down config/stacks/three-hosts.yaml    # delete them
"""
import argparse
import ipaddress
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
# A realtime stack under test runs at SCHED_FIFO 80 and delays an `ip`/`tc`/`nft` at normal priority by tens of
# ms (once 1.2 s) on 2 busy cores, so a fault is applied inside this (SCHED_FIFO 85 where permitted).
from mftstack.simlog import fifo_priority as realtime_priority  # noqa: E402

IFACE = "eth0"
NFT_TABLE = "mft_fault"


class NetError(Exception):
    pass


def _run(cmd, check=True, input_text=None):
    p = subprocess.run(cmd, capture_output=True, text=True, input=input_text, timeout=30)
    if check and p.returncode != 0:
        raise NetError(f"{' '.join(cmd)}: {(p.stderr or p.stdout).strip()}")
    return p


def netns_exists(name):
    return Path("/run/netns", name).exists() or Path("/var/run/netns", name).exists()


def remove_stale_namespaces():
    """Deletes namespaces mftd<pid>-... of test processes that are gone: a test killed by CTest's timeout
    (SIGKILL) never reaches its tearDown. Returns the names deleted."""
    deleted = []
    for d in (Path("/run/netns"), Path("/var/run/netns")):
        for entry in sorted(d.glob("mftd*-*")) if d.is_dir() else []:
            pid = entry.name[4:].split("-", 1)[0]
            if not pid.isdigit() or Path("/proc", pid).exists():
                continue
            if subprocess.run(["ip", "netns", "del", entry.name], capture_output=True, timeout=30).returncode == 0:
                deleted.append(entry.name)
    return deleted


def netns_permitted(probe_name=None):
    """(True, "") when this process may create network namespaces, else (False, why)."""
    if os.geteuid() != 0:
        return False, "not root (network namespaces need CAP_SYS_ADMIN)"
    name = probe_name or f"mftprobe{os.getpid()}"
    try:
        p = subprocess.run(["ip", "netns", "add", name], capture_output=True, text=True, timeout=10)
    except FileNotFoundError:
        return False, "the 'ip' command (iproute2) is not installed"
    if p.returncode != 0:
        return False, f"'ip netns add' failed: {p.stderr.strip()}"
    subprocess.run(["ip", "netns", "del", name], capture_output=True, timeout=10)
    for tool in ("nft", "tc"):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            return False, f"'{tool}' is not installed"
    return True, ""


class TestNet:
    """hosts: {host name: (namespace name, IPv4 address)}, all on one /`prefix_len` subnet."""

    def __init__(self, hosts, switch_ns, prefix_len=24):
        self.hosts = dict(hosts)
        self.switch = switch_ns
        self.prefix_len = prefix_len
        self.created = []  # namespaces this object made: the only ones destroy() deletes
        nets = {ipaddress.IPv4Interface(f"{a}/{prefix_len}").network for _, a in self.hosts.values()}
        if len(nets) != 1:
            raise NetError(f"the hosts' addresses are not on one /{prefix_len}: {sorted(map(str, nets))}")

    @classmethod
    def for_test(cls, tag, host_names, third_octet):
        """Namespaces named mftd<pid>-<tag>-<host> on 10.77.<third_octet>.0/24 (hosts .1, .2, ...)."""
        remove_stale_namespaces()
        base = f"mftd{os.getpid()}-{tag}"
        hosts = {h: (f"{base}-{h}", f"10.77.{third_octet}.{i + 1}") for i, h in enumerate(host_names)}
        return cls(hosts, f"{base}-sw")

    def ns(self, host):
        return self.hosts[host][0]

    def address(self, host):
        return self.hosts[host][1]

    # ------------------------------------------------------------------------------------ create/destroy
    def _add_ns(self, name):
        if netns_exists(name):
            raise NetError(f"network namespace {name} already exists: not touching it")
        _run(["ip", "netns", "add", name])
        self.created.append(name)
        _run(["ip", "-n", name, "link", "set", "lo", "up"])
        for key in ("all", "default"):
            _run(["ip", "netns", "exec", name, "sh", "-c", f"echo 1 > /proc/sys/net/ipv6/conf/{key}/disable_ipv6"],
                 check=False)

    def create(self):
        try:
            self._add_ns(self.switch)
            _run(["ip", "-n", self.switch, "link", "add", "br0", "type", "bridge"])
            _run(["ip", "-n", self.switch, "link", "set", "br0", "up"])
            for i, (host, (ns, addr)) in enumerate(self.hosts.items()):
                self._add_ns(ns)
                port = f"p{i}"
                # Both ends are created directly in their namespaces: nothing ever appears in the root one.
                _run(["ip", "-n", self.switch, "link", "add", port, "type", "veth", "peer", "name", IFACE, "netns", ns])
                _run(["ip", "-n", self.switch, "link", "set", port, "master", "br0"])
                _run(["ip", "-n", self.switch, "link", "set", port, "up"])
                _run(["ip", "-n", ns, "addr", "add", f"{addr}/{self.prefix_len}", "dev", IFACE])
                _run(["ip", "-n", ns, "link", "set", IFACE, "up"])
        except Exception:
            self.destroy()
            raise
        return self

    def destroy(self):
        """Deletes every namespace this object created (their veths and bridge go with them)."""
        errors = []
        for name in reversed(self.created):
            p = subprocess.run(["ip", "netns", "del", name], capture_output=True, text=True, timeout=30)
            if p.returncode != 0 and netns_exists(name):
                errors.append(f"{name}: {p.stderr.strip()}")
        self.created = [n for n in self.created if netns_exists(n)]
        if errors:
            raise NetError("could not delete: " + "; ".join(errors))

    def __enter__(self):
        return self.create()

    def __exit__(self, *exc):
        self.destroy()

    # ----------------------------------------------------------------------------------------- stack file
    def stack_yaml(self, placement, discovery="initial_peers", server_host=None, port=11811):
        lines = ["# written by tests/distributed/testnet.py", "hosts:"]
        for host, (ns, addr) in self.hosts.items():
            lines.append(f"  {host}: {{address: {addr}, netns: {ns}}}")
        lines.append("services:")
        lines += [f"  {svc}: {host}" for svc, host in placement.items()]
        lines.append(f"discovery: {discovery}")
        if discovery == "server":
            lines.append(f"discovery_server: {{host: {server_host}, port: {port}}}")
        return "\n".join(lines) + "\n"

    # --------------------------------------------------------------------------------------------- faults
    def set_loss(self, host, percent):
        """Drops `percent` % of the packets leaving `host` on its link, at random (nftables numgen)."""
        ns = self.ns(host)
        _run(["ip", "netns", "exec", ns, "nft", "delete", "table", "inet", NFT_TABLE], check=False)
        if percent <= 0:
            return
        if not (0 < percent <= 100 and float(percent).is_integer()):
            raise NetError(f"loss: {percent} is not a whole percentage in 1..100")
        rules = (f"table inet {NFT_TABLE} {{\n"
                 f"  chain egress {{ type filter hook output priority 0; policy accept;\n"
                 f"    oifname \"{IFACE}\" numgen random mod 100 < {int(percent)} counter drop\n"
                 f"    oifname \"{IFACE}\" counter\n  }}\n}}\n")
        _run(["ip", "netns", "exec", ns, "nft", "-f", "-"], input_text=rules)

    def loss_counters(self, host):
        """(packets dropped, packets passed) by the loss rule of `host`, or None without one."""
        p = _run(["ip", "netns", "exec", self.ns(host), "nft", "-j", "list", "table", "inet", NFT_TABLE], check=False)
        if p.returncode != 0:
            return None
        counters = []
        for item in json.loads(p.stdout)["nftables"]:
            for expr in item.get("rule", {}).get("expr", []):
                if "counter" in expr:
                    counters.append(expr["counter"]["packets"])
        return tuple(counters[:2]) if len(counters) >= 2 else None

    def set_rate(self, host, rate, burst="32kbit", latency="5ms"):
        """Token bucket on `host`'s egress: at most `rate` (tc units, e.g. 20mbit), a packet waiting longer
        than `latency` is dropped."""
        _run(["tc", "-n", self.ns(host), "qdisc", "replace", "dev", IFACE, "root", "tbf", "rate", rate,
              "burst", burst, "latency", latency])

    def rate_stats(self, host):
        """tbf's own counters: {"sent_bytes", "sent_packets", "dropped", "overlimits"} (None without tbf)."""
        p = _run(["tc", "-n", self.ns(host), "-s", "-j", "qdisc", "show", "dev", IFACE], check=False)
        for q in json.loads(p.stdout or "[]"):
            if q.get("kind") == "tbf":
                return {"sent_bytes": q.get("bytes"), "sent_packets": q.get("packets"), "dropped": q.get("drops"),
                        "overlimits": q.get("overlimits")}
        return None

    def clear_rate(self, host):
        _run(["tc", "-n", self.ns(host), "qdisc", "del", "dev", IFACE, "root"], check=False)

    def link(self, host, up):
        _run(["ip", "-n", self.ns(host), "link", "set", IFACE, "up" if up else "down"])

    def cut(self, host, seconds):
        """Takes `host`'s link down for `seconds`. Returns (shortest, longest) time it can have been down [s]:
        from after `ip link set down` returned to before `up` was issued, and from before the first to after
        the second command."""
        with realtime_priority():
            t0 = time.monotonic()
            self.link(host, False)
            t1 = time.monotonic()
            try:
                time.sleep(seconds)
            finally:
                t2 = time.monotonic()
                self.link(host, True)
                t3 = time.monotonic()
        return t2 - t1, t3 - t0

    def clear(self, host):
        self.set_loss(host, 0)
        self.clear_rate(host)
        self.link(host, True)

    # --------------------------------------------------------------------------------------------- counters
    def counters(self, host):
        """Bytes and packets of `host`'s link: {"rx_bytes", "tx_bytes", "rx_packets", "tx_packets", "tx_dropped"}."""
        p = _run(["ip", "-n", self.ns(host), "-s", "-j", "link", "show", "dev", IFACE])
        st = json.loads(p.stdout)[0]["stats64"]
        return {"rx_bytes": st["rx"]["bytes"], "tx_bytes": st["tx"]["bytes"], "rx_packets": st["rx"]["packets"],
                "tx_packets": st["tx"]["packets"], "tx_dropped": st["tx"]["dropped"]}


# ------------------------------------------------------------------------------------------------- by hand
def _from_stack(path):
    import yaml
    doc = yaml.safe_load(Path(path).read_text())
    hosts = {}
    for name, h in doc["hosts"].items():
        if not h.get("netns"):
            raise NetError(f"{path}: hosts.{name} has no netns: nothing to create")
        hosts[name] = (h["netns"], str(h["address"]))
    return TestNet(hosts, f"{Path(path).stem}-switch")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("command", choices=["up", "down", "loss", "rate", "cut", "clear", "stats"])
    ap.add_argument("stack", help="stack file whose hosts name their netns")
    ap.add_argument("args", nargs="*", help="loss: PERCENT [HOST]; rate: HOST RATE [BURST LATENCY]; cut: HOST SECONDS")
    a = ap.parse_args(argv)
    net = _from_stack(a.stack)
    try:
        if a.command == "up":
            net.create()
            for host, (ns, addr) in net.hosts.items():
                print(f"{host}: namespace {ns}, {addr} on {IFACE} (switch namespace {net.switch})")
        elif a.command == "down":
            net.created = [n for n in [net.switch] + [ns for ns, _ in net.hosts.values()] if netns_exists(n)]
            net.destroy()
            print("deleted")
        elif a.command == "loss":
            for host in ([a.args[1]] if len(a.args) > 1 else net.hosts):
                net.set_loss(host, float(a.args[0]))
        elif a.command == "rate":
            net.set_rate(a.args[0], a.args[1], *a.args[2:4])
        elif a.command == "cut":
            lo, hi = net.cut(a.args[0], float(a.args[1]))
            print(f"{a.args[0]} down for {lo:.3f} to {hi:.3f} s")
        elif a.command == "clear":
            for host in net.hosts:
                net.clear(host)
        elif a.command == "stats":
            for host in net.hosts:
                print(host, net.counters(host), "loss", net.loss_counters(host), "tbf", net.rate_stats(host))
    except (NetError, IndexError, ValueError) as e:
        print(f"testnet: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
