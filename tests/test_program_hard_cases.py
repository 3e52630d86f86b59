"""Every registered ray-cast program against its float64 twin on the hard cases it declares
(splinevis.gl.contract.HardCase): per pixel, no leaks (a GPU miss whose reference and all 8 neighbours hit:
a crack), few pixels where exactly one side hits (silhouettes grazed within rounding), and depths within the
program's derived bound (splinevis.analysis.agreement). The cases live with their families; this file knows
no family."""

import pytest

from splinevis import programs
from splinevis.analysis.agreement import agreement_failures, hard_case_agreement

pytestmark = pytest.mark.gl

# every program with a float64 twin (ray-cast proxies and per-fragment surface evaluation alike)
TWINNED = [p for p in programs.all_programs() if p.reference is not None and p.depth_bound is not None]
CASES = [(p.name, case) for p in TWINNED if p.hard_cases is not None for case in p.hard_cases()]


def test_every_program_with_a_twin_declares_hard_cases():
    names = {p.name for p in TWINNED}
    assert {p.name for p in programs.all_programs() if p.kind == "raycast"} <= names
    assert names == {name for name, _ in CASES}


@pytest.mark.parametrize("case", [c for _, c in CASES], ids=[f"{n}-{c.name}" for n, c in CASES])
def test_gpu_matches_float64_twin_on_hard_case(case):
    r = hard_case_agreement(case)
    assert agreement_failures(r, case) == []
