"""Everything checked before the first service starts: options, executables, configuration files (each
service's --check-config), the scenario, the --record target, DDS Security material, the stack file's
hosts, and a DDS domain nobody else uses (mft-participants). Each refusal is one line (exit status 2);
docs/results/faults.md "Bad input and misuse"."""
import json
import os
import subprocess
import time
from pathlib import Path

from .ddsxml import write_host_profiles
from .errors import SupervisorError, log
from .processes import ANSI_ESCAPE, CORE_SERVICES
from .stackfile import check_stack_environment, load_stack

MAX_DOMAIN_ID = 232
REQUIRED_CONFIG = ["robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml",
                   "dds_profiles.xml"]
# Before it starts anything, the supervisor asks mft-participants who is on the domain (a second stack on one
# domain hears the first one's commands). It listens this long: discovery of a running participant on loopback
# took 92-368 ms on this 2-core VM under a load average of 15-40 (docs/results/faults.md), so 1 s leaves a margin.
DOMAIN_PROBE_TOOL = "mft-participants"
DOMAIN_PROBE_WAIT_MS = 1000
# Set in the detached `up --foreground` child: its parent has just checked the domain.
DOMAIN_CHECKED_ENV = "MFT_SUPERVISOR_DOMAIN_CHECKED"


def check_domain_range(domain):
    if not (0 <= domain <= MAX_DOMAIN_ID):
        raise SupervisorError(f"bad domain id {domain}: must be in [0, {MAX_DOMAIN_ID}]")


def check_record_target(args):
    """--record FILE never replaces a recording silently: refused unless --overwrite."""
    if not getattr(args, "record", None):
        return
    rec = Path(args.record)
    if rec.is_dir():
        raise SupervisorError(f"--record {rec}: is a directory")
    sidecar = rec.with_name(rec.name + ".yaml")
    if (rec.exists() or sidecar.exists()) and not getattr(args, "overwrite", False):
        raise SupervisorError(f"--record {rec}: {rec if rec.exists() else sidecar} already exists; refusing to replace a "
                              f"recording (--overwrite replaces it)")


def check_service_configs(args):
    """`--check-config` of every service this run starts, in parallel, before any of them starts: each loads
    its configuration files with its strict loaders and dds_profiles.xml with Fast DDS's XML loader."""
    common = ["--check-config", "--domain", str(args.domain), "--scenario", str(Path(args.scenario).resolve()),
              "--mode", args.mode, "--config-dir", str(args.config_dir)]
    for name in getattr(args, "profile", None) or []:
        common += ["--profile", name]  # the configuration as the services will load it
    procs = {}
    try:
        for name in args.services_here:
            argv = [str(Path(args.bin_dir) / name)] + common
            if name == "mft-record":
                argv += ["--output", str(Path(args.record).resolve())] + (["--overwrite"] if args.overwrite else [])
            procs[name] = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                           stdin=subprocess.DEVNULL)
        problems = {}  # message -> services that reported it (robot.yaml and the scenario are read by all)
        for name, proc in procs.items():
            try:
                out, err = proc.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                problems.setdefault(f"{name} --check-config did not answer within 30 s", []).append(name)
                continue
            if proc.returncode != 0:
                text = (err or out).decode(errors="replace")
                lines = [ANSI_ESCAPE.sub("", l).strip() for l in text.splitlines()]
                lines = [l for l in lines if l and not l.startswith("Try '")]
                msg = lines[0] if lines else f"exit status {proc.returncode}"
                msg = msg[len(name) + 2:] if msg.startswith(name + ": ") else msg
                problems.setdefault(msg, []).append(name)
    finally:
        for proc in procs.values():
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    if problems:
        lines = [f"{msg} ({', '.join(names)})" for msg, names in problems.items()]
        raise SupervisorError("configuration refused before anything started: " + "\n  ".join(lines))


