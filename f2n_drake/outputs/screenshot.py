"""``python -m f2n_drake.outputs.screenshot REPLAY.html --out viewer.png``: the replay as a PNG.

Renders a meshcat HTML replay (``python -m f2n_drake.run PLAN --html REPLAY.html``) in headless
Chromium (Debian's ``chromium`` package; WebGL in software, no display or GPU needed) and writes
what a user sees when opening it: the plan from above, the route and the robot. The replay plays
in real time from when the page loads; the picture is taken ``--wait-s`` seconds of page time
later (Chromium's virtual time, so it does not take that long). The ``CHROMIUM`` environment
variable names another browser binary.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from f2n_drake.core.errors import F2NError, InputError, run_cli

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
INSTALL_HINT = (
    "headless Chromium renders the replay, and none was found: install it with "
    "`apt-get install chromium` (Debian; `chromium-browser` on Ubuntu) or set CHROMIUM to a "
    "Chromium or Chrome binary"
)
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",  # WebGL in software: meshcat needs it without a GPU
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)


def find_chromium() -> str:
    """The Chromium binary: ``$CHROMIUM`` or the first of ``CHROMIUM_NAMES`` on the PATH.

    Raises:
        InputError: none found (the message says how to install it).
    """
    explicit = os.environ.get("CHROMIUM")
    if explicit:
        found = shutil.which(explicit)
        if found is None:
            raise InputError(f"CHROMIUM={explicit} is not an executable; {INSTALL_HINT}")
        return found
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found is not None:
            return found
    raise InputError(INSTALL_HINT)


def chromium_command(
    chromium: str,
    html_path: Path,
    png_path: Path,
    profile_dir: Path,
    *,
    width_px: int,
    height_px: int,
    wait_s: float,
) -> list[str]:
    """The Chromium command line that writes ``png_path``, a ``width_px`` x ``height_px``
    screenshot of ``html_path`` after ``wait_s`` seconds of virtual time."""
    return [
        chromium,
        *CHROMIUM_FLAGS,
        f"--user-data-dir={profile_dir}",
        f"--window-size={width_px},{height_px}",
        f"--virtual-time-budget={round(1000 * wait_s)}",
        f"--screenshot={png_path}",
        html_path.resolve().as_uri(),
    ]


def screenshot_replay(
    html_path: str | Path,
    png_path: str | Path,
    *,
    width_px: int = 1200,
    height_px: int = 800,
    wait_s: float = 20.0,
    timeout_s: float = 300.0,
) -> Path:
    """Render the HTML replay ``html_path`` in headless Chromium and write ``png_path``.

    Args:
        html_path: a meshcat HTML replay (``--html`` of ``python -m f2n_drake.run``).
        png_path: the PNG to write (its folder is made).
        width_px, height_px: the browser window [px].
        wait_s: page time before the picture [s]; the replay plays from page load.
        timeout_s: wall-clock limit for Chromium [s].
    Raises:
        InputError: no such HTML file, bad sizes, or no Chromium (with how to install it).
        F2NError: Chromium ran but wrote no picture (its last output lines in the message).
    """
    html_path, png_path = Path(html_path), Path(png_path).resolve()
    if not html_path.is_file():
        raise InputError(f"no such replay: {html_path}")
    if width_px < 16 or height_px < 16 or not wait_s >= 0:
        raise InputError(f"bad window {width_px}x{height_px} px or wait {wait_s} s")
    chromium = find_chromium()
    png_path.parent.mkdir(parents=True, exist_ok=True)
    png_path.unlink(missing_ok=True)
    with tempfile.TemporaryDirectory(prefix="f2n_chromium_") as profile:
        command = chromium_command(
            chromium,
            html_path,
            png_path,
            Path(profile),
            width_px=width_px,
            height_px=height_px,
            wait_s=wait_s,
        )
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s)
    if not png_path.is_file() or png_path.stat().st_size == 0:
        tail = "\n".join((done.stderr or done.stdout).strip().splitlines()[-5:])
        raise F2NError(f"Chromium wrote no screenshot (exit {done.returncode}):\n{tail}")
    return png_path


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m f2n_drake.outputs.screenshot",
        description="Render a meshcat HTML replay in headless Chromium and write a PNG.",
    )
    p.add_argument("html", help="HTML replay (python -m f2n_drake.run PLAN --html FILE)")
    p.add_argument("--out", default="viewer.png", help="PNG to write [viewer.png]")
    p.add_argument("--width", type=int, default=1200, help="window width [1200 px]")
    p.add_argument("--height", type=int, default=800, help="window height [800 px]")
    p.add_argument(
        "--wait-s",
        type=float,
        default=20.0,
        help="seconds of page time before the picture; the replay plays from page load [20]",
    )
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    path = screenshot_replay(
        args.html, args.out, width_px=args.width, height_px=args.height, wait_s=args.wait_s
    )
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
