#!/usr/bin/env python3
"""SegNet trained with PyTorch, on a GPU when there is one.

The same network, data and augmentations as `saloam segment-train` (libtorch,
CPU), for training runs too long for the CPU: the larger SegNets of issue #38.
What it trains runs in saloam as every SegNet does (`network: {type: segnet}`,
on the CPU): `export` writes the weights as the libtorch archive the plugin
reads and the model description beside them.

  scans    the labelled scans are saloam's own scan caches (`RUN/scans/*.scans`,
           written by `saloam segment-train`: positions at 5 mm, remission,
           learning class and ring per point), read as they are or from a
           `pack`ed copy (delta-coded and xz-compressed, a third of the size).
  train    draws samples as segment-train does (a scan, augmented, projected
           into ring rows x 2048 columns with the model's channel statistics,
           a crop of --pixels-per-sample pixels; one beam count per batch),
           class-weighted cross-entropy (1/sqrt of each class's frequency),
           AdamW with a warm-up and a cosine, a fixed number of steps; real
           sequences (`folder-*`) drawn with probability --real-fraction, any
           of them left out with --hold-out. Writes OUT/weights.npz and
           OUT/training.json. Reproducible for a fixed seed and device.
  export   OUT/weights.npz -> NAME.pt (libtorch archive) and NAME.yaml (the
           template description with this network's shape). Needs the
           libtorch that saloam links (Debian: python3-torch).

  scripts/segnet_torch.py pack RUN/scans DATA.xz
  scripts/segnet_torch.py train --scans DATA.xz --template models/segmenter/saloam.yaml \\
      --widths 32,64,128 --stem-stride 2 --context-blocks 4 --steps 6000 --out OUT [--hold-out 00,01]
  scripts/segnet_torch.py export OUT --template models/segmenter/saloam.yaml --name NAME --dir DIR

The augmentations follow train/scan_dataset.cpp's distributions (their random
draws differ): yaw, mirror, tilt, height shift, range noise, point and ring
dropout, occluded sectors, remission gamma / gain / offset / noise / constant.
"""

import argparse
import json
import lzma
import math
import os
import struct
import sys
import time

import numpy as np

POSITION_STEP = 0.005  # [m] train/scan_dataset.hpp: kScanPositionStep
NO_RING = 255
CLASSES = 20
LEAKY = 0.1

AUGMENT = dict(rotate=True, flip=0.5, max_tilt_deg=2.0, max_height_shift=0.3, max_range_noise=0.03,
               max_point_dropout=0.2, max_ring_dropout=0.1, occlusion=0.5, remission_constant=0.2,
               remission_gamma=2.0, remission_gain=0.5, remission_offset=0.1, remission_noise=0.05)


# ---- scans ----

def read_scan_cache(path):
    """The scans of a `saloam segment-train` cache file (train/scan_dataset.cpp: write_cache)."""
    data = open(path, "rb").read()
    offset = 0

    def vector(dtype, width=1):
        nonlocal offset
        (n,) = struct.unpack_from("<Q", data, offset)
        offset += 8
        count = n * width
        a = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
        offset += a.nbytes
        return a.reshape(n, width) if width > 1 else a

    if vector(np.uint8).tobytes() != b"saloam-scans-1":
        raise SystemExit(f"{path}: not a saloam scan cache")
    vector(np.uint8)  # the cache key
    (count,) = struct.unpack_from("<Q", data, offset)
    offset += 8
    scans = []
    for _ in range(count):
        beams = int(vector(np.int32)[0])
        scans.append(dict(beams=beams, xyz=vector(np.int16, 3), remission=vector(np.uint8),
                          target=vector(np.uint8), ring=vector(np.uint8)))
    return scans


def pack(scan_dir, out, prefix="", every=1):
    """The caches of scan_dir whose names start with `prefix`, every `every`-th scan of each, in one xz file:
    per scan its counts, then positions delta-coded along the storage order (neighbours on a ring are
    close), remission, target and ring planes."""
    parts = []
    index = []
    for name in sorted(os.listdir(scan_dir)):
        if not name.endswith(".scans") or not name.startswith(prefix):
            continue
        for scan in read_scan_cache(os.path.join(scan_dir, name))[::every]:
            xyz = scan["xyz"].astype(np.int32)
            delta = np.diff(xyz, axis=0, prepend=np.zeros((1, 3), np.int32)).astype(np.int16)
            parts += [delta.T.copy().tobytes(), scan["remission"].tobytes(), scan["target"].tobytes(),
                      scan["ring"].tobytes()]
            index.append([name[: -len(".scans")], scan["beams"], len(scan["remission"])])
    header = json.dumps(index).encode()
    with open(out + ".tmp", "wb") as f:
        f.write(lzma.compress(struct.pack("<Q", len(header)) + header + b"".join(parts), preset=6))
    os.replace(out + ".tmp", out)
    print(f"{out}: {len(index)} scans of {len(set(i[0] for i in index))} sources")


