"""mft-experiment's library (the launcher is tools/mft-experiment/mft-experiment): the paper's experiments on the
stack. It sits beside mftstack in python/ and takes paths and the supervisor from it; mftstack imports nothing of it."""
import sys
from pathlib import Path

PYTHON_DIR = str(Path(__file__).resolve().parent.parent)
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)
