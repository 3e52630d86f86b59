"""The structure check of IGES files (:func:`check_iges`), run before either back end reads a file: section
letters and sequence numbers, the terminate record's counts, directory entries and their parameter records
and back pointers, numbers in geometry records, and the pointers faces are built from. See "Damaged files" in
:mod:`.nurbs_iges`. Why our own: OpenCASCADE and pyiges skip what they cannot parse without saying which face
it took with it."""

from __future__ import annotations

import re
from pathlib import Path

from .nurbs_common import Damage


__all__ = ["check_iges", "IGES_TYPES"]

#: IGES entity type names, for the messages and ``skipped``.
IGES_TYPES = {
    100: "circular arc", 102: "composite curve", 104: "conic arc", 106: "copious data", 108: "plane",
    110: "line", 112: "parametric spline curve", 114: "parametric spline surface", 116: "point",
    118: "ruled surface", 120: "surface of revolution", 122: "tabulated cylinder", 123: "direction",
    124: "transformation matrix", 126: "rational B-spline curve", 128: "rational B-spline surface",
    130: "offset curve", 140: "offset surface", 141: "boundary", 142: "curve on surface",
    143: "bounded surface", 144: "trimmed surface", 186: "manifold solid B-rep", 190: "plane surface",
    192: "cylindrical surface", 194: "conical surface", 196: "spherical surface", 198: "toroidal surface",
    212: "general note", 308: "subfigure definition", 314: "color", 402: "associativity", 406: "property",
    408: "subfigure instance", 502: "vertex list", 504: "edge list", 508: "loop", 510: "face", 514: "shell",
}

# Independent entities that carry surfaces (OCP transfers them to faces).
_SURFACE_TYPES = {108, 114, 118, 120, 122, 128, 140, 143, 144, 186, 190, 192, 194, 196, 198, 510, 514}
# Structure, not geometry: neither read nor reported as skipped.
_STRUCTURE_TYPES = {124, 314, 402, 406}


def _child(subordinate: int) -> bool:
    """Physically dependent (01, or 03: both): read through its parent. Logically dependent (02) entities,
    e.g. the 144s of a 402 group, stand alone."""
    return subordinate in (1, 3)


def _type_key(t: int) -> str:
    return f"{t} ({IGES_TYPES.get(t, 'entity')})"


# --------------------------------------------------------------------------------------------------
# Structure check (see "Damaged files" in the module notes)

# Parameter positions (1-based, after the type number) that hold directory pointers, by entity type: a fixed
# list, or a function of the parsed parameters for the variable-length records.
def _ptrs_102(p):
    return list(range(2, 2 + _int(p, 1)))


def _ptrs_141(p):
    out, k = [3], 5
    for _ in range(_int(p, 4)):
        out += [k] + list(range(k + 3, k + 3 + _int(p, k + 2)))
        k += 3 + _int(p, k + 2)
    return out


def _ptrs_508(p):
    out, k = [], 2
    for _ in range(_int(p, 1)):
        out.append(k + 1)
        n = _int(p, k + 4)
        out += [k + 6 + 2 * j for j in range(n)]
        k += 5 + 2 * n
    return out


_POINTERS = {
    102: _ptrs_102, 108: [5], 118: [1, 2], 120: [1, 2], 122: [1], 141: _ptrs_141, 142: [2, 3, 4],
    143: lambda p: [2] + list(range(4, 4 + _int(p, 3))),
    144: lambda p: [1, 4] + list(range(5, 5 + _int(p, 3))),
    186: lambda p: [1] + [4 + 2 * j for j in range(_int(p, 3))],
    190: [1, 2, 3], 192: [1, 2, 4], 194: [1, 2, 5], 196: [1, 3, 4], 198: [1, 2, 5],
    504: lambda p: [k for j in range(_int(p, 1)) for k in (2 + 5 * j, 3 + 5 * j, 5 + 5 * j)],
    508: _ptrs_508,
    510: lambda p: [1] + list(range(4, 4 + _int(p, 2))),
    514: lambda p: [2 + 2 * j for j in range(_int(p, 1))],
}


#: Entities whose parameters are all numbers (and pointers): a field that is not one is garbled.
_NUMERIC = {100, 102, 104, 110, 116, 118, 120, 122, 123, 124, 126, 128, 141, 142, 143, 144, 186, 190, 192, 194, 196,
            198, 502, 504, 508, 510, 514}
_NUMBER = re.compile(r"|[-+]?(\d+\.?\d*|\.\d+)([EeDd][-+]?\d+)?")


