#!/usr/bin/env python3
"""Leave-sequences-out cross-validation of SegNet on real labelled scans.

The protocol of docs/segmentation.md ("Real scans: cross-validation"): the
real sequences are split into folds of whole sequences; for each fold a
model is trained (`saloam segment-train`) on every other fold's sequences
(optionally beside the simulated sources of a recipe) and scored on the
fold's own sequences through the inference path (`saloam segment
--segmenter`), its `score.json` confusion matrices pooled over the fold.
The model scored is the last epoch's (`model.yaml`), never one chosen on
the held-out scans. Without training (`--model`), a given model is scored
fold by fold the same way (the baseline).

Self-training (`--pseudo DRIVE --teacher T`): unlabelled real scans (a
sequence folder or a KITTI raw drive) are labelled by a teacher and trained
on beside the rest as a source of weight `--pseudo-weight`. In a fold the
teacher is that fold's own model of an earlier cross-validation
(`T/foldK/run/model.yaml`: it never saw the held-out sequences, so neither
do its labels); with `--final`, T is a model.

  scripts/segment_cv.py --data SEQUENCES --out CV [--model M.yaml | --init M.yaml --sim-recipe R.yaml
                        --real-weight W --train-args "..."] [--jobs 2]
  scripts/segment_cv.py --final --data SEQUENCES --out RUN --init M.yaml --sim-recipe R.yaml ...

Writes CV/folds.json (per fold: per-class IoU, mIoU, the big eight's mean)
and CV/table.md (per class, per fold, and their mean). Needs Python 3 with
PyYAML (Debian: python3-yaml) for --sim-recipe.
"""

import argparse
import concurrent.futures
import json
import math
import os
import shlex
import subprocess
import sys

CLASSES = ["car", "bicycle", "motorcycle", "truck", "other-vehicle", "person", "bicyclist", "motorcyclist", "road",
           "parking", "sidewalk", "other-ground", "building", "fence", "vegetation", "trunk", "terrain", "pole",
           "traffic-sign"]
BIG = ["road", "sidewalk", "building", "vegetation", "terrain", "fence", "car", "parking"]
DEFAULT_FOLDS = "00,01;02,03;04,05;06,07;09,10"


def run(cmd, log):
    with open(log, "a") as out:
        out.write("$ " + " ".join(shlex.quote(c) for c in cmd) + "\n")
        out.flush()
        done = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT)
    if done.returncode != 0:
        raise RuntimeError(f"{cmd[0]} {cmd[1]} failed ({done.returncode}); see {log}")


def sim_sources(recipe_file, section="train"):
    import yaml  # only needed with --sim-recipe
    with open(recipe_file) as f:
        recipe = yaml.safe_load(f)
    defaults = recipe.get("defaults", {})
    base = os.path.dirname(os.path.abspath(recipe_file))
    out = []
    for entry in recipe[section]:
        e = dict(defaults)
        e.update(entry)
        for key in ("simulate", "calib"):
            if key in e and not str(e[key]).startswith("preset:"):
                e[key] = os.path.normpath(os.path.join(base, e[key]))
        out.append(e)
    return out


def pooled(scores):
    """Per-class IoU (learning classes by name) of summed confusion matrices."""
    n = len(scores[0]["confusion"])
    conf = [[sum(s["confusion"][t][p] for s in scores) for p in range(n)] for t in range(n)]
    iou = {}
    for c in range(1, n):
        tp = conf[c][c]
        fn = sum(conf[c][p] for p in range(n) if p != c)
        fp = sum(conf[t][c] for t in range(1, n) if t != c)
        if sum(conf[c]) > 0:  # classes present in the truth, as SemanticKITTI's mIoU
            iou[CLASSES[c - 1]] = tp / (tp + fp + fn)
    points = {CLASSES[c - 1]: sum(conf[c]) for c in range(1, n)}
    return iou, points


