"""scripts/segnet_torch.py: SegNet trained with PyTorch runs in saloam as it was trained.

A tiny SegNet is trained on the CPU on two "real" scans (a folder source: the
trainer draws folder sources as real scans) and two simulated ones, from the
scan cache `saloam segment-train` writes; exported, saloam's plugin runs it
(`network: {type: segnet}`) and labels every point exactly as the trained
module's own forward pass does (that pass run by the plugin as TorchScript).
"""
import json
import os
import sys

import numpy as np
import pytest

from conftest import run_cli

torch = pytest.importorskip("torch")  # Debian: python3-torch (scripts/install_deps.sh installs it)

SOURCE_DIR = os.environ.get("SALOAM_SOURCE_DIR") or os.path.join(os.path.dirname(__file__), "../..")
sys.path.insert(0, os.path.join(SOURCE_DIR, "scripts"))
import segnet_torch  # noqa: E402

TEMPLATE = os.path.join(SOURCE_DIR, "models/segmenter/saloam.yaml")


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    """segment-train's scan cache (two folder scans, two simulated ones, one simulated validation scan)
    and the folder."""
    root = tmp_path_factory.mktemp("segnet")
    seq = root / "seq"
    run_cli("-q", "simulate", "--preset", "urban-loop", "--frames", "0:4", "--beams", "16", "--labels", "noisy",
            "--out", seq)
    recipe = root / "recipe.yaml"
    recipe.write_text("defaults: {beams: 16}\n"
                      f"train: [{{folder: '{seq}', labels: '{seq / 'labels_gt'}', frames: '0:2', frame_step: 1}},\n"
                      "        {simulate: 'preset:urban-loop', frames: '0:40', frame_step: 20, seed: 3}]\n"
                      "validation: [{simulate: 'preset:urban-loop', frames: '0:20', frame_step: 20, seed: 4}]\n")
    run_cli("-q", "segment-train", "--data", recipe, "--out", root / "cache", "--epochs", "1", "--samples-per-epoch",
            "1", "--batch", "1", "--widths", "4,8,8", "--stem-stride", "2", "--validation-scans", "1")
    return root / "cache" / "scans", seq


def test_the_packed_scans_are_the_cache(scans, tmp_path):
    cache, _ = scans
    segnet_torch.pack(str(cache), str(tmp_path / "scans.xz"))
    packed = segnet_torch.load_sources([str(tmp_path / "scans.xz")])
    direct = segnet_torch.load_sources([str(cache)])
    # Two folder scans (drawn as real ones), two simulated ones, and the validation source's one.
    assert sorted(packed) == sorted(direct)
    assert sorted((segnet_torch.is_real(name), len(scan_list)) for name, scan_list in direct.items()) == [
        (False, 1), (False, 2), (True, 2)]
    for name, scan_list in direct.items():
        for a, b in zip(scan_list, packed[name]):
            assert a["beams"] == b["beams"] == 16
            for field in ("xyz", "remission", "target", "ring"):
                np.testing.assert_array_equal(a[field], b[field])


def test_training_lowers_the_loss_and_saloam_runs_the_network_as_trained(scans, tmp_path):
    cache, seq = scans
    run = tmp_path / "run"
    segnet_torch.main_args(["train", "--cpu", "--scans", str(cache), "--template", TEMPLATE, "--out", str(run),
                            "--widths", "8,16,16", "--stem-stride", "2", "--context-blocks", "1", "--steps", "200",
                            "--warmup", "5", "--batch", "2", "--pixels-per-sample", "4096", "--lr", "5e-3",
                            "--real-fraction", "0.5", "--log-every", "40"])
    log = json.loads((run / "training.json").read_text())
    losses = [loss for _, loss, _ in log["losses"]]
    assert len(losses) == 5
    assert losses[-1] < 0.7 * losses[0], losses

    model = tmp_path / "model"
    segnet_torch.main_args(["export", str(run), "--template", TEMPLATE, "--name", "tiny", "--dir", str(model)])
    # The same module's forward pass as TorchScript: what was trained, run by the plugin.
    net = segnet_torch.network_module()([8, 16, 16], 2, 1)
    net.load_state_dict(segnet_torch.read_weights(str(run / "weights.npz")))
    net.eval()

    class Logits(torch.nn.Module):
        def __init__(self, segnet):
            super().__init__()
            self.segnet = segnet

        def forward(self, x):
            return self.segnet(x).permute(0, 3, 1, 2)

    torch.jit.save(torch.jit.script(Logits(net)), str(model / "forward.pt"))
    spec = (model / "tiny.yaml").read_text()
    assert "widths: [8, 16, 16]" in spec and "stem_stride: 2" in spec and "context_blocks: 1" in spec
    script_spec = "\n".join(line for line in spec.splitlines()
                            if not line.strip().startswith(("widths", "stem_stride", "context_blocks")))
    (model / "forward.yaml").write_text(script_spec.replace("type: segnet", "type: torchscript")
                                        .replace("file: tiny.pt", "file: forward.pt") + "\n")
    for name in ("tiny", "forward"):
        run_cli("-q", "segment", seq, "--segmenter", model / f"{name}.yaml", "--out", tmp_path / name, "--no-score")
    for frame in ("000000", "000003"):
        exported = np.fromfile(tmp_path / "tiny" / f"{frame}.label", np.uint32)
        forward = np.fromfile(tmp_path / "forward" / f"{frame}.label", np.uint32)
        assert len(exported) > 1000
        np.testing.assert_array_equal(exported, forward)
