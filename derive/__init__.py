"""derive-ik: closed-form inverse kinematics derived from a DH table with SymPy.

The generator runs at build time; the modules it writes need only numpy and math.
"""
