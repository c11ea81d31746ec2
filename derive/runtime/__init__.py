"""The generated modules' runtime: every routine a generated solver calls that is not about
one arm, as ordinary Python that is linted, type-checked and tested here.

A generated module is standalone (math, numpy and ctypes): the emitter
(:mod:`derive.assemble`) copies into it the source of exactly the routines its arm's code
calls, with everything they call, in the order of :data:`MODULES`, and prints the names of
:mod:`derive.runtime.arm` from the arm's plan. In a generated module everything lives in one
namespace; here each module imports what it uses from the modules before it.

Modules, in copy order:

=============  ==========================================================================
``constants``  tolerances and settings (CERTIFY_TOL, BACKEND, the seam, ...)
``native``     the arm's C solver: compiled on first use into a per-user cache, loaded
               through ctypes
``api``        fk, fk_batch, ik, ik_batch, nearest, warmup: wrapping and dropping
               repeats, joint limits, the choice between the C and the Python solver
``common``     argument checks and joint-value helpers the others share
``redundant``  ik_sweep and the searching nearest of arms with free joints (copied only
               into their modules, whose nearest it replaces)
``task``       ik_position, ik_direction, ik_lookat and ik_pointing of arms solved for a
               task (tasks.py; copied only into their modules)
``motion``     jacobian and manipulability (the Jacobian derive/jacobian.py derives)
``closed``     closed forms of the Python solver (quadratic, quartic, atan2, Newton
               steps, the free-joint reach searches)
``general``    the general 6R method in the Python solver (numpy's eigensolver)
``scalar``     the Python solver's step routines (``a cos + b sin = e``, polynomials)
``refine``     Newton's steps onto the exact chain, for an arm whose closed form solves a
               nominal table near its own (derive/nominal.py)
=============  ==========================================================================

``arm`` is never copied: it stands in for the names each generated module prints for its
arm (DOF, LIMITS, the forward kinematics, the solver bodies), so that this package imports.
"""

MODULES = (
    "constants", "native", "api", "common", "redundant", "task", "motion", "closed", "general",
    "scalar", "refine",
)  # fmt: skip
