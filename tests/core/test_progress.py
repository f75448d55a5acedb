"""The run's progress line: the step named, nothing written where stderr is no terminal."""

from __future__ import annotations

import io

from f2n_drake.core.progress import Progress


def test_the_line_names_the_step_running_and_is_cleared_at_the_end():
    stream = io.StringIO()
    with Progress(disable=False, file=stream) as progress:
        progress("reading the words")
        progress("segmenting the drawing")
        redraw = progress._redraw
    written = stream.getvalue()
    assert "f2n_drake: reading the words [" in written
    assert "f2n_drake: segmenting the drawing [" in written
    assert not redraw.is_alive()  # the redrawing thread ends with the run


def test_nothing_is_written_where_stderr_is_no_terminal():
    stream = io.StringIO()  # no tty, as a log or a pipe
    with Progress(file=stream) as progress:
        progress("reading the words")
    assert stream.getvalue() == ""