def domain_probe_places(args, tmp):
    """Where to look for participants: [(label, command prefix, profile file, address)]. Without a stack file
    this machine with the project's profile; with one, every host the run uses, from inside its network
    namespace with that host's profile (its address, its peers or the discovery server). With --host the
    address is set: the other hosts' participants then belong to the other supervisors of the same stack."""
    stack = args.stack_file
    if not stack:
        return [("this machine", [], Path(args.config_dir) / "dds_profiles.xml", None)]
    profiles = write_host_profiles(stack, Path(args.config_dir), Path(tmp))
    only = getattr(args, "host", None)
    return [(f"host {h}", stack.launcher(h), profiles[h], stack.hosts[h]["address"] if only else None)
            for h in stack.used_hosts(args.services_here, only)]


def probe_domain(args, launcher, profiles):
    """Runs mft-participants; returns its list of discovered participants."""
    argv = launcher + [str(Path(args.bin_dir) / DOMAIN_PROBE_TOOL), "--domain", str(args.domain),
                       "--profiles", str(profiles), "--wait-ms", str(DOMAIN_PROBE_WAIT_MS), "--json"]
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)


def check_domain_free(args):
    """Refuses a domain on which DDS participants already answer: a second stack on one domain hears the
    first one's commands (both robots misbehave), whoever started it (not only this supervisor's state files)."""
    if os.environ.get(DOMAIN_CHECKED_ENV) == str(args.domain):
        return  # the detached `up` child: its parent checked a moment ago
    import tempfile
    seen, problems = [], []
    with tempfile.TemporaryDirectory(prefix="mft-supervisor-probe-") as tmp:
        places = domain_probe_places(args, tmp)
        procs = []
        try:
            procs = [(label, address, probe_domain(args, launcher, profiles)) for label, launcher, profiles, address in places]
            for label, address, proc in procs:
                try:
                    out, err = proc.communicate(timeout=30)
                except subprocess.TimeoutExpired:
                    problems.append(f"{label}: {DOMAIN_PROBE_TOOL} did not answer within 30 s")
                    continue
                try:
                    found = json.loads(out.decode(errors="replace"))["participants"]
                except (ValueError, KeyError, TypeError):
                    text = ANSI_ESCAPE.sub("", err.decode(errors="replace")).strip().splitlines()
                    problems.append(f"{label}: {text[0] if text else f'{DOMAIN_PROBE_TOOL} exit status {proc.returncode}'}")
                    continue
                for p in found:
                    # The probes of a stack file run at once, one per host, and discover each other: another
                    # probe is no stack (two supervisors probing the same instant both pass: a narrow race).
                    if p.get("name") == DOMAIN_PROBE_TOOL or p.get("left"):
                        continue  # a participant that said goodbye while we listened is a stack shutting down
                    if address is None or address in p.get("addresses", []):
                        seen.append((label, p))
        finally:
            for _, _, proc in procs:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
    if problems:
        raise SupervisorError(f"cannot tell whether domain {args.domain} is in use: " + "; ".join(problems))
    if seen:
        what = ", ".join(f"{p.get('name') or '(unnamed)'} at {'/'.join(p.get('addresses') or ['?'])}"
                         + (f" ({label})" if args.stack_file else "") for label, p in seen)
        raise SupervisorError(f"domain {args.domain} is in use: {len(seen)} DDS participant(s) answered: {what}. Stop "
                              f"that stack first (mft-supervisor down --domain {args.domain}) or choose another --domain")


def check_before_start(args):
    """Everything that must hold before the first service starts, after the scenario was validated."""
    if os.environ.get(DOMAIN_CHECKED_ENV) == str(args.domain):
        return  # the detached `up` child: its parent checked everything a moment ago
    t0 = time.monotonic()
    check_record_target(args)
    check_service_configs(args)
    t1 = time.monotonic()
    check_domain_free(args)
    log(f"configuration checked in {t1 - t0:.2f} s, domain {args.domain} free ({time.monotonic() - t1:.2f} s)",
        getattr(args, "json", False))


