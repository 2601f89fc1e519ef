"""Where things are: the repository, the built executables, the configuration and the runs folder. The one
place for these defaults; MFT_BIN_DIR and MFT_RUNS_DIR override them (as CTest and the tests do).

Two layouts (docs/guide/library.md#layout-of-an-install):
- the source tree: python/mftstack beside config/ and services/, executables in build/release/bin, runs in runs/;
- an install (cmake --install, the .deb): <prefix>/share/mft_wbc/python/mftstack beside
  <prefix>/share/mft_wbc/config, executables and mft-supervisor in <prefix>/bin, runs in ./runs (the prefix
  may be read-only). REPO is then <prefix>/share/mft_wbc, which holds config/ and python/ like the repository."""
import os
from pathlib import Path

_PYTHON_DIR = Path(__file__).resolve().parent.parent  # python/ or <prefix>/share/mft_wbc/python
INSTALLED = _PYTHON_DIR.parent.name == "mft_wbc" and _PYTHON_DIR.parent.parent.name == "share"
REPO = _PYTHON_DIR.parent
if INSTALLED:
    PREFIX = REPO.parent.parent
    _BUILT_BIN = PREFIX / "bin"
    SUPERVISOR = PREFIX / "bin" / "mft-supervisor"  # the launcher of mftstack.cli
    _RUNS = Path.cwd() / "runs"
else:
    PREFIX = None
    _BUILT_BIN = REPO / "build" / "release" / "bin"
    SUPERVISOR = REPO / "services" / "mft-supervisor"  # the launcher of mftstack.cli
    _RUNS = REPO / "runs"
DEFAULT_BIN = Path(os.environ.get("MFT_BIN_DIR", _BUILT_BIN))
DEFAULT_CONFIG = REPO / "config"
DEFAULT_RUNS = Path(os.environ.get("MFT_RUNS_DIR", _RUNS))
SCENARIOS = DEFAULT_CONFIG / "scenarios"
