"""Where things are: the repository, the built executables, the configuration and the runs folder. The one
place for these defaults; MFT_BIN_DIR and MFT_RUNS_DIR override them (as CTest and the tests do)."""
import os
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent.parent
DEFAULT_BIN = Path(os.environ.get("MFT_BIN_DIR", REPO / "build" / "release" / "bin"))
DEFAULT_CONFIG = REPO / "config"
DEFAULT_RUNS = Path(os.environ.get("MFT_RUNS_DIR", REPO / "runs"))
SCENARIOS = DEFAULT_CONFIG / "scenarios"
SUPERVISOR = REPO / "services" / "mft-supervisor"  # the launcher of mftstack.cli
