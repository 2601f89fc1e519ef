#!/usr/bin/env python3
"""The supervisor and /dev/shm: a chain segment left by a supervisor killed with SIGKILL is removed by the next
start; an explicit --chain-transport shm on a /dev/shm that is read-only or too full is an error, the default
falls back to DDS with a note (it used to run on DDS without a word, or crash with SIGBUS on a full /dev/shm).
The read-only and full cases mount a private tmpfs on /dev/shm (unshare -m, root only; skipped otherwise)."""
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
from mftstack import processes  # noqa: E402


def dead_pid():
    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid


class OrphanSegments(unittest.TestCase):
    def test_segments_of_gone_supervisors_are_removed_and_live_ones_kept(self):
        d = Path(tempfile.mkdtemp(prefix="mft-shm-test-"))
        self.addCleanup(shutil.rmtree, d)
        gone, alive = dead_pid(), os.getpid()
        for name in (f"mft-chain-d7-{gone}-123", f"mft-chain-d7-{alive}-456", "mft-other-1", f"mft-chain-x-{gone}"):
            (d / name).write_bytes(b"x" * 10)
        removed = processes.remove_orphan_segments(str(d))
        self.assertEqual(removed, [f"mft-chain-d7-{gone}-123"])
        self.assertEqual(sorted(p.name for p in d.iterdir()),
                         sorted([f"mft-chain-d7-{alive}-456", "mft-other-1", f"mft-chain-x-{gone}"]))


@unittest.skipUnless(os.geteuid() == 0 and shutil.which("unshare"), "needs root and unshare for a private /dev/shm")
class PrivateDevShm(unittest.TestCase):
    def choose(self, mount_options, transport):
        """chain_shm_name under a private /dev/shm tmpfs mounted with `mount_options`: (name or error, stderr)."""
        code = textwrap.dedent(f"""
            import sys, types
            sys.path.insert(0, {str(ROOT / "python")!r})
            from mftstack import processes
            from mftstack.errors import SupervisorError
            args = types.SimpleNamespace(chain_transport={transport!r}, domain=5, secure=None)
            try:
                print("name", processes.chain_shm_name(args, False))
            except SupervisorError as e:
                print("error", e)
            """)
        script = f"mount -t tmpfs -o {mount_options} tmpfs /dev/shm && exec {sys.executable} -c \"$0\""
        r = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script, code],
                           capture_output=True, text=True, timeout=60)
        if r.returncode != 0 and "mount" in r.stderr:
            self.skipTest(f"cannot mount a tmpfs here: {r.stderr.strip()}")
        return r.stdout.strip(), r.stderr

    def test_explicit_shm_on_a_read_only_dev_shm_is_an_error(self):
        out, _ = self.choose("ro,size=8m", "shm")
        self.assertEqual(out, "error --chain-transport shm: /dev/shm is not writable")

    def test_explicit_shm_on_a_full_dev_shm_is_an_error(self):
        out, _ = self.choose("size=64k", "shm")
        self.assertRegex(out, r"^error --chain-transport shm: /dev/shm has 0\.1 MB free, the chain's segment needs "
                              r"3\.3 MB$")

    def test_the_default_falls_back_to_dds_with_a_note(self):
        out, err = self.choose("size=64k", None)
        self.assertEqual(out, "name None")
        self.assertIn("chain transport: dds (/dev/shm has 0.1 MB free", err)

    def test_room_enough_gives_a_name(self):
        out, _ = self.choose("size=8m", "shm")
        self.assertRegex(out, r"^name /mft-chain-d5-\d+-\d+$")


if __name__ == "__main__":
    unittest.main()
