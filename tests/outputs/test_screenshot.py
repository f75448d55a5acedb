"""The screenshot command, without Chromium: no test may need a browser."""

from __future__ import annotations

import pytest

from f2n_drake.core.errors import InputError
from f2n_drake.outputs import screenshot


def test_screenshot_without_chromium_says_how_to_install_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CHROMIUM", raising=False)
    with pytest.raises(InputError, match="apt-get install chromium"):
        screenshot.find_chromium()
    html = tmp_path / "replay.html"
    html.write_text("<html></html>")
    assert screenshot.run_cli(screenshot.main, [str(html), "--out", str(tmp_path / "a.png")]) == 2
    assert "apt-get install chromium" in capsys.readouterr().err


def test_screenshot_command_line(tmp_path):
    command = screenshot.chromium_command(
        "chromium",
        tmp_path / "r.html",
        tmp_path / "v.png",
        tmp_path / "profile",
        width_px=1200,
        height_px=800,
        wait_s=12.5,
    )
    assert "--headless" in command and "--no-sandbox" in command
    assert "--window-size=1200,800" in command and "--virtual-time-budget=12500" in command
    assert command[-1].startswith("file://") and command[-1].endswith("r.html")
    with pytest.raises(InputError, match="no such replay"):
        screenshot.screenshot_replay(tmp_path / "missing.html", tmp_path / "v.png")
