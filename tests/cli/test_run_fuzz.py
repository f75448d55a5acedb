"""The run CLI fed random small drawings and option values: every run ends with exit code 0, 2, 3
or 4, never a traceback, and its ``--out`` is either complete or absent.

The network is replaced by a seeded stand-in that labels a drawing at random (walls on the ink,
a random class per enclosed region, random connectors): random labels reach every later stage
(instances, priors, graph, planner, writer) in more ways than the trained network's, and in a
fraction of the time.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from f2n_drake.core.classes import CLASS_ID, NUM_CLASSES
from f2n_drake.core.errors import EXIT_BAD_INPUT, EXIT_GOAL_NOT_REACHED, EXIT_NO_ROUTE, run_cli
from f2n_drake.core.paths import REPO_ROOT
from f2n_drake.outputs.writer import PARSE_FILES
from f2n_drake.run import main

EXIT_CODES = {0, EXIT_BAD_INPUT, EXIT_NO_ROUTE, EXIT_GOAL_NOT_REACHED}
EXAMPLE_JSON = REPO_ROOT / "examples" / "plan.json"


class RandomSegmenter:
    """Labels a drawing at random, seeded by its pixels."""

    def predict_with_probabilities(self, image: np.ndarray):
        grey = image if image.ndim == 2 else image.mean(axis=2)
        rng = np.random.default_rng(int(grey.astype(np.int64).sum()) % 2**32)
        ink = grey < 128
        regions, n = ndimage.label(~ink)
        labels = rng.integers(0, 6, n + 1).astype(np.uint8)[regions]
        labels[ink] = CLASS_ID["wall"]
        connectors = ink & (rng.random(ink.shape) < rng.uniform(0, 0.3))
        labels[connectors] = rng.choice([7, 8, 9], size=int(connectors.sum()))
        probabilities = rng.random((NUM_CLASSES, *labels.shape)).astype(np.float32)
        probabilities += 2.0 * (np.arange(NUM_CLASSES)[:, None, None] == labels)
        return labels, probabilities / probabilities.sum(axis=0)

    def predict(self, image: np.ndarray) -> np.ndarray:
        return self.predict_with_probabilities(image)[0]


def random_drawing(rng: np.random.Generator) -> np.ndarray:
    """A small drawing: noise, blank paper, or rooms outlined with gaps."""
    h, w = rng.integers(8, 112, 2)
    kind = rng.choice(["rooms", "rooms", "rooms", "noise", "blank", "lines"])
    if kind == "noise":
        return rng.integers(0, 256, (h, w), dtype=np.uint8)
    image = np.full((h, w), int(rng.choice([255, 0, 128])), np.uint8)
    if kind == "blank":
        return image
    image[:] = 255
    for _ in range(rng.integers(1, 7)):
        r0, c0 = rng.integers(0, max(h - 4, 1)), rng.integers(0, max(w - 4, 1))
        r1, c1 = rng.integers(r0 + 1, h + 1), rng.integers(c0 + 1, w + 1)
        t = int(rng.integers(1, 4))
        if kind == "lines":
            image[r0 : r0 + t, c0:c1] = 0
            continue
        image[r0 : r0 + t, c0:c1] = image[r1 - t : r1, c0:c1] = 0
        image[r0:r1, c0 : c0 + t] = image[r0:r1, c1 - t : c1] = 0
        if rng.random() < 0.6:  # a doorway
            g = int(rng.integers(r0, r1))
            image[g : g + 3, c0 : c0 + t] = 255
    return image


def random_options(rng: np.random.Generator) -> list[str]:
    """Options of the run CLI, each given now and then, mostly with a usable value."""
    choices = {  # option: (usable values, unusable values)
        "--start": (
            ["living", "bedroom_0", "kitchen", "1,1", "2,2.5"],
            ["sauna", "nan,1", "1e9,0"],
        ),
        "--goal": (["bedroom", "bathroom_0", "2,2", "living_0"], [";", "x,y"]),
        "--robot": (["ground", "ground", "uav"], ["tank", "missing.yaml"]),
        "--front-doors": (["0", "1", "2", "any"], ["-1"]),
        "--kitchens": (["0", "1", "any"], ["many"]),
        "--views": (["1", "2"], ["3"]),
        "--seed": (["0", "7"], ["-3"]),
        "--heading": (["0", "45", "-90"], ["nan", "720"]),
        "--origin": (["52.2,0.12", "0,0"], ["91,0", "a,b"]),
        "--plan-index": (["0"], ["1", "-1"]),
        "--correction": (["continuous", "off", "paper"], ["none"]),
    }
    argv = []
    usable = 10 ** rng.uniform(-1.7, -0.5)  # 2 to 30 cm/px: a small drawing is a small flat
    unusable = rng.choice(["nan", "-1", "inf", "abc", "1e300", f"{10 ** rng.uniform(-5, 4):.3g}"])
    if rng.random() < 0.8:
        argv += ["--scale", f"{usable:.3g}" if rng.random() < 0.85 else str(unusable)]
    for option, (good, bad) in choices.items():
        if rng.random() < 0.25:
            values = good if rng.random() < 0.85 else bad
            argv += [option, str(values[int(rng.integers(len(values)))])]
    if rng.random() < 0.9:
        argv.append("--no-sim")
    return argv


def run_case(seed: int, tmp_path, monkeypatch, capsys) -> None:
    import cv2

    rng = np.random.default_rng([seed, 31])
    plan = tmp_path / f"plan{seed}.png"
    if rng.random() < 0.1:
        plan = plan.with_suffix(".json")
        plan.write_bytes(EXAMPLE_JSON.read_bytes())
    elif rng.random() < 0.05:
        plan.write_bytes(rng.bytes(int(rng.integers(0, 200))))  # no image at all
    else:
        cv2.imwrite(str(plan), random_drawing(rng))
    out = tmp_path / f"out{seed}"
    argv = [str(plan), *random_options(rng), "--out", str(out)]
    try:
        code = run_cli(main, argv)
    except BaseException as exc:  # noqa: BLE001 - a traceback is the failure being looked for
        pytest.fail(f"{argv}: {type(exc).__name__}: {exc}")
    err = capsys.readouterr().err.strip()
    assert code in EXIT_CODES, (argv, code, err)
    assert "Traceback" not in err, (argv, err)
    if code != 0:
        assert err.splitlines()[-1].startswith("error: "), (argv, err)
    names = {p.name for p in out.iterdir()} if out.exists() else set()
    if code in (0, EXIT_NO_ROUTE, EXIT_GOAL_NOT_REACHED):
        assert set(PARSE_FILES) <= names, (argv, names)
        assert ("route.json" in names) == (code != EXIT_NO_ROUTE), (argv, names)
    else:
        assert not out.exists(), (argv, names)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


@pytest.fixture
def random_network(monkeypatch):
    from f2n_drake.segmenter.inference import Segmenter

    monkeypatch.setattr(Segmenter, "load", classmethod(lambda cls, *a, **k: RandomSegmenter()))


@pytest.mark.parametrize("seed", range(12))
def test_run_survives_random_drawings_and_options(
    seed, random_network, tmp_path, monkeypatch, capsys
):
    run_case(seed, tmp_path, monkeypatch, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(12, 300))
def test_run_survives_many_random_drawings_and_options(
    seed, random_network, tmp_path, monkeypatch, capsys
):
    run_case(seed, tmp_path, monkeypatch, capsys)
