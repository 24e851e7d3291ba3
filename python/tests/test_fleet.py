"""`saloam fleet` on a LocalCluster and on a scheduler started here, with a
worker killed in the middle of the run."""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

import saloam
from conftest import run_cli, saloam_cli

from saloam.fleet import fleet_passes

DRIVES = 3
FRAMES = 60


@pytest.fixture(scope="module")
def drives(tmp_path_factory):
    """Three short drives through one world, each overlapping the next by a third."""
    folder = tmp_path_factory.mktemp("fleet")
    passes = fleet_passes(DRIVES, FRAMES)
    out = []
    for k in range(DRIVES):
        run_cli("-q", "simulate", "--preset", "straight", "--passes", passes, "--pass", k, "--beams", "16",
                "--labels", "noisy", "--out", folder / f"drive{k}")
        out.append(folder / f"drive{k}")
    return out


def fleet(*args, **kwargs):
    return subprocess.Popen([saloam_cli(), "fleet", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, **kwargs)


def keyframe_poses(folder):
    return saloam.Map(folder).poses()


@pytest.fixture(scope="module")
def local_run(drives, tmp_path_factory):
    out = tmp_path_factory.mktemp("local") / "map"
    process = fleet(*drives, "--out", out, "--workers", 2)
    output, _ = process.communicate(timeout=120)
    assert process.returncode == 0, output
    return out, json.loads((out.parent / "map.fleet.json").read_text()), output


def test_local_cluster_maps_and_merges_every_drive(drives, local_run):
    out, summary, output = local_run
    assert "3 drives ->" in output
    info = saloam.Map(out).info()
    assert len(info["sessions"]) == DRIVES
    assert [d["drive"] for d in summary["drives"]] == [str(d) for d in drives]
    assert [j["drive"] for j in summary["joined"]] == [str(d) for d in drives]
    assert summary["linked_drives"] == sum(s["linked"] for s in info["sessions"]) == DRIVES
    assert summary["cross_drive_loops"] == info["cross_session_loops"] > 0
    assert len(summary["merges"]) == DRIVES - 1
    assert set(summary["stages"]) >= {"slam_s", "merge_s", "eval_s", "total_s"}
    errors = summary["error_per_drive"]
    assert len(errors["sessions"]) == DRIVES, errors
    # the host's cores shared among the 2 workers; each task's own CPU time and peak memory
    assert summary["threads_per_task"] == {os.uname().nodename: max(1, os.cpu_count() // 2)}
    for drive in summary["drives"]:
        assert drive["threads"] == max(1, os.cpu_count() // 2)
        assert drive["cpu_s"] > 0 and 10 < drive["peak_mib"] < 4096, drive
    assert all(m["cpu_s"] > 0 and m["peak_mib"] > 10 for m in summary["merges"]), summary["merges"]
    # each drive's map is the one `saloam slam --save-map` makes
    run_cli("-q", "slam", drives[1], "--out", out.parent / "slam1", "--no-map", "--save-map", out.parent / "map1")
    np.testing.assert_array_equal(keyframe_poses(out.parent / "map1"),
                                  keyframe_poses(out.parent / "map.fleet" / "map_001"))


def test_the_map_does_not_depend_on_the_threads_per_task(drives, local_run, tmp_path):
    out = tmp_path / "map"
    process = fleet(*drives, "--out", out, "--workers", 1, "--threads-per-task", 3)
    output, _ = process.communicate(timeout=120)
    assert process.returncode == 0, output
    summary = json.loads((tmp_path / "map.fleet.json").read_text())
    assert summary["threads_per_task"] == 3 and {d["threads"] for d in summary["drives"]} == {3}
    np.testing.assert_array_equal(keyframe_poses(out), keyframe_poses(local_run[0]))
    for k in range(DRIVES):
        for name in ("poses.txt", "poses_tum.txt", "loops.csv"):
            ours = (tmp_path / "map.fleet" / f"slam_{k:03d}" / name).read_bytes()
            assert ours == (local_run[0].parent / "map.fleet" / f"slam_{k:03d}" / name).read_bytes(), name
    assert summary["cross_drive_loops"] == local_run[1]["cross_drive_loops"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start(command, env):
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                            start_new_session=True)


def test_scheduler_and_a_worker_killed_mid_run(drives, local_run, tmp_path):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    processes = [start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port",
                        str(port), "--dashboard-address", ":0", "--no-show"], env)]
    workers = [start([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
                      "--host", "127.0.0.1", "--dashboard-address", ":0", "--death-timeout", "30"], env)
               for _ in range(2)]
    processes += workers
    try:
        out = tmp_path / "map"
        run = fleet(*drives, "--out", out, "--scheduler", address, env=env)
        # Kill the first worker as soon as a drive's SLAM is under way.
        deadline = time.time() + 60
        while time.time() < deadline and not any(
                name.startswith("slam_") for name in os.listdir(tmp_path) + (
                    os.listdir(tmp_path / "map.fleet") if (tmp_path / "map.fleet").exists() else [])):
            time.sleep(0.05)
        os.killpg(workers[0].pid, signal.SIGKILL)
        output, _ = run.communicate(timeout=120)
        assert run.returncode == 0, output
        assert workers[0].wait(timeout=10) == -signal.SIGKILL
        summary = json.loads((tmp_path / "map.fleet.json").read_text())
        assert summary["scheduler"] == address
        # the same map as the LocalCluster's
        np.testing.assert_array_equal(keyframe_poses(out), keyframe_poses(local_run[0]))
        assert summary["cross_drive_loops"] == local_run[1]["cross_drive_loops"]
        assert not [n for n in os.listdir(tmp_path / "map.fleet") if n.endswith(".part")]
    finally:
        for p in processes:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in processes:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)


def test_fleet_refuses_what_it_cannot_do(tmp_path):
    done = subprocess.run([saloam_cli(), "fleet", "--out", tmp_path / "m"], capture_output=True, text=True)
    assert done.returncode == 2 and "DRIVE folders or --simulate" in done.stderr
    help_text = subprocess.run([saloam_cli(), "fleet", "--help"], capture_output=True, text=True).stdout
    assert "--scheduler" in help_text and "--workers" in help_text and "--threads-per-task" in help_text
    done = subprocess.run([saloam_cli(), "fleet", "D", "--out", tmp_path / "m", "--threads-per-task", "-1"],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "--threads-per-task must be at least 0" in done.stderr


def _map(folder, marker):
    """A folder that passes for a saloam map (map.json), with a marker to tell maps apart."""
    folder.mkdir(parents=True)
    (folder / "map.json").write_text(json.dumps({"marker": marker}))
    return folder


def test_fleet_refuses_to_destroy_its_inputs(tmp_path):
    from saloam.fleet import check_fleet_paths
    m = _map(tmp_path / "M", "old")
    drive = tmp_path / "d0"
    drive.mkdir()
    inner = m / "drive"
    inner.mkdir()
    bind = tmp_path / "link_to_M"
    bind.symlink_to(m, target_is_directory=True)

    def refused(drives, out=m, work=tmp_path / "w", summary=tmp_path / "s.json", config=None):
        with pytest.raises(RuntimeError) as e:
            check_fleet_paths([str(d) for d in drives], str(out), str(work), str(summary), config)
        return str(e.value)

    assert "lies in the map" in refused([drive, inner])
    assert "lies in the map" in refused([drive, bind / "drive"])  # another path to the same folder
    assert "given twice" in refused([drive, tmp_path / "." / "d0"])
    assert "work folder and the map" in refused([drive], work=m)
    assert "work folder and the map" in refused([drive], out=tmp_path / "new", work=tmp_path / "new")
    assert "written into the map" in refused([drive], summary=m / "map.json")
    (drive / "poses.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n")
    assert "into the drive" in refused([drive], summary=drive / "poses.txt")
    (tmp_path / "notes.json").write_text("{}")
    assert "not a fleet summary" in refused([drive], summary=tmp_path / "notes.json")
    (m / "cfg.yaml").write_text("odometry: {}\n")
    assert "configuration lies in the map" in refused([drive], config=str(m / "cfg.yaml"))
    # What may be done: a new map beside the drives, an earlier summary replaced.
    (tmp_path / "old.json").write_text(json.dumps({"map": "M", "drives": [], "joined": []}))
    check_fleet_paths([str(drive)], str(tmp_path / "N"), str(tmp_path / "w"), str(tmp_path / "old.json"))
    # From the command line, before any work starts.
    done = subprocess.run([saloam_cli(), "fleet", drive, inner, "--out", m], capture_output=True, text=True)
    assert done.returncode == 2 and "lies in the map" in done.stderr
    assert inner.is_dir() and (m / "map.json").is_file()


def test_a_crash_while_the_map_is_replaced_leaves_a_whole_map(tmp_path, monkeypatch):
    from saloam import fleet as f
    out = str(tmp_path / "M")

    def crash_at(step):
        """Replaces the map, the process dying (an exception here) at the given rename or removal."""
        if not os.path.isdir(out):
            _map(tmp_path / "M", "old")
        new = _map(tmp_path / f"M.{step:08x}.part", "new")
        calls = {"n": 0}
        real_rename, real_rmtree = os.rename, shutil.rmtree

        def counting(real):
            def call(*args, **kwargs):
                calls["n"] += 1
                if calls["n"] == step:
                    raise KeyboardInterrupt("killed")
                return real(*args, **kwargs)
            return call
        monkeypatch.setattr(f.os, "rename", counting(real_rename))
        monkeypatch.setattr(f.shutil, "rmtree", counting(real_rmtree))
        try:
            f._place_map(str(new), out)
        except KeyboardInterrupt:
            pass
        monkeypatch.undo()
        f.recover_map(out)
        marker = json.loads((tmp_path / "M" / "map.json").read_text())["marker"]
        assert not os.path.exists(out + ".fleet-journal")
        assert not [p for p in os.listdir(tmp_path) if ".fleet-previous-" in p]
        shutil.rmtree(out)
        for p in os.listdir(tmp_path):
            shutil.rmtree(tmp_path / p)
        return marker

    assert crash_at(1) == "old"   # before the old map moved aside
    assert crash_at(2) == "old"   # the old map aside, the new one not yet in place: the old one back
    assert crash_at(3) == "new"   # the new map in place, the backup not yet removed
    assert crash_at(99) == "new"  # no crash
    # A user's folder named like a backup is never touched.
    _map(tmp_path / "M", "old")
    user = _map(tmp_path / "M.fleet-previous-12345678", "user's")
    f._place_map(str(_map(tmp_path / "M.0000000a.part", "new")), out)
    f.recover_map(out)
    assert json.loads((user / "map.json").read_text())["marker"] == "user's"
