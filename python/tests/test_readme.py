"""The README's Python example runs as it is, in a folder holding `seq`."""
import os
import re
import shutil
import subprocess
import sys

README = os.path.join(os.environ.get("SALOAM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "../..")),
                      "README.md")


def test_readme_example_runs(sequence, tmp_path):
    text = open(README).read()
    example = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    assert 5 <= len(example.strip().splitlines()) <= 12
    shutil.copytree(sequence, tmp_path / "seq")
    (tmp_path / "example.py").write_text(example)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(os.path.abspath(p) for p in sys.path if p))
    done = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert re.match(r"40 scans, \d+ m, ATE \d+\.\d+ m", done.stdout), done.stdout
    assert (tmp_path / "out" / "poses_tum.txt").is_file()
