"""saloam: semantic-aided LiDAR SLAM (SA-LOAM) from Python.

    import saloam
    source = saloam.open_source("seq")               # any layout `saloam odom` reads
    odometry = saloam.Odometry(source.config)        # the configuration the CLI would take
    for frame in source:                             # Frame(points, labels, times, stamp, rings)
        pose = odometry.register(*frame)             # 4x4 LiDAR-frame pose (poses_tum.txt's)

The whole API: docs/python.md. Fleet mapping on Dask: `saloam fleet`
(saloam.fleet, docs/fleet.md).
"""
import os as _os

from . import _paths

# The library finds its shipped data (config/sensors/, models/) here, as the
# program does from its own path; a SALOAM_DATA_DIR set by the user wins.
_os.environ.setdefault("SALOAM_DATA_DIR", _paths.DATA_DIR)
_os.environ.setdefault("SALOAM_PLUGIN_DIR", _paths.PLUGIN_DIR)

from ._saloam import (  # noqa: E402
    ConfigError,
    Error,
    Frame,
    InputError,
    Map,
    Odometry,
    Slam,
    Source,
    _Segmenter,
    config,
    eval,
    merge,
    open_source,
    read_trajectory,
    set_log_level,
    write_poses,
    write_trajectory,
)

__all__ = [
    "ConfigError", "Error", "Frame", "InputError", "Map", "Odometry", "Segmenter", "Slam", "Source", "cli_path",
    "config", "eval", "merge", "open_source", "read_trajectory", "set_log_level", "write_poses", "write_trajectory",
]


class Segmenter:
    """The segmentation network (docs/segmentation.md) for raw scans.

    model: a model description (.yaml), a TorchScript network (.pt, with
    projection=its .yaml) or a shipped model's name ("saloam_sim"); None: the
    default model. Needs a build with libtorch (its plugin); saloam.InputError
    otherwise.
    """

    def __init__(self, model=None, projection=None, config=None):
        self._segmenter = _Segmenter(model or "", projection or "", config, _paths.PLUGIN_DIR + "/libsaloam_segment_torch.so")

    def label(self, points, rings=None, confidence=False):
        """Raw SemanticKITTI class id (uint32) of every point of points ((N, 3) or (N, 4)), as saloam segment
        labels it. With confidence=True: (labels, confidence), confidence (float32) being the network's
        probability of each point's class at its pixel of the range image (0 where a point has none); a
        model's decision.min_confidence leaves the points below it unlabeled (0)."""
        return self._segmenter.label(points, rings, confidence)


def cli_path():
    """The saloam program beside this package (the build tree's or the installed one)."""
    return _os.environ.get("SALOAM_CLI") or _os.path.join(_paths.BIN_DIR, "saloam")
