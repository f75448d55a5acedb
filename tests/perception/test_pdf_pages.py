"""A PDF page read as a drawing (``perception.pdf_pages``): vector pages made with matplotlib."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from f2n_drake.core.errors import InputError
from f2n_drake.perception.pdf_pages import METRES_PER_POINT, load_pdf_page


def write_pdf(path, line_widths_pt=(2.0, 6.0), size_in=(8.0, 4.0)):
    """One landscape page per line width, each a rectangle from 10 % to 90 % of the page."""
    with PdfPages(path) as pages:
        for width in line_widths_pt:
            fig = Figure(figsize=size_in)
            ax = fig.add_axes([0, 0, 1, 1])
            ax.set_xlim(0, 1)
            ax.set_ylim(0, 1)
            ax.axis("off")
            if width:
                ax.plot([0.1, 0.9, 0.9, 0.1, 0.1], [0.1, 0.1, 0.9, 0.9, 0.1], "k", lw=width)
            pages.savefig(fig)


def test_a_page_is_drawn_grey_on_white_at_the_long_side_asked(tmp_path):
    path = tmp_path / "sheet.pdf"
    write_pdf(path)
    sheet = load_pdf_page(path, page=0, long_side_px=400)
    thin = sheet.image
    assert sheet.pages == 2
    assert thin.shape == (200, 400) and thin.dtype == np.uint8
    assert thin[100, 200] == 255 and thin[100, 40] < 128  # paper inside, the left line dark
    # 8 inches of paper over 400 px; the same from the page's size in points
    assert np.isclose(sheet.paper_metres_per_px, 8 * 0.0254 / 400)
    assert np.isclose(sheet.paper_metres_per_px, 8 * 72 * METRES_PER_POINT / 400)
    thick = load_pdf_page(path, page=1, long_side_px=400).image
    assert np.count_nonzero(thick < 128) > 2 * np.count_nonzero(thin < 128)  # the second page


def test_a_missing_page_names_how_many_there_are(tmp_path):
    path = tmp_path / "sheet.pdf"
    write_pdf(path)
    with pytest.raises(InputError, match="has 2 pages; there is no page 3"):
        load_pdf_page(path, page=2)


@pytest.mark.parametrize(
    ("content", "message"),
    [(b"", "is empty"), (b"%PDF-1.4\nnot really", "not a PDF PDFium can read")],
)
def test_damaged_files_are_input_errors(content, message, tmp_path):
    path = tmp_path / "plan.pdf"
    path.write_bytes(content)
    with pytest.raises(InputError, match=message):
        load_pdf_page(path)


def test_a_blank_page_is_no_drawing(tmp_path):
    path = tmp_path / "blank.pdf"
    write_pdf(path, line_widths_pt=(0.0,))
    with pytest.raises(InputError, match="blank"):
        load_pdf_page(path, long_side_px=200)


def test_paper_scale_argument():
    import argparse

    from f2n_drake.core.errors import paper_scale

    assert paper_scale("1:100") == 100.0 and paper_scale(" 1:50 ") == 50.0
    assert paper_scale("200") == 200.0
    for bad in ("1:0", "1:hundred", "1:1e9", "nan"):
        with pytest.raises(argparse.ArgumentTypeError):
            paper_scale(bad)


def test_a_hairline_on_a_large_sheet_stays_dark(tmp_path):
    path = tmp_path / "a1.pdf"
    with PdfPages(path) as pages:
        fig = Figure(figsize=(33.1, 23.4))  # A1, drawn 2000 px across: 0.1 pt is 0.2 px
        ax = fig.add_axes([0, 0, 1, 1])
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.axis("off")
        ax.plot([0.5, 0.5], [0.1, 0.9], "k", lw=0.1)
        ax.plot([0.1, 0.2], [0.5, 0.5], "k", lw=3)
        pages.savefig(fig)
    grey = load_pdf_page(path).image
    assert grey[grey.shape[0] // 2 + 100].min() < 64  # the hairline, where no thick line runs
