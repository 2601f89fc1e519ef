"""mft-experiment's subcommands; paths and the supervisor come from the mftstack package (python/)."""
import sys
from pathlib import Path

PYTHON_DIR = str(Path(__file__).resolve().parents[3] / "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)
