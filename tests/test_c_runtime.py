"""The C runtime as real C (derive/c/): it compiles on its own, every arm's C includes it as one
shared header (derive_ik_runtime.h), its constants are the Python runtime's,
and its routines answer as the Python ones when called from C."""

from __future__ import annotations

import re
import subprocess
from importlib import resources

import numpy as np
import pytest

from derive import emit_c
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
    for name in (
        "CLUSTER_TOL",
        "RESIDUAL_TOL",
        "SEAM",
        "SEAM_SNAP",
        "BRANCH_FOLD",
        "FOLD_NEAR",
        "FOLD_WIDTH",
    ):
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
        "CURVE_NEAR",
        "CURVE_FLAT",
        "CURVE_BEND",
        "STALL_NEAR",
        "CURVE_FLOOR",
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
    assert float(found["DK_TRIAL_SEED"]) == refine._TRIAL_SEED
    assert int(found["DK_TRIAL_PATIENCE"]) == refine._TRIAL_PATIENCE
    assert float(found["DK_PARTNER_NEAR"]) == refine._PARTNER_NEAR
    assert float(found["DK_PARTNER_FLOOR"]) == refine._PARTNER_FLOOR
    assert table(runtime, "DK_PARTNER_STEPS").tolist() == list(refine._PARTNER_STEPS)
    assert table(runtime, "DK_PARTNER_TURNS").tolist() == list(refine._PARTNER_TURNS)
    assert float(found["DK_PI"]) == np.pi and float(found["DK_TWO_PI"]) == 2 * np.pi
    assert table(runtime, "DK_FREE_STEPS").tolist() == list(constants._FREE_STEPS)
    assert table(runtime, "DK_FOLD_SEEDS").tolist() == list(constants._FOLD_SEEDS)
    assert table(runtime, "DK_ANGLE_AT").tolist() == list(closed._ANGLE_AT)
    assert table(runtime, "DK_TAN_AT").tolist() == list(closed._TAN_AT)
    assert table(runtime, "DK_UA").tolist() == np.ravel(emit_c.unit_angle_table()).tolist()
    found = defines(gen)
    for name in ("RANK_TOL", "COND_LIMIT", "IMAG_TOL", "IMAG_LOOSE", "CLUSTER_TOL", "GOOD"):
        assert float(found[f"DK_RR_{name}"]) == getattr(constants, f"_RR_{name}"), name
    for name in (
        "NULL2_TOL",
        "NEWTON_STEPS",
        "NEWTON_REACH",
        "PAIR_TOL",
        "PAIR_ANGLE",
        "DAMPED_FROM",
    ):
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
        "SINGULAR",
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


def test_every_arm_s_c_includes_one_runtime_header_holding_derive_c_as_it_is():
    """derive_ik_runtime.h holds derive/c/runtime.c and general.c's routines verbatim (the
    general method only for arms defining its tables); each arm's C includes it and checks
    its DK_RUNTIME; a header of another runtime is a compile error naming the file."""
    header = (GENERATED / "derive_ik_runtime.h").read_text()
    for name in ("runtime.c", "general.c"):
        body = c_text(name).split("*/", 1)[1]
        code = "\n".join(ln for ln in body.split("\n") if not ln.startswith("#include")).strip()
        assert code in header, name
    assert header.index("#ifdef DK_RR_SPLIT_COUNT") < header.index("static int dk_general(")
    digest = re.search(r"#define DK_RUNTIME 0x([0-9a-f]{12})", header)
    assert digest is not None
    for path in GENERATED.glob("*_ik.c"):
        text = path.read_text()
        assert '#include "derive_ik_runtime.h"' in text, path.name
        assert f"#if DK_RUNTIME != 0x{digest.group(1)}" in text, path.name
        assert "static int dk_cs1(" not in text, path.name  # (the routines are the header's)


@needs_cc
def test_an_arm_s_c_with_another_runtime_header_says_so_when_compiled(tmp_path):
    for name in ("planar_2r_ik.c", "planar_2r_ik.h", "derive_ik_runtime.h"):
        (tmp_path / name).write_text((GENERATED / name).read_text())
    header = tmp_path / "derive_ik_runtime.h"
    header.write_text(re.sub(r"DK_RUNTIME 0x\w+", "DK_RUNTIME 0x1", header.read_text()))
    source = str(tmp_path / "planar_2r_ik.c")
    flags = [*WARNINGS, "-c", "-o", str(tmp_path / "x.o")]
    done = subprocess.run([c_compiler(), *flags, source], capture_output=True, text=True)
    assert done.returncode != 0
    assert "derive_ik_runtime.h is another derive-ik's" in done.stderr


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
