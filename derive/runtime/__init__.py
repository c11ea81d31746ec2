"""The generated modules' runtime: every routine a generated solver calls that is not about
one arm, as ordinary Python that is linted, type-checked and tested here.

The emitter (:mod:`derive.assemble`) writes these modules, in the order of :data:`MODULES`,
into one file, ``derive_ik_runtime.py``, beside the generated modules (math, numpy and ctypes
are all it imports). A generated module prints the names of :mod:`derive.runtime.arm` from its
arm's plan and then runs that file in its own namespace: there everything lives in one
namespace; here each module imports what it uses from the modules before it.

Modules, in copy order:

=============  ==========================================================================
``constants``  tolerances and settings (CERTIFY_TOL, BACKEND, the seam, ...)
``native``     the arm's C solver: compiled on first use into a per-user cache, loaded
               through ctypes
``api``        fk, fk_batch, ik, ik_batch, warmup, the nearest of fixed arms: wrapping and dropping
               repeats, joint limits, the choice between the C and the Python solver
``common``     argument checks and joint-value helpers the others share
``redundant``  nearest (searching the free joints of arms with them) and ik_sweep (offered
               by the modules of those arms only)
``task``       ik_position, ik_direction, ik_lookat and ik_pointing of arms solved for a
               task (tasks.py; offered by their modules only)
``motion``     jacobian and manipulability (the Jacobian derive/jacobian.py derives)
``closed``     closed forms of the Python solver (quadratic, quartic, atan2, Newton
               steps, the free-joint reach searches)
``general``    the general 6R method in the Python solver (numpy's eigensolver)
``scalar``     the Python solver's step routines (``a cos + b sin = e``, polynomials)
``refine``     Newton's steps onto the exact chain, for an arm whose closed form solves a
               nominal table near its own (derive/nominal.py)
=============  ==========================================================================

``arm`` is never written out: it stands in for the names each generated module prints for its
arm (DOF, LIMITS, the forward kinematics, the solver bodies), so that this package imports.
"""

MODULES = (
    "constants", "native", "api", "common", "redundant", "task", "motion", "closed", "general",
    "scalar", "refine",
)  # fmt: skip
