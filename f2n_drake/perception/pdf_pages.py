"""A page of a PDF as a drawing: architects' sheets, listings and evacuation plans often come as
PDFs.

The page is rendered by PDFium (``pypdfium2``) in grey on white paper, its long side
``PAGE_LONG_SIDE_PX`` pixels whatever the paper size (an A4 listing at about 240 dpi, an A1 sheet
at about 60), the size at which the parse reads walls of generated and real drawings. Its
lines are drawn without anti-aliasing (its words with it): a CAD sheet's 0.1 pt hairlines on an
A1 page are a quarter of a pixel wide there, which anti-aliasing would leave mid-grey. What the page
holds besides the plan (a title block, a legend) is left to the parse's sheet step, as for any
drawing. A page's size is known in points, so a drawing at a paper scale (1:100) has a known
metric scale: ``PdfPage.paper_metres_per_px`` times the scale's denominator.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from f2n_drake.core.errors import InputError
from f2n_drake.perception.image import check_drawing

PAGE_LONG_SIDE_PX = 2000
"""Long side of a rendered page [px]."""
METRES_PER_POINT = 0.0254 / 72
"""A PDF's unit of length, the point (1/72 inch) [m]."""


@dataclass(frozen=True)
class PdfPage:
    """A rendered page of a PDF (:func:`load_pdf_page`).

    Attributes:
        image: (H, W) uint8 grey, dark lines on white paper.
        paper_metres_per_px: metres of paper per pixel of ``image``: times a drawing's paper
            scale (100 at 1:100), the metres of building per pixel.
        pages: how many pages the PDF has.
    """

    image: np.ndarray
    paper_metres_per_px: float
    pages: int


def load_pdf_page(
    path: str | os.PathLike, *, page: int = 0, long_side_px: int = PAGE_LONG_SIDE_PX
) -> PdfPage:
    """Render page ``page`` (0-based) of the PDF at ``path`` in grey, its long side
    ``long_side_px``.

    Raises:
        InputError: missing, empty, damaged or password-protected file, no such page, or a
            blank page.
    """
    path = Path(path)
    with _opened(path) as pdf:
        pages = len(pdf)
        if not 0 <= page < pages:
            raise InputError(
                f"{path} has {pages} page{'s' * (pages != 1)}; there is no page {page + 1}"
            )
        sheet = pdf[page]
        width_pt, height_pt = sheet.get_size()
        if min(width_pt, height_pt) <= 0:
            raise InputError(f"{path}: page {page + 1} has no area")
        px_per_pt = long_side_px / max(width_pt, height_pt)
        # paths drawn without anti-aliasing: a CAD hairline on a large sheet stays a dark pixel
        bitmap = sheet.render(scale=px_per_pt, grayscale=True, no_smoothpath=True)
        grey = np.array(bitmap.to_numpy(), dtype=np.uint8, copy=True)
    if grey.ndim == 3:
        grey = grey[..., 0]
    check_drawing(grey, name=f"{path} page {page + 1}")
    return PdfPage(grey, METRES_PER_POINT / px_per_pt, pages)


@contextlib.contextmanager
def _opened(path: Path) -> Iterator:
    """The PDF at ``path``, closed after the block; InputError where PDFium cannot read it."""
    import pypdfium2

    if not path.is_file():
        raise InputError(f"no such file: {path}")
    if path.stat().st_size == 0:
        raise InputError(f"{path} is empty")
    try:
        pdf = pypdfium2.PdfDocument(path)
    except pypdfium2.PdfiumError as exc:
        raise InputError(f"{path} is not a PDF PDFium can read ({exc})") from exc
    try:
        yield pdf
    finally:
        pdf.close()
