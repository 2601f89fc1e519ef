"""One push run: its scenario, and the recovery judgement from mft-sim's summary.

A run: stand 1 s, step in place from 1 s at the reference height, a sagittal impulse on the torso at the first
lift-off of the chosen foot after `push_after_s`, then `observe_s` more seconds. Fall = the stack's own
criteria (mft-sim, chain/run_monitor.hpp): base below 0.25 m, |pitch| > 0.8 rad, a thigh, shank or
the torso touching the ground, or a leg at a singular configuration (LTI < 0.02). Recovered: the verdict of the
project's one criterion (chain/push_recovery.hpp), computed by mft-sim (or mft-closedloop) with the
criteria written into the scenario's recovery: section. Rule "stepping" (default): no fall until the end AND back
to stepping in place over the last `window` second: |mean base speed| <= max_speed, |mean base height - mean base
height over the second before the push| <= height_band, |pitch| <= max_pitch, at least min_touchdowns touchdowns.
Rule "no_fall": no fall until the end. Both outcomes are always recorded."""
import hashlib
import json
from dataclasses import dataclass, asdict, field

from .common import write_yaml_scenario


@dataclass
class Criteria:
    rule: str = "stepping"       # stepping | no_fall: which outcome counts as recovered
    max_speed_mps: float = 0.05
    height_band_m: float = 0.02
    max_pitch_rad: float = 0.1
    min_touchdowns: int = 2


@dataclass
class PushSetup:
    push_after_s: float = 3.0   # the push is armed at this time, applied at the next lift-off of `liftoff`
    observe_s: float = 5.0      # run length after push_after_s (the last 1 s is the recovery window)
    liftoff: str = "right"
    direction: str = "forward"
    estimator: str = "kalman"
    fall_base_height_m: float = 0.25
    fall_pitch_rad: float = 0.8
    criteria: Criteria = field(default_factory=Criteria)
    profiles: list = field(default_factory=list)  # configuration profiles (docs/guide/profiles.md); [] = the paper's setup

    def key(self):
        """What makes two runs with the same height, controller and impulse the same run."""
        return hashlib.sha1(json.dumps(asdict(self), sort_keys=True).encode()).hexdigest()[:10]

    @property
    def duration_s(self):
        return round(self.push_after_s + self.observe_s, 6)


def scenario(setup, height, controller, impulse):
    sign = 1.0 if setup.direction == "forward" else -1.0
    return {
        "name": f"push-{controller}-h{height:.2f}-{setup.direction}-{impulse:.2f}",
        "description": f"mft-experiment: step in place at {height:.2f} m, {controller}, a {impulse:.2f} N s "
                       f"{setup.direction} push at the first {setup.liftoff} lift-off after {setup.push_after_s} s",
        "duration_s": setup.duration_s, "controller": controller, "estimator": setup.estimator, "terrain": "flat",
        "initial_base_height_m": float(height),
        "fall": {"base_height_below_m": setup.fall_base_height_m, "pitch_beyond_rad": setup.fall_pitch_rad},
        "recovery": {"rule": setup.criteria.rule, "window_s": 1.0, "max_speed_mps": setup.criteria.max_speed_mps,
                     "height_band_m": setup.criteria.height_band_m, "max_pitch_rad": setup.criteria.max_pitch_rad,
                     "min_touchdowns": setup.criteria.min_touchdowns},
        "commands": [{"at_s": 0.0, "mode": "stand", "z_cmd_m": float(height), "v_cmd_mps": 0.0},
                     {"at_s": 1.0, "mode": "step_in_place", "z_cmd_m": float(height), "v_cmd_mps": 0.0}],
        "pushes": [{"impulse_Ns": round(sign * impulse, 6), "at_s": setup.push_after_s, "at_liftoff": setup.liftoff}],
    }


def write_scenario(path, setup, height, controller, impulse):
    write_yaml_scenario(path, scenario(setup, height, controller, impulse))


def judge(sim, criteria=None):
    """(recovered, reason) from the verdict in mft-sim's (or mft-closedloop's) summary; recovered is None when
    the push was never applied. The rule is the one written into the scenario (criteria is not re-applied)."""
    v = (sim.get("recovery") or {}).get("verdict")
    if v is None:
        raise KeyError("the summary has no recovery verdict (rebuild mft-sim / mft-closedloop)")
    if v["outcome"] == "not_pushed":
        return None, "the push was never applied (no lift-off after the arming time)"
    return bool(v["recovered"]), v["reason"]


def signature(sim):
    """What must be identical between two runs of the same scenario (lockstep determinism)."""
    keys = ("fell", "fall_time_s", "fall_reason", "ticks", "distance_m", "final_base_height_m", "touchdowns",
            "recovery")
    return json.dumps({k: sim.get(k) for k in keys}, sort_keys=True)
