"""The three-host test stack the distributed tests and measurements share: which namespace host runs which
service (paths and the supervisor: mftstack.paths)."""
HOSTS = ["robot", "ctrl", "aux"]
PLACEMENT = {"mft-sim": "robot", "mft-wbc": "ctrl", "mft-estimator": "aux", "mft-planner": "aux", "mft-record": "aux"}
