#!/usr/bin/python3
"""The Python bindings' cost per scan: `saloam.Odometry.register` against the
command line's time per frame (`saloam bench SEQ --threads 1`), on the same
frames with the same configuration, one thread (docs/python.md).

Both sides time the registration alone, the frames read beforehand (the
bench reads each frame outside its timed region; here every frame is read
into arrays first); the Python side's time also holds what the binding adds:
checking the arrays and copying them into the library's scan, the lock, the
release of the GIL, the pose returned as an array. Thread CPU time is the
figure compared (on a shared machine wall time includes the waits for a
core); the rounds alternate, so that a drift of the machine's load touches
both sides alike.

  PYTHONPATH=build/python /usr/bin/python3 scripts/bench_python_register.py SEQ [--frames 0:120] [--rounds 3]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

import saloam


def cli_round(program, sequence, frames):
    """`saloam bench --threads 1`: (median, mean) CPU ms per frame."""
    done = subprocess.run([program, "bench", sequence, "--frames", frames, "--threads", "1"], capture_output=True,
                          text=True, check=True)
    line = next(l for l in done.stdout.splitlines() if l.startswith("cpu time:"))
    median = float(re.search(r"median [\d.]+ Hz \(([\d.]+) ms\)", line).group(1))
    mean = float(re.search(r"mean ([\d.]+) ms", line).group(1))
    return median, mean


def python_round(frames, config):
    """Odometry.register over the frames: (median, mean) thread-CPU ms and (median) wall ms per scan."""
    odometry = saloam.Odometry(config)
    cpu, wall = [], []
    for f in frames:
        c, w = time.thread_time(), time.perf_counter()
        odometry.register(f.points, f.labels, f.times, f.stamp, f.rings)
        cpu.append(1000 * (time.thread_time() - c))
        wall.append(1000 * (time.perf_counter() - w))
    return statistics.median(cpu), statistics.fmean(cpu), statistics.median(wall)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence")
    parser.add_argument("--frames", default="0:120")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--program", default=saloam.cli_path())
    args = parser.parse_args()
    # The bench reads the sequence as `saloam bench` does (no calib.txt: the odometry's input is the same).
    source = saloam.open_source(args.sequence, frames=args.frames, no_calib=True, set=["odometry.threads=1"])
    frames = list(source)
    config = source.config
    cli, py = [], []
    for r in range(args.rounds):
        cli.append(cli_round(args.program, args.sequence, args.frames))
        py.append(python_round(frames, config))
        print(f"round {r}: CLI median {cli[-1][0]:.2f} ms mean {cli[-1][1]:.2f} ms | Python register median "
              f"{py[-1][0]:.2f} ms mean {py[-1][1]:.2f} ms (wall median {py[-1][2]:.2f} ms) | load "
              f"{os.getloadavg()[0]:.2f}", flush=True)
    cli_median, cli_mean = statistics.median(c[0] for c in cli), statistics.median(c[1] for c in cli)
    py_median, py_mean = statistics.median(p[0] for p in py), statistics.median(p[1] for p in py)
    print(f"{len(frames)} frames of {args.sequence}, {args.rounds} rounds each, thread CPU ms per frame "
          f"(median of the rounds): CLI median {cli_median:.2f} / mean {cli_mean:.2f}; Python median "
          f"{py_median:.2f} / mean {py_mean:.2f}; Python / CLI: median {py_median / cli_median:.3f}, mean "
          f"{py_mean / cli_mean:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
