"""Printers of a plan's IK steps: the Python solver and the C one.

``common``  SymPy expressions as Python source, CSE, the steps' liveness
``scalar``  the Python solver (_ik_scalar): one loop per Solve step
``c``       the C solver (dk_solve): fixed-size results, the same steps as the Python one
``general`` the general method's splits and _rr_fill, for the Python solver

The Python backend module has a ``SOLVES`` table with a printer for each kind in
:data:`derive.plan.SOLVE_KINDS` (a test checks it).
"""

BACKENDS = ("scalar",)
