"""The C runtime of the generated C solvers, as real C files (runtime.c, general.c) that
compile on their own with standin.h; derive/emit_c.py writes them into derive_ik_runtime.h,
which every arm's C file includes, as derive/runtime/ is written into derive_ik_runtime.py."""
