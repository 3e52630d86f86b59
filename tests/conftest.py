"""Test ordering only: the slowest tests (measured with ``--durations``, 10-45 s each on this machine) are moved to
the front of the collection, so that with ``pytest -n 2 --dist loadfile`` (``tools/dev.sh test``: each file whole
to one worker, files in the order of their first test) the two workers start on the slowest files (the GPU hard
cases, about 5 minutes of one core, first) and the run does not end waiting on one long file started last. Every
test stays independent of the order."""

#: Node-id prefixes of the slowest tests (``pytest --durations=30``, 2026-12-07).
SLOW_FIRST = (
    "tests/test_program_hard_cases.py::test_gpu_matches_float64_twin_on_hard_case[terrain-fractal-2048-steep]",
    "tests/test_demo.py",
    "tests/test_lod_dynamic.py",
    "tests/test_study_walkthrough.py",
    "tests/test_selftest.py",
    "tests/test_study_geometry_image.py",
    "tests/test_lod_pipeline.py",
    "tests/test_geometry_image_reproducible.py",
)


def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        for k, prefix in enumerate(SLOW_FIRST):
            if item.nodeid.startswith(prefix):
                return k
        return len(SLOW_FIRST)

    items.sort(key=rank)  # stable: the rest keeps its order