def sure_teacher(teacher, min_confidence, out_dir):
    """A copy of the `teacher` description in `out_dir` that leaves the points it is less sure of than
    `min_confidence` unlabeled (decision.min_confidence; the loss ignores them)."""
    lines = []
    with open(teacher) as f:
        for line in f:
            if line.startswith("  file: "):  # the weights stay where they are
                line = "  file: " + os.path.join(os.path.dirname(os.path.abspath(teacher)), line.split(":", 1)[1].strip()) + "\n"
            if line.startswith("decision:"):
                sys.exit(f"{teacher}: a teacher with its own decision: is not supported")
            lines.append(line)
    lines.append(f"decision: {{min_confidence: {min_confidence}}}\n")
    copy = os.path.join(out_dir, "teacher.yaml")
    with open(copy, "w") as f:
        f.writelines(lines)
    return copy


def pseudo_source(args, teacher, out_dir, log):
    """The --pseudo drive labelled by `teacher`, as a recipe source."""
    labels = os.path.join(out_dir, "pseudo_labels")
    if args.pseudo_min_confidence > 0:
        teacher = sure_teacher(teacher, args.pseudo_min_confidence, out_dir)
    if not os.path.isdir(labels):  # a rerun of the fold reuses the labels
        run([args.saloam, "segment", args.pseudo, "--segmenter", teacher, "--out", labels, "--no-score"], log)
    return {"folder": args.pseudo, "labels": labels, "frame_step": 1, "weight": args.pseudo_weight}


def train_model(args, out_dir, train_sequences, validation, log, teacher=None):
    """segment-train on the real sequences (and the simulated and pseudo-labelled sources); returns the last
    epoch's model."""
    train = [{"folder": os.path.join(args.data, s), "frame_step": 1, "weight": args.real_weight}
             for s in train_sequences]
    if args.pseudo:
        train.append(pseudo_source(args, teacher, out_dir, log))
    if args.sim_recipe:
        train += sim_sources(args.sim_recipe)
    recipe_file = os.path.join(out_dir, "recipe.yaml")
    with open(recipe_file, "w") as f:
        json.dump({"train": train, "validation": validation}, f, indent=1)  # JSON is YAML
    run_dir = os.path.join(out_dir, "run")
    if args.scan_cache and not os.path.exists(os.path.join(run_dir, "scans")):
        # The simulated scans are the same in every fold: hard links to one cache.
        os.makedirs(os.path.join(run_dir, "scans"))
        for name in os.listdir(args.scan_cache):
            if name.startswith("sim-"):
                os.link(os.path.join(args.scan_cache, name), os.path.join(run_dir, "scans", name))
    cmd = [args.saloam, "segment-train", "--data", recipe_file, "--out", run_dir]
    if args.init:
        cmd += ["--init", args.init]
    run(cmd + shlex.split(args.train_args), log)
    return os.path.join(run_dir, "model.yaml")


def fold_job(args, k, held_out, all_sequences):
    fold_dir = os.path.join(args.out, f"fold{k}")
    os.makedirs(fold_dir, exist_ok=True)
    log = os.path.join(fold_dir, "log.txt")
    model = args.fold_models.format(k=k) if args.fold_models else args.model
    if model is None:
        teacher = os.path.join(args.teacher, f"fold{k}", "run", "model.yaml") if args.pseudo else None
        model = train_model(args, fold_dir, [s for s in all_sequences if s not in held_out],
                            [{"folder": os.path.join(args.data, s), "frame_step": 1} for s in held_out], log,
                            teacher)
    scores = []
    for s in held_out:
        labels = os.path.join(fold_dir, "labels", s)
        run([args.saloam, "segment", os.path.join(args.data, s), "--segmenter", model, "--out", labels,
             "--truth", os.path.join(args.data, s, "labels")] + shlex.split(args.segment_args), log)
        with open(os.path.join(labels, "score.json")) as f:
            scores.append(json.load(f))
    iou, points = pooled(scores)
    return {"fold": k, "held_out": held_out, "model": model, "iou": iou, "points": points,
            "miou": sum(iou.values()) / len(iou),
            "big8": sum(iou[c] for c in BIG if c in iou) / sum(1 for c in BIG if c in iou)}


