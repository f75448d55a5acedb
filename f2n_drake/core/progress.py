"""A long run's progress on stderr: the step running and the time it has taken.

Parsing a large sheet takes a minute or more (its words read, the network run over tiles), and a
drive in Drake can take as long again. :class:`Progress` keeps one line on stderr, ``f2n_drake:
reading the words [00:12]``, redrawn every second from a background thread so a long step still
shows time passing, and cleared when the run ends. Where stderr is no terminal (a log, a pipe, the
tests) it writes nothing, as tqdm decides (``disable=None``).
"""

from __future__ import annotations

import threading
from types import TracebackType

from tqdm import tqdm

REDRAW_S = 1.0
"""Seconds between two redraws of the line while a step runs."""


class Progress:
    """``with Progress() as progress: progress("reading the words")``: each call names the
    step now running; the line shows it with the time since the run began."""

    def __init__(self, *, disable: bool | None = None, file=None) -> None:
        self._bar = tqdm(
            desc="f2n_drake: starting",
            bar_format="{desc} [{elapsed}]",
            disable=disable,
            file=file,
            leave=False,
        )
        self._done = threading.Event()
        self._redraw = threading.Thread(target=self._redraw_until_done, daemon=True)
        if not self._bar.disable:
            self._redraw.start()

    def __call__(self, step: str) -> None:
        """Show ``step`` as the step now running."""
        self._bar.set_description_str(f"f2n_drake: {step}")

    def _redraw_until_done(self) -> None:
        while not self._done.wait(REDRAW_S):
            self._bar.refresh()

    def close(self) -> None:
        """Stop redrawing and clear the line."""
        self._done.set()
        if self._redraw.is_alive():
            self._redraw.join()
        self._bar.close()

    def __enter__(self) -> Progress:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self.close()
