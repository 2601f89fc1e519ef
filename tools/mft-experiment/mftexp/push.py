"""One push run: its scenario, and the recovery judgement from mft-sim's summary.

A run: stand 1 s, step in place from 1 s at the reference height, a sagittal impulse on the torso at the first
lift-off of the chosen foot after `push_after_s`, then `observe_s` more seconds. Fall = the stack's own
criteria (mft-sim, services/runtime/run_monitor.hpp): base below 0.25 m, |pitch| > 0.8 rad, a thigh, shank or
the torso touching the ground, or a leg at a singular configuration (LTI < 0.02). Recovered = no fall until
the end AND back to stepping in place over the last `window` second (mft-sim's recovery.tail):
|mean base speed| <= max_speed, |mean base height - mean base height over the second before the push| <=
height_band, |pitch| <= max_pitch, at least min_touchdowns touchdowns (still stepping)."""
import hashlib
import json
from dataclasses import dataclass, asdict, field

from .common import write_yaml_scenario


@dataclass
class Criteria:
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
    profiles: list = field(default_factory=list)  # configuration profiles (docs/profiles.md); [] = the paper's setup

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
        "commands": [{"at_s": 0.0, "mode": "stand", "z_cmd_m": float(height), "v_cmd_mps": 0.0},
                     {"at_s": 1.0, "mode": "step_in_place", "z_cmd_m": float(height), "v_cmd_mps": 0.0}],
        "pushes": [{"impulse_Ns": round(sign * impulse, 6), "at_s": setup.push_after_s, "at_liftoff": setup.liftoff}],
    }


def write_scenario(path, setup, height, controller, impulse):
    write_yaml_scenario(path, scenario(setup, height, controller, impulse))


def judge(sim, criteria):
    """(recovered, reason) from mft-sim's summary."""
    rec = sim["recovery"]
    if sim.get("fell"):
        return False, f"fell at {sim.get('fall_time_s', 0):.3f} s: {sim.get('fall_reason')}"
    if rec.get("push_time_s") is None or rec.get("impulses", 0) < 1:
        return None, "the push was never applied (no lift-off after the arming time)"
    tail, pre = rec["tail"], rec["pre"]
    why = []
    if abs(tail["mean_speed_mps"]) > criteria.max_speed_mps:
        why.append(f"|mean speed| {abs(tail['mean_speed_mps']):.3f} > {criteria.max_speed_mps} m/s")
    dz = tail["mean_base_height_m"] - pre["mean_base_height_m"]
    if abs(dz) > criteria.height_band_m:
        why.append(f"base height {dz * 1000:+.1f} mm from before the push (band {criteria.height_band_m * 1000:.0f} mm)")
    if tail["max_abs_pitch_rad"] > criteria.max_pitch_rad:
        why.append(f"|pitch| {tail['max_abs_pitch_rad']:.3f} > {criteria.max_pitch_rad} rad")
    if tail["touchdowns"] < criteria.min_touchdowns:
        why.append(f"{tail['touchdowns']} touchdowns in the last {rec['window_s']} s (not stepping)")
    if why:
        return False, "no fall but not recovered: " + "; ".join(why)
    return True, "recovered"


def signature(sim):
    """What must be identical between two runs of the same scenario (lockstep determinism)."""
    keys = ("fell", "fall_time_s", "fall_reason", "ticks", "distance_m", "final_base_height_m", "touchdowns",
            "recovery")
    return json.dumps({k: sim.get(k) for k in keys}, sort_keys=True)
