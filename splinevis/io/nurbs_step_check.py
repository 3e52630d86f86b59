"""The structure check of STEP files (:func:`check_step`), run before OpenCASCADE sees a file: broken references
(``#n`` pointing nowhere), garbled or duplicate instances, cut-off files; and, for ``partial=True``, a cleaned
copy without the lost faces. See "Damaged files" in :mod:`.nurbs_step`. Why our own: OpenCASCADE crashes the
Python process on a dangling reference (seen on a real file with one reference broken), so the check must come
first and cannot use it."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np



# Structure check (see "Damaged files" in the module notes)

_STRINGS = re.compile(r"'(?:[^']|'')*'|/\*.*?\*/", re.S)
_INSTANCE = re.compile(r"#(\d+)\s*=\s*([^;]*);", re.S)
_REF = re.compile(r"#(\d+)")
_TYPE = re.compile(r"\s*\(?\s*([A-Za-z_][A-Za-z0-9_]*)")
#: Face entities (what the reader turns into patches).
_FACES = {"ADVANCED_FACE", "FACE_SURFACE"}
#: Instances that hold lists of independent items (faces of a shell, items of a representation): a lost
#: member is dropped from the list in a partial read; any other instance with a lost reference is lost itself.
_CONTAINERS = {"CLOSED_SHELL", "OPEN_SHELL", "CONNECTED_FACE_SET", "SHELL_BASED_SURFACE_MODEL", "BREP_WITH_VOIDS",
               "GEOMETRIC_SET", "GEOMETRIC_CURVE_SET", "PRESENTATION_LAYER_ASSIGNMENT", "DRAUGHTING_MODEL"}
_SHOWN_REFS = 3
#: Shape items a representation lists (what OpenCASCADE transfers as a part's shape).
_SHAPE_ITEMS = {"MANIFOLD_SOLID_BREP", "SHELL_BASED_SURFACE_MODEL", "BREP_WITH_VOIDS", "FACETED_BREP"}


def _blank(match) -> str:
    return re.sub(r"[^\n]", " ", match.group())


class _StepCheck:
    """A STEP file's data section: instances (id -> type, line, references), what is broken (``problems``;
    ``bad``: instances that are garbled or refer to instances the file does not define) and the faces lost."""

    def __init__(self, path, text: str):
        self.path, self.text, self.problems = path, text, []
        masked = _STRINGS.sub(_blank, text)
        self.masked = masked
        newlines = np.flatnonzero(np.frombuffer(masked.encode("latin-1", "replace"), dtype=np.uint8) == 10)
        self.line_of = lambda pos: int(np.searchsorted(newlines, pos)) + 1
        head = re.search(r"\bDATA\s*(\([^;]*\))?\s*;", masked)
        self.data_start = head.end() if head else None
        self.types, self.lines, self.refs, self.spans = {}, {}, {}, {}
        self.bad, self.garbled, self.member_cache = {}, [], {}
        self.cut = head is None
        if head is None:
            self.problems.append(f"the file has no DATA section (it ends at line {masked.count(chr(10)) + 1})")
            return
        end = re.compile(r"\bENDSEC\s*;").search(masked, head.end())
        stop = end.start() if end else len(masked)
        duplicates = []
        last = head.end()
        for m in _INSTANCE.finditer(masked, head.end(), stop):
            n = int(m.group(1))
            if masked[last:m.start()].strip():
                where = last + len(masked[last:m.start()]) - len(masked[last:m.start()].lstrip())
                self.problems.append(f"line {self.line_of(where)} holds text that is no instance: "
                                     f"{text[where:where + 30].strip()!r}")
            last = m.end()
            if n in self.types:
                duplicates.append(n)
            body = m.group(2)
            t = _TYPE.match(body)
            self.types[n] = ("(complex) " if body.lstrip().startswith("(") else "") + (t.group(1).upper() if t else "?")
            self.lines[n] = self.line_of(m.start())
            self.refs[n] = [int(r) for r in _REF.findall(body)]
            self.spans[n] = (m.start(), m.end(), m.start(2))
            if body.count("(") != body.count(")") or t is None:
                self.bad[n] = f"{self._name(n)} is garbled (unbalanced parentheses or no entity name)"
                self.garbled.append(n)
        tail = masked[last:stop]
        cut = end is None or not re.search(r"END-ISO-10303-21\s*;", masked[end.end():] if end else "")
        self.cut = end is None  # the data section itself was cut: what followed is unknown
        if cut:
            inside = re.search(r"#(\d+)\s*=\s*([A-Za-z_0-9]*)", tail)
            where = f" inside #{inside.group(1)} ({inside.group(2) or '?'})" if inside else ""
            self.problems.append(f"the file ends at line {masked.count(chr(10)) + 1}{where} without "
                                 f"{'ENDSEC; and ' if end is None else ''}END-ISO-10303-21;: it was cut off")
        elif tail.strip():
            self.problems.append(f"line {self.line_of(last)} holds text that is no instance: {tail.strip()[:30]!r}")
        if duplicates:
            self.problems.append(f"{len(duplicates)} instance numbers are defined twice: "
                                 + ", ".join(f"#{n}" for n in duplicates[:_SHOWN_REFS]))
        self.problems += [self.bad[n] for n in list(self.bad)[:_SHOWN_REFS]]
        broken = [(n, r) for n, refs in self.refs.items() for r in refs if r not in self.types]
        for n, r in broken:
            self.bad.setdefault(n, f"{self._name(n)} refers to #{r}, which the file does not define")
        if broken:
            first = {}
            for n, r in broken:
                first.setdefault(n, r)
            examples = "; ".join(f"{self._name(n)} refers to #{r}" for n, r in list(first.items())[:_SHOWN_REFS])
            missing = sorted({r for _, r in broken})
            which = f" (#{missing[0]}...#{missing[-1]})" if len(missing) > 1 else ""
            self.problems.append(f"{len(broken)} reference{'s' if len(broken) > 1 else ''} in {len(first)} instance"
                                 f"{'s' if len(first) > 1 else ''} to {len(missing)} instance"
                                 f"{'s' if len(missing) > 1 else ''} the file does not define{which}: {examples}"
                                 + (f"; and {len(first) - _SHOWN_REFS} more" if len(first) > _SHOWN_REFS else ""))

    def _rehomed(self, dropped: set, damage) -> list:
        """New instances that give the intact solids and surface models no representation refers to any more a
        shape representation and a product (OpenCASCADE transfers products' shapes only); in millimetres when
        no 3-D context with units is left (noted in ``damage.problems``)."""
        kept = [n for n in self.types if n not in dropped]
        referenced = {r for n in kept for r in self.refs[n]}
        orphans = [n for n in kept if self.types[n] in _SHAPE_ITEMS and n not in referenced]
        if not orphans:
            return []
        k = max(self.types) + 1
        new = []

        def add(text: str) -> int:
            nonlocal k
            new.append(f"#{k}={text};\n")
            k += 1
            return k - 1

        context = next((n for n in kept if "GEOMETRIC_REPRESENTATION_CONTEXT(3)" in
                        re.sub(r"\s", "", self.masked[self.spans[n][0]:self.spans[n][1]]).upper()
                        and "GLOBAL_UNIT_ASSIGNED_CONTEXT" in self.masked[self.spans[n][0]:self.spans[n][1]].upper()),
                       None)
        if context is None:
            units = [add("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))"),
                     add("(NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.))"),
                     add("(NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT())")]
            context = add("(GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((" +
                          ",".join(f"#{u}" for u in units) + ")) REPRESENTATION_CONTEXT('',''))")
            damage.problems.append("the units were lost with the damage: the intact faces are read in millimetres")
        rep = add("SHAPE_REPRESENTATION('',(" + ",".join(f"#{n}" for n in orphans) + f"),#{context})")
        used = {r for n in kept if self.types[n] == "SHAPE_DEFINITION_REPRESENTATION" for r in self.refs[n]}
        shape = next((n for n in kept if self.types[n] == "PRODUCT_DEFINITION_SHAPE" and n not in used), None)
        if shape is None:
            app = add("APPLICATION_CONTEXT('')")
            product = add(f"PRODUCT('intact faces of a damaged file','intact faces of a damaged file','',"
                          f"(#{add(f'PRODUCT_CONTEXT({chr(39) * 2},#{app},{chr(39)}mechanical{chr(39)})')}))")
            formation = add(f"PRODUCT_DEFINITION_FORMATION('','',#{product})")
            pdc = add(f"PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')")
            shape = add(f"PRODUCT_DEFINITION_SHAPE('','',#{add(f'PRODUCT_DEFINITION({chr(39)}design{chr(39)},{chr(39) * 2},#{formation},#{pdc})')})")
        add(f"SHAPE_DEFINITION_REPRESENTATION(#{shape},#{rep})")
        return new

    def _members(self, n: int) -> tuple:
        """:func:`_list_members` of instance ``n`` (cached)."""
        if n not in self.member_cache:
            start, stop, _ = self.spans[n]
            self.member_cache[n] = _list_members(self.masked[start:stop], "(complex)" in self.types[n])
        return self.member_cache[n]

    def _name(self, n: int) -> str:
        return f"#{n} ({self.types[n]}, line {self.lines[n]})"

    def damage(self):
        """``(Damage, repaired text or None)``."""
        from .nurbs_common import Damage

        up = {}
        for n, refs in self.refs.items():
            for r in refs:
                up.setdefault(r, []).append(n)
        lost, todo = set(self.bad), list(self.bad)
        while todo:  # everything that reaches a broken instance
            for parent in up.get(todo.pop(), ()):
                if parent not in lost:
                    lost.add(parent)
                    todo.append(parent)
        faces = [n for n, t in self.types.items() if t in _FACES]
        kinds = {}
        for n in faces:
            if n in lost:
                kinds[self.types[n]] = kinds.get(self.types[n], 0) + 1
        shells = [n for n, t in self.types.items() if t in ("CLOSED_SHELL", "OPEN_SHELL", "CONNECTED_FACE_SET")]
        never = {r for s in shells for r in self.refs[s] if r not in self.types}
        if never:
            kinds["face listed by a shell but not in the file"] = len(never)
        damage = Damage("STEP", self.problems, len(faces) + len(never), kinds, cut=self.cut)
        return damage, ((lambda: self._repaired(damage)) if damage else None)

    def _repaired(self, damage) -> str:
        """The data section without the lost instances: a container (shell, representation, ...) keeps its list
        without them; any other instance that refers to a lost one is dropped too (a face is drawn whole or
        not at all, never without a bound). Solids and surface models left without a representation (its
        context or product cut off) get a new one (:meth:`_rehomed`)."""
        dropped = set(self.garbled) | {r for refs in self.refs.values() for r in refs if r not in self.types}
        up = {}
        for n, refs in self.refs.items():
            for r in refs:
                up.setdefault(r, []).append(n)
        edits, todo = {}, list(dropped)
        while todo:
            r = todo.pop()
            for parent in up.get(r, ()):
                if parent in dropped:
                    continue
                t = self.types[parent].replace("(complex) ", "")
                if (t in _CONTAINERS or t.endswith("REPRESENTATION")) and r in self._members(parent)[0]:
                    edits.setdefault(parent, set()).add(r)
                    if set(self.refs[parent]) <= edits[parent]:  # nothing left in it: lost too
                        dropped.add(parent)
                        todo.append(parent)
                else:
                    dropped.add(parent)
                    todo.append(parent)
        out = [self.text[:self.data_start], "\n"]
        for n in self.types:
            if n in dropped:
                continue
            start, stop, _ = self.spans[n]
            text = self.text[start:stop]
            if n in edits:
                text = _without(text, self.masked[start:stop], edits[n], self._members(n)[1])
            out += [text, "\n"]
        out += self._rehomed(dropped, damage)
        out.append("ENDSEC;\nEND-ISO-10303-21;\n")
        text = "".join(out)
        if _StepCheck(self.path, text).problems:  # never hand OpenCASCADE a dangling reference (it may crash)
            raise RuntimeError(f"{self.path}: the repaired copy of this damaged file is still damaged; please "
                               "report this file.")
        return text


def _list_members(masked: str, complex_: bool) -> tuple:
    """``(members, lists)`` of an instance's masked text: the references that appear only as members of its
    list attributes (removable), and the ``(open, close)`` positions of those lists."""
    list_depth = 3 if complex_ else 2  # attributes sit at depth 1 (a complex instance's at 2); their lists one deeper
    depth, open_at, lists, members, others = 0, 0, [], set(), set()
    for k in range(masked.index("=") + 1, len(masked)):
        c = masked[k]
        if c == "(":
            depth += 1
            open_at = k if depth == list_depth else open_at
        elif c == ")":
            if depth == list_depth:
                lists.append((open_at, k))
            depth -= 1
        elif c == "#":
            r = int(_REF.match(masked, k).group(1))
            (members if depth == list_depth else others).add(r)
    return members - others, lists


def _without(text: str, masked: str, refs: set, lists) -> str:
    """An instance's text (``#n=...;``) with the references ``refs`` taken out of its lists (with their commas)."""
    for a, b in reversed(lists):
        members, depth, start = [], 0, a + 1
        for k in range(a + 1, b + 1):
            c = masked[k]
            if c == "(":
                depth += 1
            elif c == ")" and depth:
                depth -= 1
            elif (c == "," and depth == 0) or k == b:
                members.append((start, k))
                start = k + 1
        kept = [text[x:y] for x, y in members if not ((m := _REF.fullmatch(masked[x:y].strip())) and int(m.group(1)) in refs)]
        if len(kept) != len(members):
            text = text[:a + 1] + ",".join(kept) + text[b:]
    return text


def check_step(path) -> tuple:
    """The structure check of a STEP file: ``(Damage, repaired)``; ``repaired()`` gives the file's text without
    the lost instances for a partial read (None when the file is intact; module notes, "Damaged files").

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "a.stp"
    ...     _ = f.write_text("ISO-10303-21;\\nHEADER;\\nENDSEC;\\nDATA;\\n#1=CLOSED_SHELL('',(#2,#3,#8));\\n"
    ...                      "#2=ADVANCED_FACE('',(),#9,.T.);\\n#3=ADVANCED_FACE('',(),#4,.T.);\\n"
    ...                      "#4=PLANE('',#5);\\n#5=AXIS2_PLACEMENT_3D('',#6,$,$);\\n#6=CARTESIAN_POINT('',(0.,0.,0.));\\n"
    ...                      "#7=CARTESIAN_POI")
    ...     damage, repaired = check_step(f)
    >>> print(damage.summary())
    2 of the 3 faces named before the cut cannot be read (1 x ADVANCED_FACE, 1 x face listed by a shell but not in the file), and the faces after the cut are lost
    >>> damage.problems
    ['the file ends at line 11 inside #7 (CARTESIAN_POI) without ENDSEC; and END-ISO-10303-21;: it was cut off', '2 references in 2 instances to 2 instances the file does not define (#8...#9): #1 (CLOSED_SHELL, line 5) refers to #8; #2 (ADVANCED_FACE, line 6) refers to #9']
    >>> text = repaired()
    >>> print(text[text.index("DATA;"):])
    DATA;
    #1=CLOSED_SHELL('',(#3));
    #3=ADVANCED_FACE('',(),#4,.T.);
    #4=PLANE('',#5);
    #5=AXIS2_PLACEMENT_3D('',#6,$,$);
    #6=CARTESIAN_POINT('',(0.,0.,0.));
    ENDSEC;
    END-ISO-10303-21;
    <BLANKLINE>
    """
    text = Path(path).read_bytes().decode("latin-1")
    return _StepCheck(path, text).damage()
