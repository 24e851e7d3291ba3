"""Fleet mapping on Dask: `saloam fleet DRIVES... --out MAP` (docs/fleet.md).

Each drive's SLAM is one Dask task that saves the drive's map; the maps are
then merged by a tree of pairwise merges, each merge a task of its own
(`saloam merge`: cross-session loop closure and one pose graph, in the first
map's frame; a drive that overlaps none of the others stays a separate,
unlinked session). The tasks run the `saloam` program in the worker (one
subprocess per task), not the Python module: a crash or an out-of-memory
kill of the C++ takes down that subprocess only, the worker reports it and
the task is retried; workers need only dask and the program, the memory of a
drive goes back to the system when its task ends, and every task's outputs
(poses, loops, evaluations, summary.json) are exactly the command line's.

Nothing is lost when a worker dies: the scheduler runs its tasks again on
another worker, every output is written under a name of its own per attempt
and put in place by one rename (a map already in place is the same map: the
SLAM does not depend on timing), and a task's subprocess dies with its
worker (PR_SET_PDEATHSIG).
"""
import argparse
import ctypes
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import uuid

from . import cli_path


def _die_with_parent():
    """In the child: SIGKILL when the worker that started it dies (Linux)."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def run_saloam(args, program=None):
    """Runs `saloam ARGS...`; returns its output (stdout and stderr), CPU seconds (user + sys) and peak resident
    memory [MiB] (the subprocess's own rusage); RuntimeError with the output when it fails."""
    command = [program or cli_path(), "-q", *[str(a) for a in args]]
    # Dask's workers set MALLOC_TRIM_THRESHOLD_ for their own heap; in the
    # program it made the SLAM 30-60 % slower (docs/fleet.md).
    env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               preexec_fn=_die_with_parent, env=env)
    with process.stdout:
        output = process.stdout.read()
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({process.returncode}):\n{output}")
    return {"output": output, "cpu_s": round(usage.ru_utime + usage.ru_stime, 3),
            "peak_mib": round(usage.ru_maxrss / 1024, 1)}


def threads_per_task(plan):
    """The odometry threads of a task on this host: `plan` is an int, or {host name: threads} (1 on a host that
    joined after the plan was made)."""
    if isinstance(plan, int):
        return plan
    return plan.get(os.uname().nodename, 1)