def unpack(path):
    data = lzma.decompress(open(path, "rb").read())
    (n,) = struct.unpack_from("<Q", data, 0)
    index = json.loads(data[8:8 + n])
    offset = 8 + n
    sources = {}
    for name, beams, points in index:
        delta = np.frombuffer(data, np.int16, 3 * points, offset).reshape(3, points).T
        offset += 6 * points
        planes = []
        for _ in range(3):
            planes.append(np.frombuffer(data, np.uint8, points, offset))
            offset += points
        xyz = np.cumsum(delta.astype(np.int32), axis=0).astype(np.int16)
        sources.setdefault(name, []).append(dict(beams=beams, xyz=xyz, remission=planes[0], target=planes[1],
                                                 ring=planes[2]))
    return sources


def load_sources(paths):
    sources = {}
    for path in paths:
        if os.path.isdir(path):
            for name in sorted(os.listdir(path)):
                if name.endswith(".scans"):
                    sources[name[: -len(".scans")]] = read_scan_cache(os.path.join(path, name))
        else:
            sources.update(unpack(path))
    return sources


def is_real(source):
    return source.startswith("folder-")


def sequence_of(source):
    return source.split("-")[1]


# ---- augmentation and projection (train/scan_dataset.cpp, segmentation/range_projection.cpp) ----
# Torch on the training device: a batch's scans are augmented and projected
# where the network runs. Per-scan draws come from a NumPy generator seeded by
# (seed, batch), per-point draws from a torch generator seeded likewise.

def rotation(a, rng):
    yaw = rng.uniform(0, 2 * math.pi) if a["rotate"] else 0.0
    tilt = math.radians(a["max_tilt_deg"])
    pitch, roll = rng.uniform(-tilt, tilt), rng.uniform(-tilt, tilt)
    cy, sy, cp, sp, cr, sr = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch), math.cos(roll), math.sin(roll)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return (rz @ ry @ rx).astype(np.float32)


def augment(scan, a, rng, gen):
    """Points, remission, rings and targets (torch, on the scan's device) of an augmented copy of the scan
    (a dict of tensors: xyz int16 [N, 3], remission, target, ring uint8; beams)."""
    import torch
    dev = scan["xyz"].device
    n = scan["xyz"].shape[0]
    beams = max(scan["beams"], 1)
    rand = lambda *shape: torch.rand(*shape, generator=gen, device=dev)
    normal = lambda k: torch.randn(k, generator=gen, device=dev)
    ring = scan["ring"].long()
    ring = torch.where(ring == NO_RING, torch.full_like(ring, -1), ring)
    keep = rand(n) >= a["max_point_dropout"] * rng.random()
    lost = torch.from_numpy(rng.random(beams) < a["max_ring_dropout"] * rng.random()).to(dev)
    keep &= ~((ring >= 0) & lost[ring.clamp(0, beams - 1)])
    p = scan["xyz"].float() * POSITION_STEP
    if rng.random() < a["occlusion"]:
        azimuth = torch.atan2(p[:, 1], p[:, 0])
        for _ in range(1 + int(rng.random() * 3)):
            start, width = rng.random() * 2 * math.pi, math.radians(5 + 35 * rng.random())
            first = int(rng.random() * beams)
            keep &= ~((torch.remainder(azimuth - start + 4 * math.pi, 2 * math.pi) < width) & (ring >= first))
    p, ring, target = p[keep], ring[keep], scan["target"][keep].long()
    remission = scan["remission"][keep].float() / 255.0
    r = p.norm(dim=1)
    sigma = a["max_range_noise"] * rng.random()
    if sigma > 0:
        p = p * torch.where(r > 0, (r + sigma * normal(len(r))) / r.clamp_min(1e-9), torch.ones_like(r))[:, None]
    if rng.random() < a["flip"]:
        p[:, 1] = -p[:, 1]
    p = p @ torch.from_numpy(rotation(a, rng)).to(dev).T
    p[:, 2] += a["max_height_shift"] * (2 * rng.random() - 1)
    constant = rng.random() < a["remission_constant"]
    gamma = math.exp((2 * rng.random() - 1) * math.log(a["remission_gamma"]))
    gain = 1 + a["remission_gain"] * (2 * rng.random() - 1)
    offset = a["remission_offset"] * (2 * rng.random() - 1)
    noise = a["remission_noise"] * rng.random()
    if constant:
        remission = torch.zeros_like(remission)
    else:
        remission = gain * remission.pow(gamma) + offset + noise * normal(len(remission))
    return p, remission.clamp(0, 1), ring, target


