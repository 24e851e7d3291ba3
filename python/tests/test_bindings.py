"""The Python module against the command line: the same poses to the byte,
the same configuration, the same errors; array checks."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import saloam
from conftest import run_cli


def run_odometry(source, odometry):
    for frame in source:
        odometry.register(*frame)
    return odometry


def test_odometry_poses_are_byte_identical_to_saloam_odom(sequence, tmp_path):
    run_cli("-q", "odom", sequence, "--out", tmp_path / "cli")
    source = saloam.open_source(sequence)
    assert len(source) == 40 and source.has_labels and source.format == "semantickitti"
    odometry = run_odometry(source, saloam.Odometry(source.config))
    poses = odometry.poses()
    assert poses.shape == (40, 4, 4) and poses.dtype == np.float64
    saloam.write_poses(tmp_path / "py", poses, source.times, source.velo_to_cam)
    for name in ("poses.txt", "poses_tum.txt"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # poses.txt: the camera frame, P = Tr Q Tr^-1
    tr = source.velo_to_cam
    camera = np.array([tr @ q @ np.linalg.inv(tr) for q in poses])
    cli_camera, _ = saloam.read_trajectory(tmp_path / "cli" / "poses.txt")
    np.testing.assert_allclose(camera, cli_camera, atol=2e-9)
    local_map = odometry.local_map()
    assert local_map["edges"].shape[1] == 3 and len(local_map["planars"]) > 100
    assert len(local_map["planars_labels"]) == len(local_map["planars"])
    assert odometry.last_registration()["ok"]


def test_slam_poses_are_byte_identical_to_saloam_slam(sequence, tmp_path):
    run_cli("-q", "slam", sequence, "--out", tmp_path / "cli", "--no-map", "--save-map", tmp_path / "cli_map")
    source = saloam.open_source(sequence)
    slam = saloam.Slam(source.config)
    for frame in source:
        slam.register(*frame)
    saloam.write_poses(tmp_path / "py", slam.poses(), source.times, source.velo_to_cam)
    saloam.write_poses(tmp_path / "py_odometry", slam.odometry_poses(), source.times, source.velo_to_cam)
    for ours, theirs in [("py/poses.txt", "poses.txt"), ("py/poses_tum.txt", "poses_tum.txt"),
                         ("py_odometry/poses.txt", "poses_odometry.txt"),
                         ("py_odometry/poses_tum.txt", "poses_odometry_tum.txt")]:
        assert (tmp_path / ours).read_bytes() == (tmp_path / "cli" / theirs).read_bytes(), theirs
    assert isinstance(slam.loops(), list)
    slam.save_map(tmp_path / "py_map", sensor=source.sensor, velo_to_cam=source.velo_to_cam)
    ours, theirs = saloam.Map(tmp_path / "py_map"), saloam.Map(tmp_path / "cli_map")
    assert ours.info()["keyframes"] == theirs.info()["keyframes"] == slam.keyframes()
    np.testing.assert_array_equal(ours.poses(), theirs.poses())


def test_eval_gives_the_numbers_of_saloam_eval(sequence, tmp_path):
    run_cli("-q", "odom", sequence, "--out", tmp_path / "odom")
    run_cli("-q", "eval", "--gt", sequence / "poses.txt", "--est", tmp_path / "odom" / "poses.txt", "--json",
            tmp_path / "eval.json")
    cli = json.loads((tmp_path / "eval.json").read_text())
    ours = saloam.eval(sequence / "poses.txt", tmp_path / "odom" / "poses.txt")
    assert ours == cli
    # TUM against KITTI needs the calibration, as on the command line
    with pytest.raises(saloam.InputError, match="pass --calib"):
        saloam.eval(sequence / "poses.txt", tmp_path / "odom" / "poses_tum.txt")
    tum = saloam.eval(sequence / "poses.txt", tmp_path / "odom" / "poses_tum.txt", calib=sequence / "calib.txt")
    assert tum["ate"]["rmse_aligned"] == pytest.approx(cli["ate"]["rmse_aligned"], abs=1e-6)
    # pose arrays, paired by index
    gt, _ = saloam.read_trajectory(sequence / "poses.txt")
    est, _ = saloam.read_trajectory(tmp_path / "odom" / "poses.txt")
    arrays = saloam.eval(gt, est, align="se3")
    assert arrays["ate"]["rmse_aligned"] == cli["ate"]["rmse_aligned"]


def test_configuration_dict_has_the_keys_and_checks_of_saloam_config(tmp_path):
    config = saloam.config()
    cli = run_cli("config").stdout
    for section, fields in [("odometry", config["odometry"]), ("loop", config["loop"])]:
        assert f"{section}:" in cli
        for key in fields:
            assert f"  {key}:" in cli, key
    assert config["odometry"]["features"]["alpha"] == 0.1
    assert saloam.config(config) == config
    changed = saloam.config({"odometry.features.alpha": 0.2, "loop": {"detector": "ssc"}}, set=["num_loop=7"])
    assert changed["odometry"]["features"]["alpha"] == 0.2 and changed["loop"]["detector"] == "ssc"
    assert changed["loop"]["num_loop"] == 7
    assert saloam.config("paper")["odometry"]["local_map_frames"] == 20
    # One validation: the message of a --config file holding the same values.
    (tmp_path / "bad.yaml").write_text("odometry:\n  features:\n    alpha: -1\n")
    cli_error = run_cli("config", "--config", tmp_path / "bad.yaml", check=False)
    assert cli_error.returncode == 2
    with pytest.raises(saloam.ConfigError) as error:
        saloam.Odometry({"odometry": {"features": {"alpha": -1}}})
    problem = str(error.value).split(": ", 1)[1]
    assert problem in cli_error.stderr
    with pytest.raises(ValueError, match="unknown configuration key 'odometry.nope'"):
        saloam.config({"odometry": {"nope": 1}})
    with pytest.raises(saloam.ConfigError, match="must be less than"):
        saloam.config({"odometry.features.min_range": 200})
    with pytest.raises(TypeError):
        saloam.config(42)


def test_library_errors_are_python_exceptions_with_the_cli_messages(tmp_path):
    missing = tmp_path / "nowhere"
    cli = run_cli("odom", missing, "--out", tmp_path / "out", check=False)
    with pytest.raises(saloam.InputError) as error:
        saloam.open_source(missing)
    assert isinstance(error.value, saloam.Error)
    assert str(error.value) in cli.stderr
    with pytest.raises(saloam.InputError):
        saloam.Map(tmp_path)


def scan(n=2000, seed=0):
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, n)
    points = np.stack([10 * np.cos(angle), 10 * np.sin(angle), rng.uniform(-1.5, 2, n),
                       rng.uniform(0, 1, n)], axis=1)
    return points.astype(np.float32)


def test_wrong_shapes_dtypes_and_values_raise():
    odometry = saloam.Odometry()
    points = scan()
    with pytest.raises(TypeError, match="float32 or float64"):
        odometry.register(points.astype(np.int32))
    with pytest.raises(TypeError, match="numpy array"):
        odometry.register(points.tolist())
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        odometry.register(points[:, :2])
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        odometry.register(points.reshape(-1))
    bad = points.copy()
    bad[17, 1] = np.nan
    with pytest.raises(ValueError, match="row 17 holds a non-finite value"):
        odometry.register(bad)
    bad[17, 1] = np.inf
    with pytest.raises(ValueError, match="row 17"):
        odometry.register(bad)
    with pytest.raises(ValueError, match=r"shape \(2000,\)"):
        odometry.register(points, labels=np.zeros(5, np.uint32))
    with pytest.raises(TypeError, match="integers"):
        odometry.register(points, labels=np.zeros(2000, np.float32))
    with pytest.raises(ValueError, match="out of range"):
        odometry.register(points, labels=np.full(2000, -1, np.int64))
    with pytest.raises(ValueError, match="not finite"):
        odometry.register(points, times=np.full(2000, np.nan, np.float32))
    assert len(odometry) == 0  # nothing was registered
    odometry.register(points, stamp=1.0)
    with pytest.raises(ValueError, match="does not follow"):
        odometry.register(points, stamp=1.0)


def test_views_of_larger_arrays_and_float64_give_the_same_poses(sequence):
    frames = list(saloam.open_source(sequence, frames="0:6"))
    reference = saloam.Odometry()
    for f in frames:
        reference.register(f.points, f.labels, f.times, f.stamp)
    views, doubles = saloam.Odometry(), saloam.Odometry()
    for f in frames:
        # rows every other one of a wider array, columns reversed twice: a strided view
        wide = np.zeros((2 * len(f.points), 7), np.float32)
        wide[::2, 6:2:-1] = f.points
        view = wide[::2, 6:2:-1]
        assert not view.flags.c_contiguous
        labels = np.zeros(2 * len(f.labels), np.uint64)
        labels[1::2] = f.labels
        views.register(view, labels[1::2], f.times, f.stamp)
        doubles.register(np.asfortranarray(f.points.astype(np.float64)), f.labels.astype(np.int64), f.times, f.stamp)
    np.testing.assert_array_equal(views.poses(), reference.poses())
    np.testing.assert_array_equal(doubles.poses(), reference.poses())
    # (N, 3) points: remission 0
    xyz = saloam.Odometry().register(np.ascontiguousarray(frames[0].points[:, :3]))
    np.testing.assert_array_equal(xyz, np.eye(4))


def test_source_frames_and_options(sequence):
    source = saloam.open_source(sequence, frames="5:9", semantics=False)
    assert len(source) == 4 and source.first_frame == 5
    frame = source[0]
    assert frame.points.dtype == np.float32 and frame.points.shape[1] == 4
    assert frame.labels is None  # semantics=False: labels not read
    assert frame.stamp == pytest.approx(source.times[0])
    assert source[-1].stamp == source.times[3]
    with pytest.raises(IndexError):
        source[4]
    labelled = saloam.open_source(sequence)[0]
    assert labelled.labels.dtype == np.uint32 and len(labelled.labels) == len(labelled.points)
    assert source.reference_poses.shape == (4, 4, 4)
    assert source.config["odometry"]["use_semantics"] is False
    with pytest.raises(saloam.ConfigError):
        saloam.open_source(sequence, frames="100:200")


def test_segmenter_labels_as_saloam_segment_and_says_how_sure_it_is(sequence, tmp_path):
    run_cli("-q", "segment", sequence, "--frames", "0:2", "--segment", "--out", tmp_path / "cli", "--no-score")
    segmenter = saloam.Segmenter()
    frame = saloam.open_source(sequence, semantics=False)[1]
    labels = segmenter.label(frame.points)
    cli = np.fromfile(tmp_path / "cli" / "000001.label", dtype=np.uint32)
    np.testing.assert_array_equal(labels, cli)
    again, confidence = segmenter.label(frame.points, confidence=True)
    np.testing.assert_array_equal(again, labels)
    assert confidence.dtype == np.float32 and confidence.shape == labels.shape
    assert np.all((confidence >= 0) & (confidence <= 1))
    # a probability among 19 classes: above 1/19 where the point keeps its pixel's class, and spread out
    assert np.median(confidence) > 0.3 and np.percentile(confidence, 10) < np.percentile(confidence, 90)


def test_docstrings():
    for item in (saloam.Odometry.register, saloam.open_source, saloam.Slam, saloam.eval, saloam.merge, saloam.config,
                 saloam.Map.localize, saloam.Segmenter):
        assert item.__doc__ and len(item.__doc__) > 40, item


@pytest.mark.skipif("SALOAM_CMAKE" not in os.environ, reason="run by CTest (needs the build's cmake and folder)")
def test_installed_package_finds_its_data_and_program(tmp_path):
    prefix = tmp_path / "prefix"
    # what `cmake --install` does for the program (and its data) and the package
    for folder in ("apps/saloam", "python"):
        subprocess.run([os.environ["SALOAM_CMAKE"], f"-DCMAKE_INSTALL_PREFIX={prefix}", "-P",
                        os.path.join(os.environ["SALOAM_BUILD_DIR"], folder, "cmake_install.cmake")],
                       check=True, capture_output=True)
    package = prefix / os.environ["SALOAM_INSTALL_PYTHON_DIR"]
    env = {k: v for k, v in os.environ.items() if k not in ("SALOAM_DATA_DIR", "SALOAM_PLUGIN_DIR", "SALOAM_CLI")}
    env["PYTHONPATH"] = str(package)
    code = ("import saloam, os; print(saloam.__file__); print(saloam.config('real_kitti')['odometry']['features']"
            "['pose_time_in_sweep']); print(os.environ['SALOAM_DATA_DIR']); print(saloam.cli_path())")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith(str(package))
    assert lines[2] == str(prefix / "share" / "saloam") and lines[3] == str(prefix / "bin" / "saloam")
    fleet = subprocess.run([prefix / "bin" / "saloam", "fleet", "--help"], capture_output=True, text=True, env=env)
    assert fleet.returncode == 0 and "--scheduler" in fleet.stdout, fleet.stderr


@pytest.fixture(scope="module")
def two_maps(sequence, tmp_path_factory):
    """The sequence's first and second halves mapped by `saloam slam --save-map` (overlapping by 10 frames)."""
    folder = tmp_path_factory.mktemp("maps")
    for name, frames in (("a", "0:25"), ("b", "15:40")):
        run_cli("-q", "slam", sequence, "--frames", frames, "--out", folder / f"slam_{name}", "--no-map",
                "--save-map", folder / f"map_{name}")
    return folder / "map_a", folder / "map_b"


