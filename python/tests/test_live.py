"""saloam.open_source("udp://...") serves a sensor's frames as its packets arrive.

A simulated VLP-16 capture is replayed to 127.0.0.1 at its recorded rate by
`saloam replay` while Python iterates the live source: the frames are the
capture's own, byte for byte, with their times, and the counts say that none
was dropped; a consumer that holds the source open without reading loses
whole frames beyond its queue, counted.
"""
import re
import subprocess
import time

import numpy as np
import pytest

import saloam
from conftest import run_cli, saloam_cli

FRAMES = 10


@pytest.fixture(scope="module")
def capture(tmp_path_factory):
    out = tmp_path_factory.mktemp("live") / "cap"
    run_cli("-q", "simulate", "--preset", "straight", "--frames", f"0:{FRAMES}", "--sensor", "vlp16", "--format",
            "velodyne-pcap", "--out", out)
    return out


def replay(capture, source, rate):
    port = re.search(r"udp://127\.0\.0\.1:(\d+)", source.name).group(1)
    return subprocess.Popen([saloam_cli(), "-q", "replay", str(capture / "velodyne.pcap"), f"udp://127.0.0.1:{port}",
                             "--rate", str(rate)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def test_the_live_frames_are_the_captures_byte_for_byte(capture):
    recorded = list(saloam.open_source(capture / "velodyne.pcap", sensor="vlp16"))
    assert len(recorded) == FRAMES
    live = saloam.open_source("udp://127.0.0.1:0", sensor="vlp16", metadata=capture / "velodyne.yaml",
                              idle_timeout=2)
    assert not live.rereadable and live.stream_stats["frames_served"] == 0
    sender = replay(capture, live, 1)
    frames = list(live)
    assert sender.wait(timeout=60) == 0, sender.stdout.read()
    assert len(frames) == FRAMES
    for got, want in zip(frames, recorded):
        assert got.stamp == want.stamp
        for a, b in ((got.points, want.points), (got.times, want.times), (got.rings, want.rings)):
            np.testing.assert_array_equal(a, b)
    stats = live.stream_stats
    assert (stats["frames_made"], stats["frames_served"], stats["frames_dropped"]) == (FRAMES, FRAMES, 0)
    assert "no packet for 2 s" in stats["ended_by"]
    with pytest.raises(IndexError, match="once each, in order"):
        live[0]


def test_a_consumer_that_does_not_keep_up_loses_whole_frames_counted(capture):
    live = saloam.open_source("udp://127.0.0.1:0", sensor="vlp16", metadata=capture / "velodyne.yaml",
                              idle_timeout=1, queue=2)
    sender = replay(capture, live, 10)
    assert sender.wait(timeout=60) == 0, sender.stdout.read()
    time.sleep(0.5)  # every packet received, none read: the queue keeps the newest frames
    frames = list(live)
    stats = live.stream_stats
    # The two queued, and the sweep still being assembled, completed when the stream ends (idle for 1 s).
    assert len(frames) == stats["frames_served"] <= 3
    assert stats["frames_dropped"] == stats["frames_made"] - len(frames) >= FRAMES - 4
    recorded_stamps = [f.stamp for f in saloam.open_source(capture / "velodyne.pcap", sensor="vlp16")]
    assert [f.stamp for f in frames] == recorded_stamps[len(recorded_stamps) - len(frames):]


def test_live_options_are_checked(capture):
    with pytest.raises(ValueError, match="idle_timeout"):
        saloam.open_source("udp://127.0.0.1:0", sensor="vlp16", idle_timeout=-1)
    with pytest.raises(ValueError, match="queue"):
        saloam.open_source("udp://127.0.0.1:0", sensor="vlp16", queue=0)
    with pytest.raises(saloam.InputError, match="no port"):
        saloam.open_source("udp://127.0.0.1", sensor="vlp16")