def table(folds):
    present = [c for c in CLASSES if any(c in f["iou"] for f in folds)]
    mean = lambda xs: sum(xs) / len(xs) if xs else math.nan
    head = "| fold (held out) | mIoU | big 8 | " + " | ".join(present) + " |"
    lines = [head, "|" + "---|" * (3 + len(present))]
    for f in folds:
        cells = [f"{100 * f['iou'][c]:.0f}" if c in f["iou"] else "" for c in present]
        lines.append(f"| {f['fold']} ({'+'.join(f['held_out'])}) | {100 * f['miou']:.1f} | {100 * f['big8']:.1f} | "
                     + " | ".join(cells) + " |")
    cells = [f"{100 * mean([f['iou'][c] for f in folds if c in f['iou']]):.1f}" for c in present]
    lines.append(f"| **mean** | **{100 * mean([f['miou'] for f in folds]):.1f}** | "
                 f"**{100 * mean([f['big8'] for f in folds]):.1f}** | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", required=True, help="folder of the real labelled sequences (SemanticKITTI layout: NN/)")
    p.add_argument("--out", required=True)
    p.add_argument("--saloam", default=os.path.join(os.path.dirname(__file__), "..", "build", "saloam"))
    p.add_argument("--folds", default=DEFAULT_FOLDS, help=f"sequences per fold, ';' between folds ({DEFAULT_FOLDS})")
    p.add_argument("--run-folds", help="only these folds (numbers, e.g. 0,1); each still trains on every other fold")
    p.add_argument("--model", help="score this model in every fold, without training (a baseline)")
    p.add_argument("--fold-models", help="score a model trained elsewhere per fold, without training: a path with "
                                         "{k} for the fold's number (e.g. segnet_torch.py's runs, exported)")
    p.add_argument("--init", help="segment-train --init: the model to fine-tune")
    p.add_argument("--sim-recipe", help="a segment-train recipe whose train: sources are trained on beside the real ones")
    p.add_argument("--scan-cache", help="a run's scans/ folder holding the simulated sources' cache (hard-linked)")
    p.add_argument("--real-weight", type=float, default=1.0, help="the recipe weight of each real scan")
    p.add_argument("--train-args", default="", help="further segment-train options, e.g. '--epochs 8 --lovasz 1'")
    p.add_argument("--pseudo", help="unlabelled real scans (sequence folder or KITTI raw drive) to self-train on")
    p.add_argument("--teacher", help="with --pseudo: the cross-validation folder whose fold models label it (with "
                                     "--final: a model)")
    p.add_argument("--pseudo-weight", type=float, default=1.0, help="the recipe weight of each pseudo-labelled scan")
    p.add_argument("--pseudo-min-confidence", type=float, default=0.0,
                   help="with --pseudo: points the teacher gives a lower probability stay unlabeled (0: label all)")
    p.add_argument("--segment-args", default="", help="further segment options")
    p.add_argument("--jobs", type=int, default=1, help="folds run at once")
    p.add_argument("--final", action="store_true",
                   help="no folds: train once on every sequence (the shipped model), validated on the simulated "
                        "recipe's validation sources")
    args = p.parse_args()
    args.data = os.path.abspath(args.data)
    if args.pseudo:
        if not args.teacher:
            sys.exit("--pseudo needs --teacher")
        args.pseudo, args.teacher = os.path.abspath(args.pseudo), os.path.abspath(args.teacher)
    folds = [f.split(",") for f in args.folds.split(";")]
    sequences = [s for f in folds for s in f]
    os.makedirs(args.out, exist_ok=True)
    if args.final:
        if not args.sim_recipe:
            sys.exit("--final needs --sim-recipe (its validation sources choose nothing, they are reported)")
        model = train_model(args, args.out, sequences, sim_sources(args.sim_recipe, "validation"),
                            os.path.join(args.out, "log.txt"), args.teacher)
        print(f"trained on {', '.join(sequences)}: {model}")
        return
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        chosen = [int(k) for k in args.run_folds.split(",")] if args.run_folds else range(len(folds))
        results = list(pool.map(lambda k: fold_job(args, k, folds[k], sequences), chosen))
    with open(os.path.join(args.out, "folds.json"), "w") as f:
        json.dump(results, f, indent=1)
    text = table(results)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
