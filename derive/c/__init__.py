"""The C runtime of the generated C solvers, as real C files (runtime.c, general.c) that
compile on their own with standin.h; derive/assemble.py (split_c, assemble_c) copies into an
arm's C file the routines its code uses, as derive/runtime/ is copied into its Python module."""
