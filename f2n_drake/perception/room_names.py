"""Room names to room classes, from the lexicon ``room_names.yaml`` (a data file beside this
module: names and abbreviations in English, German, French, Spanish, Italian, Dutch, Swedish
and Finnish).

A printed name is folded (case, accents, digits, spaces, hyphens, dots, apostrophes dropped:
"Bedroom 3" and "BEDROOM3" are "bedroom", "Salle d'eau" is "salledeau") and looked up whole,
then without a plural -s, then part by part ("Kitchen/Diner", "Great Room / Dining": the first
part with a class gives it), then word by word ("Master Bedroom": the first word of two or more
letters that the lexicon knows), and last as the nearest name of six letters or more that
differs from it by a letter or two ("SitingRoom"). A name the lexicon marks ``none`` (hall,
closet, garage) is known to give no class.
"""

from __future__ import annotations

import difflib
import functools
import re
import unicodedata
from importlib.resources import files

import yaml

from f2n_drake.core.classes import CLASS_NAMES
from f2n_drake.core.errors import InputError

NO_CLASS = "none"
"""What the lexicon says of a known name that makes a room no class of its own."""

_PARTS = re.compile(r"\s*(?:/|&|\+|\band\b|\bund\b|\bet\b|\boch\b|\bja\b|\by\b|\be\b|\ben\b)\s*")


def fold(text: str) -> str:
    """``text`` lower-cased, accents and digits dropped, words separated by single spaces;
    "/", "&" and "+" kept (they join the parts of a combined name)."""
    text = unicodedata.normalize("NFKD", text.replace("ß", "ss"))
    text = "".join(c for c in text if not unicodedata.combining(c)).casefold()
    text = re.sub(r"[^a-z/&+]+", " ", text.replace("'", "").replace(".", "").replace("-", ""))
    return " ".join(text.split())


def _key(text: str) -> str:
    return fold(text).replace(" ", "").replace("/", "").replace("&", "").replace("+", "")


@functools.lru_cache(maxsize=1)
def lexicon() -> dict[str, str]:
    """Folded name -> class name (or ``NO_CLASS``), from ``room_names.yaml``.

    Raises:
        InputError: the file names a class that is not one of ``CLASS_NAMES``, or gives one
            name two classes.
    """
    data = yaml.safe_load(files("f2n_drake.perception").joinpath("room_names.yaml").read_text())
    out: dict[str, str] = {}
    for class_name, languages in data.items():
        if class_name != NO_CLASS and class_name not in CLASS_NAMES:
            raise InputError(f"room_names.yaml: {class_name!r} is not a class")
        for names in languages.values():
            for name in names:
                key = _key(str(name))
                if out.setdefault(key, class_name) != class_name:
                    raise InputError(
                        f"room_names.yaml: {name!r} is both {out[key]} and {class_name}"
                    )
    return out


def _lookup(key: str) -> str | None:
    known = lexicon()
    if key in known:
        return known[key]
    if len(key) > 3 and key.endswith("s") and key[:-1] in known:
        return known[key[:-1]]
    return None


def room_class(text: str) -> str | None:
    """The class a printed room name gives (one of ``CLASS_NAMES``), ``NO_CLASS`` for a known
    name of no class, None when the text is no name the lexicon knows."""
    folded = fold(text)
    if not folded.replace("/", "").replace("&", "").replace("+", "").strip():
        return None
    whole = _lookup(_key(text))
    if whole is not None:
        return whole
    found = None
    for part in filter(None, _PARTS.split(folded)):
        cls = _lookup(part.replace(" ", ""))
        if cls is None:
            words = [w for w in part.split() if len(w) >= 2]
            cls = next((c for c in map(_lookup, words) if c is not None), None)
        if cls not in (None, NO_CLASS):
            return cls
        found = found or cls
    if found is None and len(key := _key(text)) >= 6:
        near = difflib.get_close_matches(key, [k for k in lexicon() if len(k) >= 6], 1, 0.85)
        found = lexicon()[near[0]] if near else None
    return found
