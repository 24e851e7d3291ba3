"""What the Python tests share: the saloam program and short simulated sequences."""
import os
import subprocess

import pytest


def saloam_cli():
    return os.environ.get("SALOAM_CLI") or os.path.join(os.path.dirname(__file__), "../../build/saloam")


def run_cli(*args, check=True):
    done = subprocess.run([saloam_cli(), *[str(a) for a in args]], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"saloam {' '.join(map(str, args))} failed ({done.returncode}):\n{done.stderr}")
    return done


@pytest.fixture(scope="session")
def sequence(tmp_path_factory):
    """A short simulated sequence (16 beams, noisy labels, calib.txt, poses.txt)."""
    seq = tmp_path_factory.mktemp("sim") / "seq"
    run_cli("-q", "simulate", "--preset", "straight", "--frames", "0:40", "--beams", "16", "--labels", "noisy",
            "--out", seq)
    return seq
