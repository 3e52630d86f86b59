"""Citations: the repository names the works it follows by key, defined once in docs/references.md.

* No text file names a paper-extraction file, a path outside the repository, a work-item number or a
  numbered paper: code, docs and study outputs speak of features and cite a key with the equation,
  figure or section instead (see docs/references.md for the form).
* Every bracketed key used in code or docs (a CamelCase name followed by a year, first in square
  brackets, then a comma, a semicolon or the closing bracket) is defined in docs/references.md.
* Every key defined there is cited at least once elsewhere (no dead entries).
* Every entry names authors, a title, a venue and a year; keys are sorted and unique.

The files checked are the ones git tracks (plus this file and docs/references.md while they are
new): Python, Markdown, GLSL, TOML, shell, JSON, text and configuration files, Makefiles and scripts
with a shebang line. Failure messages list ``file:line`` of every offence. No GL needed.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCES = ROOT / "docs" / "references.md"
THIS_FILE = Path(__file__).resolve()

TEXT_SUFFIXES = {".py", ".md", ".glsl", ".toml", ".sh", ".json", ".txt", ".rst", ".cfg", ".ini", ".yml", ".yaml"}
TEXT_NAMES = {"Makefile"}

# A citation key: a CamelCase name (one or more capitalised words) followed by a 4-digit year and an
# optional letter, e.g. Kalbe2008, MarschnerLobb1994, Reis2008b.
KEY = r"[A-Z][A-Za-z]+(?:1[5-9]|20)\d\d[a-z]?"
# A citation: '[' not preceded by an identifier character or a closing bracket (that would be an index
# or subscript such as x[Key2008] or f(x)[Key2008]), then a key, then ',', ';' or ']'. The rest of the
# bracket (up to 300 characters, line breaks allowed) may cite more keys after semicolons:
# "[Farin2002, ch. 17; LaiSchumaker2007, Thm. 2.15]".
CITATION_RE = re.compile(r"(?<![\w\])}])\[(" + KEY + r")(?=[,;\]])([^\[\]]{0,300})\]")
MORE_KEYS_RE = re.compile(r";\s*(" + KEY + r")\b")
DEFINITION_RE = re.compile(r"^- \*\*\[(" + KEY + r")\]\*\*", re.MULTILINE)
ENTRY_RE = re.compile(
    r"^- \*\*\[(?P<key>" + KEY + r")\]\*\* "
    r"(?P<authors>[^*]*?[A-Za-z][^*]*?)\. "           # authors, ending with ". "
    r"\*(?P<title>[^*]*?[A-Za-z]{2}[^*]*?)\*[.,]? "  # *Title*. (or *Title*, 5th ed.)
    r"(?P<venue>[^\n]*?[A-Za-z]{2}[^\n]*?)"          # venue, publisher, volume(issue):pages
    r"\b(?P<year>(?:1[5-9]|20)\d\d)\b"               # year
)
YEAR_RE = re.compile(r"\b(?:1[5-9]|20)\d\d\b")

# What no text file may contain. The patterns are written so that they do not match their own source.
FORBIDDEN = {
    "paper-extraction file name": [r"\b00[0-4]_[0-9a-f]{16}\b"],
    # the one allowed: the real-file folder the check job reads when CI provides it (skipped when absent; nothing
    # in the repository depends on it)
    "path outside the repository": [r"\.\./shared(?!/data\b)", r"/wor[k]/", r"\bshared/(?:papers|notes)\b"],
    "work-item number": [r"\b[Ii]ssues? #?\d+\b", r"\b[Tt]asks? #?\d+\b"],
    "numbered paper": [r"\b[Pp]aper ?0\d\d\b"],
}
ADVICE = {
    "paper-extraction file name": "cite the work by its key from docs/references.md instead",
    "path outside the repository": "the repository must stand alone; cite docs/references.md keys instead",
    "work-item number": "describe the feature instead of the work item",
    "numbered paper": "cite the key instead, e.g. the volume paper as Kalbe2008 with its section",
}


def _is_text_file(path: Path) -> bool:
    if path.suffix in TEXT_SUFFIXES or path.name in TEXT_NAMES:
        return True
    if path.suffix == "" and path.is_file():
        with path.open("rb") as f:
            return f.read(2) == b"#!"
    return False


def _checked_files() -> list[Path]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError) as exc:  # e.g. an unpacked sdist without git
        pytest.skip(f"git ls-files failed: {exc}")
    paths = {ROOT / name for name in out.decode("utf-8", "replace").split("\0") if name}
    paths |= {REFERENCES, THIS_FILE}
    files = sorted(p for p in paths if p.is_file() and _is_text_file(p))
    assert len(files) > 20, f"only {len(files)} text files found by git ls-files in {ROOT}"
    return files


_TEXTS: dict[Path, str] = {}


def _texts() -> dict[Path, str]:
    if not _TEXTS:
        for path in _checked_files():
            _TEXTS[path] = path.read_text(encoding="utf-8", errors="replace")
    return _TEXTS


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _line_of(text: str, pos: int) -> int:
    return text.count("\n", 0, pos) + 1


def _citations(text: str):
    """(key, position) of every cited key in text."""
    for m in CITATION_RE.finditer(text):
        yield m.group(1), m.start(1)
        for more in MORE_KEYS_RE.finditer(m.group(2)):
            yield more.group(1), m.start(2) + more.start(1)


def _references_text() -> str:
    assert REFERENCES.is_file(), "docs/references.md is missing"
    return REFERENCES.read_text(encoding="utf-8")


def _defined_keys() -> list[str]:
    return DEFINITION_RE.findall(_references_text())


# ---------------------------------------------------------------------------------------------------
# (a) no extraction file names, outside paths, work-item numbers or numbered papers
# ---------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", list(FORBIDDEN))
def test_no_forbidden_mentions(kind):
    patterns = [re.compile(p) for p in FORBIDDEN[kind]]
    offences = []
    for path, text in _texts().items():
        for lineno, line in enumerate(text.splitlines(), 1):
            if any(p.search(line) for p in patterns):
                offences.append(f"  {_rel(path)}:{lineno}: {line.strip()[:160]}")
    assert not offences, (f"{len(offences)} line(s) with a {kind} ({ADVICE[kind]}):\n"
                          + "\n".join(offences))


# ---------------------------------------------------------------------------------------------------
# (b) every cited key is defined
# ---------------------------------------------------------------------------------------------------
def test_citation_pattern_finds_citations_and_skips_indexing():
    text = ("see [Kalbe2008, sec. 5.1] and [Farin2002, ch. 17; LaiSchumaker2007, Thm. 2.15] or\n"
            "[MarschnerLobb1994]; not x[Kalbe2008], f(x)[Reis2008, 1], a[0][Reis2008], [Reis2008:], "
            '["Reis2008"], [kalbe2008], [K2008], [Kalbe208]')
    assert [k for k, _ in _citations(text)] == ["Kalbe2008", "Farin2002", "LaiSchumaker2007",
                                                "MarschnerLobb1994"]


def test_every_cited_key_is_defined():
    defined = set(_defined_keys())
    undefined = []
    for path, text in _texts().items():
        for key, pos in _citations(text):
            if key not in defined:
                undefined.append(f"  {_rel(path)}:{_line_of(text, pos)}: [{key}]")
    assert not undefined, (f"{len(undefined)} citation(s) of keys not defined in docs/references.md "
                           "(add an entry or fix the key):\n" + "\n".join(undefined))


# ---------------------------------------------------------------------------------------------------
# (c) every defined key is cited outside docs/references.md
# ---------------------------------------------------------------------------------------------------
def test_every_defined_key_is_cited_somewhere_else():
    used = {key for path, text in _texts().items() if path not in (REFERENCES, THIS_FILE)
            for key, _ in _citations(text)}
    dead = [key for key in _defined_keys() if key not in used]
    assert not dead, (f"{len(dead)} key(s) of docs/references.md cited nowhere else (cite them where "
                      "the code or docs use the work, as [Key, eq./fig./sec.], or drop the entry): "
                      + ", ".join(dead))


# ---------------------------------------------------------------------------------------------------
# (d) entries are complete; keys sorted and unique
# ---------------------------------------------------------------------------------------------------
def test_each_entry_has_authors_title_venue_and_year():
    text = _references_text()
    bad = []
    for lineno, line in enumerate(text.splitlines(), 1):
        if not line.startswith("- **["):
            continue
        m = ENTRY_RE.match(line)
        if m is None:
            bad.append(f"  docs/references.md:{lineno}: not '- **[Key]** Authors. *Title*. Venue, ..., "
                       f"year.': {line[:120]}")
            continue
        key_year = re.search(r"\d{4}", m["key"]).group()
        if key_year not in YEAR_RE.findall(line):
            bad.append(f"  docs/references.md:{lineno}: year {key_year} of the key {m['key']} is not "
                       "the entry's year")
    assert not bad, f"{len(bad)} incomplete entr(y/ies):\n" + "\n".join(bad)


def test_reference_keys_are_sorted_unique_and_include_the_specifying_papers():
    keys = _defined_keys()
    assert keys, "docs/references.md defines no keys ('- **[Key]** ...' lines)"
    duplicates = sorted({k for k in keys if keys.count(k) > 1})
    assert not duplicates, f"keys defined twice: {duplicates}"
    assert keys == sorted(keys, key=str.casefold), f"keys not in alphabetical order: {keys}"
    specifying = {"Reis2008", "Kumar1997", "Losasso2003", "Kalbe2008", "Kanai2007"}
    assert specifying <= set(keys), f"missing entries: {sorted(specifying - set(keys))}"
