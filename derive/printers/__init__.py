"""Printers of a plan's IK steps, one module per backend of the generated solver.

``common``  SymPy expressions as Python source, CSE, the steps' liveness
``scalar``  the Python solver (_ik_scalar): one loop per Solve step
``vector``  the numpy batch solver (_ik_candidates): one array axis per Solve step
``kernel``  the compiled solver (_ksolve): fixed-size results, numba's subset of Python

Every backend module has a ``SOLVES`` table with a printer for each kind in
:data:`derive.plan.SOLVE_KINDS` (a test checks it).
"""

BACKENDS = ("scalar", "vector", "kernel")