def thread_plan(client, threads):
    """`threads` (> 0) for every task; 0: each host's cores shared among the task slots (worker threads) it
    runs, at least 1, as {host name: threads}. On a 2-core host, 2 one-thread workers give each task's SLAM 1
    thread and 1 worker gives it 2: the workers use the cores without oversubscribing them."""
    if threads > 0:
        return threads
    hosts = client.run(lambda: (os.uname().nodename, os.cpu_count() or 1))
    nthreads = {address: w["nthreads"] for address, w in client.scheduler_info()["workers"].items()}
    slots, cores = {}, {}
    for address, (host, count) in hosts.items():
        slots[host] = slots.get(host, 0) + nthreads.get(address, 1)
        cores[host] = count
    return {host: max(1, cores[host] // slots[host]) for host in cores}


def _identity(path):
    st = os.stat(path)
    return st.st_dev, st.st_ino


def _same_or_inside(path, folder):
    """Whether `path` is `folder` or lies inside it, compared by device and inode along the path: a bind mount
    or a link of the folder is the folder. False when `folder` does not exist."""
    if not os.path.exists(folder):
        return False
    target = _identity(folder)
    p = os.path.abspath(path)
    while True:
        if os.path.exists(p) and _identity(p) == target:
            return True
        parent = os.path.dirname(p)
        if parent == p:
            return False
        p = parent


def _is_fleet_summary(path):
    try:
        with open(path) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        return False
    return isinstance(summary, dict) and {"map", "drives", "joined"} <= summary.keys()


def check_fleet_paths(drives, out, work, summary_file, config=None):
    """RuntimeError naming the path when a run would destroy an input or a user's file: the old map at `out` is
    replaced, so no input may lie in it; the work folder holds the per-drive runs, so it may not be the map or
    lie in it; the summary may not be written into the map, into a drive or over a file that is not an earlier
    fleet summary; and a drive given twice would double its keyframes."""
    seen = {}
    for d in drives:
        if not os.path.isdir(d):
            raise RuntimeError(f"{d}: not a folder (a drive is a sequence folder)")
        if _same_or_inside(d, out):
            raise RuntimeError(f"{d}: lies in the map {out} that the fleet replaces (it would be deleted with it)")
        if _identity(d) in seen:
            raise RuntimeError(f"{d}: the same drive as {seen[_identity(d)]} (given twice)")
        seen[_identity(d)] = d
    if config and os.path.exists(config) and _same_or_inside(config, out):
        raise RuntimeError(f"{config}: the configuration lies in the map {out} that the fleet replaces")
    if os.path.abspath(work) == os.path.abspath(out) or _same_or_inside(work, out) or _same_or_inside(out, work):
        raise RuntimeError(f"{work}: the work folder and the map {out} must be apart (the map replaces its folder)")
    if _same_or_inside(summary_file, out):
        raise RuntimeError(f"{summary_file}: the summary would be written into the map {out}")
    for d in drives:
        if _same_or_inside(summary_file, d):
            raise RuntimeError(f"{summary_file}: the summary would be written into the drive {d} (an input)")
    if os.path.exists(summary_file) and not _is_fleet_summary(summary_file):
        raise RuntimeError(f"{summary_file}: exists and is not a fleet summary (not overwritten)")


def _write_json(path, value):
    """Writes `value` as JSON to `path` whole or not at all (a temporary file renamed)."""
    with open(path + ".part", "w") as f:
        json.dump(value, f, indent=2)
        f.write("\n")
    os.replace(path + ".part", path)


# An old map is replaced through a journal beside it ({out}.fleet-journal):
# it names the backup that holds the old map until the new one is in place,
# so a crash at any step leaves the old map or the new one whole, and the
# next run restores or removes only the backup that the journal names.
def _journal(out):
    return out + ".fleet-journal"


def recover_map(out):
    """Finishes or undoes a replacement of the map at `out` that a crash interrupted (see _place_map)."""
    journal = _journal(out)
    if not os.path.isfile(journal):
        return
    with open(journal) as f:
        backup = json.load(f)["backup"]
    if os.path.isdir(backup):
        if os.path.isdir(out):
            shutil.rmtree(backup)  # the new map is in place
        else:
            os.rename(backup, out)  # the old map back
    os.remove(journal)


def _place_map(new, out):
    """Renames the map folder `new` to `out`, the old map at `out` kept as a backup until then."""
    backup = f"{out}.fleet-previous-{uuid.uuid4().hex[:8]}"
    journal = _journal(out)
    _write_json(journal, {"backup": backup})
    if os.path.isdir(out):
        os.rename(out, backup)
    os.rename(new, out)
    if os.path.isdir(backup):
        shutil.rmtree(backup)
    os.remove(journal)


def _put_in_place(attempt, final):
    """Renames the folder `attempt` to `final` unless an earlier attempt is there already."""
    try:
        os.rename(attempt, final)
    except OSError:
        if not os.path.isdir(final):
            raise
        shutil.rmtree(attempt, ignore_errors=True)


def slam_drive(index, drive, work, program=None, options=(), threads=1):
    """Task: `saloam slam DRIVE --save-map` with `threads` odometry threads (an int, or a plan of
    thread_plan()); returns what the summary needs."""
    start = time.time()
    final_out, final_map = os.path.join(work, f"slam_{index:03d}"), os.path.join(work, f"map_{index:03d}")
    threads = threads_per_task(threads)
    usage = {"cpu_s": None, "peak_mib": None}  # when an earlier attempt's map is in place
    if not os.path.isdir(final_map):
        token = uuid.uuid4().hex[:8]
        out, saved = f"{final_out}.{token}.part", f"{final_map}.{token}.part"
        # The fleet's thread count first: a --set threads=N of the options comes later and wins.
        usage = run_saloam(["slam", drive, "--out", out, "--no-map", "--save-map", saved,
                            "--set", f"odometry.threads={threads}", *options], program)
        _put_in_place(out, final_out)
        _put_in_place(saved, final_map)
    with open(os.path.join(final_out, "summary.json")) as f:
        summary = json.load(f)
    return {"drive": os.path.abspath(drive), "map": final_map, "drives": [index], "start": start, "end": time.time(),
            "frames": summary.get("frames"), "keyframes": summary.get("keyframes"),
            "loops_accepted": summary.get("loops_accepted"), "host": os.uname().nodename, "threads": threads,
            "cpu_s": usage["cpu_s"], "peak_mib": usage["peak_mib"]}


def merge_pair(a, b, out, program=None, options=()):
    """Task: `saloam merge A B --out OUT` (A's frame); returns the merged map and its drives."""
    start = time.time()
    usage = {"cpu_s": None, "peak_mib": None}
    if not os.path.isdir(out):
        attempt = f"{out}.{uuid.uuid4().hex[:8]}.part"
        usage = run_saloam(["merge", a["map"], b["map"], "--out", attempt, *options], program)
        _put_in_place(attempt, out)
    return {"map": out, "drives": a["drives"] + b["drives"], "start": start, "end": time.time(),
            "merged": [a["map"], b["map"]], "cpu_s": usage["cpu_s"], "peak_mib": usage["peak_mib"]}


def simulate_drive(index, out, preset, passes, beams, seed, program=None):
    """Task: `saloam simulate --passes ... --pass INDEX`: drive INDEX of a simulated fleet."""
    if not os.path.isdir(out):
        attempt = f"{out}.{uuid.uuid4().hex[:8]}.part"
        run_saloam(["simulate", "--preset", preset, "--passes", passes, "--pass", index, "--beams", beams,
                    "--seed", seed, "--labels", "noisy", "--out", attempt], program)
        _put_in_place(attempt, out)
    return out


def fleet_passes(drives, frames, reverse=False):
    """--passes for `drives` drives of `frames` frames along one route: each starts two thirds of a drive
    after the previous one (a third overlaps); with `reverse` every second one drives the opposite lane."""
    step = max(1, (2 * frames) // 3)
    passes = []
    for k in range(drives):
        a = k * step
        passes.append(f"{a}:{a + frames}" + (":reverse" if reverse and k % 2 == 1 else ""))
    return ",".join(passes)


def _client(scheduler, workers):
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler), None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    return Client(cluster), cluster


def _span(records):
    return round(max(r["end"] for r in records) - min(r["start"] for r in records), 3) if records else 0.0


def map_fleet(drives, out, work=None, scheduler=None, workers=2, program=None, slam_options=(), merge_options=(),
              simulate=None, summary_file=None, threads=0, log=print):
    """Maps `drives` (sequence folders) into one map at `out`; returns the summary (also written as JSON).

    threads: each drive's odometry threads; 0: each host's cores shared among its worker threads (thread_plan).

    simulate: {"drives": N, "frames": F, "preset": P, "beams": B, "seed": S, "reverse": bool} makes the
    drives first (tasks as well), in `work`/drives.
    """
    from dask.distributed import wait

    program = os.path.abspath(program or cli_path())
    out = os.path.abspath(out)
    recover_map(out)
    if os.path.exists(out) and not os.path.isfile(os.path.join(out, "map.json")):
        raise RuntimeError(f"{out}: exists and is not a saloam map (the fleet's map replaces only a map)")
    work = os.path.abspath(work or out + ".fleet")
    summary_file = os.path.abspath(summary_file or out + ".fleet.json")
    check_fleet_paths([os.path.abspath(d) for d in drives or []], out, work, summary_file,
                      config=next((b for a, b in zip(slam_options, slam_options[1:]) if a == "--config"), None))
    os.makedirs(work, exist_ok=True)
    begin = time.time()
    client, cluster = _client(scheduler, workers)
    try:
        stages = {}
        if simulate:
            passes = fleet_passes(simulate["drives"], simulate["frames"], simulate.get("reverse", False))
            folder = os.path.join(work, "drives")
            os.makedirs(folder, exist_ok=True)
            t = time.time()
            futures = [client.submit(simulate_drive, k, os.path.join(folder, f"drive_{k:03d}"), simulate["preset"],
                                     passes, simulate["beams"], simulate["seed"], program, pure=False, retries=2,
                                     key=f"simulate-{k}-{uuid.uuid4().hex[:8]}")
                       for k in range(simulate["drives"])]
            drives = client.gather(futures)
            stages["simulate_s"] = round(time.time() - t, 3)
            log(f"simulated {len(drives)} drives ({passes}) in {stages['simulate_s']:.1f} s")
        if not drives:
            raise RuntimeError("no drives given")
        drives = [os.path.abspath(d) for d in drives]
        plan = thread_plan(client, threads)
        t = mapping_start = time.time()
        slams = [client.submit(slam_drive, k, d, work, program, tuple(slam_options), plan, pure=False, retries=2,
                               key=f"slam-{k}-{uuid.uuid4().hex[:8]}")
                 for k, d in enumerate(drives)]
        # The merge tree: pairs of neighbours, level by level. A merge runs
        # once its two inputs are there: Dask hands a free worker a ready
        # merge before the SLAMs still queued, so the merging overlaps the
        # mapping, and after the last SLAM only the merges on its path up
        # the tree remain (log2 N of them, one after the other).
        level, merges, depth = slams, [], 0
        while len(level) > 1:
            depth += 1
            nxt = []
            for i in range(0, len(level) - 1, 2):
                target = out + f".{uuid.uuid4().hex[:8]}.part" if len(level) == 2 else \
                    os.path.join(work, f"merge_{depth}_{i // 2:03d}")
                merges.append(client.submit(merge_pair, level[i], level[i + 1], target, program,
                                            tuple(merge_options), pure=False, retries=2,
                                            key=f"merge-{depth}-{i // 2}-{uuid.uuid4().hex[:8]}"))
                nxt.append(merges[-1])
            if len(level) % 2:
                nxt.append(level[-1])
            level = nxt
        wait(level)
        slam_results = client.gather(slams)
        merge_results = client.gather(merges)
        final = client.gather(level[0])
        stages["slam_s"] = _span(slam_results)
        stages["merge_s"] = _span(merge_results)
        stages["mapping_s"] = round(time.time() - t, 3)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    # Attempts of dead workers left their partial outputs, named by the
    # fleet (NAME.XXXXXXXX.part): every task is done and their subprocesses
    # died with them. Nothing else is touched.
    for folder, own in ((work, r"(slam|map|merge)_[0-9_]+"), (os.path.dirname(out), re.escape(os.path.basename(out)))):
        for name in os.listdir(folder):
            if re.fullmatch(own + r"\.[0-9a-f]{8}\.part", name) and os.path.join(folder, name) != final["map"]:
                shutil.rmtree(os.path.join(folder, name), ignore_errors=True)
    # The final map in place (a lone drive's map is copied first).
    new_map = final["map"]
    if not merge_results:
        new_map = f"{out}.{uuid.uuid4().hex[:8]}.part"
        shutil.copytree(final["map"], new_map)
    _place_map(new_map, out)
    with open(os.path.join(out, "map.json")) as f:
        manifest = json.load(f)
    sessions = manifest.get("sessions", [])
    joined = [{"drive": drives[d], "linked": bool(s.get("linked", True)), "keyframes": s.get("keyframes")}
              for d, s in zip(final["drives"], sessions)]
    summary = {
        "map": out,
        "drives": [{k: r[k] for k in ("drive", "map", "frames", "keyframes", "loops_accepted", "host", "threads",
                                      "cpu_s", "peak_mib")} |
                   {"started_s": round(r["start"] - mapping_start, 3), "seconds": round(r["end"] - r["start"], 3)}
                   for r in slam_results],
        "joined": joined,
        "linked_drives": sum(j["linked"] for j in joined),
        "cross_drive_loops": manifest.get("cross_session_loops", 0),
        "keyframes": manifest.get("keyframes"),
        "merges": [{"maps": m["merged"], "started_s": round(m["start"] - mapping_start, 3),
                    "seconds": round(m["end"] - m["start"], 3), "cpu_s": m["cpu_s"],
                    "peak_mib": m["peak_mib"]}
                   for m in merge_results],
        "workers": None if scheduler else workers,
        "threads_per_task": plan,
        "scheduler": scheduler or "LocalCluster",
    }
    # The merged map's error per drive, when every drive has reference poses.
    if all(os.path.isfile(os.path.join(d, "poses.txt")) for d in drives):
        t = time.time()
        report = os.path.join(work, "eval_map.json")
        gts = [a for d in final["drives"] for a in ("--gt", drives[d])]
        try:
            run_saloam(["eval", "--map", out, *gts, "--json", report], program)
            with open(report) as f:
                summary["error_per_drive"] = json.load(f)
        except RuntimeError as e:
            summary["error_per_drive"] = {"error": str(e)}
        stages["eval_s"] = round(time.time() - t, 3)
    stages["total_s"] = round(time.time() - begin, 3)
    summary["stages"] = stages
    _write_json(summary_file, summary)
    log(f"{len(drives)} drives -> {out}: {summary['linked_drives']} of {len(joined)} sessions linked, "
        f"{summary['cross_drive_loops']} cross-drive loops; SLAM {stages['slam_s']:.1f} s, merges "
        f"{stages['merge_s']:.1f} s, total {stages['total_s']:.1f} s; summary {summary_file}")
    return summary


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="saloam fleet",
        description="Fleet mapping on Dask: each drive's SLAM a task, the maps merged by a tree of pairwise merges "
                    "(docs/fleet.md).")
    parser.add_argument("drives", nargs="*", metavar="DRIVE", help="sequence folders (any layout saloam slam reads)")
    parser.add_argument("--out", required=True, help="the merged map's folder")
    parser.add_argument("--scheduler", help="a running Dask scheduler (tcp://HOST:8786); default a LocalCluster")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster workers, one thread each (default 2)")
    parser.add_argument("--threads-per-task", type=int, default=0, metavar="N",
                        help="odometry threads of each drive's SLAM (default 0: each host's cores divided by its "
                             "workers' threads, at least 1)")
    parser.add_argument("--work", help="intermediate results (per-drive runs and maps, merges); default OUT.fleet, "
                                       "on a file system every worker sees")
    parser.add_argument("--summary", help="the summary JSON (default OUT.fleet.json)")
    parser.add_argument("--simulate", type=int, metavar="N", help="simulate N drives through one world first")
    parser.add_argument("--drive-frames", type=int, default=150, help="frames per simulated drive (default 150)")
    parser.add_argument("--preset", default="urban-loop", help="simulated route (default urban-loop)")
    parser.add_argument("--beams", type=int, default=16, choices=(16, 32, 64), help="simulated beams (default 16)")
    parser.add_argument("--seed", type=int, default=1, help="simulated world's seed")
    parser.add_argument("--reverse", action="store_true", help="every second simulated drive in the opposite lane")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="configuration overrides for every drive's SLAM")
    parser.add_argument("--config", help="configuration file or shipped name for every drive's SLAM")
    args = parser.parse_args(argv)
    if bool(args.drives) == bool(args.simulate):
        parser.error("give DRIVE folders or --simulate N (one of them)")
    if args.workers < 1:
        parser.error("--workers must be at least 1")
    if args.threads_per_task < 0:
        parser.error("--threads-per-task must be at least 0 (0: the host's cores divided among its workers)")
    slam_options = [a for s in args.set for a in ("--set", s)] + (["--config", args.config] if args.config else [])
    simulate = None
    if args.simulate:
        simulate = {"drives": args.simulate, "frames": args.drive_frames, "preset": args.preset, "beams": args.beams,
                    "seed": args.seed, "reverse": args.reverse}
    try:
        map_fleet(args.drives, args.out, work=args.work, scheduler=args.scheduler, workers=args.workers,
                  slam_options=slam_options, simulate=simulate, summary_file=args.summary,
                  threads=args.threads_per_task)
    except (RuntimeError, OSError) as e:
        print(f"[error] {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