def project(p, remission, ring, target, beams, columns, means, stds, first=0, crop=None):
    """Columns first..first+crop (wrapping) of the range image: image [6, beams, crop] (range, x, y, z,
    remission, mask; normalised, 0 without a point) and the target of each pixel (its nearest point's)."""
    import torch
    crop = crop or columns
    r = p.norm(dim=1)
    col = torch.floor(0.5 * (1 - torch.atan2(p[:, 1], p[:, 0]) / math.pi) * columns).long().clamp(0, columns - 1)
    col = torch.remainder(col - first, columns)
    ok = (ring >= 0) & (ring < beams) & (r > 0) & torch.isfinite(r) & (col < crop)
    p, remission, ring, target, r, col = p[ok], remission[ok], ring[ok], target[ok], r[ok], col[ok]
    pixel = ring * crop + col
    pixels = beams * crop
    nearest = torch.full((pixels,), float("inf"), device=p.device).scatter_reduce(0, pixel, r, "amin")
    index = torch.arange(len(r), device=p.device)
    shown = torch.full((pixels,), -1, dtype=torch.long, device=p.device)
    shown = shown.scatter_reduce(0, pixel, torch.where(r == nearest[pixel], index, torch.full_like(index, -1)), "amax")
    has = shown >= 0
    s = shown[has]
    raw = torch.stack([r[s], p[s, 0], p[s, 1], p[s, 2], remission[s], torch.ones_like(r[s])])
    image = torch.zeros((6, pixels), device=p.device)
    image[:, has] = (raw - means[:, None]) / stds[:, None]
    labels = torch.zeros(pixels, dtype=torch.long, device=p.device)
    labels[has] = target[s]
    return image.reshape(6, beams, crop), labels.reshape(beams, crop)


