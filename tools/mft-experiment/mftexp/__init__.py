"""mft-experiment: the paper's experiments (section IV) on the real multi-process stack (issue 9)."""
