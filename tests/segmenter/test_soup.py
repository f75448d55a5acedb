"""Model soups (``f2n_drake.segmenter.soup``): the average of two checkpoints of one network."""

from __future__ import annotations

import torch

from f2n_drake.core.errors import run_cli
from f2n_drake.segmenter import soup
from f2n_drake.segmenter.network import DeepLabV3Plus
from f2n_drake.segmenter.weights import load_segmenter, save_segmenter

TINY = dict(width=0.25, aspp_channels=16, decoder_channels=16, low_level_channels=8)


def test_soup_averages_two_checkpoints_and_records_both_parents(tmp_path, capsys):
    torch.manual_seed(0)
    paths = [tmp_path / "a.pt", tmp_path / "b.pt"]
    for path in paths:
        save_segmenter(DeepLabV3Plus(**TINY), path, input_size=128)  # two random inits
    a, b = (load_segmenter(p).model.state_dict() for p in paths)
    out = tmp_path / "soup.pt"
    assert soup.main([str(paths[0]), str(paths[1]), "--out", str(out), "--share", "0.25"]) == 0
    mixed = load_segmenter(out)
    name = next(k for k, v in a.items() if v.dim() == 4)  # the first convolution's kernel
    expected = (0.75 * a[name] + 0.25 * b[name]).half().float()  # stored fp16, like any checkpoint
    assert torch.equal(mixed.model.state_dict()[name], expected)
    assert not torch.equal(a[name], b[name])
    parents = mixed.training["soup_of"]
    assert [p["share"] for p in parents] == [0.75, 0.25]
    assert parents[1]["sha256"] == load_segmenter(paths[1]).sha256
    assert "wrote" in capsys.readouterr().out


def test_soup_refuses_different_networks_and_bad_shares(tmp_path, capsys):
    small, wide = tmp_path / "small.pt", tmp_path / "wide.pt"
    save_segmenter(DeepLabV3Plus(**TINY), small, input_size=128)
    save_segmenter(DeepLabV3Plus(**{**TINY, "width": 0.5}), wide, input_size=128)
    out = tmp_path / "soup.pt"
    assert run_cli(soup.main, [str(small), str(wide), "--out", str(out)]) == 2
    assert "different networks" in capsys.readouterr().err
    assert run_cli(soup.main, [str(small), str(small), "--out", str(out), "--share", "2"]) == 2
    assert "0..1" in capsys.readouterr().err
    assert run_cli(soup.main, [str(small), str(tmp_path / "none.pt"), "--out", str(out)]) == 2
    assert "not found" in capsys.readouterr().err
    assert not out.exists()