def sample(scan, a, rng, gen, columns, pixels, means, stds):
    crop = min(columns, pixels // max(scan["beams"], 1))
    first = int(rng.integers(columns))
    return project(*augment(scan, a, rng, gen), scan["beams"], columns, means, stds, first, crop)


# ---- the network (segmentation/torch/segnet.cpp, parameter for parameter) ----

def network_module():
    import torch
    from torch import nn
    import torch.nn.functional as F

    class ConvBn(nn.Module):
        def __init__(self, cin, cout, kernel=(3, 3), stride=(1, 1), dilation=(1, 1)):
            super().__init__()
            padding = (dilation[0] * (kernel[0] - 1) // 2, dilation[1] * (kernel[1] - 1) // 2)
            self.conv = nn.Conv2d(cin, cout, kernel, stride=stride, padding=padding, dilation=dilation, bias=False)
            self.bn = nn.BatchNorm2d(cout)

        def forward(self, x, activate: bool = True):
            y = self.bn(self.conv(x))
            return F.leaky_relu(y, 0.1) if activate else y  # LEAKY (a literal for TorchScript)

    class ResidualBlock(nn.Module):
        def __init__(self, channels, column_dilation):
            super().__init__()
            self.first = ConvBn(channels, channels, dilation=(1, column_dilation))
            self.second = ConvBn(channels, channels)

        def forward(self, x):
            return F.leaky_relu(self.second(self.first(x), False) + x, 0.1)

    class SegNet(nn.Module):
        def __init__(self, widths, stem_stride, context_blocks, in_channels=6, classes=CLASSES):
            super().__init__()
            w0, w1, w2 = widths
            s = stem_stride
            self.s, self.classes = s, classes
            self.stem = ConvBn(in_channels, w0, (3, max(3, 2 * s - 1)), (1, s))
            self.level0 = ResidualBlock(w0, 1)
            self.down1 = ConvBn(w0, w1, stride=(2, 2))
            self.level1 = ResidualBlock(w1, 1)
            self.down2 = ConvBn(w1, w2, stride=(2, 2))
            self.context = nn.ModuleList([ResidualBlock(w2, 1 << min(i, 3)) for i in range(context_blocks)])
            self.up2 = ConvBn(w2 + w1, w1)
            self.up1 = ConvBn(w1 + w0, w0)
            self.head = nn.Conv2d(w0, classes * s, 1)

        def forward(self, x):
            """Logits [N, H, W, K] of images [N, C, H, W] (SegNetImpl::pixel_logits)."""
            l0 = self.level0(self.stem(x))
            l1 = self.level1(self.down1(l0))
            l2 = self.down2(l1)
            for block in self.context:
                l2 = block(l2)
            u1 = self.up2(torch.cat([F.interpolate(l2, size=(l1.shape[2], l1.shape[3]), mode="bilinear",
                                                   align_corners=False), l1], 1))
            u0 = self.up1(torch.cat([F.interpolate(u1, size=(l0.shape[2], l0.shape[3]), mode="bilinear",
                                                   align_corners=False), l0], 1))
            logits = self.head(u0)  # channel j * K + k: class k at column phase j
            n, h, w = logits.shape[0], logits.shape[2], logits.shape[3]
            return logits.permute(0, 2, 3, 1).reshape(n, h, w * self.s, self.classes)

    return SegNet


def read_weights(path):
    """A state dict from weights.npz or from a SegNet's libtorch archive (a model's NAME.pt)."""
    import torch
    if path.endswith(".npz"):
        return {k: torch.from_numpy(np.array(v)) for k, v in np.load(path).items()}
    return dict(torch.jit.load(path, map_location="cpu").state_dict())


def read_template(path):
    import yaml
    with open(path) as f:
        return yaml.safe_load(f)


# ---- training ----

def class_weights(sources, train, real_fraction):
    counts = {True: np.zeros(CLASSES), False: np.zeros(CLASSES)}
    for name in train:
        for scan in sources[name]:
            counts[is_real(name)] += np.bincount(scan["target"], minlength=CLASSES)[:CLASSES]
    mixed = np.zeros(CLASSES)
    for real, share in ((True, real_fraction), (False, 1 - real_fraction)):
        if counts[real][1:].sum() > 0:
            mixed += share * counts[real] / counts[real][1:].sum()
    weights = np.zeros(CLASSES)
    present = mixed[1:] > 0
    weights[1:][present] = 1 / np.sqrt(mixed[1:][present] / mixed[1:].sum())
    return weights * present.sum() / weights.sum()


class Samples:
    """Training batches, each of one beam count, its scans drawn (real ones with probability real_fraction),
    augmented and cropped on the device; batch b is a pure function of (seed, b) on a given device."""

    def __init__(self, sources, train, args, means, stds, device):
        import torch
        self.scans = {True: [], False: []}
        for name in train:
            for s in sources[name]:
                self.scans[is_real(name)].append(dict(
                    beams=s["beams"], xyz=torch.from_numpy(np.array(s["xyz"])).to(device),
                    remission=torch.from_numpy(np.array(s["remission"])).to(device),
                    target=torch.from_numpy(np.array(s["target"])).to(device),
                    ring=torch.from_numpy(np.array(s["ring"])).to(device)))
        self.args, self.device = args, device
        self.means = torch.from_numpy(means).to(device)
        self.stds = torch.from_numpy(stds).to(device)
        self.real_fraction = args.real_fraction if self.scans[True] else 0.0
        if not self.scans[False]:
            self.real_fraction = 1.0

    def batch(self, b):
        import torch
        rng = np.random.default_rng([self.args.seed, b])
        gen = torch.Generator(device=self.device)
        gen.manual_seed(int(rng.integers(1 << 62)))
        first = self.pick(rng)
        scans = [first] + [self.pick(rng, first["beams"]) for _ in range(self.args.batch - 1)]
        images, labels = zip(*(sample(s, AUGMENT, rng, gen, self.args.columns, self.args.pixels_per_sample,
                                      self.means, self.stds) for s in scans))
        return torch.stack(images), torch.stack(labels)

    def pick(self, rng, beams=None):
        while True:
            pool = self.scans[bool(rng.random() < self.real_fraction)]
            scan = pool[int(rng.integers(len(pool)))]
            if beams is None or scan["beams"] == beams:
                return scan


def training_data(args, device):
    """The training sources (the held-out real sequences left out), the sample stream and the loss's class
    weights."""
    import torch
    projection = read_template(args.template)["projection"]
    means = np.array(projection["means"], np.float32)
    stds = np.array(projection["stds"], np.float32)
    sources = load_sources(args.scans)
    held = set(args.hold_out.split(",")) if args.hold_out else set()
    names = [n for n in sorted(sources) if not (is_real(n) and sequence_of(n) in held)]
    samples = Samples(sources, names, args, means, stds, device)
    weights = torch.tensor(class_weights(sources, names, samples.real_fraction), dtype=torch.float32)
    return names, samples, weights


def build_network(args, device):
    import torch
    widths = [int(w) for w in args.widths.split(",")]
    net = network_module()(widths, args.stem_stride, args.context_blocks)
    if args.init:
        net.load_state_dict(read_weights(args.init))
    return net.to(device).to(memory_format=torch.channels_last), widths


class Schedule:
    """The learning rate's factor: a linear warm-up over args.warmup steps, then a cosine to 1 % at `steps`
    (with --time-budget, the steps that fit: set once the warm-up is timed, from its speed after step 20)."""

    def __init__(self, args):
        self.args, self.steps, self.timed_from = args, args.steps, None

    def __call__(self, step):
        warmup = self.args.warmup
        if step < warmup:
            return (step + 1) / warmup
        t = min(1.0, (step - warmup) / max(1, self.steps - warmup))
        return 0.01 + 0.99 * 0.5 * (1 + math.cos(math.pi * t))

    def timed(self, step, start):
        """After step `step` (counted from 1): fixes the step count at the end of a timed warm-up; True then."""
        if step == 20:
            self.timed_from = time.time()  # after the first steps' one-time costs
        if not self.args.time_budget or step != self.args.warmup:
            return False
        now = time.time()
        speed = (step - 20) / (now - self.timed_from)
        self.steps = max(step + 1, int(step + speed * (self.args.time_budget - (now - start))))
        return True


def train(args):
    import torch
    import torch.nn.functional as F

    if args.time_budget and args.warmup < 40:
        raise SystemExit("--time-budget needs --warmup of at least 40 steps to time")
    torch.manual_seed(args.seed)
    torch.backends.cudnn.benchmark = True  # a GPU run is not bit-reproducible anyway (atomic scatters)
    device = torch.device("cuda" if torch.cuda.is_available() and not args.cpu else "cpu")
    names, samples, weights = training_data(args, device)
    net, widths = build_network(args, device)
    optimiser = torch.optim.AdamW(net.parameters(), lr=args.lr, weight_decay=args.weight_decay)
    schedule = Schedule(args)
    rates = torch.optim.lr_scheduler.LambdaLR(optimiser, schedule)
    os.makedirs(args.out, exist_ok=True)
    log = dict(args=vars(args), train_sources=names, class_weights=weights.tolist(), losses=[],
               device=str(device), torch=torch.__version__)
    weights = weights.to(device)
    start, total, count, step = time.time(), torch.zeros((), device=device), 0, 0
    net.train()
    while step < schedule.steps:
        # One step: a batch augmented on the device, the class-weighted cross-entropy (bf16 on a GPU).
        images, labels = samples.batch(step)
        with torch.autocast(device.type, dtype=torch.bfloat16, enabled=device.type == "cuda"):
            logits = net(images.contiguous(memory_format=torch.channels_last))
        loss = F.cross_entropy(logits.float().permute(0, 3, 1, 2), labels, weight=weights, ignore_index=0)
        optimiser.zero_grad(set_to_none=True)
        loss.backward()
        optimiser.step()
        rates.step()
        total, count, step = total + loss.detach(), count + 1, step + 1
        # The steps that fit the time budget (training.json records them: `--steps` with them repeats the run).
        if schedule.timed(step, start):
            log["steps_for_time_budget"] = schedule.steps
            print(f"{args.out}: {schedule.steps} steps fit {args.time_budget:.0f} s", flush=True)
        if count == args.log_every or step == schedule.steps:
            log["losses"].append([step, total.item() / count, time.time() - start])
            print(f"{args.out}: step {step}/{schedule.steps} loss {total.item() / count:.4f} "
                  f"{time.time() - start:.0f} s", flush=True)
            total, count = torch.zeros((), device=device), 0
        if args.max_seconds and time.time() - start > args.max_seconds:
            log["stopped_at_step"] = step
            print(f"{args.out}: stopped at step {step} after {args.max_seconds} s", flush=True)
            break
    np.savez(os.path.join(args.out, "weights.npz"), **{k: v.detach().cpu().numpy() for k, v in net.state_dict().items()})
    log.update(seconds=time.time() - start,
               shape=dict(widths=widths, stem_stride=args.stem_stride, context_blocks=args.context_blocks))
    with open(os.path.join(args.out, "training.json"), "w") as f:
        json.dump(log, f, indent=1)


# ---- export ----

def export(args):
    import torch
    log = json.load(open(os.path.join(args.run, "training.json")))
    shape = log["shape"]
    SegNet = network_module()
    net = SegNet(shape["widths"], shape["stem_stride"], shape["context_blocks"])
    state = {k: torch.from_numpy(np.array(v)) for k, v in np.load(os.path.join(args.run, "weights.npz")).items()}
    net.load_state_dict(state)
    net.eval()
    os.makedirs(args.dir, exist_ok=True)
    weights = os.path.join(args.dir, args.name + ".pt")
    torch.jit.save(torch.jit.script(net), weights)  # a module of the same names is what torch::load reads
    template = open(args.template).read().splitlines()
    out, in_network = [], False
    for line in template:
        if line.startswith("network:"):
            in_network = True
            out += ["network:", "  type: segnet", f"  file: {args.name}.pt",
                    "  widths: [" + ", ".join(str(w) for w in shape["widths"]) + "]",
                    f"  stem_stride: {shape['stem_stride']}", f"  context_blocks: {shape['context_blocks']}"]
            continue
        if in_network and line.startswith("  "):
            continue
        in_network = False
        if line.startswith("#"):
            line = f"# SegNet trained by scripts/segnet_torch.py ({args.run})."
        out.append(line)
    with open(os.path.join(args.dir, args.name + ".yaml"), "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"wrote {weights} and {args.name}.yaml")


def main_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    pk = sub.add_parser("pack")
    pk.add_argument("scan_dir")
    pk.add_argument("out")
    pk.add_argument("--prefix", default="", help="only the caches whose names start so (e.g. folder-, sim-)")
    pk.add_argument("--every", type=int, default=1, help="every k-th scan of each cache")
    t = sub.add_parser("train")
    t.add_argument("--scans", nargs="+", required=True, help="scan cache folders (RUN/scans) or packed files")
    t.add_argument("--template", required=True, help="a model description: projection and channel statistics")
    t.add_argument("--out", required=True)
    t.add_argument("--hold-out", default="", help="real sequences left out, e.g. 00,01")
    t.add_argument("--init", help="weights of the same shape to start from: weights.npz or a SegNet's .pt")
    t.add_argument("--widths", default="16,32,64")
    t.add_argument("--stem-stride", type=int, default=4)
    t.add_argument("--context-blocks", type=int, default=2)
    t.add_argument("--steps", type=int, default=6000)
    t.add_argument("--warmup", type=int, default=200, help="steps of the linear warm-up")
    t.add_argument("--time-budget", type=float, default=0,
                   help="[s] instead of --steps: the steps that fit, from the speed of the warm-up (at least 40 steps)")
    t.add_argument("--batch", type=int, default=16)
    t.add_argument("--pixels-per-sample", type=int, default=65536)
    t.add_argument("--columns", type=int, default=2048)
    t.add_argument("--lr", type=float, default=2e-3)
    t.add_argument("--weight-decay", type=float, default=1e-4)
    t.add_argument("--real-fraction", type=float, default=0.2, help="share of samples from real scans")
    t.add_argument("--seed", type=int, default=1)
    t.add_argument("--max-seconds", type=float, default=0, help="stop early after this long (0: never); noted")
    t.add_argument("--log-every", type=int, default=100)
    t.add_argument("--cpu", action="store_true", help="train on the CPU even where a GPU is")
    e = sub.add_parser("export")
    e.add_argument("run")
    e.add_argument("--template", required=True)
    e.add_argument("--name", required=True)
    e.add_argument("--dir", required=True)
    args = p.parse_args(argv)
    if args.command == "pack":
        pack(args.scan_dir, args.out, args.prefix, args.every)
    elif args.command == "train":
        train(args)
    else:
        export(args)


if __name__ == "__main__":
    sys.exit(main_args(sys.argv[1:]))
