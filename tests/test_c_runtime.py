"""The C runtime as real C (derive/c/): it compiles on its own, its routines are copied into an
arm's C by the dependency closure of the arm's code, its constants are the Python runtime's,
and its routines answer as the Python ones when called from C."""

from __future__ import annotations

import re
import subprocess
from importlib import resources

import numpy as np
import pytest

from derive import emit_c
from derive.assemble import assemble_c, c_runtime_pieces, split_c
from derive.cbuild import WARNINGS, c_compiler
from derive.runtime import closed, constants, general, refine

from conftest import GENERATED, needs_cc

C = resources.files("derive.c")


def c_text(name: str) -> str:
    return C.joinpath(name).read_text(encoding="utf-8")


@needs_cc
@pytest.mark.parametrize("name", ["runtime.c", "general.c"])
def test_the_c_runtime_compiles_on_its_own(name, tmp_path):
    # every routine is static and unused on its own: -Wno-unused-function only
    flags = [*WARNINGS, "-Wno-unused-function", "-c", "-o", str(tmp_path / "x.o")]
    done = subprocess.run(
        [c_compiler(), *flags, str(C.joinpath(name))], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr


def test_c_runtime_lines_fit_in_100_characters():
    for name in ("runtime.c", "general.c", "standin.h"):
        long = [n for n, line in enumerate(c_text(name).split("\n"), 1) if len(line) > 100]
        assert not long, (name, long[:5])


def defines(text: str) -> dict[str, str]:
    return dict(re.findall(r"^#define (\w+) \(?([^)\s]+)\)?", text, re.M))


def table(text: str, name: str) -> np.ndarray:
    """The numbers of a C table `name[...] = {...};`."""
    body = re.search(rf"\b{name}\[[^=]*= (\{{.*?\}});", text, re.S)
    assert body is not None, name
    return np.array([float(x) for x in re.findall(r"-?[\d.]+(?:e[-+]?\d+)?", body.group(1))])


def test_the_c_runtime_holds_the_python_runtimes_constants():
    runtime, gen = c_text("runtime.c"), c_text("general.c")
    found = defines(runtime)
    tolerances = ("FREE_TOL", "FREE_TOL_EXACT", "CLAMP_TOL", "CLAMP_ABS", "FOLD_TOL", "LEAD_TOL")
    for name in (*tolerances, "ROOT_IMAG_TOL", "MERGE_TOL", "SPLIT_TOL"):
        assert float(found[f"DK_{name}"]) == getattr(constants, f"_{name}"), name
    for name in ("CLUSTER_TOL", "RESIDUAL_TOL", "SEAM", "SEAM_SNAP", "BRANCH_FOLD", "FOLD_NEAR"):
        assert float(found[f"DK_{name}"]) == getattr(constants, f"_{name}"), name
    for name in (
        "SPREAD_WIDTH",
        "SPREAD_COUNT",
        "FOLD_SPREAD",
        "SEED_BAND",
        "WRIST_WIDTH",
        "WRIST_SPREAD",
        "AIM_POLISH",
        "WRIST_NEAR",
    ):
        assert float(found[f"DK_{name}"]) == getattr(constants, f"_{name}"), name
    for name in ("DEDUP_TOL", "POSE_TOL"):
        assert float(found[f"DK_{name}"]) == getattr(constants, name), name
    assert float(found["DK_RIGID_SNAP"]) == constants._RIGID_SNAP
    for name in (
        "STEPS",
        "STRIDE",
        "DONE",
        "PATIENCE",
        "LAST",
        "TRUST",
        "TOL",
        "STALL",
        "POLISH",
        "POLISH_PATIENCE",
    ):
        assert float(found[f"DK_REFINE_{name}"]) == getattr(refine, f"_REFINE_{name}"), name
    for name in ("SETTLE",):
        assert float(found[f"DK_REFINE_{name}"]) == getattr(refine, f"_REFINE_{name}"), name
    assert float(found["DK_LOOSE_REACH"]) == refine._LOOSE_REACH
    assert float(found["DK_PI"]) == np.pi and float(found["DK_TWO_PI"]) == 2 * np.pi
    assert table(runtime, "DK_FREE_STEPS").tolist() == list(constants._FREE_STEPS)
    assert table(runtime, "DK_FOLD_SEEDS").tolist() == list(constants._FOLD_SEEDS)
    assert table(runtime, "DK_ANGLE_AT").tolist() == list(closed._ANGLE_AT)
    assert table(runtime, "DK_TAN_AT").tolist() == list(closed._TAN_AT)
    assert table(runtime, "DK_UA").tolist() == np.ravel(emit_c.unit_angle_table()).tolist()
    found = defines(gen)
    for name in ("RANK_TOL", "COND_LIMIT", "IMAG_TOL", "IMAG_LOOSE", "CLUSTER_TOL", "GOOD"):
        assert float(found[f"DK_RR_{name}"]) == getattr(constants, f"_RR_{name}"), name
    for name in ("NULL2_TOL", "NEWTON_STEPS", "NEWTON_REACH", "PAIR_TOL", "PAIR_ANGLE"):
        assert float(found[f"DK_RR_{name}"]) == getattr(constants, f"_RR_{name}"), name
    for name in (
        "SEARCH_FROM",
        "SEARCH_BAIL",
        "SEARCH_STEPS",
        "SEARCH_SLIDE",
        "PATH_STEPS",
        "SAME",
        "NEAR_SINGULAR",
        "PAIR_DOUBT",
        "FOLD_STEP",
    ):
        assert float(found[f"DK_RR_{name}"]) == getattr(constants, f"_RR_{name}"), name
    assert (float(found["DK_RR_NEWTON_DONE"]), float(found["DK_RR_NEWTON_DONE_STEP"])) == (
        constants._RR_NEWTON_DONE
    )
    assert (float(found["DK_RR_SHIFT4"]), float(found["DK_RR_SHIFT5"])) == constants._RR_SHIFT45
    assert table(gen, "DK_RR_MOEBIUS").tolist() == np.ravel(constants._RR_MOEBIUS).tolist()
    assert table(gen, "DK_RR_PATH").tolist() == list(constants._RR_PATH)
    for name, values in (
        ("DK_RR_H45", general._RR_H45),
        ("DK_RR_MIX", general._RR_MIX),
        ("DK_RR_MOTIONS", general._RR_MOTIONS),
        ("DK_RR_SEARCH_STARTS", general._RR_SEARCH_STARTS),
        ("DK_RR_MONOMIAL_RULES", np.array(general._RR_MONOMIAL_RULES)),
    ):
        assert table(gen, name).tolist() == np.ravel(values).tolist(), name


def test_routines_are_chosen_by_what_the_arms_code_uses():
    names = {n for p in c_runtime_pieces() for n in p.defines}
    assert {"dk_poly", "dk_cs1", "dk_general", "DK_UA", "dk_values"} <= names
    # a code that calls dk_cs1 gets it and what it calls, and nothing of the general method
    text = assemble_c("n = dk_cs1(&v, a, b, e, 1.0, 0.0);")
    assert "static int dk_cs1(" in text and "static double dk_uangle(" in text
    assert "DK_UA[DK_UA_COUNT]" in text and "dk_general" not in text and "dk_poly(" not in text
    # what the bundled arms' C holds is what their code uses: the PUMA's no general method
    puma = (GENERATED / "puma560_ik.c").read_text()
    manocha = (GENERATED / "manocha_canny_ik.c").read_text()
    assert "static int dk_general(" not in puma and "static int dk_general(" in manocha
    pieces = split_c("x", "/* a */\nstatic int f(int a)\n{\n    return g(a); /* } */\n}\n")
    assert [(sorted(p.defines), sorted(p.uses & {"g"})) for p in pieces] == [(["f"], ["g"])]


QUARTIC_PROBE = r"""
#include <stdio.h>
#include "runtime.c"
int main(void)
{
    double B, C, D, E;
    while (scanf("%lf %lf %lf %lf", &B, &C, &D, &E) == 4) {
        dk_cx z[4];
        int k;
        dk_quartic_real(B, C, D, E, z);
        for (k = 0; k < 4; k++) {
            printf("%.17g %.17g ", z[k].re, z[k].im);
        }
        printf("\n");
    }
    return 0;
}
"""


@needs_cc
def test_the_c_quartic_gives_the_companion_matrixs_roots(tmp_path):
    """dk_quartic_real called from C (derive/c/runtime.c compiled into a probe) against
    numpy's companion-matrix roots, as tests/test_runtime.py holds the Python one."""
    (tmp_path / "probe.c").write_text(QUARTIC_PROBE)
    include = str(C.joinpath("runtime.c")).rsplit("/", 1)[0]
    exe = tmp_path / "probe"
    subprocess.run(
        [c_compiler(), "-std=c99", "-O2", "-Wno-unused-function", f"-I{include}",
         str(tmp_path / "probe.c"), "-o", str(exe), "-lm"],
        check=True,
    )  # fmt: skip
    rng = np.random.default_rng(5)
    polys = rng.normal(size=(300, 5))
    polys /= polys[:, :1]
    text = "\n".join(" ".join(repr(float(x)) for x in p[1:]) for p in polys)
    out = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    for p, line in zip(polys, out.stdout.splitlines()):
        v = np.array([float(x) for x in line.split()])
        roots = v[0::2] + 1j * v[1::2]
        reference = np.roots(p)
        distance = np.abs(np.subtract.outer(roots, reference))
        assert distance.min(axis=0).max() <= 1e-8 and distance.min(axis=1).max() <= 1e-8
