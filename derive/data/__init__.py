"""Data derived once and shipped with the package (see derive.raghavan_roth)."""