def test_map_localize_gives_the_poses_of_saloam_localize(sequence, two_maps, tmp_path):
    map_a, _ = two_maps
    run_cli("-q", "localize", sequence, "--frames", "10:40", "--map", map_a, "--out", tmp_path / "cli")
    source = saloam.open_source(sequence, frames="10:40")
    counts = saloam.Map(map_a).localize(source, tmp_path / "py")
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert counts["frames"] == cli["frames"] == 30
    for key in ("localized", "unplaced", "odometry", "first_placed_frame"):
        assert counts[key] == cli[key], key
    assert counts["localized"] > 0 and counts["localized"] + counts["unplaced"] + counts["odometry"] == 30
    for name in ("poses.txt", "poses_tum.txt", "frames.csv", "relocalizations.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # the frames from the first placed one on, near the reference
    ours, _ = saloam.read_trajectory(tmp_path / "py" / "poses.txt")
    reference = source.reference_poses[counts["first_placed_frame"]:]
    assert len(ours) == len(reference) == counts["localized"]
    assert np.max(np.linalg.norm(ours[:, :3, 3] - reference[:, :3, 3], axis=1)) < 0.5


def test_merge_gives_the_map_of_saloam_merge(two_maps, tmp_path):
    map_a, map_b = two_maps
    run_cli("-q", "merge", map_a, map_b, "--out", tmp_path / "cli")
    result = saloam.merge(map_a, map_b, tmp_path / "py")
    ours, theirs = saloam.Map(tmp_path / "py"), saloam.Map(tmp_path / "cli")
    np.testing.assert_array_equal(ours.poses(), theirs.poses())
    info, cli_info = ours.info(), theirs.info()
    for key in ("keyframes", "edges", "loop_edges", "cross_session_loops", "sessions", "detector"):
        assert info[key] == cli_info[key], key
    assert result["linked"] and result["sessions"] == 2 == len(info["sessions"])
    assert result["cross_session_loops"] == info["cross_session_loops"] > 0
    assert info["keyframes"] == saloam.Map(map_a).info()["keyframes"] + saloam.Map(map_b).info()["keyframes"]
    # the rule for paths holds here too: an output inside an input is refused before anything is written
    with pytest.raises(saloam.Error, match="inside"):
        saloam.merge(map_a, map_b, map_a / "merged")
    assert not (map_a / "merged").exists()


def test_the_writers_never_overwrite_an_input(sequence, two_maps, tmp_path):
    """Issue #53: a sequence's ground truth, a map localised in, the scans a map is made from."""
    source = saloam.open_source(sequence, frames="0:12")
    poses = np.tile(np.eye(4), (12, 1, 1))
    truth = (sequence / "poses.txt").read_bytes()
    with pytest.raises(saloam.InputError, match="holds a sequence"):
        saloam.write_poses(sequence, poses, source.times, source.velo_to_cam)
    assert (sequence / "poses.txt").read_bytes() == truth
    map_a, _ = two_maps
    before = sorted(os.listdir(map_a))
    with pytest.raises(saloam.InputError):
        saloam.Map(map_a).localize(source, map_a / "runs")
    with pytest.raises(saloam.InputError):
        saloam.Map(map_a).localize(source, sequence)
    assert sorted(os.listdir(map_a)) == before
    # A map made from scans that lie in the old map it would replace.
    slam = saloam.Slam(source.config)
    for frame in source:
        slam.register(*frame)
    slam.save_map(tmp_path / "M")
    inner = tmp_path / "M" / "seq"
    subprocess.run(["cp", "-r", str(sequence), str(inner)], check=True)
    with pytest.raises(saloam.InputError, match="source"):
        slam.save_map(tmp_path / "M", source=str(inner))
    assert (inner / "poses.txt").is_file()
    slam.save_map(tmp_path / "M", source=str(sequence))  # from scans elsewhere: replaced
    assert not inner.exists()