def _record_lines(check, de: int) -> str:
    ptr, count = check.extent[de]
    return f"{ptr}-{ptr + count - 1}" if count > 1 else f"{ptr}"


def _int(p, k: int) -> int:
    """Parameter ``k`` (1-based) as an integer."""
    try:
        return int(p[k - 1])
    except (IndexError, ValueError):
        raise _BadRecord(f"parameter {k} is {p[k - 1] if k <= len(p) else 'missing'!r}, not an integer") from None


class _BadRecord(ValueError):
    pass


def _delimiters(g: str):
    """The parameter and record delimiters from the global section (default ``,`` and ``;``)."""
    pd = g[2] if g.startswith("1H") else ","
    rest = g[4:] if g.startswith("1H") else g[1:]
    rd = rest[2] if rest.startswith("1H") else ";"
    return pd, rd


class _IgesCheck:
    """The IGES file's structure: sections, directory entries, parameter records and their pointers. ``problems``
    lists what is broken; ``bad`` the directory entries (sequence numbers) whose own record is broken;
    ``faces`` maps each face-bearing independent entity to its faces (510s of a B-rep, else itself);
    ``lost(de)`` tells whether a face reaches a broken record."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.problems, self.bad, self.types, self.status = [], {}, {}, {}
        self.params, self.refs, self.beyond, self.extent, self.incomplete = {}, {}, [], {}, []
        self.out_of_order = False
        lines = text.splitlines()
        self.nlines = len(lines)
        sections = {c: [] for c in "SGDPT"}
        expected = {c: 1 for c in "SGDP"}
        foreign = []
        for number, line in enumerate(lines, 1):
            letter = line[72:73]
            if letter not in sections or not line[73:80].strip().isdigit():
                foreign.append(number)
                continue
            seq = int(line[73:80])
            if letter in expected:
                if seq != expected[letter]:
                    self.out_of_order = True
                    self.problems.append(f"line {number} is {_SECTION[letter]} line {seq}, expected "
                                         f"{_SECTION[letter]} line {expected[letter]}")
                expected[letter] = seq + 1
            sections[letter].append((number, seq, line))
        self.out_of_order = self.out_of_order or bool(foreign)
        if foreign:
            self.problems.insert(0, f"{len(foreign)} lines are not IGES records (no section letter S/G/D/P/T "
                                    f"and sequence number in columns 73-80): {_ranges(foreign)}")
        self.sections = sections
        self.p_lines = {seq: (number, line) for number, seq, line in sections["P"]}
        self.last_p = max(self.p_lines, default=0)
        if not sections["T"]:
            where = lines[-1][72:73] if lines else ""
            self.problems.append(f"the file ends at line {self.nlines}"
                                 + (f" ({_SECTION[where]} line {lines[-1][73:80].strip().lstrip('0')})" if where in _SECTION else "")
                                 + " without the terminate (T) record: it was cut off")
        else:
            t = sections["T"][0][2]
            for k, c in enumerate("SGDP"):
                field = t[8 * k:8 * k + 8]
                if field[:1] == c and field[1:].strip().isdigit():
                    promised, found = int(field[1:]), len(sections[c])
                    if promised != found:
                        self.problems.append(f"the terminate record promises {promised} {_SECTION[c]} lines, "
                                             f"the file has {found}")
        pd, rd = _delimiters("".join(line[:72] for _, _, line in sections["G"]))
        d = {seq: line for _, seq, line in sections["D"]}
        n_d = max(d, default=0)
        self.n_d = n_d
        for de in range(1, n_d + 1, 2):
            self._entry(de, d.get(de), d.get(de + 1), pd, rd)
        if self.incomplete:
            self.problems.append(f"directory entries {_ranges(self.incomplete, 2)} are incomplete (directory lines "
                                 "missing or garbled)")
        if self.beyond:
            de, first = self.beyond[0]
            more = f", and so do {len(self.beyond) - 1} more entries ({_ranges((d for d, _ in self.beyond[1:]), 2)})" \
                if len(self.beyond) > 1 else ""
            self.problems.append(f"{first}{more}")
        self.faces = self._faces()

    def _entry(self, de, one, two, pd, rd):
        if one is None or two is None:
            self.bad[de] = f"directory entry {de} is incomplete (a directory line is missing or garbled)"
            self.incomplete.append(de)
            return
        try:
            t, ptr, count = int(one[0:8]), int(one[8:16]), int(two[24:32])
            t2 = int(two[0:8])
            status = one[64:72].strip()
            transform = int(one[48:56] or 0)
        except ValueError:
            self.bad[de] = f"directory entry {de} is garbled ({one[:72].strip()!r})"
            self.problems.append(self.bad[de])
            return
        self.types[de] = t
        self.extent[de] = (ptr, count)
        self.status[de] = (int(status) // 10000) % 100 if status.isdigit() else 0  # the subordinate switch
        name = f"directory entry {de} (type {t})"
        if t != t2:
            self.bad[de] = f"{name}: its second line says type {t2}"
        elif count < 1 or ptr < 1:
            self.bad[de] = f"{name} points to parameter line {ptr}, {count} lines: no parameter record"
        elif ptr + count - 1 > self.last_p:
            self.bad[de] = (f"{name} points to parameter lines {ptr}-{ptr + count - 1}, the parameter section ends at "
                            f"line {self.last_p} (file line {self.nlines})")
            self.beyond.append((de, self.bad[de]))  # one problem for all of them (a cut file)
            return
        else:
            missing = [ptr + k for k in range(count) if ptr + k not in self.p_lines]
            owners = [k for k in range(ptr, ptr + count) if k in self.p_lines and
                      self.p_lines[k][1][64:72].strip().lstrip("0") != str(de)]
            if missing:
                self.bad[de] = f"{name}: its parameter lines {_ranges(missing)} are missing or garbled"
            elif owners:
                k = owners[0]
                self.bad[de] = (f"{name}: parameter line {k} (file line {self.p_lines[k][0]}) belongs to directory "
                                f"entry {self.p_lines[k][1][64:72].strip().lstrip('0') or '(blank)'}")
            else:
                record = "".join(self.p_lines[k][1][:64] for k in range(ptr, ptr + count)).rstrip()
                head = record.split(pd, 1)[0].strip()
                if not record.endswith(rd) and rd not in record:
                    self.bad[de] = f"{name}: its parameter record (lines {ptr}-{ptr + count - 1}) has no end ({rd!r})"
                elif head != str(t):
                    self.bad[de] = f"{name}: its parameter record (line {ptr}) starts with {head[:20]!r}, not {t}"
                else:
                    self._pointers(de, t, name, record[:record.index(rd)].split(pd)[1:], transform)
        if de in self.bad:
            self.problems.append(self.bad[de])

    def _pointers(self, de, t, name, p, transform):
        if t in _NUMERIC:
            for k, field in enumerate(p, 1):
                if not _NUMBER.fullmatch(field.strip()):
                    self.bad[de] = f"{name}: parameter {k} of its record (lines {_record_lines(self, de)}) is " \
                                   f"{field.strip()[:20]!r}, not a number"
                    return
        refs = [transform] if transform > 0 else []
        rule = _POINTERS.get(t)
        if rule is not None:
            try:
                positions = rule(p) if callable(rule) else rule
                refs += [int(float(p[k - 1])) for k in positions if k - 1 < len(p) and p[k - 1].strip()]
            except (_BadRecord, ValueError) as err:
                self.bad[de] = f"{name}: its parameter record is garbled ({err})"
                return
        self.params[de] = p
        refs = [abs(r) for r in refs if r]
        wrong = [r for r in refs if r > self.n_d or r % 2 == 0]
        if wrong:
            self.bad[de] = (f"{name} refers to directory entry {wrong[0]}, which the directory (entries 1-"
                            f"{self.n_d}) does not hold")
        self.refs[de] = refs

    def repaired(self) -> str | None:
        """The file with its sections renumbered as the directory expects (None when no line is out of place),
        for a partial read: lost lines become placeholders (a damaged directory entry a null entity, type 0),
        so that every intact entry keeps its sequence number and its parameter lines."""
        if not self.out_of_order:
            return None
        out = [line[:80] for c in "SG" for _, _, line in self.sections[c]]
        d = {seq: line for _, seq, line in self.sections["D"]}
        nulls = []
        for de in range(1, self.n_d + 1, 2):
            if de in self.types and de + 1 in d:
                out += [d[de][:80], d[de + 1][:80]]
                continue
            nulls.append(de)
            ptr = self.last_p + len(nulls)
            out.append(f"{0:8d}{ptr:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}{'00010000':>8}D{de:7d}")
            out.append(f"{0:8d}{0:8d}{0:8d}{1:8d}{0:8d}{'':8}{'':8}{'':8}{0:8d}D{de + 1:7d}")
        owner = {ptr + k: (de, k == count - 1) for de, (ptr, count) in self.extent.items() for k in range(count)}
        for seq in range(1, self.last_p + 1):
            if seq in self.p_lines:
                out.append(self.p_lines[seq][1][:80])
                continue
            de, last = owner.get(seq, (0, True))  # in the owner's record: the owner is lost anyway
            out.append(f"{'0;' if last else '0,':64}{de:8d}P{seq:7d}")
        for k, de in enumerate(nulls, self.last_p + 1):
            out.append(f"{'0;':64}{de:8d}P{k:7d}")
        counts = [len(self.sections["S"]), len(self.sections["G"]), 2 * ((self.n_d + 1) // 2), self.last_p + len(nulls)]
        out.append("".join(f"{c}{n:7d}" for c, n in zip("SGDP", counts)).ljust(72) + "T      1")
        return "\n".join(out) + "\n"

    def _faces(self) -> dict:
        """Face-bearing independent entity -> the entities that are its faces."""
        faces = {}
        for de, t in self.types.items():
            if t not in _SURFACE_TYPES or _child(self.status.get(de, 0)):
                continue
            if t in (186, 514):
                shells = [de] if t == 514 else [r for r in self.refs.get(de, []) if self.types.get(r) == 514]
                faces[de] = [f for s in shells for f in self.refs.get(s, []) if self.types.get(f) == 510] or [de]
            else:
                faces[de] = [de]
        return faces

    def lost(self, face: int, root: int) -> bool:
        """Whether the face (or its B-rep ``root``'s shell records) reaches a broken record."""
        seen, todo = set(), [face] + ([root] if root != face else [])
        while todo:
            de = todo.pop()
            if de in seen:
                continue
            seen.add(de)
            if de in self.bad or de not in self.types:
                return True
            if de == root and face != root:  # the B-rep: its own record and shells, not the other faces
                todo += [r for r in self.refs.get(de, []) if self.types.get(r) != 510]
                continue
            if self.types.get(de) == 514 and face != de:
                continue
            todo += self.refs.get(de, [])
        return False

    def damage(self) -> tuple:
        """``(Damage, roots)``: the damage, and the face-bearing entities that lose a face."""
        lost, roots, expected = {}, set(), 0
        for root, faces in self.faces.items():
            expected += len(faces)
            for f in faces:
                if self.lost(f, root):
                    k = _type_key(self.types.get(f, self.types[root]))
                    lost[k] = lost.get(k, 0) + 1
                    roots.add(root)
        unknown = [de for de in self.bad if de not in self.types]  # garbled directory entries
        cut = not self.sections["T"] and not self.sections["P"]  # cut in the directory: the rest is unknown
        damage = Damage("IGES", self.problems, expected, lost, len(unknown), "directory entries", cut=cut)
        damage.records = set(self.bad)  # the directory entries whose records are broken
        return damage, roots, self.repaired()


_SECTION = {"S": "start", "G": "global", "D": "directory", "P": "parameter", "T": "terminate"}


def _ranges(numbers, step: int = 1) -> str:
    """``[3, 4, 5, 9]`` -> ``"3-5, 9"`` (at most 5 ranges shown; ``step`` 2 for directory entries).

    >>> _ranges([3, 4, 5, 9]), _ranges([1, 3, 5, 9], step=2)
    ('3-5, 9', '1-5, 9')
    """
    numbers = sorted(numbers)
    runs = []
    for n in numbers:
        if runs and n == runs[-1][1] + step:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    text = ", ".join(f"{a}-{b}" if b > a else f"{a}" for a, b in runs[:5])
    return text + (f", ... ({len(runs) - 5} more ranges)" if len(runs) > 5 else "")


def check_iges(path) -> tuple:
    """The structure check of an IGES file: ``(Damage, roots, repaired)`` with the independent face-bearing
    entities (directory sequence numbers) that lose faces, and the file's text renumbered for a partial read
    (None when its lines are in order; module notes, "Damaged files").

    >>> import tempfile
    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> from OCP.IGESControl import IGESControl_Writer
    >>> from splinevis.io.nurbs_step import _quiet_occ
    >>> _quiet_occ()
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), True).Shape()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "box.igs"
    ...     w = IGESControl_Writer("MM", 0); _ = w.AddShape(box); w.ComputeModel(); _ = w.Write(str(f))
    ...     lines = f.read_text().splitlines(keepends=True)
    ...     _ = f.write_text("".join(lines[:len(lines) - 40]))
    ...     damage, roots, repaired = check_iges(f)
    >>> damage.expected, damage.problems[0]
    (6, 'the file ends at line ... (parameter line ...) without the terminate (T) record: it was cut off')
    """
    path = Path(path)
    text = path.read_bytes().decode("latin-1")
    if text[72:73] == "C":  # compressed ASCII form: left to the reader
        return Damage("IGES", [], None, {}), set(), None
    return _IgesCheck(path, text).damage()
