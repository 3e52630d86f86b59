"""Program assembly: includes, flags, origins, cache, errors (no GPU needed)."""

from pathlib import Path

import pytest

from splinevis.errors import ShaderCompileError, ShaderIncludeError, parse_glsl_log
from splinevis.gl.assembler import assemble, glsl_root


def _root(tmp_path: Path, files: dict) -> Path:
    for name, text in files.items():
        p = tmp_path / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path


def test_includes_resolve_once_in_dependency_order(tmp_path):
    root = _root(tmp_path, {
        "lib/a.glsl": "float a() { return 1.0; }\n",
        "lib/b.glsl": '#include "lib/a.glsl"\nfloat b() { return a(); }\n',
        "main.glsl": '#include "lib/a.glsl"\n#include "lib/b.glsl"\nvoid main() {}\n',
    })
    block = assemble("main.glsl", root=root)
    assert block.files == ("main.glsl", "lib/a.glsl", "lib/b.glsl")
    assert block.text.count("float a()") == 1
    assert block.text.index("float a()") < block.text.index("float b()")


def test_origins_map_every_line_to_its_file(tmp_path):
    root = _root(tmp_path, {"lib/a.glsl": "// one\nfloat a() { return 1.0; }\n", "main.glsl": '#include "lib/a.glsl"\nvoid main() {}\n'})
    block = assemble("main.glsl", {"SV_X": 3}, root=root)
    lines = block.text.splitlines()
    assert len(lines) == len(block.origins)
    k = lines.index("float a() { return 1.0; }")
    assert block.origins[k] == ("lib/a.glsl", 2)
    k = lines.index("void main() {}")
    assert block.origins[k] == ("main.glsl", 2)
    assert "#define SV_X 3" in lines


def test_flags_false_is_absent_true_is_one():
    block = assemble("// nothing\n", {"SV_ON": True, "SV_OFF": False, "SV_N": 2, "SV_F": 0.5})
    assert "#define SV_ON 1" in block.text
    assert "SV_OFF" not in block.text
    assert "#define SV_N 2" in block.text and "#define SV_F 0.5" in block.text


def test_cache_returns_same_object_for_same_key():
    a = assemble('#include "lib/core/raycast.glsl"\n', {"SV_A": 1})
    b = assemble('#include "lib/core/raycast.glsl"\n', {"SV_A": 1})
    c = assemble('#include "lib/core/raycast.glsl"\n', {"SV_A": 2})
    assert a is b and a is not c


def test_missing_include_names_file_and_includer(tmp_path):
    root = _root(tmp_path, {"main.glsl": '#include "lib/nope.glsl"\n'})
    with pytest.raises(ShaderIncludeError, match=r"lib/nope.glsl.*included from main.glsl"):
        assemble("main.glsl", root=root)


def test_include_cycle_is_reported(tmp_path):
    root = _root(tmp_path, {"a.glsl": '#include "b.glsl"\n', "b.glsl": '#include "a.glsl"\n'})
    with pytest.raises(ShaderIncludeError, match="cycle: a.glsl -> b.glsl -> a.glsl"):
        assemble("a.glsl", root=root)


@pytest.mark.parametrize("name", ["sv_lower", "1BAD", "A-B", ""])
def test_bad_flag_names_are_rejected(name):
    with pytest.raises(ValueError, match="not valid"):
        assemble("// x\n", {name: 1})


def test_bad_flag_value_type_is_rejected():
    with pytest.raises(TypeError, match="SV_X must be bool, int or float"):
        assemble("// x\n", {"SV_X": "four"})


def test_shipped_glsl_root_has_the_library():
    root = glsl_root()
    for f in ["lib/core/raycast.glsl", "lib/core/shading.glsl", "lib/core/bernstein.glsl", "lib/core/roots.glsl", "lib/simplex/blossom.glsl",
              "programs/analytic_patch.glsl"]:
        assert (root / f).is_file(), f


def test_mesa_nvidia_intel_log_formats_parse():
    log = "0:12(5): error: `x' undeclared\n0(7) : error C0000: syntax error\nERROR: 0:3: 'y' : undeclared"
    assert parse_glsl_log(log) == [(12, "error: `x' undeclared"), (7, "error C0000: syntax error"), (3, "'y' : undeclared")]


def test_compile_error_message_carries_origin_and_source_line(tmp_path):
    root = _root(tmp_path, {"lib/bad.glsl": "float ok() { return 1.0; }\nfloat bad() { return nope; }\n"})
    block = assemble('#include "lib/bad.glsl"\n', root=root)
    full = "#version 150\n" + block.text
    lineno = full.splitlines().index("float bad() { return nope; }") + 1
    err = ShaderCompileError(f"0:{lineno}(22): error: `nope' undeclared", full, "fragment", block.origin_in(full))
    assert "lib/bad.glsl:2" in str(err)
    assert "return nope;" in str(err)
    assert err.locations[0][2] == "lib/bad.glsl:2"


def test_sv_conditionals_are_resolved_at_assembly_other_conditionals_kept():
    src = "\n".join([
        "#ifdef SV_A", "float a_on;", "#else", "float a_off;", "#endif",
        "#if defined(SV_B) || defined(SV_A)", "float a_or_b;", "#endif",
        "#if defined(SV_B)", "float b1;", "#elif defined(SV_A) && !defined(SV_B)", "float a_not_b;", "#else", "float none;", "#endif",
        "#ifdef GL_ES", "precision highp float;", "#ifdef SV_B", "float nested_b;", "#endif", "#endif",
        "#ifndef SV_B", "float not_b;", "#endif",
    ]) + "\n"
    text = assemble(src, {"SV_A": True}).text
    for kept in ["float a_on;", "float a_or_b;", "float a_not_b;", "#ifdef GL_ES", "precision highp float;", "float not_b;"]:
        assert kept in text, kept
    for dropped in ["a_off", "b1;", "none;", "nested_b", "#ifdef SV_", "#if defined(SV_", "#else"]:
        assert dropped not in text, dropped


def test_unclosed_sv_conditional_is_reported():
    with pytest.raises(ValueError, match="not closed"):
        assemble("#ifdef SV_A\nfloat x;\n", {})


def test_generated_blossom_steps_are_current():
    import importlib.util

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("gen_blossom_glsl", root / "tools" / "gen_blossom_glsl.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    assert (glsl_root() / "lib" / "simplex" / "blossom_steps.glsl").read_text() == gen.generate(), \
        "run: python tools/gen_blossom_glsl.py"
