"""The generator under hostile input: clear errors, no side effects, nothing evaluated."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from derive.cli import main

from conftest import ROOT, spec_text

ARMS = ROOT / "derive" / "arms"
GOOD = spec_text("arm", "standard", [(-90, 0, 0.5, 0), (0, 1, 0, 0)])

HOSTILE = [
    ("name = \"__import__('os').system('touch PWNED')\"\n" + GOOD.split("\n", 1)[1], "name"),
    (GOOD.replace('name = "arm"', 'name = "../../etc/passwd"'), "name"),
    (GOOD.replace('name = "arm"', 'name = "a/b"'), "name"),
    (GOOD.replace('name = "arm"', 'name = "' + "a" * 200 + '"'), "name"),
    (GOOD.replace("a = 1.0", "a = \"__import__('os').system('touch PWNED')\""), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = 1e300"), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = 1e-300"), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = 1" + "0" * 400), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = {x = 1}"), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = [[[[[1]]]]]"), "joint 2: a"),
    ("x = " + "[" * 5000 + "]" * 5000 + "\n", "not valid TOML"),
    ("\x00\x01\x02\xff binary", "not"),
]


@pytest.mark.parametrize("text, field", HOSTILE)
def test_hostile_spec_is_refused_without_side_effects(text, field, tmp_path):
    spec = tmp_path / "hostile.toml"
    spec.write_bytes(text.encode("utf-8", "surrogateescape") if isinstance(text, str) else text)
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "derive", "generate", str(spec), "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert field in result.stderr and str(spec) in result.stderr
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hostile.toml"]


def test_check_never_writes_into_the_folder(tmp_path):
    out = tmp_path / "gen"
    assert main(["generate", "planar_2r", "--out", str(out)]) == 0
    before = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir()}
    (out / "planar_2r.py").write_text("edited")
    before["planar_2r.py"] = (
        (out / "planar_2r.py").read_bytes(),
        (out / "planar_2r.py").stat().st_mtime_ns,
    )
    assert main(["check", "planar_2r", "--out", str(out)]) == 1
    after = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir()}
    assert after == before


def test_no_partial_file_when_rendering_fails(tmp_path, monkeypatch):
    import derive.cli as cli

    out = tmp_path / "out"
    assert main(["generate", "planar_2r", "--out", str(out)]) == 0
    original = (out / "planar_2r.py").read_bytes()

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(cli.os, "replace", broken)
    assert main(["generate", "planar_2r", "--out", str(out)]) == 2
    assert (out / "planar_2r.py").read_bytes() == original
    assert sorted(p.name for p in out.iterdir()) == [
        "derive_ik_runtime.h",
        "derive_ik_runtime.py",
        "planar_2r.md",
        "planar_2r.py",
        "planar_2r_ik.c",
        "planar_2r_ik.h",
    ]


MUTATIONS = st.lists(
    st.tuples(
        st.sampled_from(["flip", "insert", "delete"]),
        st.floats(0, 1),
        st.binary(min_size=1, max_size=3),
    ),
    min_size=1,
    max_size=4,
)


def mutate(data: bytes, edits: list) -> bytes:
    for kind, where, payload in edits:
        k = int(where * len(data))
        if kind == "flip":
            data = data[:k] + payload[:1] + data[k + 1 :]
        elif kind == "insert":
            data = data[:k] + payload + data[k:]
        else:
            data = data[:k] + data[k + len(payload) :]
    return data


@settings(
    max_examples=int(os.environ.get("DERIVE_FUZZ_EXAMPLES", "40")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(name=st.sampled_from(sorted(p.name for p in ARMS.glob("*.toml"))), edits=MUTATIONS)
def test_mutated_bundled_specs_succeed_or_fail_cleanly(name, edits, tmp_path_factory, capsys):
    folder = tmp_path_factory.mktemp("fuzz")
    spec = folder / "spec.toml"
    spec.write_bytes(mutate((ARMS / name).read_bytes(), edits))
    code = main(["generate", str(spec), "--out", str(folder / "out")])
    err = capsys.readouterr().err
    assert code in (0, 2)
    if code == 2:
        assert err.startswith("error: ") and "Traceback" not in err
        assert not (folder / "out").exists() or not any((folder / "out").iterdir())


def test_two_specs_of_one_name_are_refused_before_anything_is_written(tmp_path, capsys):
    """Both would write NAME.py and NAME.md: the second would silently replace the first."""
    first, second = tmp_path / "first.toml", tmp_path / "second.toml"
    first.write_text(GOOD)
    second.write_text(GOOD.replace("a = 1.0", "a = 2.0"))
    out = tmp_path / "out"
    assert main(["generate", str(first), str(second), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"error: {second}: name: 'arm' is also the name of {first}; arm names must be unique\n"
    )
    assert not out.exists()
