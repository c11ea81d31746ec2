"""The jinja2 templates of the generated files (package data: read with importlib.resources)."""
