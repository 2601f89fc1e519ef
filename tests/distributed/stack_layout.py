"""The three-host test stack the distributed tests and measurements share: where things are and which
namespace host runs which service."""
import os
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent.parent
SUPERVISOR = REPO / "services" / "mft-supervisor"
BIN = Path(os.environ.get("MFT_BIN_DIR", REPO / "build" / "release" / "bin"))
SCENARIOS = REPO / "config" / "scenarios"
HOSTS = ["robot", "ctrl", "aux"]
PLACEMENT = {"mft-sim": "robot", "mft-wbc": "ctrl", "mft-estimator": "aux", "mft-planner": "aux", "mft-record": "aux"}