def check_common(args):
    check_domain_range(args.domain)
    bin_dir = Path(args.bin_dir)
    needed = CORE_SERVICES + ["mft-sim"] + (["mft-record"] if getattr(args, "record", None) else [])
    args.stack_file = None
    if getattr(args, "stack", None):
        args.stack_file = load_stack(args.stack, needed)
        needed = check_host_option(args, args.stack_file, needed)  # --host: only the services placed there
        if getattr(args, "secure", None) and args.stack_file.discovery == "server":
            # The clients only talk to authenticated participants, and fast-discovery-server has no identity
            # (scripts/make-security.sh makes none for it): every client would wait for discovery forever.
            raise SupervisorError(f"{args.stack_file.path}: discovery: server does not work with --secure (the discovery "
                                  f"server has no DDS Security identity); use discovery: initial_peers")
    elif getattr(args, "host", None):
        raise SupervisorError("--host needs --stack (the stack file names the hosts)")
    args.services_here = list(needed)
    missing = [n for n in needed + [DOMAIN_PROBE_TOOL] if not os.access(bin_dir / n, os.X_OK)]
    if missing:
        raise SupervisorError(f"missing executables in {bin_dir}: {', '.join(missing)} (build first: scripts/build.sh)")
    cfg = Path(args.config_dir)
    missing = [c for c in REQUIRED_CONFIG if not (cfg / c).is_file()]
    if missing:
        raise SupervisorError(f"missing configuration in {cfg}: {', '.join(missing)}")
    if args.mode not in ("lockstep", "realtime"):
        raise SupervisorError(f"bad mode '{args.mode}': expected lockstep or realtime")
    if getattr(args, "secure", None):
        check_secure(Path(args.secure), needed)
    if args.stack_file:
        check_stack_environment(args.stack_file, needed, getattr(args, "host", None))


def check_host_option(args, stack, needed):
    """`--host NAME`: this supervisor starts only the services the stack file places on NAME (one supervisor
    per machine). `run` follows the simulator, so it must be on that host; the other hosts use `up`."""
    host = getattr(args, "host", None)
    if not host:
        return needed
    if host not in stack.hosts:
        raise SupervisorError(f"--host {host}: no such host in {stack.path} (hosts: {', '.join(stack.hosts)})")
    if getattr(args, "command", None) == "run" and stack.placement["mft-sim"] != host:
        raise SupervisorError(f"--host {host}: 'run' follows the simulator, which is on host "
                              f"{stack.placement['mft-sim']}; start the services of {host} with 'up'")
    local = [n for n in needed if stack.placement[n] == host]
    if not local and not (stack.discovery == "server" and stack.server_host == host):
        raise SupervisorError(f"--host {host}: {stack.path} places no service on {host}")
    return local


def check_secure(sec, services):
    """The DDS Security material of every service (scripts/make-security.sh), checked before anything starts."""
    if not sec.is_dir():
        raise SupervisorError(f"--secure: {sec} is not a directory (make one with scripts/make-security.sh {sec})")
    files = ["ca.pem", "governance.p7s"]
    for name in services:
        ident = name[len("mft-"):]
        files += [f"{ident}.pem", f"{ident}.key", f"permissions_{ident}.p7s"]
    missing = [f for f in files if not (sec / f).is_file()]
    if missing:
        raise SupervisorError(f"--secure: missing in {sec}: {', '.join(missing)} (made by scripts/make-security.sh)")


def load_scenario(args):
    path = Path(args.scenario)
    if not path.is_file():
        raise SupervisorError(f"scenario file {path} does not exist")
    argv = [str(Path(args.bin_dir) / "mft-sim"), "--check-scenario", str(path), "--json", "--config-dir", str(args.config_dir)]
    for name in getattr(args, "profile", None) or []:
        argv += ["--profile", name]  # checked against every configuration file before anything starts
    proc = subprocess.run(argv, capture_output=True, text=True, errors="replace", timeout=30)
    if proc.returncode != 0:
        raise SupervisorError((proc.stderr or proc.stdout).strip() or f"scenario {path} is invalid")
    try:
        return json.loads(proc.stdout)
    except ValueError:
        raise SupervisorError(f"mft-sim --check-scenario printed no JSON for {path}")
